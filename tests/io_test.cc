// Tests of io/: every file format read and written per docs/spec.md, and every error located.
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "file_open_counter.h"
#include "imufit/io/calibration.h"
#include "imufit/io/csv_reader.h"
#include "imufit/io/error.h"
#include "imufit/io/hand_procedure.h"
#include "imufit/io/limits.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/noise_file.h"
#include "imufit/io/output_file.h"
#include "imufit/io/parallel_samples.h"
#include "imufit/io/plan.h"
#include "imufit/io/run_header.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/io/station.h"
#include "imufit/pipeline/correct_file.h"
#include "test_models.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

class IoTest : public testing::TempDirTest {
 protected:
  static std::string Read(const std::string& path) { return testing::ReadBytes(path); }
  // Runs `action`, expects an InputError, returns it.
  template <typename F>
  static InputError Catch(F action) {
    try {
      action();
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << "no InputError";
    return InputError("none", "none");
  }
};

// ---------------------------------------------------------------- station

constexpr const char* kStation = R"(format: imufit-station
version: 1
station: "Rate table bench 2"
station_id: CB-02
location: "Building 4, room 112"
operator: J. Smith
rate_table: {model: Acutronic AC1120S, serial: RT-2291}
chamber: {model: Espec SU-262}
reference_calibration_due: 2028-02-29
notes: "Rate table calibrated by the national lab, certificate NL-2026-0412."
)";

TEST_F(IoTest, StationFileIsRead) {
  const Station station = ReadStation(Write("station.yaml", kStation));
  EXPECT_EQ(station.name, "Rate table bench 2");
  EXPECT_EQ(station.id, "CB-02");
  EXPECT_EQ(station.location, "Building 4, room 112");
  EXPECT_EQ(station.operator_name, "J. Smith");
  EXPECT_EQ(station.rate_table.model, "Acutronic AC1120S");
  EXPECT_EQ(station.rate_table.serial, "RT-2291");
  EXPECT_EQ(station.chamber.model, "Espec SU-262");
  EXPECT_EQ(station.chamber.serial, "");
  EXPECT_EQ(station.reference_calibration_due, "2028-02-29");  // a leap day
  EXPECT_NE(station.notes.find("NL-2026-0412"), std::string::npos);
  // Only the name is required.
  const Station minimal =
      ReadStation(Write("minimal.yaml", "format: imufit-station\nversion: 1\nstation: B2\n"));
  EXPECT_EQ(minimal.name, "B2");
  EXPECT_TRUE(minimal.operator_name.empty());
}

TEST_F(IoTest, StationFileErrorsNameFileLineAndColumn) {
  const std::string head = "format: imufit-station\nversion: 1\nstation: B2\n";
  const struct {
    std::string text;
    std::string expected;  // part of the message, from ":line:column: " on
  } cases[] = {
      {head + "operater: J. Smith\n", ":4:1: unknown key \"operater\""},
      {head + "operator: A\noperator: B\n", ":5:1: key \"operator\" appears twice"},
      {head + "operator: [J. Smith]\n", ":4:11: operator: expected a text value"},
      {head + "rate_table: RT-2291\n", ":4:13: rate_table: expected a mapping"},
      {head + "rate_table: {model: X, serial: Y, due: 2027-01-01}\n",
       ":4:35: rate_table: unknown key \"due\""},
      {head + "chamber: {serial: {id: 1}}\n", ":4:19: chamber.serial: expected a text value"},
      {head + "reference_calibration_due: 2027-02-29\n",
       ":4:28: reference_calibration_due: \"2027-02-29\" is not a date"},
      {head + "reference_calibration_due: 31.03.2027\n",
       ":4:28: reference_calibration_due: \"31.03.2027\" is not a date"},
      {head + "location: \"\"\n", ":4:11: location: is empty"},
      {head + "notes: \"two\\nlines\"\n", ":4:8: notes: must be one line"},
      {head + "notes: " + std::string(kMaxStationTextBytes + 1, 'n') + "\n",
       ":4:8: notes: is 501 bytes long"},
      {"format: imufit-station\nversion: 1\n", ":1: station: missing (required)"},
      {"format: imufit-limits\nversion: 1\nstation: B2\n",
       ":1:9: format: \"imufit-limits\" is not \"imufit-station\""},
      {"format: imufit-station\nversion: 2\nstation: B2\n", ":2:10: version: version 2 is not supported"},
      {"format: imufit-station\nversion: 1\nstation: [\n", ":4:1: YAML syntax"},
  };
  int n = 0;
  for (const auto& c : cases) {
    const std::string path = Write("station" + std::to_string(n++) + ".yaml", c.text);
    const InputError e = Catch([&] { ReadStation(path); });
    EXPECT_NE(std::string(e.what()).find(path + c.expected), std::string::npos)
        << "got: " << e.what() << "\nexpected: " << c.expected;
  }
}

// ---------------------------------------------------------------- calibration

Calibration ExampleCalibration() {
  Calibration calibration;
  calibration.serial = "SN: 0001 \"quoted\"";
  calibration.created_utc = "2026-11-22T06:00:00Z";
  calibration.software = "imufit 0.1.0";
  calibration.fit_temp_range_c = {-40.0, 85.0};
  calibration.model = testing::RandomMemsModel(42);
  SensorModel sigma = testing::RandomMemsModel(43);
  calibration.sigma = sigma;
  calibration.fit.emplace().iterations = 7;
  return calibration;
}

// A plan's soak set-points (soak_temps_c) are read, written back by PlanYaml to the same numbers, and
// a value outside what an IMU reports (a set-point in kelvin) is refused at its place; a record's
// uncalibrated_sensors names sensors only.
TEST_F(IoTest, PlanSoakSetPointsAndUncalibratedSensorsAreRead) {
  const std::string text =
      "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsoak_temps_c: [-40, 25.5, 85]\n"
      "segments:\n  - {id: 1, up: [0, 0, 1]}\n";
  const Plan plan = ReadPlanText(text, "plan.yaml");
  EXPECT_EQ(plan.soak_temps_c, (std::vector<double>{-40.0, 25.5, 85.0}));
  EXPECT_EQ(ReadPlanText(PlanYaml(plan, ""), "again.yaml").soak_temps_c, plan.soak_temps_c);
  EXPECT_TRUE(
      ReadPlanText(
          "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n  - {id: 1, up: [0, 0, 1]}\n",
          "none.yaml")
          .soak_temps_c.empty());
  std::string kelvin = text;
  kelvin.replace(kelvin.find("85]"), 3, "358.15]");
  try {
    ReadPlanText(kelvin, "plan.yaml");
    ADD_FAILURE() << "a set-point in kelvin";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plan.yaml:4:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("358.15 degC is outside -100..200 degC"), std::string::npos)
        << e.what();
  }
  Calibration calibration;
  calibration.model = SensorModel::Identity();
  calibration.fit.emplace().uncalibrated_sensors = std::vector<std::string>{"gyro"};
  const std::string path = Path("cal.yaml");
  WriteCalibration(path, calibration);
  EXPECT_EQ(UncalibratedSensors(ReadCalibration(path)), std::vector<std::string>{"gyro"});
  std::string bad = testing::ReadFile(path);
  bad.replace(bad.find("[gyro]"), 6, "[magnetometer]");
  std::ofstream(path) << bad;
  try {
    ReadCalibration(path);
    ADD_FAILURE() << "magnetometer";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"magnetometer\" is not a sensor (gyro, accel)"), std::string::npos)
        << e.what();
  }
}

TEST_F(IoTest, CalibrationRoundTripsBitExactly) {
  const Calibration written = ExampleCalibration();
  const std::string path = (dir_ / "cal.yaml").string();
  WriteCalibration(path, written);
  const Calibration read = ReadCalibration(path);
  EXPECT_EQ(read.serial, written.serial);
  EXPECT_EQ(read.created_utc, written.created_utc);
  EXPECT_EQ(read.software, written.software);
  EXPECT_EQ(read.fit_temp_range_c, written.fit_temp_range_c);
  EXPECT_EQ(read.model.gyro, written.model.gyro);  // ==, bit for bit
  EXPECT_EQ(read.model.accel, written.model.accel);
  EXPECT_EQ(read.model.basis.center_c, 25.0);
  ASSERT_TRUE(read.sigma.has_value());
  EXPECT_EQ(read.sigma->gyro, written.sigma->gyro);
  EXPECT_EQ(read.sigma->accel, written.sigma->accel);
  ASSERT_TRUE(read.fit.has_value());
  EXPECT_EQ(read.fit->iterations, 7);
  // Writing what was read gives the same text again.
  EXPECT_EQ(CalibrationToYaml(read), CalibrationToYaml(written));
}

TEST_F(IoTest, CalibrationLayoutFollowsTheSpec) {
  const std::string text = CalibrationToYaml(ExampleCalibration());
  const YAML::Node root = YAML::Load(text);
  EXPECT_EQ(root["format"].as<std::string>(), "imufit-calibration");
  EXPECT_EQ(root["version"].as<int>(), 1);
  EXPECT_EQ(root["gyro"]["unit"].as<std::string>(), "rad/s");
  EXPECT_EQ(root["accel"]["unit"].as<std::string>(), "m/s^2");
  EXPECT_EQ(root["gyro"]["g_sensitivity"]["zy"].size(), 4u);
  EXPECT_EQ(root["gyro"]["misalignment"].size(), 6u);
  EXPECT_EQ(root["accel"]["misalignment"]["yx"].size(), 4u);
  EXPECT_FALSE(root["accel"]["g_sensitivity"]);
}

