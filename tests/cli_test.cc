// End-to-end tests of the `imufit` command (docs/spec.md section 4): the built program (IMUFIT_EXE) is
// run on fixtures (IMUFIT_FIXTURES_DIR) and on files written into a fresh temporary folder per
// test, never the working directory.
//
// The key acceptance test: a run simulated without noise from a known calibration, corrected by
// `imufit apply` with that calibration, gives back the true rate and specific force of every
// sample, transitions included, to kRecoveryToleranceSi. It is done twice: on `imufit simulate`'s
// own output and truth, and on samples this file computes with its own forward model written
// from docs/spec.md (it reads the calibration with yaml-cpp, not with imufit's reader), so that
// neither the simulator nor imufit's reader and model are checked only against themselves.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Dense>

#include "imufit/io/sha256.h"
#include "imufit/model/sensor_model.h"
#include "run_program.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::ReadBytes;
using testing::RunProgram;
using testing::RunResult;

// Worst-case absolute error of a recovered rate (rad/s) or specific force (m/s^2).
constexpr double kRecoveryToleranceSi = 1e-9;
// Worst-case relative difference between two forward models that do the same arithmetic in a
// different order.
constexpr double kForwardAgreementRelative = 1e-12;
// Earth's rotation rate, rad/s, as docs/spec.md section 2 states it.
constexpr double kEarthRate = 7.292115e-5;
constexpr double kDegToRad = M_PI / 180.0;

const std::string kFixtures = IMUFIT_FIXTURES_DIR;

std::string Fixture(const std::string& name) { return kFixtures + "/" + name; }

// Reads a file, decompressing it when it is gzip (zlib passes other files through unchanged).
std::string ReadFile(const std::string& path) {
  gzFile file = gzopen(path.c_str(), "rb");
  if (file == nullptr) return "<cannot open " + path + ">";
  std::string text;
  char block[1 << 16];
  int n = 0;
  while ((n = gzread(file, block, sizeof block)) > 0) text.append(block, n);
  gzclose(file);
  return text;
}

// A CSV file split into its header and rows ('#' lines skipped), for checking outputs.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  int Column(const std::string& name) const {
    for (size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  double Number(size_t row, const std::string& name) const { return std::stod(rows[row][Column(name)]); }
  Eigen::Vector3d Vector(size_t row, const std::string& prefix) const {
    return Eigen::Vector3d(Number(row, prefix + "_x"), Number(row, prefix + "_y"),
                           Number(row, prefix + "_z"));
  }
};

std::vector<std::string> Split(const std::string& line, char separator) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, separator)) fields.push_back(field);
  if (!line.empty() && line.back() == separator) fields.emplace_back();
  return fields;
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

std::string FormatExactly(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// ------------------------------------------------------------------------------------------
// A forward model written from docs/spec.md section 1, independent of imufit's reader and model:
//   B = diag(S_g) inv(M_g) omega + V_g + H a,   A = diag(S_a) inv(M_a) a + V_a,
// every coefficient c0 + c1 dT + c2 dT^2 + c3 dT^3 with dT = T - reference_temp_c.
class SpecForwardModel {
 public:
  explicit SpecForwardModel(const std::string& calibration_path) {
    const YAML::Node root = YAML::LoadFile(calibration_path);
    reference_c_ = root["reference_temp_c"] ? root["reference_temp_c"].as<double>() : 25.0;
    gyro_ = root["gyro"];
    accel_ = root["accel"];
  }

  // The calibration's coefficient `group`.`name` (e.g. "bias", "x") at temp_c.
  static double Coefficient(const YAML::Node& sensor, const std::string& group, const std::string& name,
                            double dT) {
    const YAML::Node c = sensor[group][name];
    EXPECT_EQ(c.size(), 4u) << group << "." << name;
    return c[0].as<double>() + c[1].as<double>() * dT + c[2].as<double>() * dT * dT +
           c[3].as<double>() * dT * dT * dT;
  }

  Eigen::Vector3d Raw(const YAML::Node& sensor, double temp_c, const Eigen::Vector3d& truth,
                      const Eigen::Vector3d& specific_force, bool with_g_sensitivity) const {
    const double dT = temp_c - reference_c_;
    const char* axes[3] = {"x", "y", "z"};
    Eigen::Vector3d bias;
    Eigen::Vector3d scale;
    Eigen::Matrix3d misalignment = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d g_sensitivity = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) {
      bias(i) = Coefficient(sensor, "bias", axes[i], dT);
      scale(i) = Coefficient(sensor, "scale", axes[i], dT);
      for (int j = 0; j < 3; ++j) {
        const std::string name = std::string(axes[i]) + axes[j];  // row i, column j
        if (i != j) misalignment(i, j) = Coefficient(sensor, "misalignment", name, dT);
        if (with_g_sensitivity) g_sensitivity(i, j) = Coefficient(sensor, "g_sensitivity", name, dT);
      }
    }
    const Eigen::Vector3d sensor_frame = misalignment.fullPivLu().inverse() * truth;
    return scale.asDiagonal() * sensor_frame + bias + g_sensitivity * specific_force;
  }

  Eigen::Vector3d Gyro(double temp_c, const Eigen::Vector3d& omega, const Eigen::Vector3d& a) const {
    return Raw(gyro_, temp_c, omega, a, true);
  }
  Eigen::Vector3d Accel(double temp_c, const Eigen::Vector3d& a) const {
    return Raw(accel_, temp_c, a, Eigen::Vector3d::Zero(), false);
  }

  // The same coefficients in imufit's parameter layout (sensor_model.h), to cross-check the
  // model header's forward form against this one.
  SensorModel ToSensorModel() const {
    SensorModel model;
    model.basis.center_c = reference_c_;
    Fill(gyro_, kGyroCoefficients, model.gyro.data());
    Fill(accel_, kAccelCoefficients, model.accel.data());
    return model;
  }

 private:
  static void Fill(const YAML::Node& sensor, int coefficients, double* params) {
    for (int i = 0; i < coefficients; ++i) {
      const YAML::Node c = sensor[kCoefficientNames[i].group][kCoefficientNames[i].axis];
      for (int k = 0; k < kPolynomialTerms; ++k) params[i * kPolynomialTerms + k] = c[k].as<double>();
    }
  }

  double reference_c_ = 25.0;
  YAML::Node gyro_;
  YAML::Node accel_;
};

// The truth of a plan's dwell segments, written from docs/spec.md section 2 (rad/s, m/s^2, body).
std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> SpecTruthOfPlan(const std::string& plan_path) {
  const YAML::Node plan = YAML::LoadFile(plan_path);
  const auto vector = [](const YAML::Node& v) {
    return Eigen::Vector3d(v[0].as<double>(), v[1].as<double>(), v[2].as<double>());
  };
  const double g = plan["gravity_mps2"].as<double>();
  const bool has_latitude = static_cast<bool>(plan["latitude_deg"]);
  const double phi = has_latitude ? plan["latitude_deg"].as<double>() * kDegToRad : 0.0;
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> truth;
  for (const YAML::Node& segment : plan["segments"]) {
    const Eigen::Vector3d up = vector(segment["up"]).normalized();
    const double rate = segment["rate_dps"] ? segment["rate_dps"].as<double>() * kDegToRad : 0.0;
    Eigen::Vector3d omega = rate * up;
    if (has_latitude) {
      omega += kEarthRate * std::sin(phi) * up;
      if (rate == 0.0 && segment["north"])
        omega += kEarthRate * std::cos(phi) * vector(segment["north"]).normalized();
    }
    Eigen::Vector3d a = g * up;
    if (rate != 0.0 && segment["lever_arm_m"]) {
      const Eigen::Vector3d r = vector(segment["lever_arm_m"]);
      a -= rate * rate * (r - up * r.dot(up));
    }
    truth[segment["id"].as<int>()] = {omega, a};
  }
  return truth;
}

