// imufit export end to end: every format's golden file (fixtures/golden/export), every lossy
// format's round trip (the consumer's equations, written here from its documentation, applied to
// a simulated raw run and compared with `imufit apply` within the loss the export reported), the
// JSON and blob read back bit for bit (the refusal beyond --max-loss and the error paths: cli_export_test).
//
// IMUFIT_UPDATE_GOLDEN=1 in the environment rewrites the golden files instead of comparing.
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Dense>

#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "imufit_runtime.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::ReadBytes;
using testing::RunProgram;
using testing::RunResult;

const std::string kFixtures = IMUFIT_FIXTURES_DIR;
constexpr double kGravity = 9.80665;
constexpr double kDegPerRad = 180.0 / M_PI;
// The reported loss is printed to 3 significant digits and measured on a grid: a run's samples
// lie inside the envelope but between its points.
constexpr double kLossReportMargin = 1.01;
// Where the loss is float32 rounding alone, a sample between the grid's points may round a little
// worse than any of them: a few units of float32 rounding of the sample's own value are allowed.
constexpr double kFloat32Rounding = 4 * 0x1p-24;

// What a consumer's driver divides the raw output by: raw per rad/s, raw per m/s^2.
struct Driver {
  double gyro_raw_per_radps;
  double accel_raw_per_mps2;
  std::vector<std::string> Args() const {
    return {"--gyro-raw-per-radps", FormatDouble(gyro_raw_per_radps), "--accel-raw-per-mps2",
            FormatDouble(accel_raw_per_mps2)};
  }
};
// The MEMS unit in counts (fixtures/README.md): 16.4 LSB per deg/s, 2048 LSB per g.
const Driver kMemsDriver = {939.65, 208.838};
// The tactical unit in physical units: deg/s and g.
const Driver kTacticalDriver = {180.0 / M_PI, 1.0 / 9.80665};
const std::vector<std::string> kDriver = kMemsDriver.Args();

// A noise block, as `imufit allan --noise-yaml` writes its Kalibr figures, appended to a unit.
constexpr const char* kNoiseBlock = R"(noise:
  format: imufit-noise
  version: 1
  kalibr:
    gyroscope_noise_density: 0.00026
    gyroscope_random_walk: 2.1e-05
    accelerometer_noise_density: 0.0023
    accelerometer_random_walk: 0.00011
    update_rate: 50
)";

struct Format {
  const char* name;
  const char* calibration;  // in fixtures/, or mems_truth_noise.yaml (written by the test)
  const char* golden;       // in fixtures/golden/export/
  std::vector<std::string> args;
};

std::vector<std::string> Plus(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

const std::vector<Format>& Formats() {
  static const std::vector<Format> formats = {
      {"c", "mems_truth.yaml", "mems_truth.h", {}},
      {"bin", "mems_truth.yaml", "mems_truth.bin", {}},
      {"px4", "mems_truth.yaml", "mems_truth.params", Plus(kDriver, {"--device-id", "2621474", "--force"})},
      {"ardupilot", "mems_truth.yaml", "mems_truth.parm",
       Plus(kDriver, {"--device-id", "2621474", "--force"})},
      {"kalibr", "mems_truth_noise.yaml", "mems_truth_noise_kalibr.yaml", Plus(kDriver, {"--force"})},
      {"imucal", "mems_truth.yaml", "mems_truth_imucal.json", {"--force"}},
      {"json", "mems_truth.yaml", "mems_truth.json", {}}};
  return formats;
}

// The worst-case loss per axis an export printed: gyro deg/s, accel mg.
struct ReportedLoss {
  Eigen::Vector3d gyro_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mg = Eigen::Vector3d::Zero();
};

ReportedLoss ParseLoss(const std::string& out) {
  ReportedLoss loss;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    double x, y, z;
    if (std::sscanf(line.c_str(), " gyro worst x %lf y %lf z %lf", &x, &y, &z) == 3)
      loss.gyro_dps = {x, y, z};
    if (std::sscanf(line.c_str(), " accel worst x %lf y %lf z %lf", &x, &y, &z) == 3)
      loss.accel_mg = {x, y, z};
  }
  return loss;
}

// A consumer's correction of one raw sample: rad/s and m/s^2 in imufit's body frame.
struct Corrected {
  Eigen::Vector3d omega_radps, a_mps2;
};
using Consumer = std::function<Corrected(const Sample& raw)>;