TEST_F(IoTest, CalibrationErrorsNameFileLineAndKey) {
  const std::string good = CalibrationToYaml(ExampleCalibration());
  {
    std::string text = good;
    text.replace(text.find("imufit-calibration"), 18, "imufit-plan");
    const InputError e = Catch([&] { ReadCalibration(Write("a.yaml", text)); });
    EXPECT_EQ(e.line(), 1);
    EXPECT_NE(e.message().find("format"), std::string::npos) << e.what();
  }
  {
    std::string text = good;
    text.replace(text.find("version: 1"), 10, "version: 2");
    const InputError e = Catch([&] { ReadCalibration(Write("b.yaml", text)); });
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(e.message().find("not supported"), std::string::npos) << e.what();
  }
  {
    std::string text = good;
    const size_t at = text.find("    x: [", text.find("accel:"));
    const size_t end = text.find(']', at);
    text.replace(at, end - at + 1, "    x: [1, 2, 3]");
    const InputError e = Catch([&] { ReadCalibration(Write("c.yaml", text)); });
    EXPECT_GT(e.line(), 10);
    EXPECT_NE(e.message().find("accel.bias.x"), std::string::npos) << e.what();
    EXPECT_NE(e.message().find("exactly 4"), std::string::npos) << e.what();
  }
  {
    std::string text = good;
    const size_t at = text.find("[", text.find("yz:", text.find("g_sensitivity")));
    text.replace(at + 1, 1, "x");
    const InputError e = Catch([&] { ReadCalibration(Write("d.yaml", text)); });
    EXPECT_NE(e.message().find("gyro.g_sensitivity.yz[0]"), std::string::npos) << e.what();
    EXPECT_NE(e.message().find("is not a number"), std::string::npos) << e.what();
  }
  {
    std::string text = good;
    const size_t at = text.find("  scale:");
    text.erase(at, text.find("  misalignment:") - at);
    const InputError e = Catch([&] { ReadCalibration(Write("e.yaml", text)); });
    EXPECT_NE(e.message().find("gyro.scale: missing"), std::string::npos) << e.what();
  }
  {
    const InputError e = Catch([&] { ReadCalibration(Write("f.yaml", "format: [unclosed\n")); });
    EXPECT_NE(e.message().find("YAML syntax"), std::string::npos) << e.what();
    EXPECT_GE(e.line(), 1);
  }
  const InputError missing = Catch([&] { ReadCalibration((dir_ / "none.yaml").string()); });
  EXPECT_NE(std::string(missing.what()).find("cannot open"), std::string::npos);
}

TEST_F(IoTest, CalibrationReaderIgnoresUnknownKeysAndHonoursReferenceTemperature) {
  std::string text = CalibrationToYaml(ExampleCalibration());
  text.replace(text.find("reference_temp_c: 25"), 20, "reference_temp_c: 20");
  text += "lab:\n  gyro_arw_deg_per_sqrt_hr: 0.3\n";
  const Calibration read = ReadCalibration(Write("cal.yaml", text));
  EXPECT_EQ(read.model.basis.center_c, 20.0);
  EXPECT_EQ(read.extra["lab"]["gyro_arw_deg_per_sqrt_hr"].as<double>(), 0.3);
}