// ------------------------------------------------------------------------------------------

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("imufit_cli_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
    work_ = dir_ / "work";
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // A path in this test's work folder (where outputs go; the captured stdout and stderr of each
  // run live one level up so that folder listings see only what imufit wrote).
  std::string Path(const std::string& name) const { return (work_ / name).string(); }

  std::string Write(const std::string& name, const std::string& text) const {
    const std::string path = Path(name);
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // Runs imufit with `args`, stdin from /dev/null, and captures its output.
  RunResult Run(const std::vector<std::string>& args) const {
    return RunProgram(IMUFIT_EXE, args, (dir_ / "stdout.txt").string(), (dir_ / "stderr.txt").string());
  }

  // The arguments of `imufit simulate` for a small noisy run of the 6-position plan (10 Hz, 3 s
  // dwells, four soaks: enough for a fit, quick to make) into `out`; `extra` adds options.
  static std::vector<std::string> SmallRunArgs(const std::string& out,
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

  // As Run, but the program cannot write a file larger than `max_file_bytes` (RLIMIT_FSIZE, with
  // SIGXFSZ ignored: a write past it fails with EFBIG, as on a disk that fills up).
  RunResult RunWithFileSizeLimit(const std::vector<std::string>& args, rlim_t max_file_bytes) const {
    const std::string out = (dir_ / "stdout.txt").string(), err = (dir_ / "stderr.txt").string();
    std::vector<std::string> storage = {IMUFIT_EXE};
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& arg : storage) argv.push_back(arg.data());
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {  // only async-signal-safe calls until exec
      const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int null_fd = ::open("/dev/null", O_RDONLY);
      if (out_fd < 0 || err_fd < 0 || null_fd < 0) ::_exit(126);
      ::dup2(null_fd, 0);
      ::dup2(out_fd, 1);
      ::dup2(err_fd, 2);
      const struct rlimit limit = {max_file_bytes, max_file_bytes};
      ::setrlimit(RLIMIT_FSIZE, &limit);
      ::signal(SIGXFSZ, SIG_IGN);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    RunResult result;
    int status = 0;
    if (pid < 0 || ::waitpid(pid, &status, 0) != pid) {
      ADD_FAILURE() << "cannot run " << IMUFIT_EXE;
      return result;
    }
    result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    result.out = ReadBytes(out);
    result.err = ReadBytes(err);
    return result;
  }

  // The names in the work folder.
  std::set<std::string> Listing() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(work_)) names.insert(entry.path().filename().string());
    return names;
  }

  // Runs a noiseless simulation at 20 Hz with 1 s dwells and 0.75 s transitions (`extra` adds
  // options or overrides these) and returns the paths of {samples, truth}.
  std::pair<std::string, std::string> SimulateNoiseless(const std::string& plan,
                                                        const std::string& calibration,
                                                        const std::string& stem,
                                                        const std::vector<std::string>& extra = {}) {
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

  // Expects `corrected` (imufit apply's output) to hold the truth of `truth` in every row.
  static void ExpectRecovered(const std::string& corrected, const std::string& truth_path) {
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

  fs::path dir_;
  fs::path work_;
};

// ------------------------------------------------------------------------------------------ help

// The subcommands listed by `imufit --help` (CLI11 lists them under "Subcommands:").
std::vector<std::string> SubcommandsIn(const std::string& help) {
  std::vector<std::string> names;
  std::stringstream lines(help);
  std::string line;
  bool in_list = false;
  while (std::getline(lines, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
    } else if (in_list && line.size() > 2 && line[0] == ' ') {
      std::stringstream words(line);
      std::string name;
      words >> name;
      names.push_back(name);
    } else if (in_list) {
      in_list = !line.empty() && line[0] == ' ';
    }
  }
  return names;
}

TEST_F(CliTest, HelpOfTheProgramAndOfEverySubcommandExitsZero) {
  const RunResult help = Run({"--help"});
  EXPECT_EQ(help.status, 0) << help.err;
  const std::vector<std::string> commands = SubcommandsIn(help.out);
  EXPECT_NE(std::find(commands.begin(), commands.end(), "apply"), commands.end()) << help.out;
  EXPECT_NE(std::find(commands.begin(), commands.end(), "simulate"), commands.end()) << help.out;
  for (const std::string& command : commands) {
    const RunResult r = Run({command, "--help"});
    EXPECT_EQ(r.status, 0) << command << ": " << r.err;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << command << ": " << r.out;
  }
  const RunResult version = Run({"--version"});
  EXPECT_EQ(version.status, 0);
  EXPECT_NE(version.out.find("imufit"), std::string::npos);
}

TEST_F(CliTest, BadInvocationsExitTwo) {
  EXPECT_EQ(Run({}).status, 2);
  EXPECT_EQ(Run({"no-such-command"}).status, 2);
  EXPECT_EQ(Run({"apply", "--samples", "x.csv"}).status, 2);  // --calibration and -o missing
  EXPECT_EQ(Run({"apply", "--no-such-option"}).status, 2);
  const RunResult r = Run({"simulate", "--plan", Fixture("plan_6pos.yaml"), "--calibration",
                           Fixture("mems_truth.yaml"), "-o", Path("s.csv"), "--rate", "-5"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("sample rate"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>{});
}

// ------------------------------------------------------------------------------------------ simulate

TEST_F(CliTest, SimulateIsDeterministic) {
  const auto simulate = [&](const std::string& name, const std::string& seed) {
    const RunResult r = Run({"simulate",
                             "--plan",
                             Fixture("plan_6pos.yaml"),
                             "--calibration",
                             Fixture("mems_truth.yaml"),
                             "-o",
                             Path(name),
                             "--ramp=-40,85",
                             "--passes",
                             "2",
                             "--rate",
                             "25",
                             "--dwell",
                             "1",
                             "--transition",
                             "0.5",
                             "--gyro-noise-density",
                             "8.7e-5",
                             "--accel-noise-density",
                             "1.5e-3",
                             "--gyro-bias-instability",
                             "2.4e-5",
                             "--accel-random-walk",
                             "3e-5",
                             "--temp-noise",
                             "0.05",
                             "--quantize",
                             "--seed",
                             seed,
                             "--quiet"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "");  // --quiet
    return ReadBytes(Path(name));
  };
  const std::string a = simulate("a.csv", "11");
  const std::string b = simulate("b.csv", "11");
  const std::string c = simulate("c.csv", "12");
  EXPECT_GT(a.size(), 10000u);
  EXPECT_EQ(a, b) << "the same seed must give the same bytes";
  EXPECT_NE(a, c) << "another seed must give another run";
  // Only the seed in the provenance comment differs? No: the samples themselves differ.
  EXPECT_NE(a.substr(a.find("time_s")), c.substr(c.find("time_s")));
}

// The truth that `imufit simulate --truth` writes for dwell samples is the truth docs/spec.md section 2
// defines (Earth rate with and without `north`, centripetal term of the lever arm).
TEST_F(CliTest, SimulatedTruthFollowsTheSpec) {
  for (const char* plan : {"plan_6pos.yaml", "plan_24pos.yaml"}) {
    const auto [samples, truth_path] = SimulateNoiseless(Fixture(plan), Fixture("mems_truth.yaml"), "run");
    const auto expected = SpecTruthOfPlan(Fixture(plan));
    const Table truth = ReadTable(truth_path);
    std::set<int> seen;
    int transitions = 0;
    for (size_t i = 0; i < truth.rows.size(); ++i) {
      const int segment = std::stoi(truth.rows[i][truth.Column("segment")]);
      if (segment < 0) {
        ++transitions;
        continue;
      }
      seen.insert(segment);
      ASSERT_TRUE(expected.count(segment)) << segment;
      EXPECT_LE((truth.Vector(i, "gyro") - expected.at(segment).first).norm(), 1e-14)
          << plan << " " << segment;
      EXPECT_LE((truth.Vector(i, "accel") - expected.at(segment).second).norm(), 1e-13)
          << plan << " " << segment;
    }
    EXPECT_EQ(seen.size(), expected.size()) << plan;
    EXPECT_GT(transitions, 0) << plan;
  }
}

// ------------------------------------------------------------------------------------------ apply

// THE acceptance test of issue 2: a noiseless simulation from a known calibration, corrected by
// `imufit apply` with that calibration, gives back the truth of every sample, transitions
// included, across the whole temperature range, with Earth rate and lever arms in the plan.
TEST_F(CliTest, ApplyRecoversTheTruthOfANoiselessSimulation) {
  for (const char* calibration : {"mems_truth.yaml", "tactical_truth.yaml"}) {
    for (const char* plan : {"plan_6pos.yaml", "plan_24pos.yaml"}) {
      SCOPED_TRACE(std::string(calibration) + " " + plan);
      const auto [samples, truth] =
          SimulateNoiseless(Fixture(plan), Fixture(calibration), "run", {"--ramp=-40,85", "--passes", "2"});
      const std::string corrected = Path("corrected.csv");
      const RunResult r =
          Run({"apply", "--calibration", Fixture(calibration), "--samples", samples, "-o", corrected});
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_EQ(r.err, "") << "no warning expected inside the fit range";
      ExpectRecovered(corrected, truth);
      const Table table = ReadTable(corrected);
      EXPECT_EQ(table.header, (std::vector<std::string>{"time_s", "temp_c", "segment", "gyro_x", "gyro_y",
                                                        "gyro_z", "accel_x", "accel_y", "accel_z"}));
    }
  }
}

// The bundled golden pair: fixtures/mems_6pos_noiseless.csv.gz corrected with mems_truth.yaml is
// fixtures/mems_6pos_noiseless_truth.csv.gz.
TEST_F(CliTest, ApplyTurnsTheNoiselessFixtureIntoItsTruth) {
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s",
                           Fixture("mems_6pos_noiseless.csv.gz"), "-o", Path("corrected.csv.gz"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  ExpectRecovered(Path("corrected.csv.gz"), Fixture("mems_6pos_noiseless_truth.csv.gz"));
}

// The same acceptance check without imufit's simulator: raw samples computed here from chosen
// truths with the forward model of docs/spec.md (SpecForwardModel), at random temperatures in
// -40..85 degC, written as a CSV with the columns in another order, an extra column, comments
// and CRLF line ends.
TEST_F(CliTest, ApplyInvertsAnIndependentForwardModel) {
  for (const char* calibration : {"mems_truth.yaml", "tactical_truth.yaml"}) {
    SCOPED_TRACE(calibration);
    const SpecForwardModel spec(Fixture(calibration));
    const SensorModel header_model = spec.ToSensorModel();
    std::mt19937_64 engine(2026);
    std::uniform_real_distribution<double> temp(-40.0, 85.0);
    std::uniform_real_distribution<double> rate(-6.0, 6.0);     // rad/s
    std::uniform_real_distribution<double> force(-30.0, 30.0);  // m/s^2
    std::string samples =
        "# hand-made raw samples\r\nnote,accel_z,gyro_y,segment,temp_c,accel_x,gyro_z,time_s,gyro_x,"
        "accel_y\r\n";
    std::string truth = "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
    constexpr int kSamples = 2000;
    for (int i = 0; i < kSamples; ++i) {
      const double t = 0.01 * i;
      const double temp_c = temp(engine);
      const int segment = i % 7 == 0 ? -1 : i / 50;
      const Eigen::Vector3d omega(rate(engine), rate(engine), rate(engine));
      const Eigen::Vector3d a(force(engine), force(engine), force(engine));
      const Eigen::Vector3d gyro_m = spec.Gyro(temp_c, omega, a);
      const Eigen::Vector3d accel_m = spec.Accel(temp_c, a);
      // The model header's forward form agrees with docs/spec.md's.
      Eigen::Vector3d header_gyro;
      Eigen::Vector3d header_accel;
      header_model.Forward(temp_c, omega, a, &header_gyro, &header_accel);
      ASSERT_LE((header_gyro - gyro_m).norm(), kForwardAgreementRelative * gyro_m.norm()) << i;
      ASSERT_LE((header_accel - accel_m).norm(), kForwardAgreementRelative * accel_m.norm()) << i;
      const auto f = FormatExactly;
      samples += "\"row " + std::to_string(i) + ", hand-made\"," + f(accel_m.z()) + "," + f(gyro_m.y()) +
                 "," + std::to_string(segment) + "," + f(temp_c) + "," + f(accel_m.x()) + "," +
                 f(gyro_m.z()) + "," + f(t) + "," + f(gyro_m.x()) + "," + f(accel_m.y()) + "\r\n";
      if (i == kSamples / 2) samples += "# a comment half way\r\n";
      truth += f(t) + "," + f(temp_c) + "," + std::to_string(segment) + "," + f(omega.x()) + "," +
               f(omega.y()) + "," + f(omega.z()) + "," + f(a.x()) + "," + f(a.y()) + "," + f(a.z()) + "\n";
    }
    const std::string samples_path = Write("raw.csv", samples);
    const std::string truth_path = Write("truth.csv", truth);
    const RunResult r = Run(
        {"apply", "--calibration", Fixture(calibration), "--samples", samples_path, "-o", Path("out.csv")});
    ASSERT_EQ(r.status, 0) << r.err;
    // Compare numerically: ExpectRecovered compares time and temperature text, which differ in
    // spelling between %.17g and the shortest round-trip form.
    const Table got = ReadTable(Path("out.csv"));
    const Table expected = ReadTable(truth_path);
    ASSERT_EQ(got.header, expected.header);
    ASSERT_EQ(got.rows.size(), static_cast<size_t>(kSamples));
    double worst = 0.0;
    for (int i = 0; i < kSamples; ++i) {
      ASSERT_EQ(got.Number(i, "time_s"), expected.Number(i, "time_s"));
      ASSERT_EQ(got.Number(i, "temp_c"), expected.Number(i, "temp_c"));
      ASSERT_EQ(got.rows[i][2], expected.rows[i][2]) << "segment";
      worst = std::max(worst, (got.Vector(i, "gyro") - expected.Vector(i, "gyro")).cwiseAbs().maxCoeff());
      worst = std::max(worst, (got.Vector(i, "accel") - expected.Vector(i, "accel")).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, kRecoveryToleranceSi);
  }
}

TEST_F(CliTest, ApplyWithoutSegmentColumnWritesNone) {
  const std::string samples = Write("raw.csv",
                                    "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                    "0,25,23.4,-41.7,12.9,35.2,-18.6,52.9\n"
                                    "0.01,25,23.4,-41.7,12.9,35.2,-18.6,52.9\n");
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv")});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table out = ReadTable(Path("out.csv"));
  EXPECT_EQ(out.header, (std::vector<std::string>{"time_s", "temp_c", "gyro_x", "gyro_y", "gyro_z", "accel_x",
                                                  "accel_y", "accel_z"}));
  ASSERT_EQ(out.rows.size(), 2u);
  // Raw = bias at 25 degC: nothing moves and there is no specific force.
  for (const char* column : {"gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"}) {
    EXPECT_EQ(out.Number(0, column), 0.0) << column;
  }
}

TEST_F(CliTest, GzipInputsAndOutputsWork) {
  const std::vector<std::string> simulate = {"simulate",
                                             "--plan",
                                             Fixture("plan_6pos.yaml"),
                                             "--calibration",
                                             Fixture("mems_truth.yaml"),
                                             "--rate",
                                             "20",
                                             "--dwell",
                                             "2",
                                             "--gyro-noise-density",
                                             "1e-4",
                                             "--seed",
                                             "5",
                                             "-q",
                                             "-o"};
  const auto with = [](std::vector<std::string> args, const std::string& last) {
    args.push_back(last);
    return args;
  };
  ASSERT_EQ(Run(with(simulate, Path("raw.csv"))).status, 0);
  ASSERT_EQ(Run(with(simulate, Path("raw.csv.gz"))).status, 0);
  const std::string gz = ReadBytes(Path("raw.csv.gz"));
  ASSERT_GT(gz.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(gz[0]), 0x1f);  // gzip magic
  EXPECT_EQ(static_cast<unsigned char>(gz[1]), 0x8b);
  EXPECT_LT(gz.size(), ReadBytes(Path("raw.csv")).size() / 2);
  EXPECT_EQ(ReadFile(Path("raw.csv.gz")), ReadBytes(Path("raw.csv")));

  const auto apply = [&](const std::string& in, const std::string& out) {
    const RunResult r =
        Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", Path(in), "-o", Path(out), "-q"});
    EXPECT_EQ(r.status, 0) << r.err;
  };
  apply("raw.csv", "plain_plain.csv");
  apply("raw.csv.gz", "gz_gz.csv.gz");
  apply("raw.csv.gz", "gz_plain.csv");
  const std::string expected = ReadBytes(Path("plain_plain.csv"));
  EXPECT_GT(expected.size(), 1000u);
  EXPECT_EQ(ReadFile(Path("gz_gz.csv.gz")), expected);
  EXPECT_EQ(ReadBytes(Path("gz_plain.csv")), expected);
  EXPECT_EQ(static_cast<unsigned char>(ReadBytes(Path("gz_gz.csv.gz"))[0]), 0x1f);
}

TEST_F(CliTest, ApplyWarnsOnceWithACountOutsideTheFitTemperatureRange) {
  std::string narrow = ReadBytes(Fixture("mems_truth.yaml"));
  const std::string range = "fit_temp_range_c: [-40, 85]";
  ASSERT_NE(narrow.find(range), std::string::npos);
  narrow.replace(narrow.find(range), range.size(), "fit_temp_range_c: [-10, 60]");
  const std::string calibration = Write("narrow.yaml", narrow);
  const auto [samples, truth] =
      SimulateNoiseless(Fixture("plan_6pos.yaml"), Fixture("mems_truth.yaml"), "ramp", {"--ramp=-40,85"});
  const Table raw = ReadTable(samples);
  // Readings within 0.5 degC of the range are the thermometer's noise, not extrapolation (the
  // README's promise; io/correct_file.h kFitRangeToleranceC).
  constexpr double kFitRangeToleranceC = 0.5;
  long long outside = 0, within_tolerance = 0;
  for (size_t i = 0; i < raw.rows.size(); ++i) {
    const double t = raw.Number(i, "temp_c");
    outside += (t < -10.0 - kFitRangeToleranceC || t > 60.0 + kFitRangeToleranceC) ? 1 : 0;
    within_tolerance += ((t < -10.0 || t > 60.0) && t >= -10.5 && t <= 60.5) ? 1 : 0;
  }
  ASSERT_GT(outside, 0);
  ASSERT_GT(within_tolerance, 0);  // the ramp passes through the tolerance: those are not counted
  ASSERT_LT(outside, static_cast<long long>(raw.rows.size()));
  const RunResult r = Run({"apply", "-c", calibration, "-s", samples, "-o", Path("out.csv")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // once
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::to_string(outside) + " of " + std::to_string(raw.rows.size()) + " samples"),
            std::string::npos)
      << r.err;
  ExpectRecovered(Path("out.csv"), truth);  // a warning, not a refusal
}

// ------------------------------------------------------------------------------------------ bad input

struct BadInput {
  const char* what;     // test case name
  const char* file;     // which input is bad: plan, samples or calibration
  const char* from;     // text in the good file ...
  const char* to;       // ... replaced by this
  long line;            // the line the message must name (0: only the file)
  const char* message;  // a piece of the expected message
};

const char kGoodPlan[] =
    "# a plan\n"
    "format: imufit-plan\n"
    "version: 1\n"
    "gravity_mps2: 9.81\n"
    "latitude_deg: 52.27\n"
    "segments:\n"
    "  - id: 1\n"
    "    up: [0, 0, 1]\n"
    "    north: [1, 0, 0]\n"
    "  - id: 2\n"
    "    up: [1, 0, 0]\n"
    "    rate_dps: 100\n"
    "    lever_arm_m: [0.01, 0, 0]\n";

const char kGoodSamples[] =
    "# raw samples\n"
    "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
    "0,25,1,23,-41,12,35,-18,2100\n"
    "0.01,25,1,24,-42,13,36,-19,2101\n"
    "0.02,25,-1,25,-43,14,37,-20,2102\n"
    "0.03,25,2,1600,-44,15,38,-21,2103\n";

const BadInput kBadInputs[] = {
    // plan
    {"plan_malformed_number", "plan", "gravity_mps2: 9.81", "gravity_mps2: 9.8.1", 4,
     "\"9.8.1\" is not a number"},
    {"plan_unknown_key", "plan", "gravity_mps2: 9.81", "gravity: 9.81", 4, "unknown key \"gravity\""},
    {"plan_unknown_segment_key", "plan", "    rate_dps: 100\n", "    rate_dps: 100\n    speed: 3\n", 13,
     "unknown key \"speed\""},
    {"plan_north_not_horizontal", "plan", "north: [1, 0, 0]", "north: [1, 0, 0.1]", 9, "not horizontal"},
    {"plan_repeated_id", "plan", "id: 2", "id: 1", 10, "repeats"},
    {"plan_wrong_format", "plan", "format: imufit-plan", "format: imufit-calibration", 2, "imufit-plan"},
    {"plan_wrong_version", "plan", "version: 1", "version: 2", 3, "not supported"},
    {"plan_zero_vector", "plan", "up: [1, 0, 0]", "up: [0, 0, 0]", 11, "zero"},
    {"plan_two_numbers", "plan", "up: [1, 0, 0]", "up: [1, 0]", 11, "3 numbers"},
    {"plan_rate_not_a_number", "plan", "rate_dps: 100", "rate_dps: fast", 12, "\"fast\" is not a number"},
    {"plan_latitude_out_of_range", "plan", "latitude_deg: 52.27", "latitude_deg: 95", 5, "latitude"},
    // yaml-cpp reports where it noticed the unclosed list: the next line.
    {"plan_yaml_syntax", "plan", "up: [0, 0, 1]", "up: [0, 0, 1", 9, "YAML"},
    {"plan_missing_gravity", "plan", "gravity_mps2: 9.81\n", "", 2, "gravity_mps2: missing"},
    {"plan_negative_id", "plan", "id: 2", "id: -2", 10, "id"},
    // samples
    {"samples_malformed_number", "samples", "24,-42", "24,-4.2.2", 4, "gyro_y: \"-4.2.2\" is not a number"},
    {"samples_missing_column", "samples", "gyro_z,accel_x", "accel_x", 2, "no column \"gyro_z\""},
    {"samples_time_not_increasing", "samples", "0.02,25,-1", "0.01,25,-1", 5, "does not increase"},
    {"samples_short_row", "samples", "37,-20,2102", "37,-20", 5, "fields"},
    {"samples_not_finite", "samples", "0.03,25,2,1600", "0.03,25,2,inf", 6, "not a finite number"},
    {"samples_bad_segment", "samples", "0.02,25,-1", "0.02,25,-3", 5, "not a segment id"},
    {"samples_segment_not_integer", "samples", "0.02,25,-1", "0.02,25,x", 5, "not an integer"},
    {"samples_empty_value", "samples", "0.01,25,1,24", "0.01,,1,24", 4, "temp_c: empty value"},
    {"samples_duplicate_column", "samples", "accel_x,accel_y", "accel_x,accel_x", 2, "appears twice"},
    // calibration
    {"calibration_wrong_format", "calibration", "format: imufit-calibration", "format: imufit-plan", 8,
     "imufit-calibration"},
    {"calibration_higher_version", "calibration", "version: 1", "version: 2", 9, "not supported"},
    {"calibration_malformed_number", "calibration", "x: [23.4, 0.118,", "x: [23.4, 0.1.18,", 18,
     "\"0.1.18\" is not a number"},
    {"calibration_three_terms", "calibration", "y: [931.52, -0.0895, -0.00017, 2.6e-06]",
     "y: [931.52, -0.0895, -0.00017]", 23, "4 numbers"},
    {"calibration_wrong_unit", "calibration", "unit: rad/s", "unit: deg/s", 16, "deg/s"},
    {"calibration_zero_scale", "calibration", "z: [209.97,", "z: [0,", 51, "scale.z: the scale factor changes sign"},
    {"calibration_missing_group", "calibration", "  misalignment:\n    xy: [-0.00214",
     "  misalign:\n    xy: [-0.00214", 43,
     "accel.misalignment: missing"},  // the line where the `accel` mapping starts
    {"calibration_reversed_range", "calibration", "fit_temp_range_c: [-40, 85]",
     "fit_temp_range_c: [85, -40]", 14, "range"},
};

void PrintTo(const BadInput& input, std::ostream* os) { *os << input.what; }

class BadInputTest : public CliTest, public ::testing::WithParamInterface<BadInput> {};

TEST_P(BadInputTest, ExitsTwoWithFileAndLineAndWritesNothing) {
  const BadInput& c = GetParam();
  const std::string kind = c.file;
  std::string text = kind == "plan"      ? std::string(kGoodPlan)
                     : kind == "samples" ? std::string(kGoodSamples)
                                         : ReadBytes(Fixture("mems_truth.yaml"));
  const size_t at = text.find(c.from);
  ASSERT_NE(at, std::string::npos) << c.from;
  text.replace(at, std::strlen(c.from), c.to);
  const std::string bad = Write(kind == "samples" ? "bad.csv" : "bad.yaml", text);
  const std::string plan = kind == "plan" ? bad : Write("plan.yaml", kGoodPlan);
  const std::string samples = kind == "samples" ? bad : Write("samples.csv", kGoodSamples);
  const std::string calibration = kind == "calibration" ? bad : Fixture("mems_truth.yaml");

  // A plan is read by simulate; samples and calibrations by apply (calibrations by both).
  std::vector<std::vector<std::string>> commands;
  if (kind != "samples") {
    commands.push_back(
        {"simulate", "--plan", plan, "--calibration", calibration, "-o", Path("out.csv"), "--dwell", "0.1"});
  }
  if (kind != "plan") commands.push_back({"apply", "-c", calibration, "-s", samples, "-o", Path("out.csv")});
  const std::set<std::string> before = Listing();
  for (const auto& command : commands) {
    SCOPED_TRACE(command[0]);
    const RunResult r = Run(command);
    EXPECT_EQ(r.status, 2) << r.err;
    const std::string location = bad + ":" + std::to_string(c.line) + ":";
    EXPECT_EQ(r.err.rfind("imufit: " + location, 0), 0u) << "expected " << location << " in: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_EQ(Listing(), before) << "nothing written";
  }
}

INSTANTIATE_TEST_SUITE_P(EveryBadInput, BadInputTest, ::testing::ValuesIn(kBadInputs),
                         [](const ::testing::TestParamInfo<BadInput>& info) { return info.param.what; });

TEST_F(CliTest, MissingOrEmptyInputFilesExitTwoNamingTheFile) {
  const std::string plan = Write("plan.yaml", kGoodPlan);
  const std::string samples = Write("samples.csv", kGoodSamples);
  const std::string missing = Path("no-such-file.yaml");
  const std::string missing_csv = Path("no-such-file.csv");
  const std::string empty = Write("empty.csv", "# nothing but a comment\n");
  const std::string cal = Fixture("mems_truth.yaml");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"simulate", "-p", missing, "-c", cal, "-o", Path("o.csv")}, missing},
      {{"simulate", "-p", plan, "-c", missing, "-o", Path("o.csv")}, missing},
      {{"apply", "-c", missing, "-s", samples, "-o", Path("o.csv")}, missing},
      {{"apply", "-c", cal, "-s", missing_csv, "-o", Path("o.csv")}, missing_csv},
      {{"apply", "-c", cal, "-s", missing_csv + ".gz", "-o", Path("o.csv")}, missing_csv + ".gz"},
      {{"apply", "-c", cal, "-s", empty, "-o", Path("o.csv")}, empty},
      {{"apply", "-c", cal, "-s", samples, "-o", Path("no-such-folder/o.csv")}, Path("no-such-folder/o.csv")},
  };
  const std::set<std::string> before = Listing();
  for (const auto& [args, file] : cases) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("imufit: " + file + ":", 0), 0u) << r.err;
    EXPECT_EQ(Listing(), before);
  }
}

// ------------------------------------------------------------------------------------------ outputs

// A failing run never damages an existing output and leaves no temporary file: the error comes
// after more than two megabytes of output were written (so part of it reached the temporary file).
TEST_F(CliTest, AFailingRunLeavesAnExistingOutputUntouched) {
  const auto [samples, truth] = SimulateNoiseless(Fixture("plan_24pos.yaml"), Fixture("mems_truth.yaml"),
                                                  "run", {"--rate", "100", "--dwell", "2", "--temps=-40,85"});
  std::string text = ReadBytes(samples);
  ASSERT_GT(text.size(), 2u << 20);     // the output is about as long: beyond the 1 MiB write buffer
  text += "1e9,25,1,1,2,3,4,5,oops\n";  // the last row is bad
  const std::string bad_samples = Write("bad.csv", text);
  fs::remove(samples);
  fs::remove(truth);
  const std::string sentinel = "precious: an earlier result\n";
  for (const char* name : {"out.csv", "out.csv.gz"}) {
    SCOPED_TRACE(name);
    const std::string out = Write(name, sentinel);
    const std::set<std::string> before = Listing();
    const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", bad_samples, "-o", out});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("bad.csv:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"oops\""), std::string::npos) << r.err;
    EXPECT_EQ(ReadBytes(out), sentinel);
    EXPECT_EQ(Listing(), before) << "a temporary file was left behind";
  }
  // simulate onto existing outputs, failing on its calibration: both outputs stay.
  const std::string out = Write("sim.csv", sentinel);
  const std::string truth_out = Write("sim_truth.csv", sentinel);
  const std::string bad_calibration = Write("bad.yaml", "format: imufit-calibration\nversion: 1\ngyro: 3\n");
  const std::set<std::string> before = Listing();
  const RunResult r = Run(
      {"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", bad_calibration, "-o", out, "--truth", truth_out});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(ReadBytes(out), sentinel);
  EXPECT_EQ(ReadBytes(truth_out), sentinel);
  EXPECT_EQ(Listing(), before);
}