class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("imufit_export_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(Path("mems_truth_noise.yaml"), std::ios::binary)
        << ReadBytes(kFixtures + "/mems_truth.yaml") << kNoiseBlock;
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string CalibrationPath(const std::string& name) const {
    return name == "mems_truth_noise.yaml" ? Path(name) : kFixtures + "/" + name;
  }
  RunResult Run(const std::vector<std::string>& args) const {
    return RunProgram(IMUFIT_EXE, args, Path("stdout.txt"), Path("stderr.txt"));
  }
  // Exports `format` to `output`; the run's result.
  RunResult Export(const Format& format, const std::string& output) const {
    return Run(Plus({"export", "-c", CalibrationPath(format.calibration), "-f", format.name, "-o", output},
                    format.args));
  }
  const Format& FormatNamed(const std::string& name) const {
    for (const Format& f : Formats()) {
      if (name == f.name) return f;
    }
    throw std::logic_error(name);
  }

  // The raw noiseless ramp of fixtures/ and `imufit apply`'s correction of it with `calibration`.
  // The run of samples_ and `imufit apply`'s correction of it with `calibration` (kept for the
  // test's next round trip of the same calibration and run).
  void ReadRun(const std::string& calibration, std::vector<Sample>* raw, std::vector<Sample>* corrected) {
    const std::string& samples = samples_;
    auto& [cached_raw, cached_corrected] = runs_[{calibration, samples}];
    if (cached_raw.empty()) {
      const RunResult apply =
          Run({"apply", "-q", "-c", calibration, "-s", samples, "-o", Path("corrected.csv")});
      ASSERT_EQ(apply.status, 0) << apply.err;
      for (const auto& [path, out] :
           {std::pair{samples, &cached_raw}, std::pair{Path("corrected.csv"), &cached_corrected}}) {
        SamplesReader reader(path, false);
        for (Sample s; reader.Next(&s);) out->push_back(s);
      }
    }
    *raw = cached_raw;
    *corrected = cached_corrected;
    ASSERT_EQ(raw->size(), corrected->size());
    ASSERT_GT(raw->size(), 1000u);
  }

  // Exports `format` (of `calibration`, mems_truth.yaml by default), builds its consumer from the
  // file and checks it against `imufit apply` on the run within the loss the export reported;
  // returns that loss.
  // `extra_args` are added to the format's; samples outside [temp_low_c, temp_high_c] are not compared.
  ReportedLoss ExpectRoundTrip(const std::string& name,
                               const std::function<Consumer(const std::string& file)>& consumer_of,
                               std::string calibration = "", const std::vector<std::string>& extra_args = {},
                               double temp_high_c = HUGE_VAL, double temp_low_c = -HUGE_VAL) {
    const Format& format = FormatNamed(name);
    if (calibration.empty()) calibration = CalibrationPath(format.calibration);
    const std::string output = Path("export." + name);
    std::vector<std::string> args = format.args;
    for (size_t i = 0; i + 1 < args.size(); ++i) {  // the driver of the unit under test
      if (args[i] == "--gyro-raw-per-radps") args[i + 1] = FormatDouble(driver_.gyro_raw_per_radps);
      if (args[i] == "--accel-raw-per-mps2") args[i + 1] = FormatDouble(driver_.accel_raw_per_mps2);
    }
    const RunResult result =
        Run(Plus(Plus({"export", "-c", calibration, "-f", format.name, "-o", output}, args), extra_args));
    EXPECT_EQ(result.status, 0) << result.err;
    const ReportedLoss loss = ParseLoss(result.out);
    const Consumer consumer = consumer_of(output);
    std::vector<Sample> raw, corrected;
    ReadRun(calibration, &raw, &corrected);
    int beyond = 0;
    std::string first;
    for (size_t i = 0; i < raw.size(); ++i) {
      if (raw[i].temp_c > temp_high_c || raw[i].temp_c < temp_low_c) continue;
      const Corrected c = consumer(raw[i]);
      const Eigen::Vector3d gyro_error = (c.omega_radps - corrected[i].gyro).cwiseAbs() * kDegPerRad;
      const Eigen::Vector3d accel_error = (c.a_mps2 - corrected[i].accel).cwiseAbs() / kGravity * 1e3;
      const Eigen::Vector3d gyro_allowed =
          loss.gyro_dps * kLossReportMargin + kFloat32Rounding * corrected[i].gyro.cwiseAbs() * kDegPerRad;
      const Eigen::Vector3d accel_allowed = loss.accel_mg * kLossReportMargin +
                                            kFloat32Rounding * corrected[i].accel.cwiseAbs() / kGravity * 1e3;
      for (int axis = 0; axis < 3; ++axis) {
        if (gyro_error(axis) > gyro_allowed(axis) || accel_error(axis) > accel_allowed(axis)) {
          if (beyond++ == 0) {
            first = "sample " + std::to_string(i) + " axis " + std::to_string(axis) + ": gyro " +
                    std::to_string(gyro_error(axis)) + " deg/s (allowed " +
                    std::to_string(gyro_allowed(axis)) + "), accel " + std::to_string(accel_error(axis)) +
                    " mg (allowed " + std::to_string(accel_allowed(axis)) + ")";
          }
        }
      }
    }
    EXPECT_EQ(beyond, 0) << name << ": errors beyond the reported loss, first " << first;
    return loss;
  }

  fs::path dir_;
  // The run the round trips correct, and the driver of its unit.
  std::string samples_ = kFixtures + "/mems_6pos_noiseless.csv.gz";
  Driver driver_ = kMemsDriver;
  std::map<std::pair<std::string, std::string>, std::pair<std::vector<Sample>, std::vector<Sample>>> runs_;
};

TEST_F(ExportTest, EveryFormatMatchesItsGoldenFile) {
  const bool update = std::getenv("IMUFIT_UPDATE_GOLDEN") != nullptr;
  for (const Format& format : Formats()) {
    const std::string golden = kFixtures + "/golden/export/" + format.golden;
    const std::string output = update ? golden : Path(format.golden);
    const RunResult result = Export(format, output);
    ASSERT_EQ(result.status, 0) << format.name << ": " << result.err;
    if (!update) {
      EXPECT_EQ(ReadBytes(output), ReadBytes(golden)) << format.name << ": differs from " << golden;
    }
  }
}

// --- The consumers, from their documentation (the exporters' sources cite the same) -----------

