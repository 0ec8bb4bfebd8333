// Fuzzes the plan reader and the hand procedure reader (the other file `plan check` reads). Oracle:
// an accepted plan has at least one segment, unique ids, unit `up` vectors, a north (when given)
// perpendicular to up, finite numbers and Earth's gravity; an accepted hand procedure at least 9
// poses, unit `up` vectors, twist axes among x, y, z, ordered angle ranges and finite numbers.
#include <cmath>
#include <set>
#include <string>

#include "fuzz_util.h"
#include "imufit/io/error.h"
#include "imufit/io/hand_procedure.h"
#include "imufit/io/plan.h"

namespace {

void CheckHandProcedure(const std::string& path) {
  using namespace imufit;
  HandProcedure hand;
  try {
    hand = ReadHandProcedure(path);
  } catch (const InputError&) {
    return;
  }
  IMUFIT_FUZZ_CHECK(hand.poses >= 9, "at least 9 poses");
  IMUFIT_FUZZ_CHECK(hand.dwell_s >= 1.0 && hand.turn_s > 0.0 && hand.rate_hz > 0.0, "positive durations");
  for (const Eigen::Vector3d& up : hand.up) {
    IMUFIT_FUZZ_CHECK(std::abs(up.norm() - 1.0) < 1e-12, "up is a unit vector");
  }
  for (int axis : hand.twist_axes) IMUFIT_FUZZ_CHECK(axis >= 0 && axis <= 2, "twist axes are x, y, z");
  IMUFIT_FUZZ_CHECK(hand.tilt_deg[0] <= hand.tilt_deg[1] && hand.twist_deg[0] <= hand.twist_deg[1],
                    "angle ranges are ordered");
  IMUFIT_FUZZ_CHECK(
      std::isfinite(hand.temp_c) && std::isfinite(hand.warmup_c) && std::isfinite(hand.height_m),
      "finite numbers");
  IMUFIT_FUZZ_CHECK(!(hand.gravity_mps2 && hand.latitude_deg), "gravity given once");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  const std::string path = fuzz::WriteInput(data, size, ".yaml");
  CheckHandProcedure(path);
  Plan plan;
  try {
    plan = ReadPlan(path);
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