TEST_F(CliTest, AnOutputThatIsAlsoAnInputIsRefused) {
  const std::string plan = Write("plan.yaml", kGoodPlan);
  const std::string samples = Write("samples.csv", kGoodSamples);
  const std::string calibration = Write("cal.yaml", ReadBytes(Fixture("mems_truth.yaml")));
  fs::create_symlink(samples, Path("link.csv"));
  const std::string plan_text = ReadBytes(plan);
  const std::string samples_text = ReadBytes(samples);
  const std::string calibration_text = ReadBytes(calibration);
  const std::vector<std::vector<std::string>> cases = {
      {"apply", "-c", calibration, "-s", samples, "-o", samples},
      {"apply", "-c", calibration, "-s", samples, "-o", (work_ / "." / "samples.csv").string()},
      {"apply", "-c", calibration, "-s", samples, "-o", Path("link.csv")},
      {"apply", "-c", calibration, "-s", samples, "-o", calibration},
      {"simulate", "-p", plan, "-c", calibration, "-o", plan},
      {"simulate", "-p", plan, "-c", calibration, "-o", calibration},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth", plan},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth", Path("new.csv")},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth",
       (work_ / "." / "new.csv").string()},
  };
  const std::set<std::string> before = Listing();
  for (const auto& args : cases) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << args.back() << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(ReadBytes(plan), plan_text);
    EXPECT_EQ(ReadBytes(samples), samples_text);
    EXPECT_EQ(ReadBytes(calibration), calibration_text);
    EXPECT_EQ(Listing(), before) << args.back();
  }
}