// Name -> value of a PX4 .params or an ArduPilot .parm, read as their loaders read them: for PX4
// QGroundControl's ParameterManager (a line starting with '#' is a comment; every other line has
// exactly five tab-separated fields: vehicle 1, component, name, value, MAV_PARAM_TYPE 6 INT32 or
// 9 REAL32); for ArduPilot MAVProxy's `param load` ('#' comments; NAME VALUE, exactly two fields
// after commas become spaces). Every value as the float32 the autopilot stores; `integers` gets
// the INT32 parameters exactly.
std::map<std::string, float> ReadParameters(const std::string& path, bool px4,
                                            std::map<std::string, long long>* integers = nullptr) {
  std::map<std::string, float> parameters;
  std::istringstream lines(ReadBytes(path));
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    if (px4) {
      std::istringstream split(line);
      for (std::string field; std::getline(split, field, '\t');) fields.push_back(field);
      EXPECT_EQ(fields.size(), 5u) << line;
      if (fields.size() != 5) continue;
      EXPECT_EQ(fields[0], "1") << line;
      EXPECT_TRUE(fields[4] == "6" || fields[4] == "9") << line;
      if (fields[4] == "6") {
        size_t used = 0;
        const long long value = std::stoll(fields[3], &used);
        EXPECT_EQ(used, fields[3].size()) << "an INT32 parameter that is not a whole number: " << line;
        EXPECT_TRUE(value >= INT32_MIN && value <= INT32_MAX) << line;
        if (integers != nullptr) (*integers)[fields[2]] = value;
      }
      fields = {fields[2], fields[3]};
    } else {
      std::replace(line.begin(), line.end(), ',', ' ');
      std::istringstream split(line);
      for (std::string field; split >> field;) fields.push_back(field);
      EXPECT_EQ(fields.size(), 2u) << line;
      if (fields.size() != 2) continue;
      if (integers != nullptr) (*integers)[fields[0]] = std::llround(std::strtod(fields[1].c_str(), nullptr));
    }
    char* end = nullptr;
    parameters[fields[0]] = std::strtof(fields[1].c_str(), &end);
    EXPECT_EQ(*end, '\0') << "not a number: " << line;
    EXPECT_TRUE(std::isfinite(parameters[fields[0]])) << line;
  }
  return parameters;
}

// PX4's correction with the parameters of instance `n`; `v112_set_scale`: CAL_ACCn_xSCALE loaded as
// v1.12's Accelerometer::set_scale() loads it after boot (kept at 1 unless |scale - 1| > 0.01).
Consumer Px4ConsumerOf(const std::string& file, int n, bool v112_set_scale, Driver driver = kMemsDriver) {
  std::map<std::string, float> p = ReadParameters(file, true);
  const std::string tc_g = "TC_G" + std::to_string(n) + "_", tc_a = "TC_A" + std::to_string(n) + "_",
                    cal_gyro = "CAL_GYRO" + std::to_string(n) + "_",
                    cal_acc = "CAL_ACC" + std::to_string(n) + "_";
  EXPECT_EQ(p[tc_g + "ID"], p[cal_gyro + "ID"]);
  EXPECT_EQ(p[tc_a + "ID"], p[cal_acc + "ID"]);
  Eigen::Vector3f scale(p[cal_acc + "XSCALE"], p[cal_acc + "YSCALE"], p[cal_acc + "ZSCALE"]);
  if (v112_set_scale && !((scale - Eigen::Vector3f::Ones()).norm() > 0.01f)) scale = Eigen::Vector3f::Ones();
  return [p, tc_g, tc_a, cal_gyro, cal_acc, scale, driver](const Sample& raw) mutable {
    // TemperatureCompensation::calc_thermal_offsets_3D, then the calibration's Correct().
    const auto offsets = [&](const std::string& s) {
      const float t = static_cast<float>(raw.temp_c);
      const float tmax = p[s + "TMAX"], tmin = p[s + "TMIN"], tref = p[s + "TREF"];
      const float dt = t > tmax ? tmax - tref : t < tmin ? tmin - tref : t - tref;
      Eigen::Vector3f offset;
      for (int i = 0; i < 3; ++i) {
        const std::string axis = std::to_string(i);
        offset(i) = p[s + "X0_" + axis] + p[s + "X1_" + axis] * dt + p[s + "X2_" + axis] * (dt * dt) +
                    p[s + "X3_" + axis] * (dt * dt * dt);
      }
      return offset;
    };
    const Eigen::Vector3f gyro_offset = offsets(tc_g), accel_offset = offsets(tc_a);
    Corrected c;
    for (int i = 0; i < 3; ++i) {
      const std::string xyz(1, "XYZ"[i]);
      const float gyro = static_cast<float>(raw.gyro(i) / driver.gyro_raw_per_radps),
                  accel = static_cast<float>(raw.accel(i) / driver.accel_raw_per_mps2);
      c.omega_radps(i) = gyro - gyro_offset(i) - p[cal_gyro + xyz + "OFF"];
      c.a_mps2(i) = (accel - accel_offset(i) - p[cal_acc + xyz + "OFF"]) * scale(i);
    }
    return c;
  };
}

Consumer Px4Consumer(const std::string& file) {
  EXPECT_EQ(ReadParameters(file, true)["TC_G0_ID"], 2621474.0f);
  return Px4ConsumerOf(file, 0, false);
}

Consumer Px4V112Consumer(const std::string& file) { return Px4ConsumerOf(file, 0, true); }

