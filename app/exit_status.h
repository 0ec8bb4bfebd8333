// imufit — the exit statuses of the `imufit` program, once: the program's help is derived from this
// table, and cli_test checks that docs/spec.md section 4 ("Exit statuses") lists the same ones.
// io/ throws InputError (2), fit/ reports through its summary, and app/ maps them here.
#ifndef IMUFIT_APP_EXIT_STATUS_H_
#define IMUFIT_APP_EXIT_STATUS_H_

#include <string>

namespace imufit {

inline constexpr int kExitDone = 0;
// The job could not be done (the fit did not converge, the data do not determine the model, ...).
inline constexpr int kExitNotDone = 1;
// A bad invocation or bad input: an unknown option, a missing or malformed file.
inline constexpr int kExitBadInput = 2;
// The job was done, but a unit failed its acceptance limits (or, in a batch, could not be fitted);
// plan check and design: a tolerance cannot be met.
inline constexpr int kExitFailedLimits = 3;

struct ExitStatusEntry {
  int status;
  const char* meaning;  // in the program's help
};
inline constexpr ExitStatusEntry kExitStatuses[] = {
    {kExitDone, "done"},
    {kExitNotDone, "the job could not be done"},
    {kExitBadInput, "bad invocation or bad input"},
    {kExitFailedLimits, "done but acceptance limits failed"},
};

// "0 done, 1 the job could not be done, 2 bad invocation or bad input, 3 done but ...".
inline std::string ExitStatusText() {
  std::string text;
  for (const ExitStatusEntry& e : kExitStatuses) {
    text += (text.empty() ? "" : ", ") + std::to_string(e.status) + " " + e.meaning;
  }
  return text;
}

}  // namespace imufit

#endif  // IMUFIT_APP_EXIT_STATUS_H_