// ------------------------------------------------------------------------------------------
// imufit fit, end to end.

TEST_F(CliTest, FitWritesACalibrationThatCorrectsAnotherRun) {
  const std::string calibration = Path("calibration.yaml");
  const RunResult fit = Run({"fit", "--plan", Fixture("plan_6pos.yaml"), "--samples", Fixture("mems_6pos_soak.csv.gz"),
                             "-o", calibration, "--validate"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("converged"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("at 25 degC (+- 1 sigma)"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("leave-one-temperature-out validation"), std::string::npos) << fit.out;
  const YAML::Node written = YAML::LoadFile(calibration);
  EXPECT_EQ(written["format"].as<std::string>(), "imufit-calibration");
  EXPECT_EQ(written["sigma"]["gyro"]["g_sensitivity"]["zz"].size(), 4u);
  EXPECT_EQ(written["fit"]["windows_used"].as<int>(), 90);
  EXPECT_EQ(written["fit"]["distinct_temperatures_c"].size(), 5u);

  // The fitted calibration corrects the noiseless run (same unit, other temperatures) to within
  // what the noise of the fitted run leaves: a few thousandths of a deg/s, a few tenths of a mg.
  constexpr double kGyroToleranceRadps = 0.02 * kDegToRad;
  constexpr double kAccelToleranceMps2 = 1e-3 * 9.80665;
  const std::string corrected = Path("corrected.csv");
  const RunResult apply =
      Run({"apply", "-c", calibration, "-s", Fixture("mems_6pos_noiseless.csv.gz"), "-o", corrected, "-q"});
  ASSERT_EQ(apply.status, 0) << apply.err;
  const Table got = ReadTable(corrected);
  const Table truth = ReadTable(Fixture("mems_6pos_noiseless_truth.csv.gz"));
  ASSERT_EQ(got.rows.size(), truth.rows.size());
  double worst_gyro = 0.0;
  double worst_accel = 0.0;
  for (size_t r = 0; r < got.rows.size(); ++r) {
    for (const char* axis : {"x", "y", "z"}) {
      const int g = got.Column(std::string("gyro_") + axis);
      const int a = got.Column(std::string("accel_") + axis);
      worst_gyro = std::max(worst_gyro, std::abs(std::stod(got.rows[r][g]) - std::stod(truth.rows[r][g])));
      worst_accel = std::max(worst_accel, std::abs(std::stod(got.rows[r][a]) - std::stod(truth.rows[r][a])));
    }
  }
  EXPECT_LT(worst_gyro, kGyroToleranceRadps);
  EXPECT_LT(worst_accel, kAccelToleranceMps2);
}

TEST_F(CliTest, FitRefusesARunThatCannotDetermineTheModel) {
  const std::string samples = Path("one_temperature.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", samples,
                 "--temps", "25", "--rate", "10", "--dwell", "3", "-q"})
                .status,
            0);
  const std::string output = Write("calibration.yaml", "precious\n");
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", output});
  EXPECT_EQ(fit.status, 1);
  EXPECT_NE(fit.err.find("does not determine the model"), std::string::npos) << fit.err;
  EXPECT_NE(fit.err.find("too few temperatures for a cubic temperature model: 1 distinct temperature (25.0 degC), "
                         "at least 4 needed"),
            std::string::npos)
      << fit.err;
  EXPECT_EQ(ReadBytes(output), "precious\n");
  EXPECT_EQ(Listing(), (std::set<std::string>{"one_temperature.csv", "calibration.yaml"}));
  // The same run determines a constant model.
  const RunResult constant = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", Path("constant.yaml"),
                                  "--gyro-temp-order", "0", "--accel-temp-order", "0", "-q"});
  EXPECT_EQ(constant.status, 0) << constant.err;
}

// A static-only run: refused as a whole (naming the gyro scale, suggesting --fit accel), fitted
// with --fit accel: the accelerometer near the truth, the gyro held at scale 1 and 0 with sigma 0.
TEST_F(CliTest, FitAccelAloneCalibratesAStaticOnlyRun) {
  const std::string plan = Fixture("plan_6faces_static.yaml");
  const std::string samples = SimulateNoiseless(plan, Fixture("mems_truth.yaml"), "static",
                                                {"--temps=-20,5,30,55,80", "--dwell", "3"})
                                  .first;
  const RunResult whole = Run({"fit", "-p", plan, "-s", samples, "-o", Path("whole.yaml")});
  EXPECT_EQ(whole.status, 1);
  EXPECT_NE(whole.err.find("gyro scale z and misalignment xz, yz are undetermined"), std::string::npos)
      << whole.err;
  EXPECT_NE(whole.err.find("--fit accel"), std::string::npos) << whole.err;
  EXPECT_FALSE(fs::exists(Path("whole.yaml")));

  const RunResult fit = Run({"fit", "-p", plan, "-s", samples, "-o", Path("accel.yaml"), "--fit", "accel"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("gyro x   bias +0.00000 (held) deg/s"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("(gyro held, not fitted)"), std::string::npos) << fit.out;
  const YAML::Node got = YAML::LoadFile(Path("accel.yaml"));
  const YAML::Node truth = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* group : {"bias", "scale", "misalignment"}) {
    for (const auto& entry : truth["accel"][group]) {
      const std::string name = entry.first.as<std::string>();
      for (int k = 0; k < 4; ++k) {
        const double want = entry.second[k].as<double>();
        EXPECT_NEAR(got["accel"][group][name][k].as<double>(), want, 1e-6 * std::max(1.0, std::abs(want)))
            << "accel." << group << "." << name << "[" << k << "]";
      }
      EXPECT_EQ(got["sigma"]["accel"][group][name].size(), 4u);
    }
    for (const auto& entry : got["gyro"][group]) {
      const bool unit_scale = std::string(group) == "scale";
      EXPECT_EQ(entry.second[0].as<double>(), unit_scale ? 1.0 : 0.0) << "gyro." << group;
      EXPECT_EQ(got["sigma"]["gyro"][group][entry.first.as<std::string>()][0].as<double>(), 0.0);
    }
  }
  EXPECT_EQ(got["fit"]["fitted"].as<std::vector<std::string>>(),
            (std::vector<std::string>{"accel.bias", "accel.scale", "accel.misalignment"}));
  EXPECT_EQ(got["fit"]["held"].size(), 4u);
  EXPECT_EQ(got["fit"]["held_values"].as<std::string>(), "scale 1, others 0");
  const RunResult bad =
      Run({"fit", "-p", plan, "-s", samples, "-o", Path("bad.yaml"), "--fit", "accelerometer"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("is not a group to fit"), std::string::npos) << bad.err;
}

TEST_F(CliTest, FitNamesAnAxisGravityNeverPointsAlong) {
  // The 6-position plan without its -y face: g-sensitivity and accelerometer column y are lost.
  std::string plan = ReadFile(Fixture("plan_6pos.yaml"));
  YAML::Node root = YAML::Load(plan);
  YAML::Node kept(YAML::NodeType::Sequence);
  for (const YAML::Node& segment : root["segments"]) {
    if (segment["up"][1].as<double>() < -0.5) continue;
    kept.push_back(segment);
  }
  root["segments"] = kept;
  YAML::Emitter emitter;
  emitter << root;
  const std::string plan_path = Write("plan.yaml", emitter.c_str());
  const std::string samples = Path("run.csv");
  ASSERT_EQ(Run({"simulate", "-p", plan_path, "-c", Fixture("mems_truth.yaml"), "-o", samples, "--temps=-40,0,40,85",
                 "--rate", "10", "--dwell", "3", "-q"})
                .status,
            0);
  const RunResult fit = Run({"fit", "-p", plan_path, "-s", samples, "-o", Path("calibration.yaml")});
  EXPECT_EQ(fit.status, 1);
  EXPECT_NE(fit.err.find("gyro g_sensitivity column y (xy, yy, zy) is undetermined: no positions with gravity along -y"),
            std::string::npos)
      << fit.err;
  EXPECT_NE(fit.err.find("accel scale y and misalignment xy, zy are undetermined"), std::string::npos) << fit.err;
  EXPECT_FALSE(fs::exists(Path("calibration.yaml")));
}

TEST_F(CliTest, FitRefusesBadInputWithExitTwo) {
  // A segment id the plan does not have: located at its line and field.
  const std::string samples = Write("samples.csv",
                                    "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                    "0,25,99,1,2,3,4,5,6\n");
  RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", samples, "-o", Path("c.yaml")});
  EXPECT_EQ(fit.status, 2);
  EXPECT_NE(fit.err.find("samples.csv:2:3: segment: segment 99 is not in the plan"), std::string::npos) << fit.err;
  fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o", Path("c.yaml"),
             "--loss", "tukey"});
  EXPECT_EQ(fit.status, 2);
  EXPECT_NE(fit.err.find("\"tukey\" is not a robust loss (none, huber, cauchy)"), std::string::npos) << fit.err;
  fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o", Path("c.yaml"),
             "--gyro-temp-order", "4"});
  EXPECT_EQ(fit.status, 2);
  EXPECT_FALSE(fs::exists(Path("c.yaml")));
}