// ArduPilot's correction with the parameters of instance `n` (1..3): INS_TCALn_*, and the n-th
// sensor's INS_ACCOFFS / INS_ACC2OFFS, INS_ACC1_CALTEMP / INS_ACC2_CALTEMP, ...
Consumer ArduPilotConsumerOf(const std::string& file, int n, Driver driver = kMemsDriver) {
  std::map<std::string, float> p = ReadParameters(file, false);
  const std::string tcal_prefix = "INS_TCAL" + std::to_string(n) + "_", number = std::to_string(n),
                    suffix = n == 1 ? "" : number;
  EXPECT_EQ(p[tcal_prefix + "ENABLE"], 1.0f);
  // The parameters' range (AP_InertialSensor_tempcal.cpp @Range -70 80), which ground stations hold to.
  for (const char* bound : {"TMIN", "TMAX"}) {
    EXPECT_GE(p[tcal_prefix + bound], -70.0f) << bound;
    EXPECT_LE(p[tcal_prefix + bound], 80.0f) << bound;
  }
  EXPECT_EQ(p.count("INS_ACC" + suffix + "_ID"), 1u) << "accel_calibrated_ok_all() needs the saved ID";
  EXPECT_EQ(p.count("INS_GYR" + suffix + "_ID"), 1u);
  return [p, tcal_prefix, number, suffix, driver](const Sample& raw) mutable {
    // AP_InertialSensor::TCal::correct_sensor: no constant term, 35 degC reference, x1e6.
    const float tmin = p[tcal_prefix + "TMIN"], tmax = p[tcal_prefix + "TMAX"];
    const auto clamp = [&](float t) { return std::min(std::max(t, tmin), tmax); };
    const auto tcal = [&](const std::string& s, int i, float t) {
      const std::string axis = "_" + std::string(1, "XYZ"[i]);
      const float c1 = p[tcal_prefix + s + "1" + axis], c2 = p[tcal_prefix + s + "2" + axis],
                  c3 = p[tcal_prefix + s + "3" + axis];
      const float tdiff = static_cast<float>(t - 35.0);
      return (c1 + (c2 + c3 * tdiff) * tdiff) * tdiff * static_cast<float>(1.0e-6);
    };
    const float t = clamp(static_cast<float>(raw.temp_c));
    Corrected c;
    for (int i = 0; i < 3; ++i) {
      const std::string xyz(1, "XYZ"[i]);
      float accel = static_cast<float>(raw.accel(i) / driver.accel_raw_per_mps2),
            gyro = static_cast<float>(raw.gyro(i) / driver.gyro_raw_per_radps);
      accel -= tcal("ACC", i, t);
      accel += tcal("ACC", i, clamp(p["INS_ACC" + number + "_CALTEMP"]));
      gyro -= tcal("GYR", i, t);
      gyro += tcal("GYR", i, clamp(p["INS_GYR" + number + "_CALTEMP"]));
      c.a_mps2(i) = (accel - p["INS_ACC" + suffix + "OFFS_" + xyz]) * p["INS_ACC" + suffix + "SCAL_" + xyz];
      c.omega_radps(i) = gyro - p["INS_GYR" + suffix + "OFFS_" + xyz];
    }
    return c;
  };
}

Consumer ArduPilotConsumer(const std::string& file) { return ArduPilotConsumerOf(file, 1); }

Eigen::Matrix3d Matrix(const YAML::Node& node) {
  Eigen::Matrix3d m;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) m(row, col) = node[row][col].as<double>();
  }
  return m;
}

Eigen::Vector3d Vector(const YAML::Node& node) {
  return {node[0].as<double>(), node[1].as<double>(), node[2].as<double>()};
}

Consumer KalibrConsumerOf(const std::string& file, Driver driver) {
  const YAML::Node imu = YAML::LoadFile(file);
  EXPECT_EQ(imu["model"].as<std::string>(), "scale-misalignment");
  EXPECT_GT(imu["gyroscope_noise_density"].as<double>(), 0.0);
  const std::string text = ReadBytes(file), marker = "# C_i_b: ";
  const size_t at = text.find(marker);
  EXPECT_NE(at, std::string::npos);
  const Eigen::Matrix3d c_i_b =
      Matrix(YAML::Load(text.substr(at + marker.size(), text.find('\n', at) - at - marker.size())));
  const Eigen::Matrix3d m_a = Matrix(imu["accelerometers"]["M"]), m_g = Matrix(imu["gyroscopes"]["M"]),
                        a_g = Matrix(imu["gyroscopes"]["A"]),
                        c_gyro_i = Matrix(imu["gyroscopes"]["C_gyro_i"]);
  const Eigen::Vector3d b_a = Vector(imu["accelerometers"]["b"]), b_g = Vector(imu["gyroscopes"]["b"]);
  EXPECT_EQ(m_a(0, 1), 0.0);  // Kalibr's matrices are lower triangular
  EXPECT_EQ(m_g(1, 2), 0.0);
  return [=](const Sample& raw) {
    // IccScaledMisalignedImu: alpha = M_a a_i + b_a, omega = M_g C_gyro_i w_i + A C_gyro_i a_i + b_g.
    const Eigen::Vector3d a_i = m_a.inverse() * (raw.accel / driver.accel_raw_per_mps2 - b_a);
    const Eigen::Vector3d w_i =
        c_gyro_i.transpose() *
        (m_g.inverse() * (raw.gyro / driver.gyro_raw_per_radps - b_g - a_g * c_gyro_i * a_i));
    return Corrected{c_i_b.transpose() * w_i, c_i_b.transpose() * a_i};
  };
}

Consumer KalibrConsumer(const std::string& file) { return KalibrConsumerOf(file, kMemsDriver); }

Consumer ImucalConsumer(const std::string& file) {
  const YAML::Node cal = YAML::LoadFile(file);  // JSON is YAML
  EXPECT_EQ(cal["cal_type"].as<std::string>(), "Ferraris");
  EXPECT_EQ(cal["gyr_unit"].as<std::string>(), "deg/s");
  const Eigen::Matrix3d acc_mat = Matrix(cal["R_a"]).inverse() * Matrix(cal["K_a"]).inverse();
  const Eigen::Matrix3d gyr_mat = Matrix(cal["R_g"]).inverse() * Matrix(cal["K_g"]).inverse();
  const Eigen::Matrix3d k_ga = Matrix(cal["K_ga"]);
  const Eigen::Vector3d b_a = Vector(cal["b_a"]), b_g = Vector(cal["b_g"]);
  return [=](const Sample& raw) {
    // FerrarisCalibrationInfo._calibrate_acc and ._calibrate_gyr.
    const Eigen::Vector3d acc = acc_mat * (raw.accel - b_a);
    const Eigen::Vector3d gyr_dps = gyr_mat * (raw.gyro - (k_ga * acc + b_g));
    return Corrected{gyr_dps / kDegPerRad, acc};
  };
}

