// `imufit allan` on raw counts and millisecond timestamps (the fixture of cli_factory_util.h); part of
// cli_allan_test.
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_factory_util.h"

namespace imufit {
namespace {

using testing::RunResult;

// imufit allan on raw counts or millisecond timestamps says so; --scale and --time-unit silence it.
TEST_F(FactoryCliTest, AllanWarnsOnRawCountsAndMillisecondTimestamps) {
  const std::string plan = Write("static_plan.yaml",
                                 "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
                                 "  - {id: 1, up: [0, 0, 1]}\n");
  RunResult r =
      Run({"simulate", "--plan", plan, "--calibration", kFixtures + "/mems_truth.yaml", "-o",
           Path("static.csv"), "--rate", "10", "--dwell", "120", "--temps", "25", "--seed", "9", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"allan", "-s", Path("static.csv"), "-c", "gyro_x", "-o", Path("a.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("gyro_x has a mean of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("raw counts"), std::string::npos) << r.err;
  r = Run(
      {"allan", "-s", Path("static.csv"), "-c", "gyro_x", "-o", Path("b.csv"), "-q", "--scale", "939.65"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // The same log with time_s in milliseconds.
  std::string text = ReadBytes(Path("static.csv"));
  std::string ms = "time_s,gyro_x\n";
  std::istringstream lines(text);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("time_s", 0) == 0) continue;
    ms += std::to_string(100 * n++) + ",0.001\n";
  }
  Write("ms.csv", ms);
  r = Run({"allan", "-s", Path("ms.csv"), "-c", "gyro_x", "-o", Path("c.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("--time-unit ms"), std::string::npos) << r.err;
  r = Run({"allan", "-s", Path("ms.csv"), "-c", "gyro_x", "-o", Path("d.csv"), "-q", "--time-unit", "ms"});
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(ReadBytes(Path("d.csv")).find("gyro_x,oadev,0.1,"), std::string::npos);
}

}  // namespace
}  // namespace imufit
