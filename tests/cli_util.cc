#include "cli_util.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace imufit::testing {

namespace {

// `value` as the command line takes it, to the last bit.
std::string Number(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::vector<std::string> Split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, separator)) fields.push_back(field);
  if (!line.empty() && line.back() == separator) fields.emplace_back();
  return fields;
}

}  // namespace

int Table::Column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

double Table::Number(size_t row, const std::string& name) const { return std::stod(rows[row][Column(name)]); }

Eigen::Vector3d Table::Vector(size_t row, const std::string& prefix) const {
  return Eigen::Vector3d(Number(row, prefix + "_x"), Number(row, prefix + "_y"), Number(row, prefix + "_z"));
}

Table ReadTable(const std::string& path) {
  Table table;
  std::stringstream lines(ReadFile(path));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (table.header.empty()) {
      table.header = Split(line, ',');
    } else {
      table.rows.push_back(Split(line, ','));
    }
  }
  return table;
}

RunResult CliTest::Run(const std::vector<std::string>& args) const { return RunProgram(IMUFIT_EXE, args); }

RunResult CliTest::RunWithFileSizeLimit(const std::vector<std::string>& args, rlim_t max_file_bytes) const {
  return RunProgramWithFileSizeLimit(IMUFIT_EXE, args, max_file_bytes);
}

std::vector<std::string> CliTest::SmallRunArgs(const std::string& out,
                                               const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"simulate",
                                   "--plan=" + Fixture("plan_6pos.yaml"),
                                   "--calibration=" + Fixture("mems_truth.yaml"),
                                   "--output=" + out,
                                   "--rate=10",
                                   "--dwell=3",
                                   "--temps=-20,5,30,60",
                                   "--gyro-noise-density=2e-4",
                                   "--accel-noise-density=2e-3",
                                   "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::vector<std::string> CliTest::HandSessionArgs(const std::string& out,
                                                  const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"simulate",
                                   "--plan=" + Fixture("plan_hand_6faces_3turns.yaml"),
                                   "--calibration=" + Fixture("mems_truth.yaml"),
                                   "--output=" + out,
                                   "--temps=25",
                                   "--rate=100",
                                   "--dwell=10",
                                   "--transition=2",
                                   "--gyro-noise-density=8.7e-5",
                                   "--accel-noise-density=1.5e-3",
                                   "--quantize",
                                   "--no-segment-column",
                                   "--time-jitter-s=0.003",
                                   "--seed=4",
                                   "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::string CliTest::StaticPlan() const {
  return Write("static.yaml",
               "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
               "  - {id: 1, up: [0, 0, 1]}\n");
}

std::string CliTest::StaticRun(const std::string& out, int dwell_s, int temp_c, int seed) const {
  const RunResult r = Run({"simulate",
                           "-p",
                           StaticPlan(),
                           "-c",
                           Fixture("mems_truth.yaml"),
                           "-o",
                           Path(out),
                           "--rate",
                           "100",
                           "--dwell",
                           std::to_string(dwell_s),
                           "--temps",
                           std::to_string(temp_c),
                           "--gyro-noise-density",
                           Number(kStaticGyroNoiseDensity),
                           "--accel-noise-density",
                           Number(kStaticAccelNoiseDensity),
                           "--seed",
                           std::to_string(seed),
                           "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  return Path(out);
}

std::pair<std::string, std::string> CliTest::SimulateNoiseless(const std::string& plan,
                                                               const std::string& calibration,
                                                               const std::string& stem,
                                                               const std::vector<std::string>& extra) const {
  const std::string samples = Path(stem + ".csv");
  const std::string truth = Path(stem + "_truth.csv");
  std::vector<std::string> args = {"simulate", "--plan", plan,      "--calibration", calibration,
                                   "-o",       samples,  "--truth", truth,           "--quiet"};
  for (const auto& [option, value] :
       {std::pair<std::string, std::string>{"--rate", "20"}, {"--dwell", "1"}, {"--transition", "0.75"}}) {
    if (std::find(extra.begin(), extra.end(), option) == extra.end()) {
      args.push_back(option);
      args.push_back(value);
    }
  }
  args.insert(args.end(), extra.begin(), extra.end());
  const RunResult r = Run(args);
  EXPECT_EQ(r.status, 0) << r.err;
  return {samples, truth};
}

void CliTest::ExpectRecovered(const std::string& corrected, const std::string& truth_path) {
  const Table got = ReadTable(corrected);
  const Table truth = ReadTable(truth_path);
  ASSERT_EQ(got.header, truth.header);
  ASSERT_EQ(got.rows.size(), truth.rows.size());
  ASSERT_GT(got.rows.size(), 0u);
  double worst_gyro = 0.0;
  double worst_accel = 0.0;
  for (size_t i = 0; i < got.rows.size(); ++i) {
    ASSERT_EQ(got.rows[i][0], truth.rows[i][0]) << "time_s, row " << i;
    ASSERT_EQ(got.rows[i][1], truth.rows[i][1]) << "temp_c, row " << i;
    worst_gyro =
        std::max(worst_gyro, (got.Vector(i, "gyro") - truth.Vector(i, "gyro")).cwiseAbs().maxCoeff());
    worst_accel =
        std::max(worst_accel, (got.Vector(i, "accel") - truth.Vector(i, "accel")).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst_gyro, kRecoveryToleranceSi) << "rad/s";
  EXPECT_LE(worst_accel, kRecoveryToleranceSi) << "m/s^2";
}

}  // namespace imufit::testing
