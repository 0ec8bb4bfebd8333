// `imufit export` as a command: the refusal of a lossy export beyond --max-loss (exit 1, one line
// saying by how much, nothing written), bad invocations and calibrations that cannot be exported
// (exit 2 or 1, nothing written). The exporters' output itself (golden files, round trips through
// each consumer's equations, the JSON read back) is export_test's.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

TEST_F(CliTest, ExportRefusesALossyExportBeyondMaxLossSayingByHowMuch) {
  // The driver's scale of the MEMS unit (fixtures/README.md): 16.4 LSB per deg/s, 2048 LSB per g.
  std::vector<std::string> px4 = {"export",
                                  "-c",
                                  Fixture("mems_truth.yaml"),
                                  "-f",
                                  "px4",
                                  "-o",
                                  Path("unit.params"),
                                  "--device-id",
                                  "7",
                                  "--gyro-raw-per-radps",
                                  "939.65",
                                  "--accel-raw-per-mps2",
                                  "208.838"};
  const RunResult refused = Run(px4);
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("px4 export refused: the gyro's worst-case loss"), std::string::npos)
      << refused.err;
  EXPECT_NE(refused.err.find("exceeds the bound 0.5 deg/s by "), std::string::npos) << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_FALSE(fs::exists(Path("unit.params")));
  // Within a looser bound, it is written.
  px4.insert(px4.end(), {"--max-loss", "20,50"});
  const RunResult written = Run(px4);
  EXPECT_EQ(written.status, 0) << written.err;
  EXPECT_TRUE(fs::exists(Path("unit.params")));
  // The C runtime's float build loses far less than any sensible bound.
  EXPECT_EQ(Run({"export", "-c", Fixture("mems_truth.yaml"), "-f", "c", "-o", Path("unit.h"), "--max-loss",
                 "0.001,0.01"})
                .status,
            0);
}

TEST_F(CliTest, ExportBadInvocationsAndUnexportableCalibrations) {
  const std::string cal = Fixture("mems_truth.yaml");
  RunResult r = Run({"export", "-c", cal, "-f", "px4", "-o", Path("x.params")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--device-id"), std::string::npos) << r.err;
  r = Run({"export", "-c", cal, "-f", "mavlink", "-o", Path("x")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("c, bin, px4, ardupilot, kalibr, imucal, json"), std::string::npos) << r.err;
  r = Run({"export", "-c", cal, "-f", "kalibr", "-o", Path("x.yaml"), "--force"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("noise.kalibr.accelerometer_noise_density"), std::string::npos) << r.err;
  r = Run({"export", "-c", cal, "-f", "c", "-o", Path("x.h"), "--c-name", "2bad"});
  EXPECT_EQ(r.status, 2);
  r = Run({"export", "-c", cal, "-f", "json", "-o", Path("x.json"), "--full-scale-dps", "-5"});
  EXPECT_EQ(r.status, 2);
  r = Run({"export", "-c", cal, "-f", "ardupilot", "-o", Path("x.parm"), "--gyro-raw-per-radps", "0"});
  EXPECT_EQ(r.status, 2);
  r = Run({"export", "-c", cal, "-f", "imucal", "-o", Path("x.json"), "--temp-c", "100"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("outside the calibration's fitted range [-40, 85] degC"), std::string::npos) << r.err;
  std::ofstream(Path("broken.yaml")) << "format: imufit-calibration\nversion: 1\ngyro: [1, 2\n";
  r = Run({"export", "-c", Path("broken.yaml"), "-f", "json", "-o", Path("x.json")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("broken.yaml:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("x.json")));
  r = Run({"export", "-c", cal, "-f", "json", "-o", cal});
  EXPECT_EQ(r.status, 2) << "an output that names the input is refused";
}

}  // namespace
}  // namespace imufit::testing