Consumer RuntimeConsumer(const std::string& file) {
  const std::string blob = ReadBytes(file);
  imufit_calibration runtime{};
  EXPECT_EQ(imufit_load_blob(reinterpret_cast<const unsigned char*>(blob.data()), blob.size(), &runtime),
            IMUFIT_OK);
  return [runtime](const Sample& raw) {
    Corrected c;
    imufit_correct(&runtime, raw.temp_c, raw.gyro.data(), raw.accel.data(), c.omega_radps.data(),
                   c.a_mps2.data());
    return c;
  };
}

TEST_F(ExportTest, Px4RoundTripStaysWithinTheReportedLoss) { ExpectRoundTrip("px4", Px4Consumer); }

TEST_F(ExportTest, ArduPilotRoundTripStaysWithinTheReportedLoss) {
  ExpectRoundTrip("ardupilot", ArduPilotConsumer);
}

TEST_F(ExportTest, KalibrRoundTripStaysWithinTheReportedLoss) { ExpectRoundTrip("kalibr", KalibrConsumer); }

TEST_F(ExportTest, ImucalRoundTripStaysWithinTheReportedLoss) { ExpectRoundTrip("imucal", ImucalConsumer); }

TEST_F(ExportTest, BlobRoundTripThroughTheRuntimeStaysWithinTheReportedLoss) {
  ExpectRoundTrip("bin", RuntimeConsumer);
}

// Units whose model the consumer can hold: for the autopilots the bias cubics and a constant
// accelerometer scale (the gyro scale the driver's, no misalignment, no g-sensitivity); for the
// one-temperature formats any model without temperature dependence. Their loss is rounding alone,
// and the round trip through the consumer's equations shows it: the equations, signs, reference
// temperatures and re-expansions are right, not just within a large loss.
TEST_F(ExportTest, LossIsRoundingAloneWhereTheConsumerHoldsTheModel) {
  constexpr double kFloat32LossDps = 1e-3, kFloat32LossMg = 1e-2;  // worst case, float32 consumers
  constexpr double kDoubleLoss = 1e-9;                             // deg/s or mg, double consumers
  const Calibration unit = ReadCalibration(kFixtures + "/mems_truth.yaml");
  Calibration autopilot = unit;
  for (int i = kScaleCoefficient * kPolynomialTerms; i < kGyroParameters; ++i) autopilot.model.gyro[i] = 0.0;
  for (int i = kScaleCoefficient * kPolynomialTerms; i < kAccelParameters; ++i)
    autopilot.model.accel[i] = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    autopilot.model.gyro[(kScaleCoefficient + axis) * kPolynomialTerms] = 939.65;
    autopilot.model.accel[(kScaleCoefficient + axis) * kPolynomialTerms] =
        unit.model.accel[(kScaleCoefficient + axis) * kPolynomialTerms];
  }
  WriteCalibration(Path("autopilot.yaml"), autopilot);
  // ArduPilot's TMAX stops at 80 degC (the unit's range reaches 85): over the envelope up to 80.
  for (const auto& [name, consumer, args, temp_high_c] :
       {std::tuple{"px4", &Px4Consumer, std::vector<std::string>{}, HUGE_VAL},
        {"px4", &Px4V112Consumer, std::vector<std::string>{}, HUGE_VAL},
        {"ardupilot", &ArduPilotConsumer, std::vector<std::string>{"--envelope-temp-c", "-40,80"}, 80.0}}) {
    const ReportedLoss loss = ExpectRoundTrip(name, consumer, Path("autopilot.yaml"), args, temp_high_c);
    EXPECT_LT(loss.gyro_dps.maxCoeff(), kFloat32LossDps) << name;
    EXPECT_LT(loss.accel_mg.maxCoeff(), kFloat32LossMg) << name;
  }
  Calibration constant = unit;
  for (int i = 0; i < kGyroParameters; ++i) constant.model.gyro[i] *= i % kPolynomialTerms == 0;
  for (int i = 0; i < kAccelParameters; ++i) constant.model.accel[i] *= i % kPolynomialTerms == 0;
  std::ofstream(Path("constant.yaml"), std::ios::binary) << CalibrationToYaml(constant) << kNoiseBlock;
  for (const auto& [name, consumer] : {std::pair{"kalibr", KalibrConsumer}, {"imucal", ImucalConsumer}}) {
    const ReportedLoss loss = ExpectRoundTrip(name, consumer, Path("constant.yaml"));
    EXPECT_LT(loss.gyro_dps.maxCoeff(), kDoubleLoss) << name;
    EXPECT_LT(loss.accel_mg.maxCoeff(), kDoubleLoss) << name;
  }
}