TEST_F(CliTest, FitReportsErrorsOnAHeldOutRun) {
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"), "-o",
                             Path("calibration.yaml"), "--check-samples", Fixture("mems_6pos_ramp.csv.gz")});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("held-out run"), std::string::npos) << fit.out;
  EXPECT_NE(fit.out.find("    all      216"), std::string::npos) << fit.out;
  const YAML::Node written = YAML::LoadFile(Path("calibration.yaml"));
  EXPECT_LT(written["check"]["gyro_error_rms_radps"].as<double>(), 0.02 * kDegToRad);
}

// ------------------------------------------------------------------------------------------
// Inputs as they really arrive: exit 2, one located line, nothing written, nothing damaged.

TEST_F(CliTest, ATruncatedGzipRunIsRefusedNotReadAsComplete) {
  const std::string whole = ReadBytes(Fixture("mems_6pos_noiseless.csv.gz"));
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"cut.csv.gz", whole.substr(0, whole.size() - 8)},
        {"garbage.csv.gz", whole + "junk"}}) {
    const std::string samples = Write(name, bytes);
    const RunResult r =
        Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
    EXPECT_EQ(r.status, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name + ": " + (name == "cut.csv.gz" ? "truncated gzip stream" : "trailing garbage")),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(Path("out.csv")));
  }
}

TEST_F(CliTest, MultiOutputCommandsWriteAllOrNothing) {
  const std::string calibration = Write("calibration.yaml", "precious\n");
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"),
                             "-o", calibration, "--report", Path("missing/report.html"), "-q"});
  EXPECT_EQ(fit.status, 2) << fit.err;
  EXPECT_NE(fit.err.find("missing/report.html: cannot create"), std::string::npos) << fit.err;
  EXPECT_EQ(ReadBytes(calibration), "precious\n")
      << "the calibration was replaced although the report failed";
  EXPECT_EQ(Listing(), (std::set<std::string>{"calibration.yaml"}));

  std::string rows = "time_s,gyro_x\n";
  for (int i = 0; i < 2000; ++i)
    rows += std::to_string(i * 0.01) + "," + std::to_string((i * 7919 % 101) * 1e-3) + "\n";
  const std::string samples = Write("rates.csv", rows);
  const RunResult allan =
      Run({"allan", "-s", samples, "-o", Path("adev.csv"), "--noise-yaml", Path("missing/noise.yaml"), "-q"});
  EXPECT_EQ(allan.status, 2) << allan.err;
  EXPECT_EQ(Listing(), (std::set<std::string>{"calibration.yaml", "rates.csv"})) << "adev.csv written alone";
}

// simulate -o S --truth T writes both or neither: a truth file that fails at its very end (a disk
// that fills up; here a file size limit the samples fit under and the truth does not) leaves no
// samples file, which would otherwise pass for a complete simulation.
TEST_F(CliTest, SimulateWritesSamplesAndTruthTogetherOrNeither) {
  const std::vector<std::string> args = SmallRunArgs(Path("samples.csv.gz"), {"--truth", Path("truth.csv")});
  RunResult r = Run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const uintmax_t samples_bytes = fs::file_size(Path("samples.csv.gz"));
  const uintmax_t truth_bytes = fs::file_size(Path("truth.csv"));
  // The truth must fail when it is committed, after the samples are complete: it fits in the 1 MiB
  // an output holds before its first write, and the samples fit under the limit.
  constexpr uintmax_t kOutputBufferBytes = 1 << 20;
  ASSERT_LT(truth_bytes, kOutputBufferBytes);
  ASSERT_LT(samples_bytes, truth_bytes);
  fs::remove(Path("samples.csv.gz"));
  fs::remove(Path("truth.csv"));

  r = RunWithFileSizeLimit(args, (samples_bytes + truth_bytes) / 2);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("truth.csv: write failed"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>()) << "the samples were written without their truth";

  // Neither when the truth cannot even be started.
  std::vector<std::string> unwritable = args;
  unwritable.back() = Path("missing/truth.csv");  // the value of --truth
  r = Run(unwritable);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("missing/truth.csv: cannot create"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>());
}

TEST_F(CliTest, OutputsNeverReplaceALinkOrSpecialFile) {
  const std::string target = Write("target.csv", "the user's file\n");
  const std::string link = Path("link.csv");
  fs::create_symlink(target, link);
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s",
                           Fixture("mems_6pos_noiseless.csv.gz"), "-o", link, "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("link.csv: is a symbolic link"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(ReadBytes(target), "the user's file\n");
  EXPECT_EQ(Listing(), (std::set<std::string>{"target.csv", "link.csv"}));
}

TEST_F(CliTest, NoCommandWritesANonFiniteNumber) {
  // apply: an absurd temperature overflows the polynomials.
  const std::string header = "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
  const std::string samples = Write("hot.csv", header + "0,25,1,2,3,4,5,6\n0.1,1e300,1,2,3,4,5,6\n");
  RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("hot.csv:3:2: temp_c: the correction at 1e+300 degC is not a finite number"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // apply: a calibration whose scale crosses zero inside its fit range is refused on read.
  YAML::Node calibration = YAML::LoadFile(Fixture("mems_truth.yaml"));
  calibration["gyro"]["scale"]["y"][1] =
      -calibration["gyro"]["scale"]["y"][0].as<double>() / 30.0;  // 0 at 55 degC
  YAML::Emitter emitter;
  emitter << calibration;
  r = Run({"apply", "-c", Write("bad.yaml", emitter.c_str()), "-s", Fixture("mems_6pos_noiseless.csv.gz"),
           "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("gyro.scale.y: the scale factor changes sign"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // simulate: a temperature that is not a number.
  r = Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o",
           Path("sim.csv"), "--temps", "25,nan", "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("temperatures must be numbers"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("sim.csv")));
  // allan: a constant column gives zero deviations with zero-width intervals and says why there is
  // no noise fit.
  std::string rows = "time_s,gyro_x\n";
  for (int i = 0; i < 2000; ++i) rows += std::to_string(i * 0.01) + ",0.5\n";
  r = Run(
      {"allan", "-s", Write("stuck.csv", rows), "-o", Path("adev.csv"), "--noise-yaml", Path("noise.yaml")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("the column is constant"), std::string::npos) << r.out;
  for (const char* output : {"adev.csv", "noise.yaml"}) {
    const std::string text = ReadBytes(Path(output));
    EXPECT_FALSE(text.empty()) << output;
    EXPECT_EQ(text.find("nan"), std::string::npos) << output << ":\n" << text;
    EXPECT_EQ(text.find("inf"), std::string::npos) << output << ":\n" << text;
  }
}

TEST_F(CliTest, HostileInputGivesOneBoundedEscapedLine) {
  const std::string samples =
      Write("evil.csv", "time_s,temp_c,\x1b]0;owned\x07" + std::string(3000, 'x') + "\n1,2,3\n");
  const RunResult r =
      Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\x07'), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_LT(r.err.size(), 600u) << r.err;
  const RunResult zero =
      Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", "/dev/zero", "-o", Path("out.csv")});
  EXPECT_EQ(zero.status, 2) << zero.err;
  EXPECT_NE(zero.err.find("/dev/zero:1: line longer than"), std::string::npos) << zero.err;
}

// ------------------------------------------------------------------------------ unlabelled logs

// `imufit segment` labels a simulated log written without its segment column (jittered times) as the
// simulator's truth does: most samples of every dwell get their segment, none a wrong one.
TEST_F(CliTest, SegmentLabelsAnUnlabelledLogAsTheTruthDoes) {
  const std::string raw = Path("raw.csv");
  const std::string truth = Path("truth.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", raw, "--truth",
                 truth, "--temps=-20,60", "--rate", "50", "--dwell", "5", "--transition", "1", "--gyro-noise-density",
                 "8.7e-5", "--accel-noise-density", "1.5e-3", "--quantize", "--no-segment-column", "--time-jitter-s",
                 "0.005", "-q"})
                .status,
            0);
  EXPECT_EQ(ReadTable(raw).header,
            (std::vector<std::string>{"time_s", "temp_c", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"}));
  const std::string labelled = Path("labelled.csv");
  const RunResult r = Run({"segment", "--plan", Fixture("plan_6pos.yaml"), "--samples", raw, "-o", labelled});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("36 segments found in 2 passes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segment  pass  kind"), std::string::npos) << r.out;
  const Table got = ReadTable(labelled);
  const Table want = ReadTable(truth);
  ASSERT_EQ(got.rows.size(), want.rows.size());
  long long truly_labelled = 0;
  long long correct = 0;
  long long wrong = 0;
  for (size_t i = 0; i < got.rows.size(); ++i) {
    ASSERT_EQ(got.rows[i][got.Column("time_s")], want.rows[i][want.Column("time_s")]);
    const int label = std::stoi(got.rows[i][got.Column("segment")]);
    const int true_label = std::stoi(want.rows[i][want.Column("segment")]);
    truly_labelled += true_label >= 0;
    correct += label >= 0 && label == true_label;
    wrong += label >= 0 && label != true_label;
  }
  EXPECT_GE(static_cast<double>(correct) / truly_labelled, 0.7);
  EXPECT_EQ(wrong, 0);
  // The labelled log fits like any labelled run.
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", labelled, "-o", Path("cal.yaml"),
                             "--gyro-temp-order", "1", "--accel-temp-order", "1", "--no-g-sensitivity", "-q"});
  EXPECT_EQ(fit.status, 0) << fit.err;
}

TEST_F(CliTest, SegmentRefusesALogThatDisagreesWithThePlanWithExitOne) {
  const std::string raw = Path("raw.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", raw, "--rate",
                 "50", "--dwell", "5", "--transition", "1", "--no-segment-column", "-q"})
                .status,
            0);
  // The plan without its +x face (12 .. 17 s in the log): an extra rest in the log.
  YAML::Node root = YAML::Load(ReadFile(Fixture("plan_6pos.yaml")));
  YAML::Node kept(YAML::NodeType::Sequence);
  for (const YAML::Node& segment : root["segments"]) {
    if (segment["id"].as<int>() != 3) kept.push_back(segment);
  }
  root["segments"] = kept;
  YAML::Emitter emitter;
  emitter << root;
  const std::string plan = Write("plan.yaml", emitter.c_str());
  const std::string output = Write("labelled.csv", "precious\n");
  for (const char* command : {"segment", "fit"}) {
    const RunResult r = Run({command, "-p", plan, "-s", raw, "-o", output});
    EXPECT_EQ(r.status, 1) << command << ": " << r.err;
    EXPECT_NE(r.err.find("raw.csv: the log does not match the plan " + plan + ": at t = "), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("with the raw axes as they are: at t = 12."), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("nothing written"), std::string::npos) << r.err;
    EXPECT_EQ(ReadBytes(output), "precious\n");
  }
  EXPECT_EQ(Listing(), (std::set<std::string>{"raw.csv", "plan.yaml", "labelled.csv"}));
}

