// Tests of io/: every file format read and written per docs/spec.md, and every error located.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "imufit/io/calibration.h"
#include "imufit/io/csv_reader.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "test_models.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

class IoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("imufit_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  static std::string Read(const std::string& path) {
    std::ifstream stream(path, std::ios::binary);
    std::stringstream text;
    text << stream.rdbuf();
    return text.str();
  }
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

  fs::path dir_;
};

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
  calibration.extra = YAML::Node(YAML::NodeType::Map);
  calibration.extra["fit"]["iterations"] = 7;
  return calibration;
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
  EXPECT_EQ(read.extra["fit"]["iterations"].as<int>(), 7);
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
  text += "noise:\n  gyro_arw_deg_per_sqrt_hr: 0.3\n";
  const Calibration read = ReadCalibration(Write("cal.yaml", text));
  EXPECT_EQ(read.model.basis.center_c, 20.0);
  EXPECT_EQ(read.extra["noise"]["gyro_arw_deg_per_sqrt_hr"].as<double>(), 0.3);
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
  EXPECT_STREQ(e.what(), (dir_ / "samples.csv").string().append(":3:5: gyro_y: \"1.2.3\" is not a number").c_str());
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
  const std::string no_segment = Write("n.csv", "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n");
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

// ---------------------------------------------------------------- output files

TEST_F(IoTest, AnUncommittedOutputLeavesTheOldFileIntact) {
  const std::string path = Write("precious.csv", "keep me\n");
  {
    OutputFile file(path);
    file.Write("partial");
    // no Commit(): as when an error is thrown half way
  }
  EXPECT_EQ(Read(path), "keep me\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "temporary left behind";
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

}  // namespace
}  // namespace imufit