TEST_F(ExportTest, JsonReadsBackBitForBitAndAppliesIdentically) {
  const RunResult exported = Export(FormatNamed("json"), Path("unit.json"));
  ASSERT_EQ(exported.status, 0) << exported.err;
  const Calibration original = ReadCalibration(kFixtures + "/mems_truth.yaml");
  const Calibration read_back = ReadCalibration(Path("unit.json"));
  EXPECT_EQ(read_back.model.gyro, original.model.gyro);
  EXPECT_EQ(read_back.model.accel, original.model.accel);
  EXPECT_EQ(read_back.model.basis.center_c, original.model.basis.center_c);
  EXPECT_EQ(read_back.fit_temp_range_c, original.fit_temp_range_c);
  EXPECT_EQ(read_back.serial, original.serial);
  EXPECT_TRUE(read_back.extra["export"]) << "the provenance is kept as a further key";
  const std::string samples = kFixtures + "/mems_6pos_noiseless.csv.gz";
  ASSERT_EQ(
      Run({"apply", "-q", "-c", kFixtures + "/mems_truth.yaml", "-s", samples, "-o", Path("a.csv")}).status,
      0);
  ASSERT_EQ(Run({"apply", "-q", "-c", Path("unit.json"), "-s", samples, "-o", Path("b.csv")}).status, 0);
  // The same samples; only the first line, what corrected them (its hash), differs.
  const auto samples_of = [](const std::string& text) { return text.substr(text.find('\n') + 1); };
  const std::string a = ReadBytes(Path("a.csv")), b = ReadBytes(Path("b.csv"));
  EXPECT_EQ(a.rfind("# corrected by: ", 0), 0u);
  EXPECT_EQ(samples_of(a), samples_of(b));
  // Further keys keep their types; JSON has no NaN.
  std::ofstream(Path("extra.yaml"), std::ios::binary)
      << ReadBytes(kFixtures + "/mems_truth.yaml") << "fit:\n  note: \"12\"\n  rms: .nan\n  windows: 12\n";
  ASSERT_EQ(Run({"export", "-c", Path("extra.yaml"), "-f", "json", "-o", Path("extra.json")}).status, 0);
  const std::string extra = ReadBytes(Path("extra.json"));
  EXPECT_NE(extra.find("\"note\": \"12\""), std::string::npos) << extra;
  EXPECT_NE(extra.find("\"rms\": null"), std::string::npos) << extra;
  EXPECT_NE(extra.find("\"windows\": 12"), std::string::npos) << extra;
  // A JSON export of the JSON export: the same calibration, one provenance block.
  ASSERT_EQ(Run({"export", "-c", Path("unit.json"), "-f", "json", "-o", Path("again.json")}).status, 0);
  const std::string again = ReadBytes(Path("again.json"));
  EXPECT_EQ(again.find("\"export\""), again.rfind("\"export\""));
}

// A real fitted calibration (fit:, sigma:) with the noise block of `imufit allan` appended goes
// YAML -> JSON -> read -> YAML bit for bit (the text of the writer, not only the numbers), and
// `imufit apply -c unit.json` corrects as the YAML does. The fit's record keeps its types in JSON.
TEST_F(ExportTest, AFittedCalibrationWithNoiseRoundTripsThroughJsonBitForBit) {
  const std::string golden = kFixtures + "/golden/mems_6pos_soak.yaml";
  const std::string fitted = ReadBytes(golden);
  EXPECT_EQ(CalibrationToYaml(ReadCalibration(golden)), fitted) << "the writer's text is its own fixed point";
  std::ofstream(Path("static.yaml"), std::ios::binary)
      << "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n  - {id: 1, up: [0, 0, 1]}\n";
  ASSERT_EQ(Run({"simulate",
                 "-p",
                 Path("static.yaml"),
                 "-c",
                 kFixtures + "/mems_truth.yaml",
                 "-o",
                 Path("static.csv"),
                 "--rate",
                 "100",
                 "--dwell",
                 "60",
                 "--temps",
                 "25",
                 "--gyro-noise-density",
                 "1e-4",
                 "--accel-noise-density",
                 "1e-3",
                 "--seed",
                 "5",
                 "-q"})
                .status,
            0);
  const RunResult allan =
      Run({"allan", "-s", Path("static.csv"), "--calibration", kFixtures + "/mems_truth.yaml", "-o",
           Path("adev.csv"), "--noise-yaml", Path("noise.yaml"), "-q"});
  ASSERT_EQ(allan.status, 0) << allan.err;
  std::ofstream(Path("unit.yaml"), std::ios::binary) << fitted << ReadBytes(Path("noise.yaml"));
  const Calibration unit = ReadCalibration(Path("unit.yaml"));
  ASSERT_TRUE(unit.fit && unit.sigma && unit.noise);
  ASSERT_FALSE(unit.noise->columns.empty());
  const std::string yaml = CalibrationToYaml(unit);

  const RunResult exported = Run({"export", "-c", Path("unit.yaml"), "-f", "json", "-o", Path("unit.json")});
  ASSERT_EQ(exported.status, 0) << exported.err;
  const std::string json = ReadBytes(Path("unit.json"));
  for (const char* typed : {"\"samples_read\": 26950,", "\"g_sensitivity_fitted\": true,",
                            "\"fitted\": true,", "\"points_used\": "}) {
    EXPECT_NE(json.find(typed), std::string::npos) << typed;
  }
  Calibration read = ReadCalibration(Path("unit.json"));
  read.extra.remove("export");
  EXPECT_EQ(CalibrationToYaml(read), yaml);
  EXPECT_EQ(read.model.gyro, unit.model.gyro);
  EXPECT_EQ(read.sigma->accel, unit.sigma->accel);
  EXPECT_EQ(read.noise->columns[0].value, unit.noise->columns[0].value);

  const std::string samples = kFixtures + "/mems_6pos_noiseless.csv.gz";
  ASSERT_EQ(Run({"apply", "-q", "-c", Path("unit.yaml"), "-s", samples, "-o", Path("a.csv")}).status, 0);
  const RunResult applied = Run({"apply", "-q", "-c", Path("unit.json"), "-s", samples, "-o", Path("b.csv")});
  ASSERT_EQ(applied.status, 0) << applied.err;
  const auto samples_of = [](const std::string& text) { return text.substr(text.find('\n') + 1); };
  EXPECT_EQ(samples_of(ReadBytes(Path("a.csv"))), samples_of(ReadBytes(Path("b.csv"))));
}

