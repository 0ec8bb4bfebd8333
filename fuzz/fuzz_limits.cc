// Fuzzes the acceptance-limits reader. Oracle: an accepted file has criteria, each with a
// positive limit or a [lo, hi] range with lo < hi, and known axes.
#include <cmath>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  Limits limits;
  try {
    limits = ReadLimits(fuzz::WriteInput(data, size, ".yaml"));
  } catch (const InputError&) {
    return 0;
  }
  IMUFIT_FUZZ_CHECK(!limits.criteria.empty(), "a limits file has criteria");
  for (const LimitCriterion& c : limits.criteria) {
    if (c.kind == LimitKind::kCoverage) {
      IMUFIT_FUZZ_CHECK(c.covers_c[0] < c.covers_c[1], "covers [lo, hi] with lo < hi");
    } else {
      IMUFIT_FUZZ_CHECK(c.max_abs > 0.0 && std::isfinite(c.max_abs), "a positive finite limit");
    }
  }
  return 0;
}
