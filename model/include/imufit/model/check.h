// imufit — always-on invariant checks.
//
// IMUFIT_CHECK(condition, message) aborts with the source location, the condition's text and the
// message when `condition` is false, in every build (unlike assert, which Release builds compile
// out). It is for programmer errors only — wrong sizes, a broken internal promise — as Ceres's
// CHECK is; bad input is an InputError (io/) and undeterminable data a FitStatus (fit/).
//
//   IMUFIT_CHECK(free.size() == jacobian.cols(), "one Jacobian column per free parameter");
#ifndef IMUFIT_MODEL_CHECK_H_
#define IMUFIT_MODEL_CHECK_H_

#include <cstdio>
#include <cstdlib>

namespace imufit::internal {

[[noreturn]] inline void CheckFailed(const char* file, int line, const char* condition, const char* message) {
  std::fprintf(stderr, "imufit: internal error at %s:%d: check failed: %s (%s)\n", file, line, condition,
               message);
  std::fflush(stderr);
  std::abort();
}

}  // namespace imufit::internal

#define IMUFIT_CHECK(condition, message)                                                        \
  do {                                                                                          \
    if (!(condition)) ::imufit::internal::CheckFailed(__FILE__, __LINE__, #condition, message); \
  } while (false)

#endif  // IMUFIT_MODEL_CHECK_H_