// A unit the autopilots hold but for an accelerometer scale 0.4 % off the driver's on every axis:
// CAL_ACC0_xSCALE = 0.996, within 0.01 (norm 0.0069) of 1, so PX4 v1.12's set_scale() keeps 1
// after boot. The loss reported is the worse of the two loaders: about 0.4 % of 2 g, not rounding.
TEST_F(ExportTest, Px4LossCoversV112SetScaleIgnoringAScaleNearOne) {
  constexpr double kWrittenScale = 0.996;
  constexpr double kExpectedLossMg = (1.0 / kWrittenScale - 1.0) * 2.0 * 1e3;  // worst case, at 2 g
  constexpr double kLossToleranceMg = 0.5;                                     // absolute
  Calibration unit = ReadCalibration(kFixtures + "/mems_truth.yaml");
  for (int i = kScaleCoefficient * kPolynomialTerms; i < kGyroParameters; ++i) unit.model.gyro[i] = 0.0;
  for (int i = kScaleCoefficient * kPolynomialTerms; i < kAccelParameters; ++i) unit.model.accel[i] = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    unit.model.gyro[(kScaleCoefficient + axis) * kPolynomialTerms] = 939.65;
    unit.model.accel[(kScaleCoefficient + axis) * kPolynomialTerms] = 208.838 / kWrittenScale;
  }
  WriteCalibration(Path("near_one.yaml"), unit);
  for (const auto consumer : {&Px4Consumer, &Px4V112Consumer}) {
    const ReportedLoss loss = ExpectRoundTrip("px4", consumer, Path("near_one.yaml"));
    EXPECT_NEAR(loss.accel_mg.maxCoeff(), kExpectedLossMg, kLossToleranceMg);
    EXPECT_LT(loss.gyro_dps.maxCoeff(), 1e-3);
  }
  const std::string params = ReadBytes(Path("export.px4"));
  EXPECT_NE(params.find("set_scale() (which ignores this scale: within 0.01 of 1, it keeps 1)"),
            std::string::npos)
      << params;
  EXPECT_NE(params.find("take effect only after a reboot"), std::string::npos) << params;
}

// --instance and separate device IDs, read back as QGroundControl reads the file; the consumer of
// instance 3 corrects within the reported loss. An ID above INT32_MAX keeps its 32 bits.
TEST_F(ExportTest, Px4InstanceAndSeparateDeviceIds) {
  const std::vector<std::string> ids = {"--instance",        "3",         "--gyro-device-id", "11",
                                        "--accel-device-id", "3735928559"};
  ExpectRoundTrip(
      "px4", [](const std::string& file) { return Px4ConsumerOf(file, 3, true); }, "", ids);
  std::map<std::string, long long> integers;
  const std::map<std::string, float> p = ReadParameters(Path("export.px4"), true, &integers);
  EXPECT_EQ(integers["TC_G_ENABLE"], 1);
  EXPECT_EQ(integers["TC_A_ENABLE"], 1);
  EXPECT_EQ(integers["TC_G3_ID"], 11);
  EXPECT_EQ(integers["CAL_GYRO3_ID"], 11);
  EXPECT_EQ(integers["TC_A3_ID"], static_cast<int32_t>(3735928559u));
  EXPECT_EQ(integers["CAL_ACC3_ID"], static_cast<int32_t>(3735928559u));
  for (const auto& [name, value] : p) {
    const bool instance_0 = name.rfind("TC_G0_", 0) == 0 || name.rfind("TC_A0_", 0) == 0 ||
                            name.rfind("CAL_GYRO0_", 0) == 0 || name.rfind("CAL_ACC0_", 0) == 0;
    EXPECT_FALSE(instance_0) << name;
  }
  EXPECT_EQ(p.count("CAL_ACC3_XSCALE"), 1u);
}

// ArduPilot: instance 2's names, the IDs accel_calibrated_ok_all() checks, TMAX held to the
// parameter's 80 degC with a warning (the unit's range reaches 85: the loss includes ArduPilot's
// clamping there), and over a narrow envelope a smaller loss.
TEST_F(ExportTest, ArduPilotInstanceIdsAndTemperatureRange) {
  const std::vector<std::string> ids = {"--instance",        "2", "--gyro-device-id", "11",
                                        "--accel-device-id", "22"};
  const ReportedLoss full = ExpectRoundTrip(
      "ardupilot", [](const std::string& file) { return ArduPilotConsumerOf(file, 2); }, "", ids);
  const RunResult warned = Run(Plus(
      Plus({"export", "-c", kFixtures + "/mems_truth.yaml", "-f", "ardupilot", "-o", Path("warned.parm")},
           kDriver),
      Plus(ids, {"--force"})));
  EXPECT_EQ(warned.status, 0);
  EXPECT_NE(
      warned.err.find("imufit: warning: the fitted range [-40, 85] degC lies beyond INS_TCAL2_TMIN/TMAX's "
                      "range [-70, 80] degC"),
      std::string::npos)
      << warned.err;
  std::map<std::string, long long> integers;
  const std::map<std::string, float> p = ReadParameters(Path("export.ardupilot"), false, &integers);
  EXPECT_EQ(integers["INS_ACC2_ID"], 22);
  EXPECT_EQ(integers["INS_GYR2_ID"], 11);
  EXPECT_EQ(p.at("INS_TCAL2_TMAX"), 80.0f);
  EXPECT_EQ(p.at("INS_TCAL2_TMIN"), -40.0f);
  EXPECT_EQ(p.count("INS_ACC2OFFS_X") + p.count("INS_ACC2SCAL_Z") + p.count("INS_GYR2OFFS_Y"), 3u);
  EXPECT_EQ(p.count("INS_ACC2_CALTEMP") + p.count("INS_GYR2_CALTEMP"), 2u);
  for (const auto& [name, value] : p) EXPECT_EQ(name.find("INS_TCAL1_"), std::string::npos) << name;
  const std::string parm = ReadBytes(Path("export.ardupilot"));
  EXPECT_NE(parm.find("INS_TCAL2_ENABLE must be 1 before the other INS_TCAL2_* parameters exist"),
            std::string::npos);
  EXPECT_LT(parm.find("\nINS_TCAL2_ENABLE 1\n"), parm.find("\nINS_TCAL2_TMIN "));
  const ReportedLoss narrow = ExpectRoundTrip(
      "ardupilot", [](const std::string& file) { return ArduPilotConsumerOf(file, 2); }, "",
      Plus(ids, {"--envelope-temp-c", "20,30"}), 30.0, 20.0);
  EXPECT_LT(narrow.accel_mg.maxCoeff(), full.accel_mg.maxCoeff());
}

