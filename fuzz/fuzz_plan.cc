// Fuzzes the plan reader. Oracle: an accepted plan has at least one segment, unique ids, unit
// `up` vectors, a north (when given) perpendicular to up, finite numbers and Earth's gravity.
#include <cmath>
#include <set>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/plan.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  Plan plan;
  try {
    plan = ReadPlan(fuzz::WriteInput(data, size, ".yaml"));
  } catch (const InputError&) {
    return 0;
  }
  IMUFIT_FUZZ_CHECK(!plan.segments.empty(), "a plan has segments");
  IMUFIT_FUZZ_CHECK(plan.site.gravity_mps2 >= 9.7 && plan.site.gravity_mps2 <= 9.9, "gravity on Earth");
  std::set<int> ids;
  for (const TableSegment& segment : plan.segments) {
    IMUFIT_FUZZ_CHECK(ids.insert(segment.id).second, "ids are unique");
    IMUFIT_FUZZ_CHECK(std::abs(segment.up.norm() - 1.0) < 1e-12, "up is a unit vector");
    IMUFIT_FUZZ_CHECK(std::isfinite(segment.rate_radps), "the rate is finite");
    if (segment.north) {
      IMUFIT_FUZZ_CHECK(std::abs(segment.north->norm() - 1.0) < 1e-12, "north is a unit vector");
      IMUFIT_FUZZ_CHECK(std::abs(segment.north->dot(segment.up)) < 1e-9, "north is horizontal");
    }
    if (segment.lever_arm_m) IMUFIT_FUZZ_CHECK(segment.lever_arm_m->allFinite(), "the lever arm is finite");
  }
  return 0;
}