// The fit's record: every key of the `fit:` and `check:` blocks round-trips through its typed
// member, lists of temperatures one per line and lists of names and ids on one line, keys the
// reader does not know kept after the others, and a value of the wrong type located at its key.
TEST_F(IoTest, FitRecordRoundTripsThroughItsTypedMembers) {
  Calibration calibration = ExampleCalibration();
  FitRecord& fit = *calibration.fit;
  fit.plan = "plan.yaml";
  fit.samples = "runs/unit 1.csv.gz";
  fit.plan_sha256 = std::string(64, 'a');
  fit.samples_sha256 = std::string(64, 'b');
  fit.samples_read = 26950;
  fit.segments_found_in_data = 8;
  fit.plan_passes_found = 1;
  fit.windows_used = 90;
  fit.windows_downweighted = 2;
  fit.distinct_temperatures_c = std::vector<double>{-40.000955338170442, 24.99948422253722};
  fit.termination = "Function tolerance reached. |cost_change|/cost: 6.794760e-12 <= 1.000000e-10";
  fit.gyro_residual_rms_radps = 4.0316131030556947e-05;
  fit.accel_residual_rms_mps2 = 0.00071912390028319533;
  fit.gyro_reduced_chi2 = std::numeric_limits<double>::quiet_NaN();
  fit.accel_reduced_chi2 = 1.2273404099354459;
  fit.gyro_temp_order = 3;
  fit.accel_temp_order = 2;
  fit.g_sensitivity_fitted = false;
  fit.fitted = std::vector<std::string>{"gyro.bias", "accel.bias"};
  fit.held = std::vector<std::string>{};
  fit.held_values = "prior";
  fit.loss = "huber";
  fit.gyro_bias_stability_radps = 0.0;
  fit.accel_bias_stability_mps2 = 0.00071588544999999992;
  fit.bias_correlation_s = 100.0;
  fit.segments_without_windows = std::vector<int>{3, 7};
  fit.missing_segments = 2;
  calibration.check.emplace().samples = "check.csv";
  calibration.check->gyro_error_rms_radps = 1e-3;
  calibration.noise.emplace().software = "imufit 0.1.0";
  const std::string text = CalibrationToYaml(calibration);
  for (const char* line : {"\nfit:\n  plan: plan.yaml\n  samples: runs/unit 1.csv.gz\n",
                           "\n  distinct_temperatures_c:\n    - -40.00095533817044\n",
                           "\n  fitted: [gyro.bias, accel.bias]\n  held: []\n  held_values: prior\n",
                           "\n  gyro_reduced_chi2: .nan\n", "\n  g_sensitivity_fitted: false\n",
                           "\n  segments_without_windows: [3, 7]\n  missing_segments: 2\ncheck:\n",
                           "\ncheck:\n  samples: check.csv\n  gyro_error_rms_radps: 0.001\nnoise:\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\nin:\n" << text;
  }
  const Calibration read = ReadCalibration(Write("cal.yaml", text));
  ASSERT_TRUE(read.fit.has_value());
  EXPECT_EQ(read.fit->samples, fit.samples);
  EXPECT_EQ(read.fit->samples_read, 26950);
  EXPECT_EQ(read.fit->distinct_temperatures_c, fit.distinct_temperatures_c);
  EXPECT_TRUE(std::isnan(*read.fit->gyro_reduced_chi2));
  EXPECT_EQ(read.fit->accel_reduced_chi2, fit.accel_reduced_chi2);  // ==, bit for bit
  EXPECT_EQ(read.fit->g_sensitivity_fitted, false);
  EXPECT_EQ(read.fit->held, std::vector<std::string>{});
  EXPECT_EQ(read.fit->segments_without_windows, (std::vector<int>{3, 7}));
  EXPECT_FALSE(read.fit->extra.IsMap());
  ASSERT_TRUE(read.check.has_value());
  EXPECT_EQ(read.check->gyro_error_rms_radps, 1e-3);
  EXPECT_FALSE(read.check->accel_error_rms_mps2.has_value());  // not written: not set
  ASSERT_TRUE(read.noise.has_value());
  EXPECT_EQ(read.noise->software, "imufit 0.1.0");
  EXPECT_EQ(read.extra.size(), 0u);
  EXPECT_EQ(CalibrationToYaml(read), text);

  // A key of the block this reader does not know is kept, after the others.
  std::string unknown = text;
  unknown.insert(unknown.find("  plan: plan.yaml"), "  leave_one_out: [1, 2]\n");
  const Calibration kept = ReadCalibration(Write("unknown.yaml", unknown));
  ASSERT_TRUE(kept.fit->extra.IsMap());
  EXPECT_EQ(kept.fit->extra["leave_one_out"].size(), 2u);
  EXPECT_NE(CalibrationToYaml(kept).find("missing_segments: 2\n  leave_one_out: [1, 2]\ncheck:"),
            std::string::npos);

  std::string wrong = text;
  wrong.replace(wrong.find("iterations: 7"), 13, "iterations: seven");
  const InputError e = Catch([&] { ReadCalibration(Write("wrong.yaml", wrong)); });
  EXPECT_NE(e.message().find("fit.iterations: \"seven\" is not an integer"), std::string::npos) << e.what();
}

// A calibration by hand: the `fit: field:` block round-trips through its typed record (after the
// fit's other keys, a key it does not know kept), `body_frame` through its typed member (after the
// records); a body frame imufit does not know is refused at its line.
TEST_F(IoTest, FieldRecordAndBodyFrameRoundTrip) {
  Calibration calibration = ExampleCalibration();
  calibration.body_frame = kBodyFrameAccelerometerXy;
  FieldRecord& field = calibration.fit->field.emplace();
  field.poses = 12;
  field.turns = 11;
  field.gravity_mps2 = 9.80665;
  field.accel_norm_rms_mps2 = 0.00082805122694389294;
  field.gravity_direction_rms_rad = std::numeric_limits<double>::quiet_NaN();
  field.noise_scale_turns = 1.0;
  field.saturated_turns = 0;
  const std::string text = CalibrationToYaml(calibration);
  for (const char* line : {"\n  field:\n    poses: 12\n    turns: 11\n    gravity_mps2: 9.80665\n",
                           "\n    gravity_direction_rms_rad: .nan\n", "\nbody_frame: accelerometer_xy\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\nin:\n" << text;
  }
  const Calibration read = ReadCalibration(Write("field.yaml", text));
  EXPECT_EQ(read.body_frame, std::optional<std::string>(kBodyFrameAccelerometerXy));
  ASSERT_TRUE(read.fit && read.fit->field);
  EXPECT_EQ(read.fit->field->poses, 12);
  EXPECT_EQ(read.fit->field->accel_norm_rms_mps2, field.accel_norm_rms_mps2);  // ==, bit for bit
  EXPECT_TRUE(std::isnan(*read.fit->field->gravity_direction_rms_rad));
  EXPECT_FALSE(read.fit->field->reduced_chi2.has_value());  // not written: not set
  EXPECT_FALSE(read.extra.IsMap() && read.extra["body_frame"]);
  EXPECT_EQ(CalibrationToYaml(read), text);

  std::string unknown = text;
  unknown.insert(unknown.find("    poses: 12"), "    hand: left\n");
  const Calibration kept = ReadCalibration(Write("field_unknown.yaml", unknown));
  EXPECT_EQ(kept.fit->field->extra["hand"].as<std::string>(), "left");
  EXPECT_NE(CalibrationToYaml(kept).find("saturated_turns: 0\n    hand: left\n"), std::string::npos);

  std::string wrong = text;
  wrong.replace(wrong.find("body_frame: accelerometer_xy"), 28, "body_frame: table");
  const InputError e = Catch([&] { ReadCalibration(Write("frame.yaml", wrong)); });
  EXPECT_NE(e.message().find("body_frame: \"table\" is not a body frame imufit knows (accelerometer_xy)"),
            std::string::npos)
      << e.what();
  std::string turns = text;
  turns.replace(turns.find("turns: 11"), 9, "turns: [11]");
  const InputError t = Catch([&] { ReadCalibration(Write("turns.yaml", turns)); });
  EXPECT_NE(t.message().find("fit.field.turns"), std::string::npos) << t.what();
}

// ---------------------------------------------------------------- machine-readable text

// The one writer: numbers a YAML 1.1 reader reads as numbers (a mantissa with a point, -0 as a
// float), bit for bit; strings quoted when a YAML 1.1 or 1.2 reader would take them for something
// else; valid UTF-8 always (a Latin-1 byte as its code point); the same document as JSON.
TEST(MachineText, NumbersStringsAndBytesAreWrittenForEveryReader) {
  EXPECT_EQ(YamlNumberText(2e-06), "2.0e-06");
  EXPECT_EQ(YamlNumberText(1e+20), "1.0e+20");
  EXPECT_EQ(YamlNumberText(2.5e-06), "2.5e-06");
  EXPECT_EQ(YamlNumberText(25.0), "25");
  EXPECT_EQ(YamlNumberText(-0.0), "-0.0");
  EXPECT_EQ(YamlNumberText(std::numeric_limits<double>::quiet_NaN()), ".nan");
  EXPECT_EQ(YamlNumberText(-std::numeric_limits<double>::infinity()), "-.inf");
  EXPECT_EQ(JsonNumberText(std::numeric_limits<double>::infinity()), "null");
  for (const double value :
       {2e-06, 1e-300, 0.1, 1.0 / 3.0, -4.0316131030556947e-05, 5e-324, 1.7976931348623157e308}) {
    const std::string text = YamlNumberText(value);
    double read = 0.0;
    ASSERT_EQ(std::from_chars(text.data(), text.data() + text.size(), read).ptr, text.data() + text.size());
    EXPECT_EQ(read, value) << text;
    EXPECT_NE(text.find_first_of(".e"), std::string::npos) << text;
  }
  for (const char* plain :
       {"huber", "gyro.bias", "rad/s", "m/s^2", "imufit 0.1.0", "/imu0", "runs/unit 1.csv"}) {
    EXPECT_EQ(YamlStringText(plain), plain);
  }
  for (const char* quoted :
       {"",        "yes",  "No",       "on", "OFF",  "y",     "n",     "true",  "null",
        "~",       "nan",  ".inf",     "12", "0123", "2e-06", "1_000", "14:03", "2026-11-20T14:03:60Z",
        "0x1F",    "-1",   "<<",       "=",  "a: b", "a #b",  "[x]",   "x,y",   "*alias",
        "&anchor", "!tag", "trailing "}) {
    EXPECT_EQ(YamlStringText(quoted).front(), '"') << quoted;
  }
  EXPECT_EQ(YamlStringText("caf\xe9.csv"), "\"caf\xc3\xa9.csv\"") << "a Latin-1 byte as its code point";
  EXPECT_EQ(ValidUtf8("caf\xe9"), "caf\xc3\xa9");
  EXPECT_EQ(YamlStringText("caf\xc3\xa9"), "\"caf\xc3\xa9\"") << "valid UTF-8 kept as it is";
  EXPECT_EQ(JsonStringText("a\"b\\c\n\x7f\xc2\x85"), "\"a\\\"b\\\\c\\n\\u007f\\u0085\"");

  MachineDoc doc = MachineDoc::Map();
  doc.Comment("made by a test");
  doc.Add("n", MachineDoc::Integer(26950), "samples");
  doc.Add("flag", MachineDoc::Bool(true));
  doc.Add("list", MachineDoc::Numbers({2e-06, -0.0}));
  MachineDoc rows = MachineDoc::List(MachineDoc::Style::kBlock);
  rows.Push(
      MachineDoc::Map(MachineDoc::Style::kFlow).Add("id", MachineDoc::Integer(1)).Add("on", MachineDoc()));
  doc.Add("rows", rows);
  doc.Add("empty", MachineDoc::Map());
  EXPECT_EQ(YamlText(doc),
            "# made by a test\n\"n\": 26950  # samples\nflag: true\nlist: [2.0e-06, -0.0]\nrows:\n"
            "  - {id: 1, \"on\": null}\nempty: {}\n");
  EXPECT_EQ(JsonText(doc),
            "{\n  \"n\": 26950,\n  \"flag\": true,\n  \"list\": [2.0e-06, -0.0],\n  \"rows\": [\n"
            "    {\"id\": 1, \"on\": null}\n  ],\n  \"empty\": {}\n}\n");
}

// docs/calibration.schema.json types every key of the `fit:` record as its table does (JSON: a
// double may be null, for a value that is not finite).
TEST(MachineText, TheJsonSchemaTypesTheFitRecordAsItsTable) {
  const YAML::Node schema = YAML::LoadFile(IMUFIT_FIXTURES_DIR "/../docs/calibration.schema.json");
  const YAML::Node properties = schema["properties"]["fit"]["properties"];
  const std::map<std::string, std::string> json_types = {{"std::string", "string"},
                                                         {"long long", "integer"},
                                                         {"int", "integer"},
                                                         {"double", "[number, null]"},
                                                         {"bool", "boolean"},
                                                         {"std::vector<double>", "array of number"},
                                                         {"std::vector<int>", "array of integer"},
                                                         {"std::vector<std::string>", "array of string"},
                                                         {"FieldRecord", "object"}};
  const auto schema_type = [](const YAML::Node& property) {
    if (!property || !property["type"]) return std::string("(none)");
    const YAML::Node type = property["type"];
    if (type.IsSequence()) return "[" + type[0].as<std::string>() + ", " + type[1].as<std::string>() + "]";
    if (type.as<std::string>() == "array") return "array of " + property["items"]["type"].as<std::string>();
    return type.as<std::string>();
  };
  size_t keys = 0;
#define IMUFIT_EXPECT_SCHEMA_TYPE(type, key, description)                        \
  EXPECT_EQ(schema_type(properties[#key]), json_types.at(#type)) << "fit." #key; \
  ++keys;
  IMUFIT_FIT_RECORD_FIELDS(IMUFIT_EXPECT_SCHEMA_TYPE)
  EXPECT_EQ(properties.size(), keys) << "a key in the schema that the record does not have";
  const YAML::Node field_properties = properties["field"]["properties"];
  keys = 0;
#undef IMUFIT_EXPECT_SCHEMA_TYPE
#define IMUFIT_EXPECT_SCHEMA_TYPE(type, key, description)                                    \
  EXPECT_EQ(schema_type(field_properties[#key]), json_types.at(#type)) << "fit.field." #key; \
  ++keys;
  IMUFIT_FIELD_RECORD_FIELDS(IMUFIT_EXPECT_SCHEMA_TYPE)
#undef IMUFIT_EXPECT_SCHEMA_TYPE
  EXPECT_EQ(field_properties.size(), keys) << "a key in the schema that the field record does not have";
}

// The noise block round-trips through its typed record; a value of the wrong type is located.
TEST_F(IoTest, NoiseRecordRoundTripsThroughTheCalibration) {
  Calibration calibration = ExampleCalibration();
  NoiseRecord& noise = calibration.noise.emplace();
  noise.software = "imufit 0.1.0";
  noise.samples = "static \xe9t\xe9.csv";  // Latin-1 bytes in a file name
  noise.sample_interval_s = 0.01;
  noise.sample_count = 6000;
  noise.duration_s = 60.0;
  noise.columns.reserve(2);  // the references below stay valid
  NoiseColumnRecord& gyro = noise.columns.emplace_back();
  gyro.name = "gyro_x";
  gyro.kind = ColumnKind::kGyro;
  gyro.fitted = true;
  gyro.points_used = 12;
  gyro.reduced_chi_square = 1.0 / 3.0;
  gyro.value = {2e-06, 1.0e-4, 3e-6, std::nan(""), 0.0};
  gyro.sigma = {1e-7, 2e-6, 1e-6, std::nan(""), 1e-9};
  gyro.resolved = {true, true, true, false, false};
  gyro.readout_random_walk = 0.34377467707849391;
  NoiseColumnRecord& other = noise.columns.emplace_back();
  other.name = "yes";
  other.reason = "too short";
  const std::string text = CalibrationToYaml(calibration);
  EXPECT_NE(text.find("  samples: \"static \xc3\xa9t\xc3\xa9.csv\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    \"yes\":\n"), std::string::npos) << text;
  EXPECT_NE(text.find("quantization_rad: [2.0e-06, 1.0e-07]"), std::string::npos) << text;
  const Calibration read = ReadCalibration(Write("noise.yaml", text));
  ASSERT_TRUE(read.noise.has_value());
  EXPECT_EQ(read.noise->samples, "static \xc3\xa9t\xc3\xa9.csv");
  ASSERT_EQ(read.noise->columns.size(), 2u);
  EXPECT_EQ(read.noise->columns[0].value[kRandomWalk], 1.0e-4);
  EXPECT_FALSE(read.noise->columns[0].resolved[kRateRandomWalk]);
  EXPECT_EQ(read.noise->columns[0].readout_random_walk, 0.34377467707849391);
  EXPECT_EQ(read.noise->columns[1].name, "yes");
  EXPECT_EQ(CalibrationToYaml(read), text);
  const std::optional<std::array<double, 2>> arw = NoiseFigure(read.noise, "gyro_x", "arw_deg_per_sqrt_hr");
  ASSERT_TRUE(arw.has_value());
  EXPECT_EQ((*arw)[0], 1.0e-4 * UnitsOf(ColumnKind::kGyro, kRandomWalk).engineer_per_si);
  EXPECT_FALSE(NoiseFigure(read.noise, "gyro_x", "rate_random_walk_radps_per_sqrt_s").has_value());

  std::string wrong = text;
  wrong.replace(wrong.find("points_used: 12"), 15, "points_used: many");
  const InputError e = Catch([&] { ReadCalibration(Write("wrong_noise.yaml", wrong)); });
  EXPECT_NE(e.message().find("noise.columns.gyro_x.points_used: \"many\" is not an integer"),
            std::string::npos)
      << e.what();
}

// The record's fit options name only losses and groups a fit knows: refused at their line.
TEST_F(IoTest, FitRecordRefusesAnUnknownLossOrGroupAtItsLine) {
  Calibration calibration = ExampleCalibration();
  calibration.fit->loss = "huber";
  calibration.fit->fitted = std::vector<std::string>{"gyro.bias", "accel.bias"};
  const std::string text = CalibrationToYaml(calibration);
  std::string loss = text;
  loss.replace(loss.find("loss: huber"), 11, "loss: tukey");
  InputError e = Catch([&] { ReadCalibration(Write("loss.yaml", loss)); });
  EXPECT_NE(e.message().find("fit.loss: \"tukey\" is not a robust loss (none, huber, cauchy)"),
            std::string::npos)
      << e.what();
  EXPECT_GT(e.line(), 0);
  std::string group = text;
  group.replace(group.find("accel.bias]"), 10, "accel.bais");
  e = Catch([&] { ReadCalibration(Write("group.yaml", group)); });
  EXPECT_NE(e.message().find("fit.fitted[1]: \"accel.bais\" is not a coefficient group"), std::string::npos)
      << e.what();
  EXPECT_GT(e.column(), 0);
}

// ---------------------------------------------------------------- plan

constexpr const char* kPlan = R"(format: imufit-plan
version: 1
gravity_mps2: 9.79285
latitude_deg: 30.27
serial: SN0001
segments:
  - id: 1
    up: [0, 0, 2]
    rate_dps: 0
    north: [1, 0, 0.01]
  - id: 7
    up: [1, 0, 0]
    rate_dps: -300
    lever_arm_m: [0.0, 0.02, 0.0]
)";

TEST_F(IoTest, PlanIsReadAndConvertedToSi) {
  const Plan plan = ReadPlan(Write("plan.yaml", kPlan));
  EXPECT_EQ(plan.serial, "SN0001");
  EXPECT_EQ(plan.site.gravity_mps2, 9.79285);
  ASSERT_TRUE(plan.site.latitude_rad.has_value());
  EXPECT_NEAR(*plan.site.latitude_rad, 30.27 * M_PI / 180.0, 1e-15);
  ASSERT_EQ(plan.segments.size(), 2u);
  EXPECT_EQ(plan.segments[0].up, Eigen::Vector3d(0, 0, 1));
  ASSERT_TRUE(plan.segments[0].north.has_value());
  EXPECT_NEAR(plan.segments[0].north->dot(plan.segments[0].up), 0.0, 1e-15);
  EXPECT_NEAR(plan.segments[0].north->norm(), 1.0, 1e-15);
  EXPECT_TRUE(plan.segments[0].IsStatic());
  EXPECT_NEAR(plan.segments[1].rate_radps, -300.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(*plan.segments[1].lever_arm_m, Eigen::Vector3d(0, 0.02, 0));
  EXPECT_EQ(plan.Find(7), &plan.segments[1]);
  EXPECT_EQ(plan.Find(2), nullptr);
  EXPECT_EQ(plan.segments[1].RotationAxis(), plan.segments[1].up);
}

TEST_F(IoTest, PlanReadsTurnsAndRateAxes) {
  std::string text = kPlan;
  text +=
      "  - {id: 8, up: [0, 0, 1], angle_deg: -360, axis: [2, 0, 0]}\n"
      "  - {id: 9, up: [0, 0, 1], angle_deg: 90}\n"
      "  - {id: 10, up: [0, 0, 1], rate_dps: 60, axis: [0, 3, 4], lever_arm_m: [0.01, 0, 0]}\n";
  const Plan plan = ReadPlan(Write("plan.yaml", text));
  ASSERT_EQ(plan.segments.size(), 5u);
  const TableSegment& turn = plan.segments[2];
  EXPECT_TRUE(turn.IsTurn());
  EXPECT_FALSE(turn.IsStatic());
  EXPECT_NEAR(*turn.angle_rad, -2.0 * M_PI, 1e-15);
  EXPECT_EQ(turn.rate_radps, 0.0);
  EXPECT_EQ(turn.RotationAxis(), Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE(plan.segments[3].IsTurn());
  EXPECT_EQ(plan.segments[3].RotationAxis(), Eigen::Vector3d(0, 0, 1));  // no axis: up
  const TableSegment& tilted = plan.segments[4];
  EXPECT_FALSE(tilted.IsTurn());
  EXPECT_NEAR(tilted.rate_radps, 60.0 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR((tilted.RotationAxis() - Eigen::Vector3d(0, 0.6, 0.8)).norm(), 0.0, 1e-15);
}

TEST_F(IoTest, InvalidTurnsAndAxesAreRefusedWithLocation) {
  struct Case {
    std::string segment, expect;
  };
  const Case cases[] = {
      {"{id: 8, up: [0, 0, 1], angle_deg: 360, rate_dps: 30}", "has no rate_dps"},
      {"{id: 8, up: [0, 0, 1], angle_deg: 0}", "cannot be 0"},
      {"{id: 8, up: [0, 0, 1], angle_deg: x}", "\"x\" is not a number"},
      {"{id: 8, up: [0, 0, 1], axis: [1, 0, 0]}", "a static segment has none"},
      {"{id: 8, up: [0, 0, 1], rate_dps: 0, axis: [1, 0, 0]}", "a static segment has none"},
      {"{id: 8, up: [0, 0, 1], rate_dps: 10, axis: [0, 0, 0]}", "zero vector"},
      {"{id: 8, up: [0, 0, 1], angle_deg: 90, axis: [1, 0]}", "exactly 3 numbers"},
      {"{id: 8, up: [0, 0, 1], angle_deg: 90, lever_arm_m: [0, 0.01, 0]}", "cannot take a lever arm"},
      {"{id: 8, up: [0, 0, 1], angle_deg: 90, north: [1, 0, 0]}", "static segments only"},
      {"{id: 8, up: [0, 0, 1], rate_dps: 10, north: [1, 0, 0]}", "static segments only"},
  };
  for (const Case& c : cases) {
    const std::string text = std::string(kPlan) + "  - " + c.segment + "\n";
    const InputError e = Catch([&] { ReadPlan(Write("bad.yaml", text)); });
    EXPECT_NE(e.message().find(c.expect), std::string::npos) << c.segment << ": " << e.what();
    EXPECT_EQ(e.line(), 15) << c.segment << ": " << e.what();
  }
}

TEST_F(IoTest, InvalidPlansAreRefusedWithLocation) {
  struct Case {
    std::string from, to, expect;
    long line;
  };
  const Case cases[] = {
      {"up: [0, 0, 2]", "up: [0, 0, 0]", "zero vector", 8},
      {"up: [0, 0, 2]", "up: [0, 2]", "exactly 3 numbers", 8},
      {"north: [1, 0, 0.01]", "north: [1, 0, 0.1]", "not horizontal", 10},
      {"id: 7", "id: 1", "repeats", 11},
      {"rate_dps: -300", "rate_dps: -300\n    speed: 3", "unknown key \"speed\"", 14},
      {"rate_dps: -300", "rate_dps: fast", "\"fast\" is not a number", 13},
      {"gravity_mps2: 9.79285", "gravity: 9.79285", "unknown key", 3},
      {"version: 1", "version: 3", "not supported", 2},
      {"format: imufit-plan", "format: imufit-calibration", "is not \"imufit-plan\"", 1},
  };
  for (const Case& c : cases) {
    std::string text = kPlan;
    text.replace(text.find(c.from), c.from.size(), c.to);
    const InputError e = Catch([&] { ReadPlan(Write("bad.yaml", text)); });
    EXPECT_NE(e.message().find(c.expect), std::string::npos) << c.to << ": " << e.what();
    EXPECT_EQ(e.line(), c.line) << c.to << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.yaml:"), std::string::npos) << e.what();
  }
  std::string no_gravity = kPlan;
  no_gravity.erase(no_gravity.find("gravity_mps2"), 22);
  const InputError e = Catch([&] { ReadPlan(Write("bad.yaml", no_gravity)); });
  EXPECT_NE(e.message().find("gravity_mps2: missing"), std::string::npos) << e.what();
}

// ---------------------------------------------------------------- samples

TEST_F(IoTest, SamplesColumnsAreFoundByNameInAnyOrder) {
  const std::string path = Write("s.csv",
                                 "# a comment\n"
                                 "\n"
                                 "note,accel_z,accel_y,accel_x,gyro_z,gyro_y,gyro_x,segment,temp_c,time_s\n"
                                 "\"a, b\",6,5,4,3,2,1,7,25.5,0.01\r\n"
                                 "# comment between rows\n"
                                 "x,6,5,4,3,2,+1e0,,25.5,0.02\n");
  SamplesReader reader(path, true);
  Sample s;
  ASSERT_TRUE(reader.Next(&s));
  EXPECT_EQ(s.time_s, 0.01);
  EXPECT_EQ(s.temp_c, 25.5);
  EXPECT_EQ(s.segment, 7);
  EXPECT_EQ(s.gyro, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.accel, Eigen::Vector3d(4, 5, 6));
  ASSERT_TRUE(reader.Next(&s));
  EXPECT_EQ(s.segment, kTransitionSegment);
  EXPECT_EQ(s.gyro.x(), 1.0);
  EXPECT_FALSE(reader.Next(&s));
}

TEST_F(IoTest, SamplesErrorsNameLineFieldAndText) {
  const std::string header = "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
  const auto error_of = [&](const std::string& rows, bool require_segment = true) {
    const std::string path = Write("samples.csv", header + rows);
    return Catch([&] {
      SamplesReader reader(path, require_segment);
      Sample s;
      while (reader.Next(&s)) {
      }
    });
  };
  InputError e = error_of("0,25,1,1,2,3,4,5,6\n0.1,25,1,1,1.2.3,3,4,5,6\n");
  EXPECT_STREQ(e.what(),
               (dir_ / "samples.csv").string().append(":3:5: gyro_y: \"1.2.3\" is not a number").c_str());
  e = error_of("0,25,1,1,2,3,4,5,6\n0,25,1,1,2,3,4,5,6\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.column(), 1);
  EXPECT_NE(e.message().find("does not increase"), std::string::npos);
  e = error_of("0,25,1,1,2,3,4,5\n");
  EXPECT_NE(e.message().find("the row has 8 fields"), std::string::npos) << e.what();
  e = error_of("0,25,-2,1,2,3,4,5,6\n");
  EXPECT_NE(e.message().find("not a segment id"), std::string::npos) << e.what();
  e = error_of("0,25,1.5,1,2,3,4,5,6\n");
  EXPECT_NE(e.message().find("segment: \"1.5\" is not an integer"), std::string::npos) << e.what();
  e = error_of("0,nan,1,1,2,3,4,5,6\n");
  EXPECT_NE(e.message().find("not a finite number"), std::string::npos) << e.what();
  const std::string no_segment =
      Write("n.csv", "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n");
  e = Catch([&] { SamplesReader reader(no_segment, true); });
  EXPECT_NE(e.message().find("no column \"segment\""), std::string::npos) << e.what();
  SamplesReader without(no_segment, false);
  EXPECT_FALSE(without.has_segment());
  e = Catch([&] { SamplesReader reader(Write("empty.csv", "# only a comment\n"), false); });
  EXPECT_NE(e.message().find("empty"), std::string::npos) << e.what();
}

TEST_F(IoTest, SamplesWriteReadRoundTripsPlainAndGzip) {
  for (const std::string name : {"out.csv", "out.csv.gz"}) {
    const std::string path = (dir_ / name).string();
    std::vector<Sample> written;
    {
      SamplesWriter writer(path, true, "made by a test\nsecond line");
      std::mt19937_64 engine(5);
      std::normal_distribution<double> n(0.0, 1e3);
      for (int i = 0; i < 20000; ++i) {  // > one read block when compressed
        Sample s;
        s.time_s = i * 0.01;
        s.temp_c = n(engine) / 100.0;
        s.segment = i % 5 - 1;
        s.gyro = Eigen::Vector3d(n(engine), n(engine), 1.0 / 3.0);
        s.accel = Eigen::Vector3d(n(engine), -0.0, 1e-300);
        writer.Write(s);
        written.push_back(s);
      }
      writer.Commit();
    }
    SamplesReader reader(path, true);
    Sample s;
    for (const Sample& expected : written) {
      ASSERT_TRUE(reader.Next(&s));
      ASSERT_EQ(s.time_s, expected.time_s);
      ASSERT_EQ(s.temp_c, expected.temp_c);
      ASSERT_EQ(s.segment, expected.segment);
      ASSERT_EQ(s.gyro, expected.gyro);
      ASSERT_EQ(s.accel, expected.accel);
    }
    EXPECT_FALSE(reader.Next(&s));
  }
}

// Numbers as loggers write them (up to 15 digits, a point anywhere, a sign) read as std::from_chars
// reads them, bit for bit: the reader's shortcut for such numbers rounds as it does; longer ones
// (up to 25 digits) are left to from_chars.
TEST_F(IoTest, ShortDecimalsReadAsFromCharsReadsThem) {
  std::mt19937_64 engine(11);
  std::string text = "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
  std::vector<std::string> written;
  constexpr int kRows = 20000;
  for (int i = 0; i < kRows; ++i) {
    std::string number = engine() % 2 ? "-" : (engine() % 8 ? "" : "+");
    // 16 and more: too many for the shortcut; beyond 18 the digits overflow a long long (fuzz_series)
    const int digits = 1 + static_cast<int>(engine() % 25);
    for (int k = 0; k < digits; ++k) number += static_cast<char>('0' + engine() % 10);
    if (engine() % 4 != 0) number.insert(number.size() - engine() % (digits + 1), ".");
    written.push_back(number);
    text += std::to_string(i + 1) + "e-3,20,1," + number + ",0,0,0,0,0\n";
  }
  SamplesReader reader(Write("decimals.csv", text), true);
  Sample s;
  for (const std::string& number : written) {
    ASSERT_TRUE(reader.Next(&s));
    double expected = 0.0;
    const char* first = number.data() + (number[0] == '+');
    ASSERT_EQ(std::from_chars(first, number.data() + number.size(), expected).ec, std::errc()) << number;
    ASSERT_EQ(std::memcmp(&s.gyro.x(), &expected, sizeof expected), 0) << number;
  }
  EXPECT_FALSE(reader.Next(&s));
}

// A samples file of `rows` rows in fixed-width columns (so a value can be replaced in place).
std::string FixedWidthSamples(int rows, int samples_per_reading = 1) {
  std::string text = "# serial: SN1\ntime_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
  char row[128];
  for (int i = 0; i < rows; ++i) {
    std::snprintf(row, sizeof row, "%012.4f,%6.2f,%2d,%7d,%7d,%7d,%7d,%7d,%7d\n", 1.0 + i * 0.0125,
                  20.0 + (i / samples_per_reading % 97) * 0.01, i % 7 - 1, i % 1009, -(i % 313), 7, i % 77, 3,
                  -16384);
    text += row;
  }
  return text;
}

// Every sample of `path` with its line, or the error that stops the reading (its what()).
template <typename Reader>
std::pair<std::vector<std::pair<Sample, long>>, std::string> ReadAll(Reader* reader) {
  std::vector<std::pair<Sample, long>> samples;
  try {
    Sample s;
    while (reader->Next(&s)) samples.emplace_back(s, reader->line_number());
  } catch (const InputError& e) {
    return {samples, e.what()};
  }
  return {samples, ""};
}

// Parsing on two threads gives what one reader gives: the same samples at the same lines, the same
// error after the same samples, wherever in the file it is, also at the first row of a block.
TEST_F(IoTest, ParallelParsingGivesWhatOneReaderGives) {
  const std::string text = FixedWidthSamples(300000);  // ~20 MB: several read blocks
  const auto compare = [&](const std::string& name, const std::string& bytes) {
    const std::string path = Write(name, bytes);
    SamplesReader one(path, true);
    const auto expected = ReadAll(&one);
    for (const int threads : {1, 2}) {
      SamplesReader header(path, true);
      ParallelSamplesReader parallel(&header, threads);
      const auto got = ReadAll(&parallel);
      EXPECT_EQ(got.second, expected.second) << name << ", " << threads << " threads";
      EXPECT_EQ(got.first.size(), expected.first.size()) << name;
      EXPECT_TRUE(std::equal(got.first.begin(), got.first.end(), expected.first.begin(), expected.first.end(),
                             [](const auto& a, const auto& b) {
                               return a.second == b.second && a.first.time_s == b.first.time_s &&
                                      a.first.temp_c == b.first.temp_c &&
                                      a.first.segment == b.first.segment && a.first.gyro == b.first.gyro &&
                                      a.first.accel == b.first.accel;
                             }))
          << name << ", " << threads << " threads";
    }
    return expected;
  };
  const auto whole = compare("whole.csv", text);
  EXPECT_EQ(whole.first.size(), 300000u);
  EXPECT_EQ(whole.first.back().second, 300002);
  EXPECT_EQ(whole.second, "");

  // Where the blocks start (the second block's first line), as the reader splits the file.
  const std::string path = Write("blocks.csv", text);
  std::vector<long> starts;
  std::string rows;
  CsvReader csv(path);
  for (long line_before = csv.line_number(); csv.NextBlock(&rows, 1 << 20);
       line_before += std::count(rows.begin(), rows.end(), '\n')) {
    starts.push_back(line_before + 1);
  }
  ASSERT_GE(starts.size(), 4u);
  const size_t data_start = text.find('\n', text.find('\n') + 1) + 1;  // line 3
  const size_t row_bytes = text.find('\n', data_start) + 1 - data_start;
  const auto offset_of = [&](long line) { return data_start + (line - 3) * row_bytes; };
  ASSERT_EQ(text.substr(offset_of(4), 13), "0000001.0125,");
  constexpr size_t kGyroX = 23;          // where gyro_x starts in a row, 7 wide
  const long late = starts.back() + 10;  // a line in the second half of the file
  ASSERT_GT(late, 150000);

  std::string bad = text;
  bad.replace(offset_of(late) + kGyroX, 7, "  1.2.3");
  auto result = compare("bad_number.csv", bad);
  EXPECT_NE(
      result.second.find("bad_number.csv:" + std::to_string(late) + ":4: gyro_x: \"1.2.3\" is not a number"),
      std::string::npos)
      << result.second;
  // A time that does not increase at a block's first row, the row before being in another block;
  // and the same row with a bad value after its time (the time is reported, as one reader does).
  const long first = starts[2];
  std::string back = text;
  back.replace(offset_of(first), 12, text.substr(offset_of(first - 1), 12));
  result = compare("back.csv", back);
  EXPECT_NE(result.second.find(":" + std::to_string(first) + ":1: time_s:"), std::string::npos)
      << result.second;
  EXPECT_NE(result.second.find("does not increase"), std::string::npos) << result.second;
  back.replace(offset_of(first) + kGyroX, 7, "  1.2.3");
  const std::string time_error = result.second.substr(result.second.find(':'));
  EXPECT_EQ(compare("back_and_bad.csv", back).second, Path("back_and_bad.csv") + time_error);
  // A row error before a read error: the row's error, as one reader reads them.
  std::string cut = text;
  cut.replace(offset_of(starts[1] + 5) + kGyroX, 7, "  1.2.3");
  const std::string gz = Path("cut.csv.gz");
  WriteFileAtomically(gz, cut);
  const std::string compressed = Read(gz);
  result = compare("cut.csv.gz", compressed.substr(0, compressed.size() - 100));
  EXPECT_NE(result.second.find(":" + std::to_string(starts[1] + 5) + ":4: gyro_x"), std::string::npos)
      << result.second;
  // A segment the caller refuses is located at its row (the reader's Fail).
  SamplesReader again(Write("fail.csv", text), true);
  ParallelSamplesReader parallel(&again);
  Sample s;
  for (long i = 0; i < late - 2; ++i) ASSERT_TRUE(parallel.Next(&s));
  const InputError e = Catch([&] { parallel.Fail("segment", "not in the plan"); });
  EXPECT_EQ(e.line(), late);
  EXPECT_EQ(e.column(), 3);
}

// A file corrected on both cores (each block corrected and formatted where it was parsed), or by
// CorrectSamples, is, byte for byte, what the shared model's Correct() on each sample writes, plain
// and gzip, though both evaluate the coefficients once per thermometer reading (8 samples here); a
// correction that is not finite, in a later block, is refused at its row, and nothing is written.
TEST_F(IoTest, AFileCorrectedOnBothCoresIsWhatOneSampleAtATimeWrites) {
  std::string text = FixedWidthSamples(300000, 8);  // ~20 MB: several blocks
  Calibration calibration;
  calibration.model = SensorModel::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    calibration.model.gyro[(kBiasCoefficient + axis) * kPolynomialTerms + 1] = 1e-3 * (axis + 1);
    calibration.model.accel[(kScaleCoefficient + axis) * kPolynomialTerms + 2] = 1e-5;
  }
  const std::string input = Write("raw.csv", text);
  SamplesReader reader(input, false);
  SamplesWriter expected(Path("expected.csv"), reader.has_segment(), "serial: SN1");
  Sample corrected;
  while (reader.Next(&corrected)) {
    calibration.model.Correct(corrected.temp_c, Eigen::Vector3d(corrected.gyro),
                              Eigen::Vector3d(corrected.accel), &corrected.gyro, &corrected.accel);
    expected.Write(corrected);
  }
  expected.Commit();
  SamplesReader again(input, false);
  SamplesWriter streamed(Path("streamed.csv"), again.has_segment(), "serial: SN1");
  CorrectSamples(calibration, &again, [&](const Sample& s) { streamed.Write(s); });
  streamed.Commit();
  EXPECT_TRUE(testing::SameText(testing::ReadFile(Path("streamed.csv")), Read(Path("expected.csv"))));
  for (const std::string name : {"got.csv", "got.csv.gz"}) {
    CorrectSamplesFile(calibration, input, Path(name));
    EXPECT_TRUE(testing::SameText(testing::ReadFile(Path(name)), Read(Path("expected.csv")))) << name;
  }

  // A bias cubic that overflows at 150 degC (x = 125: 1e303 x 125^3 > 1.8e308), at a late row.
  calibration.model.gyro[kBiasCoefficient * kPolynomialTerms + 3] = 1e303;
  const size_t data_start = text.find('\n', text.find('\n') + 1) + 1;  // line 3
  const size_t row_bytes = text.find('\n', data_start) + 1 - data_start;
  const long late = 250000;
  text.replace(data_start + (late - 3) * row_bytes + 13, 6, "150.00");
  const std::string hot = Write("hot.csv", text);
  const InputError e = Catch([&] { CorrectSamplesFile(calibration, hot, Path("hot_out.csv.gz")); });
  EXPECT_EQ(e.line(), late) << e.what();
  EXPECT_EQ(e.column(), 2) << e.what();
  EXPECT_NE(e.message().find("the correction at 150 degC is not a finite number"), std::string::npos)
      << e.what();
  EXPECT_FALSE(fs::exists(Path("hot_out.csv.gz")));
}

// ---------------------------------------------------------------- output files

TEST_F(IoTest, AnUncommittedOutputLeavesTheOldFileIntact) {
  const std::string path = Write("precious.csv", "keep me\n");
  {
    OutputFile file(path);
    file.Write("partial");
    // no Commit(): as when an error is thrown half way
  }
  EXPECT_EQ(Read(path), "keep me\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1)
      << "temporary left behind";
  {
    OutputFile file(path);
    file.Write("new\n");
    file.Commit();
  }
  EXPECT_EQ(Read(path), "new\n");
}

TEST_F(IoTest, OutputsRefuseToReplaceAnInput) {
  const std::string input = Write("in.csv", "x\n");
  const InputError e = Catch([&] { RefuseToOverwriteInputs((dir_ / "." / "in.csv").string(), {input}); });
  EXPECT_NE(e.message().find("is also an input"), std::string::npos);
  RefuseToOverwriteInputs((dir_ / "other.csv").string(), {input});  // fine
  const InputError folder = Catch([&] { OutputFile file((dir_ / "missing" / "x.csv").string()); });
  EXPECT_NE(folder.message().find("cannot create"), std::string::npos);
}

// ---------------------------------------------------------------- inputs as they really arrive

// Counts the data rows of a CSV file, reading field 0 of each.
long CountRows(const std::string& path) {
  CsvReader csv(path);
  long rows = 0;
  while (csv.NextRow()) {
    csv.Field(0);
    ++rows;
  }
  return rows;
}

std::string CsvRows(int rows) {
  std::string text = "a,b\n";
  for (int i = 0; i < rows; ++i) text += std::to_string(i) + "," + std::to_string(i * 7 % 13) + "\n";
  return text;
}

TEST_F(IoTest, TruncatedCorruptOrFakeGzipIsRefused) {
  const std::string text = CsvRows(20000);
  const std::string good_path = (dir_ / "good.csv.gz").string();
  WriteFileAtomically(good_path, text);
  const std::string gz = Read(good_path);
  ASSERT_GT(gz.size(), 100u);
  EXPECT_EQ(CountRows(good_path), 20000);
  const auto error_of = [&](const std::string& name, const std::string& bytes) {
    const std::string path = Write(name, bytes);
    return Catch([&] { CountRows(path); }).message();
  };
  // No trailer, half the stream, the stream without its last byte.
  EXPECT_NE(error_of("no_trailer.csv.gz", gz.substr(0, gz.size() - 8)).find("truncated gzip stream"),
            std::string::npos);
  EXPECT_NE(error_of("half.csv.gz", gz.substr(0, gz.size() / 2)).find("truncated gzip stream"),
            std::string::npos);
  EXPECT_NE(error_of("short.csv.gz", gz.substr(0, gz.size() - 1)).find("truncated gzip stream"),
            std::string::npos);
  // A wrong CRC-32, a wrong length.
  std::string bad_crc = gz;
  bad_crc[gz.size() - 8] ^= 0x01;
  EXPECT_NE(error_of("crc.csv.gz", bad_crc).find("incorrect data check"), std::string::npos);
  std::string bad_length = gz;
  bad_length[gz.size() - 4] ^= 0x01;
  EXPECT_NE(error_of("length.csv.gz", bad_length).find("incorrect length check"), std::string::npos);
  // Bytes after the stream; a plain file named .gz; an empty one.
  EXPECT_NE(error_of("garbage.csv.gz", gz + "junk").find("trailing garbage after the gzip stream"),
            std::string::npos);
  EXPECT_NE(error_of("zeros.csv.gz", gz + std::string(4, '\0')).find("trailing garbage"), std::string::npos);
  EXPECT_NE(error_of("plain.csv.gz", text).find("not a gzip stream"), std::string::npos);
  EXPECT_NE(error_of("empty.csv.gz", "").find("not a gzip stream"), std::string::npos);
  // Concatenated members are one stream, as gzip(1) reads them.
  const std::string second_path = (dir_ / "second.csv.gz").string();
  WriteFileAtomically(second_path, "5,6\n7,8\n");
  EXPECT_EQ(CountRows(Write("two.csv.gz", gz + Read(second_path))), 20002);
}

// Compressed outputs are standard gzip: gzip(1) tests them and Python reads them back; a file that
// gzip(1) made (its header names the original file) is read, also when it is named .csv, and
// members written by either, concatenated, are one stream.
TEST_F(IoTest, GzipOutputIsStandardAndGzipInputIsFoundByItsBytes) {
  const std::string text = CsvRows(50000);
  const std::string ours = Path("ours.csv.gz");
  WriteFileAtomically(ours, text);
  testing::RunResult r = RunProgram("/bin/gzip", {"-t", ours});
  EXPECT_EQ(r.status, 0) << r.err;
  r = RunProgram("/usr/bin/python3",
                 {"-c", "import gzip,sys; sys.stdout.write(gzip.open(sys.argv[1], 'rt').read())", ours});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out == text) << "Python reads back " << r.out.size() << " bytes of " << text.size();

  const std::string plain = Write("plain.csv", text);
  r = RunProgram("/bin/gzip", {"-k", "-9", plain});  // plain.csv.gz, with the name in its header
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string theirs = Read(plain + ".gz");
  ASSERT_NE(theirs[3] & 0x08, 0) << "gzip(1) stored no name";
  EXPECT_EQ(CountRows(plain + ".gz"), 50000);
  const std::string named_csv = Write("compressed.csv", theirs);  // gzip, but named .csv
  EXPECT_EQ(CountRows(named_csv), 50000);
  Sha256 digest;
  {
    CsvReader csv(named_csv, &digest);
    EXPECT_EQ(csv.header(), (std::vector<std::string>{"a", "b"}));
    while (csv.NextRow()) {
    }
  }
  EXPECT_EQ(digest.HexDigest(), Sha256Hex(theirs)) << "the hash is of the bytes on disk";
  EXPECT_EQ(CountRows(Write("mixed.csv.gz", Read(ours) + theirs)), 100001);  // the second header is a row
  // Cut short and named .csv: the error says so, rather than showing the binary as a header.
  const InputError e = Catch([&] { CountRows(Write("cut.csv", theirs.substr(0, theirs.size() / 2))); });
  EXPECT_NE(e.message().find("truncated gzip stream"), std::string::npos) << e.what();
}

// A compressed output on a full disk names the reason, as a plain one does. The disk is a tmpfs of
// 64 KiB (mounting needs root: elsewhere the test says so and is skipped).
TEST_F(IoTest, AGzipOutputOnAFullDiskSaysWhy) {
  const std::string mount_point = Path("full");
  fs::create_directories(mount_point);
  if (::geteuid() != 0 ||
      RunProgram("/bin/mount", {"-t", "tmpfs", "-o", "size=64k", "tmpfs", mount_point}).status != 0) {
    GTEST_SKIP() << "cannot mount a 64 KiB tmpfs here (needs root): the full-disk case is not run";
  }
  std::string incompressible;
  uint32_t state = 12345;
  for (int i = 0; i < 200000; ++i) {
    state = state * 1664525u + 1013904223u;
    incompressible += std::to_string(state) + "\n";
  }
  for (const std::string name : {"out.csv.gz", "out.csv"}) {
    const InputError e = Catch([&] { WriteFileAtomically(mount_point + "/" + name, incompressible); });
    EXPECT_NE(e.message().find("write failed: No space left on device"), std::string::npos) << e.what();
    EXPECT_EQ(e.file(), mount_point + "/" + name);
  }
  // Written in many pieces, the compressing thread fails while more wait: a later Write() says why.
  const InputError e = Catch([&] {
    OutputFile file(mount_point + "/pieces.csv.gz");
    for (int i = 0; i < 8; ++i) file.Write(incompressible);
    file.Commit();
  });
  EXPECT_NE(e.message().find("write failed: No space left on device"), std::string::npos) << e.what();
  EXPECT_TRUE(fs::is_empty(mount_point)) << "a temporary file was left behind";
  EXPECT_EQ(RunProgram("/bin/umount", {mount_point}).status, 0);
}

// The error of reading every row of `text` (as a CSV file) and parsing field 0 as a number.
TEST_F(IoTest, MalformedCsvRowsAreRefusedNotGuessed) {
  const auto error_of = [&](const std::string& text) {
    const std::string path = Write("bad.csv", text);
    return Catch([&] {
      CsvReader csv(path);
      while (csv.NextRow()) csv.Number(0);
    });
  };
  InputError e = error_of("a,b\n1,2\n1,5,2\n");  // a decimal comma shifts the columns
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.message().find("the row has 3 fields, the header names 2"), std::string::npos) << e.what();
  e = error_of("a,b\n\"1\"2,3\n");
  EXPECT_EQ(e.column(), 1);
  EXPECT_NE(e.message().find("text after the closing quote"), std::string::npos) << e.what();
  e = error_of("a,b\n3,1\"2\"\n");
  EXPECT_EQ(e.column(), 2);
  EXPECT_NE(e.message().find("a quote inside an unquoted field"), std::string::npos) << e.what();
  e = error_of("a,b\n\"12,3\n");
  EXPECT_NE(e.message().find("a quote is not closed"), std::string::npos) << e.what();
  for (const char* sign : {"+-25", "++25", "-+25", "--25"}) {
    e = error_of(std::string("a\n") + sign + "\n");
    EXPECT_NE(e.message().find("is not a number"), std::string::npos) << sign << ": " << e.what();
  }
  // Well-formed quoting still reads.
  CsvReader csv(Write("good.csv", "a,b\n \"1.5\" ,\"x,\"\"y\"\"\"\n+2,\n"));
  ASSERT_TRUE(csv.NextRow());
  EXPECT_EQ(csv.Number(0), 1.5);
  EXPECT_EQ(csv.Field(1), "x,\"y\"");
  ASSERT_TRUE(csv.NextRow());
  EXPECT_EQ(csv.Number(0), 2.0);
  EXPECT_EQ(csv.Field(1), "");
}

TEST_F(IoTest, CsvLinesAndColumnsAreBounded) {
  const auto error_of = [&](const std::string& path) {
    return Catch([&] {
      CsvReader csv(path);
      while (csv.NextRow()) csv.Field(0);
    });
  };
  InputError e = error_of(Write("long.csv", "a,b\n1,2\n" + std::string(3 << 20, '7') + "\n"));
  EXPECT_EQ(e.line(), 3);
  EXPECT_NE(e.message().find("line longer than 1048576 bytes"), std::string::npos) << e.what();
  e = error_of(Write("commas.csv", "a\n" + std::string(CsvReader::kMaxLineBytes - 10, ',') + "\n"));
  EXPECT_NE(e.message().find("more than 10000 fields"), std::string::npos) << e.what();
  std::string wide;
  for (int i = 0; i < 10001; ++i) wide += (i ? ",c" : "c") + std::to_string(i);
  e = error_of(Write("wide.csv", wide + "\n"));
  EXPECT_NE(e.message().find("more than 10000 fields"), std::string::npos) << e.what();
  e = error_of("/dev/zero");
  EXPECT_NE(e.message().find("line longer than"), std::string::npos) << e.what();
  // A gzip bomb: 64 MiB of zeros in 64 KiB; refused after reading one line's worth.
  std::string zeros(1 << 20, '\0');
  {
    OutputFile bomb((dir_ / "bomb.csv.gz").string());
    for (int i = 0; i < 64; ++i) bomb.Write(zeros);
    bomb.Commit();
  }
  e = error_of((dir_ / "bomb.csv.gz").string());
  EXPECT_NE(e.message().find("line longer than"), std::string::npos) << e.what();
  // The header's duplicate check is linear; a duplicate is still found at the end of a wide header.
  std::string names;
  for (int i = 0; i < 9000; ++i) names += "c" + std::to_string(i) + ",";
  e = error_of(Write("dup.csv", names + "c17\n"));
  EXPECT_EQ(e.column(), 9001);
  EXPECT_NE(e.message().find("\"c17\" appears twice"), std::string::npos) << e.what();
}

TEST_F(IoTest, ErrorMessagesAreBoundedAndEscaped) {
  // A header with terminal escapes and a very long name; a value with BEL, CR and NUL.
  const std::string hostile = "\x1b[31mred\x07" + std::string(5000, 'n');
  CsvReader csv(Write("hostile.csv", hostile + ",b\n\x07\r\x1b" + std::string("\0z", 2) + ",2\n"));
  ASSERT_TRUE(csv.NextRow());
  for (const InputError& e : {Catch([&] { csv.Number(0); }), Catch([&] { csv.RequireColumn("gyro_x"); })}) {
    const std::string text = e.what();
    for (const char control : {'\x1b', '\x07', '\r', '\0'}) {
      EXPECT_EQ(text.find(control), std::string::npos)
          << "raw control character " << int(control) << " in " << text;
    }
    EXPECT_NE(text.find("\\x1b[31mred\\x07"), std::string::npos) << text;
    EXPECT_LT(text.size(), 400u) << text;
  }
  // Any message is bounded, whatever a caller puts in it.
  const InputError long_one("f.csv", 1, 1, std::string(100000, 'x') + "\x1b");
  EXPECT_LE(long_one.message().size(), kMaxMessageChars + 3);
  EXPECT_EQ(std::string(long_one.what()).find('\x1b'), std::string::npos);
}

TEST_F(IoTest, AUtf8ByteOrderMarkIsSkippedAndUtf16IsNamed) {
  CsvReader csv(Write("bom.csv", "\xEF\xBB\xBFtime_s,b\n1,2\n"));
  EXPECT_EQ(csv.header()[0], "time_s");
  ASSERT_TRUE(csv.NextRow());
  EXPECT_EQ(csv.Number(csv.RequireColumn("time_s")), 1.0);
  const InputError e = Catch([&] { CsvReader utf16(Write("utf16.csv", std::string("\xFF\xFEt\0i\0", 6))); });
  EXPECT_NE(e.message().find("UTF-16"), std::string::npos) << e.what();
}

TEST_F(IoTest, SilentGarbageInYamlIsRefused) {
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"latitude_deg: 30.27", "latitude_deg: 30.27\nlatitude_deg: 10", "\"latitude_deg\" appears twice"},
      {"rate_dps: -300", "rate_dps: -300\n    rate_dps: 300", "\"rate_dps\" appears twice"},
      {"serial: SN0001", "serial: SN0001\n---\nserial: other", "a second YAML document"},
      {"gravity_mps2: 9.79285", "gravity_mps2: \"9.79285\"", "quoted text"},
      {"id: 7", "id: '7'", "quoted text"},
      {"rate_dps: -300", "rate_dps: !!str -300", "quoted text"},
      {"rate_dps: -300", "rate_dps: +-300", "\"+-300\" is not a number"},
      {"up: [1, 0, 0]", "up: [1e200, 1e200, 0]", "length must lie between"},
      {"up: [1, 0, 0]", "up: [1e-200, 0, 0]", "length must lie between"},
      {"gravity_mps2: 9.79285", "gravity_mps2: 1e308", "between 9.7 and 9.9"},
      {"gravity_mps2: 9.79285", "gravity_mps2: 0.001", "between 9.7 and 9.9"},
  };
  for (const Case& c : cases) {
    std::string text = kPlan;
    text.replace(text.find(c.from), c.from.size(), c.to);
    const InputError e = Catch([&] { ReadPlan(Write("bad.yaml", text)); });
    EXPECT_NE(e.message().find(c.expect), std::string::npos) << c.to << ": " << e.what();
    EXPECT_GT(e.line(), 0) << c.to << ": " << e.what();
  }
  // A limits file whose duplicate key would have let a unit pass.
  const std::string limits = Write("limits.yaml",
                                   "format: imufit-limits\nversion: 1\ncriteria:\n"
                                   "  - {quantity: gyro_bias_dps, max_abs: 0.01, max_abs: 1000}\n");
  const InputError e = Catch([&] { ReadLimits(limits); });
  EXPECT_NE(e.message().find("\"max_abs\" appears twice"), std::string::npos) << e.what();
  EXPECT_EQ(e.line(), 4);
  // Found by fuzz_plan: input on which YAML::LoadAll never ends (an endless run of documents).
  const InputError endless =
      Catch([&] { ReadPlan(IMUFIT_FIXTURES_DIR "/../fuzz/regressions/fuzz_plan/endless-documents.yaml"); });
  EXPECT_NE(endless.message().find("a second YAML document"), std::string::npos) << endless.what();
  // Limits: file size and nesting are bounded.
  const InputError big = Catch([&] { ReadLimits("/dev/zero"); });
  EXPECT_NE(big.message().find("larger than 16 MiB"), std::string::npos) << big.what();
  const InputError deep = Catch(
      [&] { ReadLimits(Write("deep.yaml", "criteria: " + std::string(100, '[') + std::string(100, ']'))); });
  EXPECT_NE(deep.message().find("nested deeper than 64"), std::string::npos) << deep.what();
}

TEST_F(IoTest, ManyUnknownCalibrationKeysAreKeptInLinearTime) {
  // A calibration with `keys` unknown keys more; returns its path.
  const auto with_keys = [&](int keys) {
    std::string text = CalibrationToYaml(ExampleCalibration());
    for (int i = 0; i < keys; ++i) text += "k" + std::to_string(i) + ": " + std::to_string(i) + "\n";
    return Write("keys" + std::to_string(keys) + ".yaml", text);
  };
  const Calibration read = ReadCalibration(with_keys(30000));
  EXPECT_EQ(read.extra.size(), 30000u);  // `fit` is read into Calibration::fit
  EXPECT_EQ(read.extra["k29999"].as<int>(), 29999);
  // Four times the keys take about four times as long to read; a quadratic copy of them, sixteen
  // times (and many seconds at 30000 keys). Processor time, not the clock's, so that other
  // programs on a busy machine do not count; the best of a few reads of each, taken in turn.
  constexpr int kReads = 3;
  constexpr double kMostTimeRatio = 8.0;  // between linear (4) and quadratic (16)
  const auto seconds_to_read = [](const std::string& path) {
    const std::clock_t start = std::clock();
    ReadCalibration(path);
    return static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  };
  const std::string few = with_keys(2500);
  const std::string many = with_keys(10000);
  double few_s = 1e9, many_s = 1e9;
  for (int i = 0; i < kReads; ++i) {
    few_s = std::min(few_s, seconds_to_read(few));
    many_s = std::min(many_s, seconds_to_read(many));
  }
  EXPECT_LT(many_s, kMostTimeRatio * few_s) << "2500 keys: " << few_s << " s, 10000 keys: " << many_s << " s";
}

TEST_F(IoTest, CalibrationsThatCannotCorrectAreRefusedOnRead) {
  const Calibration good = ExampleCalibration();
  const auto error_of = [&](const std::function<void(Calibration*)>& change) {
    Calibration bad = good;
    change(&bad);
    return Catch([&] { ReadCalibration(Write("bad.yaml", CalibrationToYaml(bad))); }).message();
  };
  const int sx = kScaleCoefficient * kPolynomialTerms;  // gyro scale x, c0
  // A scale that crosses zero at 60 degC inside [-40, 85]: 1 - (T - 25) / 35.
  std::string e = error_of([&](Calibration* c) {
    c->model.gyro[sx] = 1.0;
    c->model.gyro[sx + 1] = -1.0 / 35.0;
    c->model.gyro[sx + 2] = c->model.gyro[sx + 3] = 0.0;
  });
  EXPECT_NE(e.find("gyro.scale.x: the scale factor changes sign"), std::string::npos) << e;
  // A cubic that dips to 1e-6 of its peak between the ends (double root at 50 degC).
  e = error_of([&](Calibration* c) {
    const int sy = sx + kPolynomialTerms;
    c->model.accel[sy] = 625.0 + 1e-4;  // (x - 25)^2 = x^2 - 50 x + 625, x = T - 25
    c->model.accel[sy + 1] = -50.0;
    c->model.accel[sy + 2] = 1.0;
    c->model.accel[sy + 3] = 0.0;
  });
  EXPECT_NE(e.find("accel.scale.y: the scale factor comes near zero"), std::string::npos) << e;
  // A negative scale (a sign-flipped axis or rotation): the convention to check is named.
  e = error_of([&](Calibration* c) { c->model.accel[sx + 2 * kPolynomialTerms] *= -1.0; });
  EXPECT_NE(e.find("accel.scale.z: the scale factor is negative"), std::string::npos) << e;
  EXPECT_NE(e.find("+g along up"), std::string::npos) << e;
  e = error_of([&](Calibration* c) {
    for (int k = 0; k < kPolynomialTerms; ++k) c->model.gyro[sx + k] *= -1.0;
  });
  EXPECT_NE(e.find("gyro.scale.x: the scale factor is negative"), std::string::npos) << e;
  EXPECT_NE(e.find("right-hand rule"), std::string::npos) << e;
  // A denormal scale; a singular M (xy = yx = 1 makes two rows equal).
  e = error_of([&](Calibration* c) {
    c->model.gyro[sx] = 1e-310;
    c->model.gyro[sx + 1] = c->model.gyro[sx + 2] = c->model.gyro[sx + 3] = 0.0;
  });
  EXPECT_NE(e.find("comes near zero"), std::string::npos) << e;
  e = error_of([&](Calibration* c) {
    c->model.accel[kMisalignmentCoefficient * kPolynomialTerms] = 1.0;        // xy
    c->model.accel[(kMisalignmentCoefficient + 2) * kPolynomialTerms] = 1.0;  // yx
  });
  EXPECT_NE(e.find("accel.misalignment: M is nearly singular"), std::string::npos) << e;
  // The example itself, and a scale that crosses zero only outside the fit range, are fine.
  ReadCalibration(Write("good.yaml", CalibrationToYaml(good)));
  Calibration outside = good;
  outside.model.gyro[sx] = 1.0;
  outside.model.gyro[sx + 1] = -1.0 / 100.0;  // zero at 125 degC
  outside.model.gyro[sx + 2] = outside.model.gyro[sx + 3] = 0.0;
  ReadCalibration(Write("outside.yaml", CalibrationToYaml(outside)));
}

TEST_F(IoTest, OutputsRefuseLinksFifosDevicesAndReadOnlyFiles) {
  const std::string target = Write("target.csv", "the user's file\n");
  const std::string link = (dir_ / "link.csv").string();
  fs::create_symlink(target, link);
  const std::string fifo = (dir_ / "fifo.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  const std::string read_only = Write("read_only.csv", "locked\n");
  fs::permissions(read_only, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  struct Case {
    std::string path, expect;
  };
  for (const Case& c : {Case{link, "is a symbolic link"}, Case{fifo, "is a FIFO, not a regular file"},
                        Case{read_only, "is read-only"}, Case{dir_.string() + "/", "not a file name"}}) {
    const InputError e = Catch([&] { WriteFileAtomically(c.path, "new\n"); });
    EXPECT_NE(e.message().find(c.expect), std::string::npos) << c.path << ": " << e.what();
  }
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(Read(target), "the user's file\n");
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(Read(read_only), "locked\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 4)
      << "temporary left behind";
  // A link that appears while the output is written is not replaced either.
  const std::string late = (dir_ / "late.csv").string();
  OutputFile file(late);
  file.Write("x\n");
  fs::create_symlink(target, late);
  EXPECT_NE(Catch([&] { file.Commit(); }).message().find("symbolic link"), std::string::npos);
  EXPECT_EQ(Read(target), "the user's file\n");
}

TEST_F(IoTest, AnOutputTransactionWritesAllOrNothing) {
  const std::string first = Write("first.yaml", "old first\n");
  const std::string second = (dir_ / "second.html").string();
  {
    OutputTransaction outputs;
    WriteFileAtomically(first, "new first\n", &outputs);
    EXPECT_EQ(Read(first), "old first\n") << "renamed before the transaction commits";
    // The second output fails (its folder does not exist): the first must not change.
    EXPECT_THROW(WriteFileAtomically((dir_ / "missing" / "x.html").string(), "y", &outputs), InputError);
  }
  EXPECT_EQ(Read(first), "old first\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1)
      << "temporary left behind";
  {
    OutputTransaction outputs;
    WriteFileAtomically(first, "new first\n", &outputs);
    WriteFileAtomically(second, "new second\n", &outputs);
    EXPECT_FALSE(fs::exists(second));
    outputs.Commit();
  }
  EXPECT_EQ(Read(first), "new first\n");
  EXPECT_EQ(Read(second), "new second\n");
  // Without a transaction, Commit() renames at once.
  WriteFileAtomically(second, "third\n");
  EXPECT_EQ(Read(second), "third\n");
}

// A transaction changes only the outputs it is given: one written without it while it is open is
// renamed at once, and is not taken back when the transaction is dropped.
TEST_F(IoTest, AnOutputTransactionHoldsOnlyTheOutputsItIsGiven) {
  const std::string held = (dir_ / "held.yaml").string();
  const std::string apart = (dir_ / "apart.yaml").string();
  {
    OutputTransaction outputs;
    WriteFileAtomically(held, "held\n", &outputs);
    WriteFileAtomically(apart, "apart\n");
    EXPECT_EQ(Read(apart), "apart\n") << "an output not given the transaction was held by it";
    EXPECT_FALSE(fs::exists(held));
  }
  EXPECT_FALSE(fs::exists(held));
  EXPECT_EQ(Read(apart), "apart\n");
}

// A CSV reader hashes the file's bytes as they are on disk (compressed, for .gz) while it streams
// them, and counts as one opening of the file.
TEST_F(IoTest, ACsvReaderHashesTheFileAsItReadsIt) {
  for (const std::string name : {"hashed.csv", "hashed.csv.gz"}) {
    const std::string path = (dir_ / name).string();
    {
      SamplesWriter writer(path, true);
      for (int i = 0; i < 200000; ++i) {  // several read blocks, plain and compressed
        Sample sample;
        sample.time_s = i * 0.01;
        sample.gyro = Eigen::Vector3d(i % 7, i % 11, i % 13);
        writer.Write(sample);
      }
      writer.Commit();
    }
    const testing::FileOpenCounter reads(path);
    Sha256 digest;
    SamplesReader reader(path, true, SamplesFormat{}, &digest);
    Sample sample;
    long long samples = 0;
    while (reader.Next(&sample)) ++samples;
    EXPECT_EQ(samples, 200000);
    EXPECT_EQ(reads.count(), 1) << name;
    EXPECT_EQ(digest.HexDigest(), Sha256OfFile(path)) << name;
    EXPECT_EQ(reads.count(), 2) << name << ": Sha256OfFile opens it too";
  }
}

TEST_F(IoTest, TemporaryOutputsAreRemovedOnSigtermSigintSighup) {
  for (const int signal_number : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string path = (dir_ / ("out" + std::to_string(signal_number) + ".csv.gz")).string();
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      InstallOutputCleanupOnSignals();
      OutputFile file(path);
      file.Write(std::string(3 << 20, 'x'));  // past the first flush
      OutputTransaction outputs;
      WriteFileAtomically(path + ".other", "pending in a transaction\n", &outputs);
      ::raise(signal_number);
      ::_exit(0);  // not reached
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child should die of the signal, as without the handler";
    EXPECT_EQ(WTERMSIG(status), signal_number);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 0)
        << "temporary file left behind after signal " << signal_number;
  }
}

// The run header's times: the ISO 8601 forms a logger writes in UTC, one normal form; local times,
// impossible dates and times are refused.
TEST(RunHeader, AcquiredIsAUtcTimeInOneForm) {
  EXPECT_EQ(NormalisedUtc("2026-11-20T14:03:00Z"), "2026-11-20T14:03:00Z");
  EXPECT_EQ(NormalisedUtc("2026-11-20T14:03Z"), "2026-11-20T14:03:00Z");
  EXPECT_EQ(NormalisedUtc("2026-11-20 14:03:07.250Z"), "2026-11-20T14:03:07Z");
  EXPECT_EQ(NormalisedUtc("2026-11-20T14:03:07+00:00"), "2026-11-20T14:03:07Z");
  for (const char* bad :
       {"2026-11-20T14:03:00", "2026-11-20T14:03:00+01:00", "2026-02-30T10:00Z", "2026-11-20T24:00Z",
        "2026-11-20T14:3Z", "20/11/2026 14:03", "2026-11-20T14:03:00.Z", "2026-11-20T14:03:60Z"}) {
    EXPECT_EQ(NormalisedUtc(bad), "") << bad;
  }
  // A leap second is 23:59:60 UTC; 14:03:60 is no time (PyYAML: "second must be in 0..59").
  EXPECT_EQ(NormalisedUtc("2016-12-31T23:59:60Z"), "2016-12-31T23:59:60Z");
  const std::string path = "run.csv";
  const RunHeader header = RunHeaderOf(
      path, {{1, 3, "serial: SN1"}, {2, 3, "acquired: 2026-11-20T14:03Z"}, {3, 3, "firmware: 2.4.1"}});
  EXPECT_EQ(header.acquired_utc, "2026-11-20T14:03:00Z");
  EXPECT_EQ(header.firmware, "2.4.1");
  EXPECT_EQ(header.model, "");
  try {
    RunHeaderOf(path, {{4, 3, "model: A"}, {5, 3, "model: B"}});
    ADD_FAILURE() << "two models";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "run.csv:5:10: a second model \"B\" after \"A\"");
  }
}

// The hand procedure file (io/hand_procedure.h): its keys, their defaults, and located refusals.
TEST(HandProcedureTest, ReadsEveryKeyAndRefusesWhatIsWrongWhereItIs) {
  const HandProcedure fixture = ReadHandProcedure(testing::Fixture("hand_12poses.yaml"));
  EXPECT_EQ(fixture.poses, 12);
  EXPECT_EQ(fixture.dwell_s, 10.0);
  EXPECT_TRUE(fixture.up.empty());  // any
  EXPECT_TRUE(fixture.twist_axes.empty());
  EXPECT_TRUE(IsHandProcedureFile(testing::Fixture("hand_12poses.yaml")));
  EXPECT_FALSE(IsHandProcedureFile(testing::Fixture("plan_24pos.yaml")));
  const std::string head = "format: imufit-hand-procedure\nversion: 1\n";
  const HandProcedure hand = ReadHandProcedureText(
      head + "up: [+x, -z, corners, [1, 1, 0]]\ntwist_axes: [z, x]\nlatitude_deg: 52.27\nheight_m: 80\n",
      "h.yaml");
  ASSERT_EQ(hand.up.size(), 11u);
  EXPECT_EQ(hand.up[0], Eigen::Vector3d::UnitX());
  EXPECT_EQ(hand.up[1], -Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(hand.up[10].dot(Eigen::Vector3d(1, 1, 0).normalized()), 1.0, 1e-15);
  EXPECT_EQ(hand.twist_axes, (std::vector<int>{2, 0}));
  EXPECT_EQ(*hand.latitude_deg, 52.27);
  EXPECT_EQ(ReadHandProcedureText(head + "twist_axes: none\n", "h.yaml").twist_deg,
            (std::array<double, 2>{0, 0}));
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"poses: 8\n", "h.yaml:3:8: poses: 8 is outside 9..10000"},
      {"up: [+w]\n", "h.yaml:3:6"},
      {"twist_axes: [q]\n", "h.yaml:3:14"},
      {"tilt_deg: [30, 10]\n", "h.yaml:3:11"},
      {"gravity_mps2: 9.81\nlatitude_deg: 50\n", "give gravity_mps2 or latitude_deg, not both"},
      {"height_m: 10\n", "height_m goes with latitude_deg"},
      {"rate_hz: 100 Hz\n", "h.yaml:3:10"},
  };
  for (const auto& [text, said] : refused) {
    try {
      ReadHandProcedureText(head + text, "h.yaml");
      ADD_FAILURE() << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(said), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace imufit