// A lab log without a thermometer and without labels: --temp-c in segment, fit and apply.
TEST_F(CliTest, ALogWithoutTemperatureOrLabelsCalibratesWithTempC) {
  const std::string raw = Path("raw.csv");
  ASSERT_EQ(Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o", raw, "--temps",
                 "21", "--rate", "50", "--dwell", "5", "--transition", "1", "--gyro-noise-density", "8.7e-5",
                 "--accel-noise-density", "1.5e-3", "--quantize", "--no-segment-column", "--no-temp-column", "-q"})
                .status,
            0);
  EXPECT_EQ(ReadTable(raw).header,
            (std::vector<std::string>{"time_s", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"}));
  const std::string plan = Fixture("plan_6pos.yaml");
  const std::string cal = Path("cal.yaml");
  RunResult r = Run({"fit", "-p", plan, "-s", raw, "-o", cal});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column \"temp_c\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--temp-c"), std::string::npos) << r.err;
  r = Run({"fit", "-p", plan, "-s", raw, "-o", cal, "--temp-c", "21", "--gyro-temp-order", "3"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("use --gyro-temp-order 0 --accel-temp-order 0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(cal));
  r = Run({"fit", "-p", plan, "-s", raw, "-o", cal, "--temp-c", "21"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("no temp_c column, every sample at 21 degC (--temp-c): temperature orders 0"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("no segment column: 18 segments found in 1 pass"), std::string::npos) << r.out;
  const YAML::Node written = YAML::LoadFile(cal);
  EXPECT_EQ(written["fit"]["gyro_temp_order"].as<int>(), 0);
  EXPECT_EQ(written["fit_temp_range_c"][0].as<double>(), 21.0);

  // A file that has temp_c is refused with --temp-c (no reading is silently replaced).
  const std::string with_temp = Write("with_temp.csv",
                                      "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
                                      "0,25,1,2,3,4,5,6\n");
  r = Run({"apply", "-c", cal, "-s", with_temp, "-o", Path("x.csv"), "--temp-c", "21"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("has a temp_c column"), std::string::npos) << r.err;
  r = Run({"apply", "-c", cal, "-s", raw, "-o", Path("x.csv")});
  EXPECT_EQ(r.status, 2);
  r = Run({"apply", "-c", cal, "-s", raw, "-o", Path("corrected.csv"), "--temp-c", "21", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Table corrected = ReadTable(Path("corrected.csv"));
  ASSERT_FALSE(corrected.rows.empty());
  EXPECT_EQ(corrected.Number(0, "temp_c"), 21.0);
  EXPECT_NEAR(corrected.Vector(0, "accel").norm(), 9.81274, 0.05);  // at rest, +z up

  // segment keeps the file's columns: temp_c only when given.
  ASSERT_EQ(Run({"segment", "-p", plan, "-s", raw, "-o", Path("a.csv"), "-q"}).status, 0);
  EXPECT_EQ(ReadTable(Path("a.csv")).header.size(), 8u);
  ASSERT_EQ(Run({"segment", "-p", plan, "-s", raw, "-o", Path("b.csv"), "--temp-c", "21", "-q"}).status, 0);
  EXPECT_EQ(ReadTable(Path("b.csv")).header,
            (std::vector<std::string>{"time_s", "temp_c", "segment", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y",
                                      "accel_z"}));
}

TEST_F(CliTest, SimulateJitterMustKeepTimesIncreasing) {
  const RunResult r = Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o",
                           Path("x.csv"), "--rate", "50", "--time-jitter-s", "0.01"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("time jitter"), std::string::npos) << r.err;
}

// Done when (issue 9): a hand-rotated session, six faces and a 360 deg turn about each axis, in raw
// counts, without labels or a thermometer, calibrates end to end through the README's commands, the
// gyro scale (set by the three turns alone) within its stated sigma.
TEST_F(CliTest, HandSessionWithLostSamplesKeepsItsGyroScaleAndSaysWhatWasLost) {
  // A serial link that loses 1 % of the frames, three in a row: the turns are integrated across
  // the gaps (before, each lost sample took its share of the angle: 0.3 % of scale, 65 sigma).
  constexpr double kTruthSigmas = 3.5;
  const std::string plan = Fixture("plan_hand_6faces_3turns.yaml");
  const std::string raw = Path("lossy.csv");
  ASSERT_EQ(Run({"simulate",
                 "--plan",
                 plan,
                 "--calibration",
                 Fixture("mems_truth.yaml"),
                 "-o",
                 raw,
                 "--temps",
                 "25",
                 "--rate",
                 "100",
                 "--dwell",
                 "10",
                 "--transition",
                 "2",
                 "--gyro-noise-density",
                 "8.7e-5",
                 "--accel-noise-density",
                 "1.5e-3",
                 "--quantize",
                 "--no-segment-column",
                 "--time-jitter-s",
                 "0.003",
                 "--drop-probability",
                 "0.0033",
                 "--drop-burst",
                 "3",
                 "--seed",
                 "4",
                 "-q"})
                .status,
            0);
  const std::string calibration = Path("lossy_cal.yaml");
  const RunResult fit = Run({"fit", "--plan", plan, "--samples", raw, "--gyro-temp-order", "0",
                             "--accel-temp-order", "0", "-o", calibration});
  ASSERT_EQ(fit.status, 0) << fit.err;
  // 33 losses of 3 were simulated; the one among the first 256 stamps (while the time grid is
  // acquired) goes uncounted.
  EXPECT_NE(fit.out.find(
                "time stamps: 96 samples lost in 32 gaps (longest 0.03 s): turns are integrated across them"),
            std::string::npos)
      << fit.out;
  const YAML::Node got = YAML::LoadFile(calibration);
  const YAML::Node want = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* axis : {"x", "y", "z"}) {
    const double estimate = got["gyro"]["scale"][axis][0].as<double>();
    const double sigma = got["sigma"]["gyro"]["scale"][axis][0].as<double>();
    const double true_value = want["gyro"]["scale"][axis][0].as<double>();
    EXPECT_LE(std::abs(estimate - true_value), kTruthSigmas * sigma)
        << axis << ": " << estimate << " vs " << true_value << " +- " << sigma;
  }
  // A gap longer than --max-turn-gap drops its turn; without the turns nothing sets the gyro scale.
  const RunResult strict =
      Run({"fit", "--plan", plan, "--samples", raw, "--gyro-temp-order", "0", "--accel-temp-order", "0",
           "--max-turn-gap", "0.015", "-o", Path("strict.yaml")});
  EXPECT_EQ(strict.status, 1) << strict.err;
  EXPECT_NE(strict.err.find("turns dropped for a gap longer than 0.015 s"), std::string::npos) << strict.err;
  EXPECT_NE(strict.err.find("gyro scale"), std::string::npos) << strict.err;
  EXPECT_FALSE(std::filesystem::exists(Path("strict.yaml")));
}

TEST_F(CliTest, HandSessionWithoutLabelsOrTemperatureCalibratesEndToEnd) {
  // Within this many of its reported sigmas (worst case over the 25 degC coefficients).
  constexpr double kTruthSigmas = 3.5;
  const std::string plan = Fixture("plan_hand_6faces_3turns.yaml");
  const std::string raw = Path("hand.csv");
  const std::string truth = Path("hand_truth.csv");
  ASSERT_EQ(Run({"simulate", "--plan", plan, "--calibration", Fixture("mems_truth.yaml"), "-o", raw, "--temps", "25",
                 "--rate", "100", "--dwell", "10", "--transition", "2", "--gyro-noise-density", "8.7e-5",
                 "--accel-noise-density", "1.5e-3", "--quantize", "--no-segment-column", "--no-temp-column",
                 "--time-jitter-s", "0.003", "--seed", "4", "--truth", truth, "-q"})
                .status,
            0);
  const RunResult segment = Run({"segment", "--plan", plan, "--samples", raw, "-o", Path("hand_labelled.csv")});
  ASSERT_EQ(segment.status, 0) << segment.err;
  EXPECT_NE(segment.out.find("9 segments found in 1 pass"), std::string::npos) << segment.out;
  EXPECT_EQ(std::count(segment.out.begin(), segment.out.end(), '\n') - 3, 9) << segment.out;
  const std::string calibration = Path("hand_cal.yaml");
  const RunResult fit = Run({"fit", "--plan", plan, "--samples", raw, "--temp-c", "25", "-o", calibration,
                             "--report", Path("hand_fit.html"), "--serial", "HAND-1"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_NE(fit.out.find("temperature orders 0"), std::string::npos) << fit.out;
  // The certificate reads the run as the fit did (labels found in the data, --temp-c): its noise
  // section looks for the longest rest instead of failing on the missing columns.
  const RunResult report = Run({"report", "-c", calibration, "-p", plan, "-s", raw, "--temp-c", "25", "-o",
                                Path("hand_report.html"), "--serial", "HAND-1"});
  ASSERT_EQ(report.status, 0) << report.err;
  for (const char* html : {"hand_fit.html", "hand_report.html"}) {
    const std::string text = ReadBytes(Path(html));
    EXPECT_NE(text.find("the longest static stretch is"), std::string::npos) << html;
    EXPECT_EQ(text.find("no segment column"), std::string::npos) << html;
    EXPECT_EQ(text.find("temp_c"), std::string::npos) << html << ": a missing-column message";
  }

  const YAML::Node got = YAML::LoadFile(calibration);
  const YAML::Node want = YAML::LoadFile(Fixture("mems_truth.yaml"));
  int checked = 0;
  for (const char* sensor : {"gyro", "accel"}) {
    for (const auto& group : got[sensor]) {
      const std::string name = group.first.as<std::string>();
      if (name == "unit") continue;
      for (const auto& coefficient : group.second) {
        const std::string axis = coefficient.first.as<std::string>();
        const double estimate = coefficient.second[0].as<double>();
        const double sigma = got["sigma"][sensor][name][axis][0].as<double>();
        const double true_value = want[sensor][name][axis][0].as<double>();  // at 25 degC
        ASSERT_GT(sigma, 0.0) << sensor << " " << name << " " << axis;
        EXPECT_LE(std::abs(estimate - true_value), kTruthSigmas * sigma)
            << sensor << " " << name << " " << axis << ": " << estimate << " vs " << true_value << " +- " << sigma;
        if (std::string(sensor) == "gyro" && name == "scale") {
          EXPECT_LT(sigma / true_value, 1e-4) << "the turns set the gyro scale to better than 100 ppm";
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 21 + 12);

  // The calibration corrects the session: every resting sample's mean within what the noise leaves.
  const RunResult apply = Run({"apply", "--calibration", calibration, "--samples", raw, "--temp-c", "25", "-o",
                               Path("hand_corrected.csv"), "-q"});
  ASSERT_EQ(apply.status, 0) << apply.err;
  const Table corrected = ReadTable(Path("hand_corrected.csv"));
  const Table true_values = ReadTable(truth);
  ASSERT_EQ(corrected.rows.size(), true_values.rows.size());
  std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> error_sum;  // per static face
  std::map<int, int> count;
  for (size_t i = 0; i < corrected.rows.size(); ++i) {
    const int face = std::stoi(true_values.rows[i][true_values.Column("segment")]);
    if (face < 1 || face > 6) continue;
    error_sum.try_emplace(face, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    error_sum[face].first += corrected.Vector(i, "gyro") - true_values.Vector(i, "gyro");
    error_sum[face].second += corrected.Vector(i, "accel") - true_values.Vector(i, "accel");
    ++count[face];
  }
  ASSERT_EQ(error_sum.size(), 6u);
  for (const auto& [face, sums] : error_sum) {
    EXPECT_LT((sums.first / count[face]).norm(), 0.005 * kDegToRad) << "face " << face << ", rad/s";
    EXPECT_LT((sums.second / count[face]).norm(), 0.5e-3 * 9.80665) << "face " << face << ", m/s^2";
  }
}

// Issue 9: a hand-rotated cube (six faces, one 360 degree turn about each axis, raw counts, one
// temperature) calibrates end to end with the gyro scale within its stated sigma, and the same
// run against a plan with one turn's sign flipped is refused, naming the convention to check.
TEST_F(CliTest, HandRotatedCubeCalibratesAndASignFlipIsRefused) {
  std::string plan_text =
      "format: imufit-plan\nversion: 1\ngravity_mps2: 9.80665\nsegments:\n"
      "  - {id: 1, up: [0, 0, 1]}\n  - {id: 2, up: [0, 0, -1]}\n  - {id: 3, up: [1, 0, 0]}\n"
      "  - {id: 4, up: [-1, 0, 0]}\n  - {id: 5, up: [0, 1, 0]}\n  - {id: 6, up: [0, -1, 0]}\n"
      "  - {id: 7, up: [0, 0, 1], angle_deg: 360, axis: [1, 0, 0]}\n"
      "  - {id: 8, up: [0, 0, 1], angle_deg: 360, axis: [0, 1, 0]}\n"
      "  - {id: 9, up: [0, 0, 1], angle_deg: 360}\n";
  const std::string plan = Write("cube.yaml", plan_text);
  RunResult r = Run({"simulate", "-p", plan, "-c", Fixture("mems_truth.yaml"), "-o", Path("cube.csv"),
                     "--gyro-noise-density", "1e-4", "--accel-noise-density", "5e-4", "--quantize", "--seed", "3",
                     "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"fit", "-p", plan, "-s", Path("cube.csv"), "-o", Path("cal.yaml"), "--gyro-temp-order", "0",
           "--accel-temp-order", "0"});
  ASSERT_EQ(r.status, 0) << r.err;
  const YAML::Node fitted = YAML::LoadFile(Path("cal.yaml"));
  const YAML::Node truth = YAML::LoadFile(Fixture("mems_truth.yaml"));
  for (const char* axis : {"x", "y", "z"}) {
    const double estimate = fitted["gyro"]["scale"][axis][0].as<double>();
    const double sigma = fitted["sigma"]["gyro"]["scale"][axis][0].as<double>();
    EXPECT_LT(std::abs(estimate - truth["gyro"]["scale"][axis][0].as<double>()), 3.0 * sigma) << axis;
  }
  // The printed sigmas are magnitudes.
  EXPECT_EQ(r.out.find("+- -"), std::string::npos) << r.out;

  plan_text.replace(plan_text.find("angle_deg: 360, axis: [1, 0, 0]"), 14, "angle_deg: -360");
  r = Run({"fit", "-p", Write("flipped.yaml", plan_text), "-s", Path("cube.csv"), "-o", Path("flipped_cal.yaml"),
           "--gyro-temp-order", "0", "--accel-temp-order", "0"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("gyro scale x is negative"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("right-hand rule"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("flipped_cal.yaml")));

  // apply refuses a calibration with a negative scale as bad input.
  YAML::Node negative = YAML::LoadFile(Path("cal.yaml"));
  negative["gyro"]["scale"]["y"][0] = -negative["gyro"]["scale"]["y"][0].as<double>();
  YAML::Emitter emitter;
  emitter << negative;
  r = Run({"apply", "-c", Write("negative.yaml", emitter.c_str()), "-s", Path("cube.csv"), "-o",
           Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("gyro.scale.y: the scale factor is negative"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
}

// ------------------------------------------------------------------------------------------ serials

// The serial a file names in a certificate, as the page shows it (data-key="serial").
std::string CertificateSerial(const std::string& html) {
  const std::string key = "data-key=\"serial\">";
  const size_t at = html.find(key);
  if (at == std::string::npos) return "<no serial element>";
  const size_t start = at + key.size();
  return html.substr(start, html.find('<', start) - start);
}

// issue 10 item 1: simulate --serial writes the serial into the samples' header, where fit, report
// and batch find it (after --serial and serial.txt, before the plan's); a certificate without a
// serial says so on stderr as well as on the page.
TEST_F(CliTest, SerialTravelsFromTheSamplesHeaderToCalibrationCertificateAndBatch) {
  const std::string plan = Fixture("plan_6pos.yaml");  // no serial of its own
  const auto simulate = [&](const std::string& out, const std::vector<std::string>& extra) {
    const RunResult r = Run(SmallRunArgs(out, extra));
    EXPECT_EQ(r.status, 0) << r.err;
  };
  fs::create_directories(work_ / "lot" / "u1");
  fs::create_directories(work_ / "lot" / "u2");
  const std::string named = Path("lot/u1/samples.csv");
  simulate(named, {"--serial", "SN-77", "--truth", Path("truth.csv"), "--seed", "1"});
  EXPECT_NE(ReadFile(named).find("\n# serial: SN-77\ntime_s,"), std::string::npos);
  EXPECT_NE(ReadFile(Path("truth.csv")).find("\n# serial: SN-77\ntime_s,"), std::string::npos);

  RunResult r =
      Run({"fit", "-p", plan, "-s", named, "-o", Path("cal.yaml"), "--report", Path("cal.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(YAML::LoadFile(Path("cal.yaml"))["serial"].as<std::string>(), "SN-77");
  EXPECT_EQ(CertificateSerial(ReadBytes(Path("cal.html"))), "SN-77");
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("cal_override.yaml"), "--serial", "SN-OTHER",
           "--allow-mismatch", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("cal_override.yaml"))["serial"].as<std::string>(), "SN-OTHER");

  // A calibration without a serial: report takes the samples' serial; without one anywhere the
  // certificate says "(no serial)" under a warning, and stderr says so too (report and fit --report).
  YAML::Node unnamed = YAML::LoadFile(Path("cal.yaml"));
  unnamed["serial"] = "";
  YAML::Emitter emitter;
  emitter << unnamed;
  const std::string unnamed_cal = Write("unnamed.yaml", emitter.c_str());
  r = Run({"report", "-c", unnamed_cal, "-p", plan, "-s", named, "-o", Path("report.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("no serial"), std::string::npos) << r.err;
  EXPECT_EQ(CertificateSerial(ReadBytes(Path("report.html"))), "SN-77");
  const std::string anonymous = Path("anonymous.csv");
  simulate(anonymous, {"--seed", "2"});
  r = Run({"fit", "-p", plan, "-s", anonymous, "-o", Path("anonymous.yaml"), "--report",
           Path("anonymous.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("anonymous.csv: no serial (give --serial"), std::string::npos) << r.err;
  std::string html = ReadBytes(Path("anonymous.html"));
  EXPECT_EQ(CertificateSerial(html), "(no serial)");
  EXPECT_NE(html.find("data-warning=\"no serial"), std::string::npos);
  r = Run(
      {"report", "-c", Path("anonymous.yaml"), "-p", plan, "-s", anonymous, "-o", Path("anonymous2.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("anonymous.yaml: no serial (give --serial"), std::string::npos) << r.err;
  html = ReadBytes(Path("anonymous2.html"));
  EXPECT_EQ(CertificateSerial(html), "(no serial)");
  EXPECT_NE(html.find("data-warning=\"no serial"), std::string::npos);

  // batch: u1 by its samples' header; u2's serial.txt wins over its header (when allowed: a
  // contradiction is refused otherwise, SerialsThatDisagreeAreWarnedAboutOrRefused).
  simulate(Path("lot/u2/samples.csv"), {"--serial", "SN-HEADER", "--seed", "3"});
  Write("lot/u2/serial.txt", "SN-FILE\n");
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--no-report", "--jobs", "1",
           "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const Table summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 2u);
  EXPECT_EQ(summary.rows[0][summary.Column("serial")], "SN-77");
  EXPECT_EQ(summary.rows[1][summary.Column("serial")], "SN-FILE");
  EXPECT_EQ(YAML::LoadFile(Path("out/u1/calibration.yaml"))["serial"].as<std::string>(), "SN-77");

  // Bad serials: exit 2 at their place, nothing written.
  r = Run(
      {"simulate", "-p", plan, "-c", Fixture("mems_truth.yaml"), "-o", Path("bad.csv"), "--serial", "SN\n1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--serial: the serial \"SN\\x0a1\" holds a control character"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("bad.csv")));
  std::string two = ReadFile(named);
  two.insert(two.find("time_s,"), "#   serial: SN-78\n");
  r = Run({"fit", "-p", plan, "-s", Write("two.csv", two), "-o", Path("two.yaml")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("two.csv:3:13: a second serial \"SN-78\" after \"SN-77\""), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("two.yaml")));
  std::string bell = ReadFile(named);
  bell.replace(bell.find("SN-77"), 5, "SN\a77");
  r = Run({"apply", "-c", Path("cal.yaml"), "-s", Write("bell.csv", bell), "-o", Path("bell_out.csv")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bell.csv:2:11: the serial \"SN\\x0777\" holds a control character"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("bell_out.csv")));
}

// The warnings of a certificate (data-warning attributes), unescaped.
std::vector<std::string> CertificateWarnings(const std::string& html) {
  std::vector<std::string> warnings;
  const std::string key = "data-warning=\"";
  for (size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + 1)) {
    const size_t start = at + key.size();
    std::string text = html.substr(start, html.find('"', start) - start);
    for (const auto& [entity, character] :
         {std::pair<std::string, std::string>{"&quot;", "\""}, {"&amp;", "&"}}) {
      for (size_t e = text.find(entity); e != std::string::npos; e = text.find(entity, e + 1))
        text.replace(e, entity.size(), character);
    }
    warnings.push_back(text);
  }
  return warnings;
}

// Whether one of `lines` holds every one of `parts`.
bool AnyHoldsAll(const std::vector<std::string>& lines, const std::vector<std::string>& parts) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& line) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](const std::string& part) { return line.find(part) != std::string::npos; });
  });
}

// --serial (a batch unit's serial.txt), the samples header's serial and the plan's may name
// different units. The first names the unit; each disagreement is a warning on stderr and on the
// certificate naming both sources and serials; a stated serial that contradicts the samples' own
// header (one unit's serial beside another unit's log) is refused at the header's line, exit 2,
// unless --allow-mismatch.
TEST_F(CliTest, SerialsThatDisagreeAreWarnedAboutOrRefused) {
  const std::string plan = Fixture("plan_6pos.yaml");  // no serial of its own
  std::string named_plan_text = ReadFile(plan);
  named_plan_text.insert(named_plan_text.find("version:"), "serial: SN-PLAN\n");
  const std::string named_plan = Write("named_plan.yaml", named_plan_text);
  fs::create_directories(work_ / "lot" / "u1");
  const auto simulate = [&](const std::string& out, const std::vector<std::string>& extra) {
    const RunResult r = Run(SmallRunArgs(out, extra));
    ASSERT_EQ(r.status, 0) << r.err;
  };
  const std::string named = Path("lot/u1/samples.csv");  // its header: "# serial: SN-77" on line 2
  simulate(named, {"--serial", "SN-77", "--seed", "1"});
  const std::string anonymous = Path("anonymous.csv");
  simulate(anonymous, {"--seed", "2"});
  const std::string header = "the samples header of " + named;

  // The samples header and the plan: the header names the unit, a warning says what the plan said.
  RunResult r =
      Run({"fit", "-p", named_plan, "-s", named, "-o", Path("a.yaml"), "--report", Path("a.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string plan_vs_header = "the plan " + named_plan + " names the unit \"SN-PLAN\", " + header +
                                     " names it \"SN-77\": \"SN-77\" is used";
  EXPECT_NE(r.err.find("imufit: warning: " + plan_vs_header + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("a.yaml"))["serial"].as<std::string>(), "SN-77");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(ReadBytes(Path("a.html"))), {plan_vs_header}));

  // --serial over the plan (the unit's log names none): a warning.
  r = Run({"fit", "-p", named_plan, "-s", anonymous, "-o", Path("b.yaml"), "--serial", "SN-1", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the plan " + named_plan +
                       " names the unit \"SN-PLAN\", --serial names it \"SN-1\": "
                       "\"SN-1\" is used"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("b.yaml"))["serial"].as<std::string>(), "SN-1");

  // --serial against the samples' own header: refused at the header's line, nothing written.
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("c.yaml"), "--serial", "SN-OTHER", "--report",
           Path("c.html")});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(
      r.err.find(named + ":2:11: " + header +
                 " names the unit \"SN-77\", --serial names it "
                 "\"SN-OTHER\": are these that unit's samples? (--allow-mismatch uses \"SN-OTHER\" anyway)"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("c.yaml")));
  EXPECT_FALSE(fs::exists(Path("c.html")));
  // Allowed: --serial names the unit, with the warning on stderr and on the certificate.
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("c.yaml"), "--serial", "SN-OTHER", "--report",
           Path("c.html"), "--allow-mismatch", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string allowed = header +
                              " names the unit \"SN-77\", --serial names it \"SN-OTHER\": \"SN-OTHER\" "
                              "is used (allowed with --allow-mismatch)";
  EXPECT_NE(r.err.find("imufit: warning: " + allowed + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("c.yaml"))["serial"].as<std::string>(), "SN-OTHER");
  std::string html = ReadBytes(Path("c.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-OTHER");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html), {allowed}));

  // report: the calibration's serial against the header is a warning; --serial against the header
  // is refused unless --allow-mismatch.
  r = Run({"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string calibration_vs_header =
      header + " names the unit \"SN-77\", the calibration " + Path("c.yaml") + " names it \"SN-OTHER\"";
  EXPECT_NE(r.err.find(calibration_vs_header), std::string::npos) << r.err;
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(ReadBytes(Path("r.html"))), {calibration_vs_header}));
  r = Run(
      {"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r2.html"), "--serial", "SN-3"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(named + ":2:11: " + header + " names the unit \"SN-77\", --serial names it \"SN-3\""),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("r2.html")));
  r = Run({"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r2.html"), "--serial", "SN-3",
           "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.err;
  html = ReadBytes(Path("r2.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-3");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html),
                          {"--serial names it \"SN-3\"", "(allowed with --allow-mismatch)"}));

  // batch: a unit whose serial.txt contradicts its samples header is an error (the lot exits 3);
  // allowed, it is fitted under serial.txt's serial with the warning on stderr and its certificate.
  Write("lot/u1/serial.txt", "SN-FILE\n");
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--jobs", "1", "-q"});
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  Table summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 1u);
  EXPECT_EQ(summary.rows[0][summary.Column("status")], "error");
  const std::string serial_txt = Path("lot/u1/serial.txt");
  EXPECT_NE(summary.rows[0][summary.Column("message")].find(named + ":2:11: " + header), std::string::npos);
  EXPECT_NE(ReadFile(Path("out/lot_summary.csv")).find(serial_txt + " names it \"\"SN-FILE\"\""),
            std::string::npos);
  EXPECT_FALSE(fs::exists(Path("out/u1/calibration.yaml")));
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--jobs", "1", "-q", "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string batch_allowed =
      header + " names the unit \"SN-77\", " + serial_txt +
      " names it \"SN-FILE\": \"SN-FILE\" is used (allowed with --allow-mismatch)";
  EXPECT_NE(r.err.find("imufit: warning: u1: " + batch_allowed + "\n"), std::string::npos) << r.err;
  summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 1u);
  EXPECT_EQ(summary.rows[0][summary.Column("serial")], "SN-FILE");
  html = ReadBytes(Path("out/u1/report.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-FILE");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html), {batch_allowed}));
}

// ------------------------------------------------------------------------------------------ allan

// The angle random walk a summary of `imufit allan` prints for `column`, deg/sqrt(h) (NaN if none).
double PrintedArw(const std::string& summary, const std::string& column) {
  const size_t at = summary.find(column + " (gyro");
  const std::string label = "angle random walk";
  const size_t line = at == std::string::npos ? std::string::npos : summary.find(label, at);
  return line == std::string::npos ? std::nan("") : std::stod(summary.substr(line + label.size()));
}

// issue 10 item 5: `imufit allan --calibration` analyses a raw-count log through the shared
// correction, with the result of `imufit apply` then `imufit allan` to the last bit, and the
// simulated noise density comes back.
TEST_F(CliTest, AllanWithCalibrationEqualsApplyThenAllanOnARawLog) {
  const std::string plan = Write("static.yaml",
                                 "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
                                 "  - {id: 1, up: [0, 0, 1]}\n");
  const std::string truth = Fixture("mems_truth.yaml");
  constexpr double kGyroNoiseDensity = 8.7e-5;  // rad/s/sqrt(Hz); ARW = N * 180/pi * 60 deg/sqrt(h)
  // 300 s at 100 Hz fix the ARW to about 1 % (one sigma); not quantised, so the white noise is
  // the simulated one alone.
  constexpr double kArwRelativeTolerance = 0.05;
  RunResult r = Run({"simulate",
                     "-p",
                     plan,
                     "-c",
                     truth,
                     "-o",
                     Path("raw.csv.gz"),
                     "--rate",
                     "100",
                     "--dwell",
                     "300",
                     "--temps",
                     "40",
                     "--gyro-noise-density",
                     "8.7e-5",
                     "--accel-noise-density",
                     "1.5e-3",
                     "--seed",
                     "11",
                     "-q"});
  ASSERT_EQ(r.status, 0) << r.err;

  // Raw counts without a calibration: the warning names the cure.
  r = Run({"allan", "-s", Path("raw.csv.gz"), "-c", "gyro_x", "-o", Path("raw_allan.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("gyro_x has a mean of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--calibration CAL.yaml"), std::string::npos) << r.err;

  r = Run({"allan", "-s", Path("raw.csv.gz"), "--calibration", truth, "-o", Path("direct.csv"),
           "--noise-yaml", Path("direct.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");  // corrected: nothing implausible, inside the fit range
  const std::string direct_summary = r.out;
  ASSERT_EQ(Run({"apply", "-c", truth, "-s", Path("raw.csv.gz"), "-o", Path("corrected.csv"), "-q"}).status,
            0);
  r = Run({"allan", "-s", Path("corrected.csv"), "-o", Path("applied.csv"), "--noise-yaml",
           Path("applied.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  // Every deviation, bound and noise term bit for bit (the files differ only in the input named).
  EXPECT_EQ(ReadBytes(Path("direct.csv")), ReadBytes(Path("applied.csv")));
  std::string direct_yaml = ReadBytes(Path("direct.yaml"));
  const std::string applied_yaml = ReadBytes(Path("applied.yaml"));
  // The noise file names the calibration the figures were corrected through, with its SHA-256
  // (only then); the summary names it too.
  EXPECT_EQ(YAML::Load(direct_yaml)["noise"]["calibration"].as<std::string>(), truth);
  EXPECT_EQ(YAML::Load(direct_yaml)["noise"]["calibration_sha256"].as<std::string>(), Sha256OfFile(truth));
  EXPECT_FALSE(YAML::Load(applied_yaml)["noise"]["calibration"]);
  EXPECT_FALSE(YAML::Load(applied_yaml)["noise"]["calibration_sha256"]);
  EXPECT_EQ(direct_summary.find(Path("raw.csv.gz") + " corrected by " + truth + ": "), 0u) << direct_summary;
  EXPECT_EQ(r.out.find(Path("corrected.csv") + ": "), 0u) << r.out;
  const std::string recorded =
      "  calibration: \"" + truth + "\"\n  calibration_sha256: \"" + Sha256OfFile(truth) + "\"\n";
  ASSERT_NE(direct_yaml.find(recorded), std::string::npos) << direct_yaml;
  direct_yaml.erase(direct_yaml.find(recorded), recorded.size());
  direct_yaml.replace(direct_yaml.find(Path("raw.csv.gz")), Path("raw.csv.gz").size(), Path("corrected.csv"));
  EXPECT_EQ(direct_yaml, applied_yaml);
  const auto summary_body = [](const std::string& summary) { return summary.substr(summary.find('\n')); };
  EXPECT_EQ(summary_body(direct_summary), summary_body(r.out));
  const double expected_arw = kGyroNoiseDensity * 180.0 / M_PI * 60.0;
  for (const char* column : {"gyro_x", "gyro_y", "gyro_z"}) {
    const double arw = PrintedArw(direct_summary, column);
    EXPECT_NEAR(arw, expected_arw, kArwRelativeTolerance * expected_arw) << column << "\n" << direct_summary;
  }

  // A log without temp_c needs --temp-c, as apply does; --temp-c alone, --scale with
  // --calibration and a column no calibration corrects are bad invocations; nothing is written.
  r = Run({"simulate", "-p", plan, "-c", truth, "-o", Path("no_temp.csv"), "--rate", "100", "--dwell", "30",
           "--no-temp-column", "--no-segment-column", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "-o", Path("x.csv")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no column \"temp_c\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--temp-c"), std::string::npos) << r.err;
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "--temp-c", "25", "-c",
           "gyro_z,temp_c", "-o", Path("no_temp_allan.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(ReadBytes(Path("no_temp_allan.csv")).find("\ntemp_c,oadev,0.01,"), std::string::npos);
  r = Run({"allan", "-s", Path("no_temp.csv"), "--calibration", truth, "--temp-c", "125", "-c", "gyro_z",
           "-o", Path("hot.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lie more than 0.5 degC outside the calibration's fit temperature range"),
            std::string::npos)
      << r.err;
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--temp-c", "25"},
        {"--calibration", truth, "--scale", "939.65"},
        {"--calibration", truth, "--temp-c", "25", "-c", "gyro_x,segment"},
        {"--calibration", Path("x.csv"), "--temp-c", "25"}}) {
    std::vector<std::string> args = {"allan", "-s", Path("no_temp.csv"), "-o", Path("x.csv")};
    args.insert(args.end(), bad.begin(), bad.end());
    r = Run(args);
    EXPECT_EQ(r.status, 2) << bad[0] << " " << bad[1] << ": " << r.err;
    EXPECT_FALSE(fs::exists(Path("x.csv"))) << bad[0];
  }
}

}  // namespace
}  // namespace imufit