// ArduPilot takes INS_ACCOFFS that are all exactly 0 for an accelerometer never calibrated and
// refuses to arm: a calibration whose accelerometer bias is 0 at every temperature is exported with
// a warning, on stderr and in the file; one with a bias is not.
TEST_F(ExportTest, ArduPilotWarnsWhenTheAccelerometerOffsetsAreAllZero) {
  std::string yaml = ReadBytes(kFixtures + "/mems_truth.yaml");
  const size_t accel = yaml.find("\naccel:");
  ASSERT_NE(accel, std::string::npos);
  const size_t bias = yaml.find("  bias:\n", accel);
  ASSERT_NE(bias, std::string::npos);
  const size_t end = yaml.find("  scale:", bias);
  yaml.replace(bias, end - bias, "  bias:\n    x: [0, 0, 0, 0]\n    y: [0, 0, 0, 0]\n    z: [0, 0, 0, 0]\n");
  std::ofstream(Path("zero_bias.yaml"), std::ios::binary) << yaml;
  const char* kWarning =
      "INS_ACCOFFS_X/Y/Z are all exactly 0: ArduPilot reads that as an accelerometer never "
      "calibrated and refuses to arm";
  const RunResult zero = Run(Plus(
      Plus({"export", "-c", Path("zero_bias.yaml"), "-f", "ardupilot", "-o", Path("zero.parm")}, kDriver),
      {"--force", "--device-id", "7"}));
  EXPECT_EQ(zero.status, 0) << zero.err;
  EXPECT_NE(zero.err.find(std::string("imufit: warning: ") + kWarning), std::string::npos) << zero.err;
  EXPECT_NE(ReadBytes(Path("zero.parm")).find(std::string("# warning: ") + kWarning), std::string::npos);
  std::map<std::string, long long> integers;
  const std::map<std::string, float> p = ReadParameters(Path("zero.parm"), false, &integers);
  EXPECT_EQ(p.at("INS_ACCOFFS_X"), 0.0f);
  const RunResult fitted = Run(Plus(
      Plus({"export", "-c", kFixtures + "/mems_truth.yaml", "-f", "ardupilot", "-o", Path("fitted.parm")},
           kDriver),
      {"--force", "--device-id", "7"}));
  EXPECT_EQ(fitted.status, 0) << fitted.err;
  EXPECT_EQ(fitted.err.find("are all exactly 0"), std::string::npos) << fitted.err;
}

// Real fitted units through the autopilots' and Kalibr's equations, on the runs they were fitted
// from: the MEMS unit in counts (fixtures/golden/mems_6pos_soak.yaml) and the tactical unit in
// physical units (deg/s and g: tactical_24pos_soak.yaml), over the whole fitted range (beyond
// ArduPilot's 80 degC for the MEMS unit, which reaches 85) and over a narrow one (20..30 degC).
TEST_F(ExportTest, RealFittedUnitsInCountsAndPhysicalUnitsStayWithinTheirLoss) {
  struct Unit {
    const char* calibration;
    const char* samples;
    Driver driver;
  };
  for (const Unit& unit : {Unit{"mems_6pos_soak.yaml", "mems_6pos_soak.csv.gz", kMemsDriver},
                           Unit{"tactical_24pos_soak.yaml", "tactical_24pos_soak.csv.gz", kTacticalDriver}}) {
    SCOPED_TRACE(unit.calibration);
    samples_ = kFixtures + "/" + unit.samples;
    driver_ = unit.driver;
    const std::string calibration = kFixtures + "/golden/" + unit.calibration;
    std::ofstream(Path("with_noise.yaml"), std::ios::binary) << ReadBytes(calibration) << kNoiseBlock;
    const Driver d = unit.driver;
    for (const auto& [range, temp_low_c, temp_high_c] :
         {std::tuple{std::vector<std::string>{}, -HUGE_VAL, HUGE_VAL},
          std::tuple{std::vector<std::string>{"--envelope-temp-c", "20,30"}, 20.0, 30.0}}) {
      const auto px4 = [d](bool v112) {
        return [d, v112](const std::string& file) { return Px4ConsumerOf(file, 0, v112, d); };
      };
      const ReportedLoss px4_loss =
          ExpectRoundTrip("px4", px4(false), calibration, range, temp_high_c, temp_low_c);
      ExpectRoundTrip("px4", px4(true), calibration, range, temp_high_c, temp_low_c);
      ExpectRoundTrip(
          "ardupilot", [d](const std::string& file) { return ArduPilotConsumerOf(file, 1, d); }, calibration,
          range, temp_high_c, temp_low_c);
      ExpectRoundTrip(
          "kalibr", [d](const std::string& file) { return KalibrConsumerOf(file, d); },
          Path("with_noise.yaml"), range, temp_high_c, temp_low_c);
      EXPECT_GT(px4_loss.gyro_dps.maxCoeff(), 0.0);
    }
  }
}

}  // namespace
}  // namespace imufit
