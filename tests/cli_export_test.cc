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
  // The refusal names every option that changes it: the bound, the envelope, --force.
  for (const char* option : {"--max-loss", "--force", "--envelope-temp-c", "--full-scale-dps", "--max-g"}) {
    EXPECT_NE(refused.err.find(option), std::string::npos) << option << ": " << refused.err;
  }
  // The loss printed names where each bound of the envelope comes from.
  EXPECT_NE(refused.out.find("(the calibration's fitted range; --envelope-temp-c)"), std::string::npos)
      << refused.out;
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
  const std::vector<std::string> driver = {"--gyro-raw-per-radps", "939.65", "--accel-raw-per-mps2",
                                           "208.838"};
  const auto run = [&](std::vector<std::string> args, const std::vector<std::string>& more = {}) {
    args.insert(args.end(), more.begin(), more.end());
    return Run(args);
  };
  RunResult r = run({"export", "-c", cal, "-f", "px4", "-o", Path("x.params")}, driver);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--device-id"), std::string::npos) << r.err;
  r = run({"export", "-c", cal, "-f", "mavlink", "-o", Path("x")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("c, bin, px4, ardupilot, kalibr, imucal, json"), std::string::npos) << r.err;
  r = run({"export", "-c", cal, "-f", "kalibr", "-o", Path("x.yaml"), "--force"}, driver);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("noise.kalibr.accelerometer_noise_density"), std::string::npos) << r.err;
  r = run({"export", "-c", cal, "-f", "c", "-o", Path("x.h"), "--c-name", "2bad"});
  EXPECT_EQ(r.status, 2);
  r = run({"export", "-c", cal, "-f", "json", "-o", Path("x.json"), "--full-scale-dps", "-5"});
  EXPECT_EQ(r.status, 2);
  r = run({"export", "-c", cal, "-f", "ardupilot", "-o", Path("x.parm"), "--gyro-raw-per-radps", "0"});
  EXPECT_EQ(r.status, 2);
  r = run({"export", "-c", cal, "-f", "imucal", "-o", Path("x.json"), "--temp-c", "100"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("outside the calibration's fitted range [-40, 85] degC"), std::string::npos) << r.err;
  std::ofstream(Path("broken.yaml")) << "format: imufit-calibration\nversion: 1\ngyro: [1, 2\n";
  r = run({"export", "-c", Path("broken.yaml"), "-f", "json", "-o", Path("x.json")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("broken.yaml:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("x.json")));
  r = run({"export", "-c", cal, "-f", "json", "-o", cal});
  EXPECT_EQ(r.status, 2) << "an output that names the input is refused";
  for (const char* file : {"x.params", "x.yaml", "x.h", "x.parm"})
    EXPECT_FALSE(fs::exists(Path(file))) << file;
}

// The autopilots' device IDs and instances, the envelope's temperatures and a unit in counts
// exported with the default driver scale: each refusal (exit 2, nothing written) names the option.
// --noise: the noise block of `imufit allan --noise-yaml` as if appended (the same file as the block
// appended by hand); refused with a calibration that has a block of its own, warned about when the
// block was measured through another calibration.
TEST_F(CliTest, ExportTakesTheNoiseBlockOfItsOwnFile) {
  const std::string cal = Fixture("mems_truth.yaml");
  const std::vector<std::string> kalibr = {
      "-f", "kalibr", "--gyro-raw-per-radps", "939.65", "--accel-raw-per-mps2", "208.838", "--force", "-q"};
  const std::string static_run = StaticRun("static.csv", 300, 25, 7);
  const std::string noise = Path("noise.yaml");
  ASSERT_EQ(Run({"allan", "-q", "-s", static_run, "--calibration", cal, "-o", Path("allan.csv"), "--columns",
                 "gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z", "--noise-yaml", noise})
                .status,
            0);
  std::vector<std::string> args = {"export", "-c", cal, "--noise", noise, "-o", Path("given.yaml")};
  args.insert(args.end(), kalibr.begin(), kalibr.end());
  RunResult r = Run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("measured through another calibration"), std::string::npos) << r.err;
  std::ifstream truth(cal), block(noise);
  const std::string appended = Path("appended.yaml");
  std::ofstream(appended) << truth.rdbuf() << block.rdbuf();
  args = {"export", "-c", appended, "-o", Path("by_hand.yaml")};
  args.insert(args.end(), kalibr.begin(), kalibr.end());
  ASSERT_EQ(Run(args).status, 0);
  // The same Kalibr content; the provenance comment names the calibration file given.
  const auto content = [](const std::string& path) {
    std::ifstream in(path);
    std::string line, text;
    while (std::getline(in, line))
      if (line.rfind("#", 0) != 0) text += line + "\n";
    return text;
  };
  EXPECT_EQ(content(Path("given.yaml")), content(Path("by_hand.yaml")));
  EXPECT_NE(content(Path("given.yaml")).find("gyroscope_noise_density"), std::string::npos);
  args = {"export", "-c", appended, "--noise", noise, "-o", Path("both.yaml")};
  args.insert(args.end(), kalibr.begin(), kalibr.end());
  r = Run(args);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--noise: the calibration " + appended + " has a noise: block of its own"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(Path("both.yaml")));
  // Measured through another calibration of the unit: written, with a warning.
  args = {"export", "-c", Fixture("golden/mems_6pos_soak.yaml"), "--noise", noise, "-o", Path("other.yaml")};
  args.insert(args.end(), kalibr.begin(), kalibr.end());
  r = Run(args);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the noise was measured through another calibration"), std::string::npos) << r.err;
}

TEST_F(CliTest, ExportRefusalsNameTheOptionThatChangesThem) {
  const std::string cal = Fixture("mems_truth.yaml");
  const std::vector<std::string> driver = {"--gyro-raw-per-radps", "939.65", "--accel-raw-per-mps2",
                                           "208.838"};
  struct Case {
    std::string format;
    std::vector<std::string> args;
    std::string named;
  };
  const std::vector<Case> cases = {
      {"ardupilot", {}, "imufit: --device-id: a ardupilot export needs the sensors' device IDs"},
      {"px4", {"--gyro-device-id", "5"}, "imufit: --accel-device-id: "},
      {"px4", {"--device-id", "5", "--instance", "4"}, "imufit: --instance: \"4\" is not an instance 0..3"},
      {"ardupilot",
       {"--device-id", "5", "--instance", "0"},
       "imufit: --instance: 0 is not an instance of ardupilot (1..3)"},
      {"px4", {"--device-id", "4294967296"}, "imufit: --device-id: \"4294967296\" is not a 32-bit device ID"},
      {"json", {"--device-id", "5"}, "imufit: --device-id: only px4, ardupilot use it, not json"},
      {"c", {"--instance", "1"}, "imufit: --instance: only px4, ardupilot use it, not c"},
      {"imucal",
       {"--envelope-temp-c", "20,100"},
       "imufit: --envelope-temp-c: 20,100 degC is not a range MIN,MAX inside "
       "the calibration's fitted range [-40, 85] degC"},
      {"imucal", {"--envelope-temp-c", "30,20"}, "imufit: --envelope-temp-c: 30,20 degC is not a range"},
      {"kalibr",
       {},
       "imufit: --gyro-raw-per-radps: the calibration's scale at its reference temperature is 941.233 "
       "raw per rad/s, 941.2 times --gyro-raw-per-radps 1"},
      {"px4",
       {"--device-id", "5", "--gyro-raw-per-radps", "939.65"},
       "imufit: --accel-raw-per-mps2: the calibration's scale at its reference temperature is 209.257 raw "
       "per m/s^2"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"export", "-c", cal, "-f", c.format, "-o", Path("x.out")};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const bool driver_given = std::find(args.begin(), args.end(), "--gyro-raw-per-radps") != args.end();
    if ((c.format == "px4" || c.format == "ardupilot") && !driver_given)
      args.insert(args.end(), driver.begin(), driver.end());
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << c.named;
    EXPECT_EQ(r.err.rfind(c.named, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(Path("x.out")));
  }
}

// A missing output folder fails before anything is measured or printed: no loss on stdout.
TEST_F(CliTest, ExportToAMissingFolderFailsBeforePrintingTheLoss) {
  const RunResult r = Run({"export", "-c", Fixture("mems_truth.yaml"), "-f", "imucal", "-o",
                           Path("no/such/folder/unit.json"), "--force"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no/such/folder"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "") << "the loss was printed before the error";
}

}  // namespace
}  // namespace imufit::testing
