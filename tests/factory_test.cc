// Tests of imufit::factory (and the io pieces it brought): SHA-256 against the FIPS 180-2
// vectors, the limits file reader and its located errors, the acceptance verdict on a known
// calibration, and the results store (records, queries, schema version).
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "imufit/factory/acceptance.h"
#include "imufit/factory/batch.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/certify.h"
#include "imufit/factory/lot_history.h"
#include "imufit/factory/report.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/io/units.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/report/allan_plot.h"
#include "imufit/report/engineering_units.h"
#include "imufit/report/html.h"
#include "imufit/report/plot.h"
#include "imufit/sim/simulator.h"
#include "imufit/store/store.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

// Relative tolerance of a unit conversion recomputed here by hand (same arithmetic, other order).
constexpr double kConversionRelative = 1e-12;

const std::string kFixtures = IMUFIT_FIXTURES_DIR;

using FactoryTest = testing::TempDirTest;

TEST(Sha256, FipsVectors) {
  // FIPS 180-2 appendix B.1, B.2, B.3, and the empty message.
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256, IncrementalEqualsOneShotAtEveryPaddingBoundary) {
  std::string message;
  for (int n = 0; n < 200; ++n) {
    Sha256 pieces;
    for (size_t at = 0; at < message.size(); at += 7) pieces.Update(std::string_view(message).substr(at, 7));
    EXPECT_EQ(pieces.HexDigest(), Sha256Hex(message)) << n << " bytes";
    message += static_cast<char>('a' + n % 26);
  }
}

TEST_F(FactoryTest, Sha256OfFileAndMissingFile) {
  EXPECT_EQ(Sha256OfFile(Write("abc.txt", "abc")), Sha256Hex("abc"));
  EXPECT_THROW(Sha256OfFile((dir_ / "missing").string()), InputError);
}

constexpr const char* kLimits = R"(format: imufit-limits
version: 1
name: test limits
nominal: {gyro_scale: 939.65, accel_scale: 208.838}
criteria:
  - {quantity: gyro_bias_dps, max_abs: 5}
  - {quantity: gyro_g_sensitivity_dpsg, max_abs: 0.03, axes: [xx, yy]}
  - {quantity: gyro_scale_error_ppm, max_abs: 20000}
  - {quantity: gyro_bias_dps, statistic: sigma, max_abs: 0.01}
  - {quantity: fit_temp_range_c, covers: [-40, 85]}
)";

TEST_F(FactoryTest, ReadsLimits) {
  const Limits limits = ReadLimits(Write("limits.yaml", kLimits));
  EXPECT_EQ(limits.name, "test limits");
  EXPECT_EQ(limits.nominal_gyro_scale, 939.65);
  ASSERT_EQ(limits.criteria.size(), 5u);
  EXPECT_EQ(limits.criteria[0].axes, (std::vector<std::string>{"x", "y", "z"}));
  EXPECT_EQ(limits.criteria[1].axes, (std::vector<std::string>{"xx", "yy"}));
  EXPECT_EQ(limits.criteria[3].statistic, LimitStatistic::kSigma);
  EXPECT_EQ(limits.criteria[4].kind, LimitKind::kCoverage);
  EXPECT_EQ(limits.criteria[4].covers_c[1], 85.0);
}

struct BadLimits {
  std::string text;
  std::string message;  // what the error must say, including its location
};

TEST_F(FactoryTest, BadLimitsAreLocatedInputErrors) {
  const std::string head = "format: imufit-limits\nversion: 1\ncriteria:\n";
  const std::vector<BadLimits> cases = {
      {head + "  - {quantity: gyro_bias_dps, max_abs: 1, colour: red}\n",
       ":4:43: criteria[0]: unknown key \"colour\""},
      {head + "  - {quantity: gyro_bias_dpx, max_abs: 1}\n",
       ":4:16: criteria[0].quantity: unknown quantity \"gyro_bias_dpx\""},
      {head + "  - {quantity: gyro_bias_dps, max_abs: -1}\n",
       ":4:40: criteria[0].max_abs: \"-1\" must be greater than 0"},
      {head + "  - {quantity: gyro_bias_dps, max_abs: abc}\n",
       "criteria[0].max_abs: \"abc\" is not a number"},
      {head + "  - {quantity: gyro_bias_dps, axes: [x, q], max_abs: 1}\n",
       "criteria[0].axes[1]: unknown axis \"q\""},
      {head + "  - {quantity: gyro_scale_error_ppm, max_abs: 1}\n", "needs nominal.gyro_scale"},
      {head + "  - {quantity: fit_temp_range_c, covers: [60, -20]}\n", "expected [lo, hi] with lo < hi"},
      {head + "  - {quantity: gyro_residual_rms_dps, statistic: sigma, max_abs: 1}\n", "has no 1-sigma"},
      {"format: imufit-plan\nversion: 1\ncriteria: []\n",
       ":1:9: format: \"imufit-plan\" is not \"imufit-limits\""},
      {"format: imufit-limits\nversion: 2\ncriteria: []\n", ":2:10: version: version 2 is not supported"},
      {"format: imufit-limits\nversion: 1\ncriteria: []\n", "no criteria"},
      {"format: imufit-limits\nversion: 1\ncriteria: [\n", "YAML syntax"},
  };
  for (const BadLimits& c : cases) {
    const std::string path = Write("bad.yaml", c.text);
    try {
      ReadLimits(path);
      ADD_FAILURE() << "accepted:\n" << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos)
          << e.what() << "\nexpected: " << c.message;
    }
  }
}

TEST_F(FactoryTest, KeyFiguresAndVerdictOnTheTruthCalibration) {
  const Calibration truth = ReadCalibration(kFixtures + "/mems_truth.yaml");
  const std::vector<Figure> figures = KeyFigures(truth);
  // By hand from fixtures/mems_truth.yaml: V_x / S_x in deg/s, H_xx / S_x in deg/s/g.
  const Figure* bias = FindFigure(figures, "gyro.bias.x");
  ASSERT_NE(bias, nullptr);
  EXPECT_EQ(bias->name, "gyro_bias_dps.x");
  EXPECT_NEAR(bias->value, 23.4 / 948.31 * 180.0 / M_PI, 23.4 / 948.31 * 180.0 / M_PI * kConversionRelative);
  const double g_sensitivity_xx = 0.0483 / 948.31 * 180.0 / M_PI * 9.80665;
  EXPECT_NEAR(FindFigure(figures, "gyro_g_sensitivity_dpsg.xx")->value, g_sensitivity_xx,
              g_sensitivity_xx * kConversionRelative);

  const Verdict verdict = EvaluateLimits(ReadLimits(Write("limits.yaml", kLimits)), truth);
  EXPECT_FALSE(verdict.pass);
  std::map<std::string, const CriterionResult*> by_name;
  for (const CriterionResult& c : verdict.criteria) by_name[c.name] = &c;
  ASSERT_EQ(verdict.criteria.size(), 3u + 2u + 3u + 3u + 1u);
  EXPECT_TRUE(by_name.at("|gyro_bias_dps.x|")->pass);
  // xx is 0.0286 deg/s/g (inside 0.03), yy is -0.0333 deg/s/g (outside).
  const CriterionResult& xx = *by_name.at("|gyro_g_sensitivity_dpsg.xx|");
  EXPECT_TRUE(xx.pass);
  EXPECT_NEAR(xx.margin, 0.03 - g_sensitivity_xx, 1e-15);
  EXPECT_FALSE(by_name.at("|gyro_g_sensitivity_dpsg.yy|")->pass);
  EXPECT_NEAR(by_name.at("|gyro_scale_error_ppm.x|")->measured, (948.31 / 939.65 - 1.0) * 1e6, 1e-6);
  // The truth file has no sigma tree: a sigma criterion cannot pass.
  EXPECT_FALSE(by_name.at("sigma(gyro_bias_dps.x)")->pass);
  EXPECT_EQ(by_name.at("sigma(gyro_bias_dps.x)")->measured_text, "not in calibration");
  // The truth claims -40..85 degC: exactly covered, margin 0.
  EXPECT_TRUE(by_name.at("fit_temp_range_c")->pass);
  EXPECT_EQ(by_name.at("fit_temp_range_c")->margin, 0.0);
  EXPECT_NE(verdict.FailedSummary().find("|gyro_g_sensitivity_dpsg.yy|"), std::string::npos);
  EXPECT_NE(verdict.Table().find("FAIL"), std::string::npos);
}

TEST(RobustZScores, FlagsTheOneFarValue) {
  // median 1.0, absolute deviations {0.2, 0.1, 0, 0.1, 5}: MAD 0.1; z of 6.0 = 0.6745 * 5 / 0.1.
  const std::vector<RobustZ> z = RobustZScores({0.8, 0.9, 1.0, 1.1, 6.0});
  EXPECT_NEAR(z[4].z, 0.6745 * 5.0 / 0.1, 1e-9);
  EXPECT_TRUE(z[4].outlier);
  EXPECT_FALSE(z[3].outlier);
  EXPECT_FALSE(RobustZScores({1.0, 1.0, 1.0, 5.0})[3].outlier);  // MAD 0: no spread to judge by
}

TEST_F(FactoryTest, NoiseLimitsUseTheNoiseBlockWhenPresent) {
  const std::string limits_path =
      Write("limits.yaml",
            "format: imufit-limits\nversion: 1\ncriteria:\n"
            "  - {quantity: gyro_arw_deg_per_sqrt_hr, max_abs: 0.2, axes: [x]}\n"
            "  - {quantity: gyro_bias_instability_dph, max_abs: 0.5, axes: [x]}\n");
  Calibration calibration = ReadCalibration(kFixtures + "/mems_truth.yaml");
  // Without a noise block the criteria cannot pass.
  Verdict verdict = EvaluateLimits(ReadLimits(limits_path), calibration);
  EXPECT_FALSE(verdict.criteria[0].pass);
  EXPECT_EQ(verdict.criteria[0].measured_text, "not in calibration");
  // With one (the record imufit allan --noise-yaml writes, io/noise_file.h), in SI units.
  NoiseColumnRecord gyro_x;
  gyro_x.name = "gyro_x";
  gyro_x.kind = ColumnKind::kGyro;
  gyro_x.fitted = true;
  const double arw = UnitsOf(ColumnKind::kGyro, kRandomWalk).engineer_per_si;
  const double instability = UnitsOf(ColumnKind::kGyro, kBiasInstability).engineer_per_si;
  gyro_x.value[kRandomWalk] = 0.1498 / arw;
  gyro_x.sigma[kRandomWalk] = 0.0002 / arw;
  gyro_x.value[kBiasInstability] = 0.94 / instability;
  gyro_x.sigma[kBiasInstability] = 0.67 / instability;
  calibration.noise.emplace().columns.push_back(gyro_x);
  verdict = EvaluateLimits(ReadLimits(limits_path), calibration);
  EXPECT_TRUE(verdict.criteria[0].pass);
  EXPECT_DOUBLE_EQ(verdict.criteria[0].measured, 0.1498);
  EXPECT_FALSE(verdict.criteria[1].pass);  // 0.94 deg/h > 0.5 deg/h
  EXPECT_DOUBLE_EQ(FindFigure(KeyFigures(calibration), "noise.gyro_x.arw_deg_per_sqrt_hr")->sigma, 0.0002);
}

// KeyFigures() lists the table's figures of a calibration in the table's order, each with the
// table's unit (the one engineering_units.h states it in) and a title in words.
TEST_F(FactoryTest, KeyFiguresFollowTheKeyFigureTable) {
  Calibration calibration = ReadCalibration(kFixtures + "/mems_truth.yaml");
  FitRecord record;
  record.gyro_residual_rms_radps = 1e-4;
  record.accel_residual_rms_mps2 = 2e-3;
  record.missing_segments = 0;
  calibration.fit = record;
  NoiseColumnRecord gyro_x;  // the noise record of one gyro column, both terms fitted
  gyro_x.name = "gyro_x";
  gyro_x.kind = ColumnKind::kGyro;
  gyro_x.fitted = true;
  gyro_x.value[kRandomWalk] = 0.1498 / UnitsOf(ColumnKind::kGyro, kRandomWalk).engineer_per_si;
  gyro_x.value[kBiasInstability] = 0.94 / UnitsOf(ColumnKind::kGyro, kBiasInstability).engineer_per_si;
  calibration.noise.emplace().columns.push_back(gyro_x);
  const std::vector<Figure> figures = KeyFigures(calibration);
  std::vector<std::string> expected;
  for (const KeyFigure& quantity : kKeyFigures) {
    if (quantity.source == FigureSource::kNoise) {
      expected.push_back(std::string(quantity.name) + ".x");
    } else if (quantity.source == FigureSource::kCoefficient) {
      for (const std::string& axis : KeyFigureAxes(quantity))
        expected.push_back(std::string(quantity.name) + "." + axis);
    } else if (quantity.source == FigureSource::kFitRecord) {
      expected.push_back(quantity.name);
    }
  }
  std::vector<std::string> names;
  for (const Figure& f : figures) {
    names.push_back(f.name);
    const KeyFigure* quantity = FindKeyFigure(f.name);
    ASSERT_NE(quantity, nullptr) << f.name;
    EXPECT_EQ(f.unit, quantity->unit) << f.name;
    EXPECT_NE(FigureTitle(f.name), f.name);
    if (quantity->source != FigureSource::kCoefficient) continue;
    int coefficient = 0;  // the model's coefficient of the figure's path ("gyro.bias.x")
    const std::string path = f.coefficient.substr(f.coefficient.find('.') + 1);
    while (path !=
           std::string(kCoefficientNames[coefficient].group) + "." + kCoefficientNames[coefficient].axis)
      ++coefficient;
    EXPECT_EQ(f.unit, EngineeringUnit(IsGyroFigure(*quantity) ? Sensor::kGyro : Sensor::kAccel, coefficient));
  }
  EXPECT_EQ(names, expected);
  // Every quantity a limits file may name has a title, the certificate's own ones too.
  for (const KeyFigure& quantity : kKeyFigures) EXPECT_NE(FigureTitle(quantity.name), quantity.name);
  // The figures the lot summary and the lot trend pick are the table's.
  for (const std::vector<std::string>* picked : {&kSummaryFigures, &kLotTrendFigures}) {
    for (const std::string& name : *picked) EXPECT_NE(FindKeyFigure(name), nullptr) << name;
  }
  EXPECT_EQ(FigureTitle("gyro_residual_max_dps"), "Gyro largest window error");
  EXPECT_EQ(FigureTitle("gyro_g_sensitivity_dpsg.xy"), "Gyro g-sensitivity X from Y");
}

// The verdict vocabulary as the store, the manifest and lot_summary.csv write it (docs/spec.md
// section 5): these texts are a file format.
TEST(VerdictNamesTest, AreTheSerialisedTexts) {
  EXPECT_EQ(AllNames(kUnitStatusNames), "fitted, not-fitted, error");
  EXPECT_EQ(AllNames(kOutcomeNames), "PASS, conditional pass, conditional fail, FAIL");
  EXPECT_EQ(AllNames(kVerdictNames), "PASS, FAIL");
  EXPECT_EQ(AllNames(kCriterionAcceptanceNames), "pass, fail");
  UnitOutcome unit;
  unit.status = UnitStatus::kNotFitted;
  EXPECT_EQ(std::string(unit.StatusText()), "not-fitted");
  EXPECT_EQ(std::string(unit.VerdictText()), "");
  unit.status = UnitStatus::kFitted;
  unit.verdict.emplace().pass = false;
  EXPECT_EQ(std::string(unit.VerdictText()), "FAIL");
  BatchResult batch;
  batch.Add(unit);
  unit.verdict.reset();
  batch.Add(unit);
  unit.status = UnitStatus::kError;
  batch.Add(unit);
  EXPECT_EQ(batch.failed, 1);
  EXPECT_EQ(batch.passed, 0);
  EXPECT_EQ(batch.errors, 1);
  EXPECT_EQ(batch.not_fitted, 0);
}

TEST_F(FactoryTest, StoreRecordsAndAnswers) {
  const std::string path = (dir_ / "store.db").string();
  const Calibration truth = ReadCalibration(kFixtures + "/mems_truth.yaml");
  {
    ResultsStore store(path);
    for (int i = 0; i < 3; ++i) {
      StoredFit fit;
      fit.serial = i == 2 ? "SN2" : "SN1";
      fit.unit = "u" + std::to_string(i);
      fit.lot = i == 0 ? "lot-a" : "lot-b";
      fit.samples_sha256 = std::string(64, static_cast<char>('a' + i));  // three runs: three logs
      fit.time_utc = "2026-11-22T07:0" + std::to_string(i) + ":00Z";
      fit.software = "imufit test";
      fit.status = "fitted";
      fit.verdict = i == 1 ? "FAIL" : "PASS";
      fit.calibration_yaml = CalibrationToYaml(truth);
      const std::vector<Figure> figures = KeyFigures(truth);
      for (const Figure& figure : figures) fit.figures.push_back(StoredFigureOf(figure));
      fit.figures[0].value += i;
      EXPECT_GT(store.Record(fit), 0);
    }
  }
  ResultsStore store(path);  // reopened: the rows are there
  const std::vector<StoredFit> fits = store.BySerial("SN1");
  ASSERT_EQ(fits.size(), 2u);
  EXPECT_EQ(fits[1].verdict, "FAIL");
  EXPECT_EQ(fits[1].calibration_yaml, CalibrationToYaml(truth));
  EXPECT_EQ(fits[1].figures.size(), KeyFigures(truth).size());
  const std::vector<LotYield> yields = store.Yield("");
  ASSERT_EQ(yields.size(), 2u);
  EXPECT_EQ(yields[1].lot, "lot-b");
  EXPECT_EQ(yields[1].units, 2);
  EXPECT_EQ(yields[1].passed, 1);
  EXPECT_EQ(yields[1].failed, 1);
  const std::vector<TrendPoint> trend = store.Trend("gyro.bias.x", "");
  ASSERT_EQ(trend.size(), 3u);
  EXPECT_EQ(trend[2].value - trend[0].value, 2.0);
  EXPECT_EQ(store.Trend("gyro_bias_dps.x", "SN2").size(), 1u);
}

TEST_F(FactoryTest, StoreRefusesANewerSchemaAndForeignFiles) {
  const std::string path = (dir_ / "store.db").string();
  { ResultsStore store(path); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE schema_version SET version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  try {
    ResultsStore store(path);
    ADD_FAILURE() << "opened a version 99 store";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("schema version 99 is not supported"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(
      ResultsStore(Write("text.db", "this is not a database, just some text long enough to matter\n")),
      InputError);
}

// A calibration whose coefficients are written about another reference temperature (40 degC)
// states the same unit: every figure is the same, to rounding.
TEST_F(FactoryTest, FiguresDoNotDependOnTheReferenceTemperature) {
  const Calibration at25 = ReadCalibration(kFixtures + "/mems_truth.yaml");
  Calibration at40 = at25;
  TemperatureBasis basis40;
  basis40.center_c = 40.0;
  const Eigen::Matrix4d L = RebaseTemperaturePolynomial(at25.model.basis, basis40);
  const auto rebase = [&](double* params, int coefficients) {
    for (int i = 0; i < coefficients; ++i) {
      Eigen::Map<Eigen::Vector4d> c(params + i * kPolynomialTerms);
      c = (L * c).eval();
    }
  };
  rebase(at40.model.gyro.data(), kGyroCoefficients);
  rebase(at40.model.accel.data(), kAccelCoefficients);
  at40.model.basis = basis40;
  const std::string path = Write("cal40.yaml", CalibrationToYaml(at40));
  const Calibration read40 = ReadCalibration(path);
  ASSERT_EQ(read40.model.basis.center_c, 40.0);
  ASSERT_NE(read40.model.gyro[0], at25.model.gyro[0]);  // the c0 terms differ: the file really moved
  // Relative agreement of a figure recomputed through a rebased cubic (rounding of L * c only).
  constexpr double kRebaseRelative = 1e-9;
  const std::vector<Figure> figures25 = KeyFigures(at25), figures40 = KeyFigures(read40);
  ASSERT_EQ(figures25.size(), figures40.size());
  for (size_t i = 0; i < figures25.size(); ++i) {
    EXPECT_NEAR(figures40[i].value, figures25[i].value,
                std::abs(figures25[i].value) * kRebaseRelative + 1e-12)
        << figures25[i].name;
  }
  // Off the reference too: the g-sensitivity xx at 60 degC.
  const double h25 =
      EngineeringCoefficient(at25.model, nullptr, Sensor::kGyro, kGSensitivityCoefficient, 60.0).value;
  const double h40 =
      EngineeringCoefficient(read40.model, nullptr, Sensor::kGyro, kGSensitivityCoefficient, 60.0).value;
  EXPECT_NEAR(h40, h25, std::abs(h25) * kRebaseRelative);
}

TEST(Html, EscapesByConstructionAndChecksNesting) {
  Html h;
  h.Open("p", {{"data-x", "a\"b<c>"}}).Text("<script>alert('x') & co</script>").Close("p");
  const std::string page = h.Finish();
  EXPECT_NE(page.find("data-x=\"a&quot;b&lt;c&gt;\""), std::string::npos) << page;
  EXPECT_NE(page.find("&lt;script&gt;alert(&#39;x&#39;) &amp; co&lt;/script&gt;"), std::string::npos) << page;
  EXPECT_EQ(page.find("<script>"), std::string::npos);
  EXPECT_DEATH(
      {
        Html bad;
        bad.Open("table").Close("tr");
      },
      "closing an element that is not open");
  EXPECT_DEATH(
      {
        Html open;
        open.Open("div");
        open.Finish();
      },
      "open element");
}

TEST(RobustZScores, NoiseBetweenIdenticalUnitsIsNotAnOutlier) {
  // 6.0 is far out by the spread, but within 3 of its own 1-sigma (2.0) of the median: not flagged.
  EXPECT_FALSE(RobustZScores({0.8, 0.9, 1.0, 1.1, 6.0}, {0.1, 0.1, 0.1, 0.1, 2.0})[4].outlier);
  EXPECT_TRUE(RobustZScores({0.8, 0.9, 1.0, 1.1, 6.0}, {0.1, 0.1, 0.1, 0.1, 0.1})[4].outlier);
}

// The renderer's number format: a value that prints as zero has no sign, whatever the format's
// flags and the text around the number; any other value keeps its own.
TEST(FormatNumber, NoFigurePrintsASignedZero) {
  EXPECT_EQ(FormatNumber("%.1f", -0.02), "0.0");  // a held-out temperature just below 0 degC
  EXPECT_EQ(FormatNumber("%.1f", -0.0), "0.0");
  EXPECT_EQ(FormatNumber("%+.6g", 0.0), "0");  // a count of segments missing
  EXPECT_EQ(FormatNumber("%+.6g", -0.0), "0");
  EXPECT_EQ(FormatNumber("%+.1f", 0.04), "0.0");
  EXPECT_EQ(FormatNumber("%.1f %%", -0.01), "0.0 %");
  EXPECT_EQ(FormatNumber("gyro %+g deg/h", 0.0), "gyro 0 deg/h");
  EXPECT_EQ(FormatNumber("%+.1f", 0.06), "+0.1");
  EXPECT_EQ(FormatNumber("%+.6g", -1e-9), "-1e-09");  // small, not zero
  EXPECT_EQ(FormatNumber("%.1f", -0.06), "-0.1");
}

// A fitted run's own sigma against the plan's prediction on its windows (relative): the fixture's
// reduced chi-square is near 1.
constexpr double kPredictedSigmaTolerance = 0.10;

// The certificate of the MEMS soak fixture: asserted on the struct, not on HTML.
class CertificateTest : public FactoryTest {
 protected:
  Certificate Make(const std::string& plan_path, const std::optional<Limits>& limits) {
    const std::string samples = kFixtures + "/mems_6pos_soak.csv.gz";
    FitRunOptions options;
    options.software = "imufit test";
    const FitRunResult fit = FitRun(plan_path, samples, options);
    if (!fit.calibration) throw std::runtime_error(fit.fit.BriefReport());
    CertificateSources sources;
    sources.calibration = *fit.calibration;
    sources.plan = fit.plan;
    sources.run = fit.run;
    sources.limits = limits;
    sources.inputs = {{"plan", plan_path, ""}, {"samples", samples, ""}};
    EXPECT_TRUE(InputMismatches(sources.calibration, plan_path, samples).empty());
    EXPECT_FALSE(
        InputMismatches(sources.calibration, plan_path, kFixtures + "/mems_6pos_noiseless.csv.gz").empty());
    ReadCertificateFiles(&sources);
    return MakeCertificate(sources);
  }
  // The certificate of a fit from its run alone (no limits, no files to hash).
  static Certificate CertificateOf(const FitRunResult& fit) {
    CertificateSources sources;
    sources.calibration = *fit.calibration;
    sources.plan = fit.plan;
    sources.run = fit.run;
    return MakeCertificate(sources);
  }
  // Simulates `plan` for the fixture truth into `name` (with its segment column); returns the path.
  std::string Simulate(const Plan& plan, const SimulationOptions& options, const std::string& name) const {
    const std::string path = (dir_ / name).string();
    SamplesWriter writer(path, true);
    SimulateRun(options, plan.site, plan.segments, ReadCalibration(kFixtures + "/mems_truth.yaml").model,
                [&](const Sample& raw, const SegmentTruth&) { writer.Write(raw); });
    writer.Commit();
    return path;
  }
};

TEST_F(CertificateTest, HoldsEveryNumberAQualityEngineerReads) {
  const Certificate c = Make(kFixtures + "/plan_6pos.yaml", std::nullopt);
  // No serial anywhere: said, not hidden, naming every place a serial can come from.
  EXPECT_TRUE(c.serial.empty());
  ASSERT_FALSE(c.warnings.empty());
  EXPECT_NE(c.warnings[0].find("no serial"), std::string::npos);
  for (const char* source : {"--serial", "the calibration", "'# serial:' header line", "the plan"}) {
    EXPECT_NE(c.warnings[0].find(source), std::string::npos) << source << ": " << c.warnings[0];
  }
  // The run: 6 static positions and two rates, every segment with windows.
  EXPECT_EQ(c.run.static_segments, 6);
  EXPECT_EQ(c.run.rates_dps, (std::vector<double>{100.0, 300.0}));
  EXPECT_EQ(c.run.turn_segments, 0);
  EXPECT_TRUE(c.run.segments_without_windows.empty());
  // The solver's reason without the tolerances it quotes.
  EXPECT_EQ(c.settings.termination.find("<="), std::string::npos) << c.settings.termination;
  EXPECT_EQ(c.settings.termination.back(), '.') << c.settings.termination;
  ASSERT_EQ(c.inputs.size(), 2u);
  EXPECT_EQ(c.inputs[1].sha256, Sha256OfFile(kFixtures + "/mems_6pos_soak.csv.gz"));
  // Key figures: expanded uncertainty k = 2; the fit recovers the truth within its own uncertainty.
  const Calibration truth = ReadCalibration(kFixtures + "/mems_truth.yaml");
  const std::vector<Figure> truth_figures = KeyFigures(truth);
  for (const KeyFigureRow& f : c.figures) {
    if (f.sigma >= 0.0) {
      EXPECT_EQ(f.expanded, 2.0 * f.sigma) << f.name;
    }
  }
  const auto figure = [&](const std::string& name) {
    for (const KeyFigureRow& f : c.figures) {
      if (f.name == name) return f;
    }
    ADD_FAILURE() << name;
    return KeyFigureRow();
  };
  // Coefficients are signed; the fit's diagnostics cannot be negative (printed without a sign).
  EXPECT_TRUE(figure("gyro_bias_dps.x").is_coefficient);
  EXPECT_TRUE(figure("accel_misalignment_mrad.xy").is_coefficient);
  EXPECT_FALSE(figure("gyro_residual_rms_dps").is_coefficient);
  EXPECT_FALSE(figure("coverage").is_coefficient);
  constexpr double kRecoverySigmas = 5.0;  // worst case, per figure
  for (const char* name : {"gyro_bias_dps.x", "gyro_g_sensitivity_dpsg.xx", "accel_bias_mg.z"}) {
    const KeyFigureRow f = figure(name);
    ASSERT_GT(f.sigma, 0.0) << name;
    EXPECT_NEAR(f.value, FindFigure(truth_figures, name)->value, kRecoverySigmas * f.sigma) << name;
  }
  // Curves: the gyro bias curve passes through the 25 degC figure; the g-sensitivity is a 3x3 grid.
  ASSERT_EQ(c.curves.size(), 7u);
  EXPECT_EQ(c.curves[0].title, "Gyro bias");
  EXPECT_EQ(c.curves[3].curves.size(), 9u);
  EXPECT_TRUE(c.curves[3].grid);
  // Residuals: the correction removes almost all of the error the scale-only correction leaves.
  ASSERT_FALSE(c.residual_table.empty());
  const ResidualRow& all = c.residual_table.back();
  EXPECT_EQ(all.segment, -1);
  EXPECT_LT(all.gyro_rms_dps, 0.01 * all.gyro_rms_before_dps);
  EXPECT_EQ(c.residuals.gyro_dps[0].size(), static_cast<size_t>(c.run.windows));
  // A 6-position soak has no minute-long static stretch: the Allan section says why not.
  EXPECT_FALSE(c.noise.computed);
  EXPECT_NE(c.noise.why_not.find("at least 60 s"), std::string::npos) << c.noise.why_not;
  EXPECT_TRUE(c.settings.known);
  EXPECT_EQ(c.settings.loss, "huber");
  EXPECT_FALSE(c.verdict.has_value());
  // The plots hold the certificate's data.
  const std::vector<PlotFigure> plots = CertificatePlots(c);
  ASSERT_EQ(plots.size(), c.curves.size() + 1);  // the coefficient groups, then the errors
  EXPECT_EQ(plots[3].panels.size(), 9u);
  EXPECT_EQ(plots[0].panels[0].series[1].y, c.curves[0].curves[0].value);
  // The window estimates are drawn over the band and the line.
  ASSERT_FALSE(c.curves[0].curves[0].points.empty());
  EXPECT_EQ(plots[0].panels[0].series[2].style, PlotSeries::Style::kErrorBars);
  EXPECT_EQ(plots[0].panels[0].series[2].y.size(), c.curves[0].curves[0].points.size());
  EXPECT_EQ(plots[0].panels[0].series[2].error[0], c.curves[0].curves[0].points[0].sigma);
}

// Written for its reader: criteria and coefficients in words, every value rounded to its U, no
// developer text (solver strings, file-format references, gnuplot's SVG titles), long paths
// shortened at a folder, and time-axis tick labels that fit their panel.
TEST_F(CertificateTest, IsWrittenForItsReader) {
  EXPECT_EQ(FigureTitle("gyro_bias_dps.x"), "Gyro bias X");
  EXPECT_EQ(FigureTitle("gyro_g_sensitivity_dpsg.xy"), "Gyro g-sensitivity X from Y");
  EXPECT_EQ(FigureTitle("accel_misalignment_mrad.zx"), "Accel misalignment Z from X");
  EXPECT_EQ(FigureTitle("fit_temp_range_c"), "Fitted temperature range");
  EXPECT_EQ(FigureTitle("something_else.q"), "something_else.q");
  // GUM 7.2.6: U to two significant digits, the value to the same place.
  const RoundedValue bias = RoundToUncertainty(7.6412345, 0.00086);
  EXPECT_EQ(bias.value, "7.64123");
  EXPECT_EQ(bias.uncertainty, "0.00086");
  EXPECT_EQ(RoundToUncertainty(0.0712, 0.0021, true).value, "+0.0712");
  EXPECT_EQ(RoundToUncertainty(1234.6, 96).value, "1235");
  const RoundedValue carried = RoundToUncertainty(12345, 996);  // U rounds up to 1000: one place fewer
  EXPECT_EQ(carried.uncertainty, "1000");
  EXPECT_EQ(carried.value, "12300");
  EXPECT_EQ(RoundToUncertainty(-0.00004, 0.0021).value, "0.0000");  // no "-0.0000"
  EXPECT_EQ(RoundToUncertainty(0.5, 0.0).uncertainty, "");

  const std::string limits_path = Write("limits.yaml", kLimits);
  Certificate c = Make(kFixtures + "/plan_6pos.yaml", ReadLimits(limits_path));
  const std::string long_path =
      "/srv/calibration/station-02/2026/lots/LOT-A/unit-0001/acceptance/limits_rev_b.yaml";
  c.inputs.push_back({"limits", long_path, std::string(64, 'a')});
  ASSERT_TRUE(c.verdict.has_value());
  if (!GnuplotAvailable()) GTEST_SKIP() << "no gnuplot on PATH: the page's plots are not drawn";
  const std::string html = CertificateHtml(c);
  // What a reader sees: the text outside tags (attributes keep the machine names).
  std::string text;
  bool in_tag = false;
  for (char ch : html) {
    if (ch == '<') in_tag = true;
    if (!in_tag) text += ch;
    if (ch == '>') in_tag = false;
  }
  for (const char* developer : {"_dps", "_mg", "_mrad", "dpsg", "docs/spec.md", "tolerance reached",
                                "Gnuplot", "GNUPLOT", "|gyro", "sigma(gyro"}) {
    EXPECT_EQ(text.find(developer), std::string::npos) << developer;
  }
  EXPECT_NE(text.find("Gyro g-sensitivity X from X"), std::string::npos);
  EXPECT_NE(text.find("g-sensitivity X from Y"), std::string::npos);
  EXPECT_NE(text.find("converged after"), std::string::npos);
  // The only <title> is the document's; no <desc> (tooltips over the plots).
  EXPECT_EQ(html.find("<title>", html.find("<title>") + 1), std::string::npos);
  EXPECT_EQ(html.find("<desc>"), std::string::npos);
  // Each coefficient's value at the decimal place of its U.
  for (const KeyFigureRow& f : c.figures) {
    if (!f.is_coefficient || !(f.expanded > 0.0)) continue;
    const RoundedValue v = RoundToUncertainty(f.value, f.expanded, true);
    EXPECT_NE(html.find("data-value=\"" + FormatDouble(f.value) + "\">" + v.value + "<"), std::string::npos)
        << f.name << " " << v.value;
    EXPECT_NE(html.find(">" + v.uncertainty + "<"), std::string::npos) << f.name;
  }
  // The long path: whole folder names after an ellipsis, the whole path kept for tools.
  EXPECT_NE(text.find("\xe2\x80\xa6/\xe2\x80\x8b"), std::string::npos);
  EXPECT_NE(text.find("limits_rev_b.yaml"), std::string::npos);
  EXPECT_EQ(text.find("/srv/"), std::string::npos);
  EXPECT_NE(html.find("data-path=\"" + long_path + "\""), std::string::npos);

  // A time axis of 0 .. 1300 s in a third of the page: the labels of 250 s steps would collide.
  PlotFigure grid;
  grid.rows = 3;
  grid.cols = 3;
  grid.width_px = 700;
  grid.height_px = 480;
  Plot time_panel;
  time_panel.max_x_tics = 7;
  PlotSeries s;
  s.x = {0.0, 650.0, 1300.0};
  s.y = {0.0, 1.0, 2.0};
  time_panel.series = {s};
  grid.panels = {time_panel};
  const std::string script = GnuplotScript(grid, "svg", "out.svg");
  const size_t at = script.find("set xtics ");
  ASSERT_NE(at, std::string::npos) << script;
  EXPECT_GE(std::stod(script.substr(at + 10)), 500.0) << script.substr(at, 20);
}

// Limits as specifications are written: the largest value and the variation over a temperature
// range (checked against the polynomial evaluated here on a finer grid), the worst window error at
// any temperature, and a noise term this run cannot resolve, which says what stretch it needs.
TEST_F(CertificateTest, LimitsOverATemperatureRangeAndTermsTheRunCannotResolve) {
  const std::string limits_path = Write("range_limits.yaml", R"(format: imufit-limits
version: 1
criteria:
  - {quantity: gyro_bias_dps, statistic: largest, over: [-40, 85], max_abs: 100, axes: [x]}
  - {quantity: gyro_bias_dps, statistic: variation, max_abs: 100, axes: [x]}
  - {quantity: gyro_residual_max_dps, max_abs: 1}
  - {quantity: gyro_arw_deg_per_sqrt_hr, max_abs: 1, axes: [x]}
)");
  const Certificate c = Make(kFixtures + "/plan_6pos.yaml", ReadLimits(limits_path));
  ASSERT_TRUE(c.verdict.has_value());
  ASSERT_EQ(c.verdict->criteria.size(), 4u);
  const CriterionResult& largest = c.verdict->criteria[0];
  const CriterionResult& variation = c.verdict->criteria[1];
  EXPECT_EQ(largest.title, "Gyro bias X, largest over -40..85 degC");
  // By hand: the polynomial on a grid four times finer than the evaluation's.
  double most = 0.0, lo = HUGE_VAL, hi = -HUGE_VAL;
  const Calibration fitted =
      FitRun(kFixtures + "/plan_6pos.yaml", kFixtures + "/mems_6pos_soak.csv.gz", FitRunOptions())
          .calibration.value();
  for (int i = 0; i <= 1000; ++i) {
    const double temp_c = -40.0 + 125.0 * i / 1000.0;
    const double v = FindFigure(KeyFigures(fitted, temp_c), "gyro_bias_dps.x")->value;
    most = std::max(most, std::abs(v));
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  constexpr double kGridRelative = 1e-3;  // the evaluation's coarser grid misses the peak by less
  EXPECT_NEAR(largest.measured, most, kGridRelative * most);
  EXPECT_LE(largest.measured, most * (1.0 + 1e-12));
  const auto& range = fitted.fit_temp_range_c;
  EXPECT_NE(largest.reason.find(" degC"), std::string::npos) << largest.reason;  // where it binds
  double flo = HUGE_VAL, fhi = -HUGE_VAL;
  for (int i = 0; i <= 1000; ++i) {
    const double v =
        FindFigure(KeyFigures(fitted, range[0] + (range[1] - range[0]) * i / 1000.0), "gyro_bias_dps.x")
            ->value;
    flo = std::min(flo, v);
    fhi = std::max(fhi, v);
  }
  EXPECT_NEAR(variation.measured, fhi - flo, kGridRelative * (fhi - flo));
  EXPECT_EQ(variation.expanded, -1.0);
  // The worst window at any temperature is the per-segment table's.
  EXPECT_EQ(c.verdict->criteria[2].measured, c.residual_table.back().gyro_max_dps);
  // A 6-position soak has no minute-long static stretch: the ARW is not resolved, and says why.
  const CriterionResult& arw = c.verdict->criteria[3];
  EXPECT_FALSE(arw.pass);
  EXPECT_EQ(arw.measured_text, "not resolved by this run");
  EXPECT_NE(arw.reason.find("needs a static stretch of 60 s"), std::string::npos) << arw.reason;
  EXPECT_NE(arw.reason.find("imufit allan --noise-yaml"), std::string::npos) << arw.reason;

  // The reader: a range needs a range statistic; a variation has no min/max; noise has no curve.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"{quantity: gyro_bias_dps, over: [-40, 85], max_abs: 1}", "a range takes `statistic: largest`"},
      {"{quantity: gyro_bias_dps, statistic: variation, min: -1, max: 1}", "a variation takes max_abs"},
      {"{quantity: gyro_arw_deg_per_sqrt_hr, statistic: largest, max_abs: 1}",
       "does not vary with temperature"},
      {"{quantity: gyro_bias_dps, statistic: largest, over: [85, -40], max_abs: 1}", "lo < hi"}};
  for (const auto& [criterion, message] : bad) {
    const std::string path =
        Write("bad_range.yaml", "format: imufit-limits\nversion: 1\ncriteria:\n  - " + criterion + "\n");
    try {
      ReadLimits(path);
      ADD_FAILURE() << criterion;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

// The window estimates of every coefficient on a run with white noise only, simulated from the
// fixture truth: they scatter about the true coefficient and about the fitted polynomial by their
// own 1-sigma error bars (normalised RMS near 1), and not less (points taken from the curve
// would have none of the data's scatter).
TEST_F(CertificateTest, WindowEstimatesScatterAboutTheTruthByTheirOwnNoise) {
  const Plan plan = ReadPlan(kFixtures + "/plan_6pos.yaml");
  const Calibration truth = ReadCalibration(kFixtures + "/mems_truth.yaml");
  SimulationOptions options;
  options.soak_temps_c = {-40.0, -10.0, 25.0, 55.0, 85.0};
  options.rate_hz = 50.0;
  options.dwell_s = 5.0;
  options.transition_s = 1.0;
  options.gyro_noise_density = 8.7e-5;
  options.accel_noise_density = 1.5e-3;
  options.seed = 21;
  const FitRunResult fit =
      FitRun(kFixtures + "/plan_6pos.yaml", Simulate(plan, options, "white.csv"), FitRunOptions());
  ASSERT_TRUE(fit.calibration.has_value()) << fit.fit.BriefReport();
  const Certificate c = CertificateOf(fit);

  // The groups in certificate order: sensor, first coefficient, whether stated as a scale change.
  struct GroupKind {
    Sensor sensor;
    int first;
    bool scale_change;
  };
  const GroupKind kinds[] = {
      {Sensor::kGyro, kBiasCoefficient, false},         {Sensor::kGyro, kScaleCoefficient, true},
      {Sensor::kGyro, kMisalignmentCoefficient, false}, {Sensor::kGyro, kGSensitivityCoefficient, false},
      {Sensor::kAccel, kBiasCoefficient, false},        {Sensor::kAccel, kScaleCoefficient, true},
      {Sensor::kAccel, kMisalignmentCoefficient, false}};
  ASSERT_EQ(c.curves.size(), std::size(kinds));
  const auto value = [](const SensorModel& model, const GroupKind& kind, int i, double temp_c) {
    return kind.scale_change
               ? ScaleChangePpm(model, nullptr, kind.sensor, i, temp_c).value
               : EngineeringCoefficient(model, nullptr, kind.sensor, kind.first + i, temp_c).value;
  };
  // Normalised RMS over a group's points (60 to 180 of them): 1 for errors of exactly the stated
  // sigma; the bounds allow the sampling spread of that many points and the fit's own error.
  // Against the fit the RMS is lower, about sqrt(1 - terms / points) (4 polynomial terms from 10 to
  // 30 points per coefficient, shared with the other coefficients of the row): at least
  // kLowestFitRms, where points computed from the curve would give 0.
  constexpr double kLowestRms = 0.6, kHighestRms = 1.5, kLowestFitRms = 0.5;
  constexpr double kWorstPointSigmas = 5.0;  // worst case over all ~700 points
  constexpr size_t kFewestPoints = 10;       // per coefficient: 2 positions or rates x 5 temperatures
  for (size_t g = 0; g < c.curves.size(); ++g) {
    double truth_squares = 0.0, fit_squares = 0.0;
    size_t count = 0;
    for (size_t i = 0; i < c.curves[g].curves.size(); ++i) {
      const CoefficientCurve& curve = c.curves[g].curves[i];
      EXPECT_GE(curve.points.size(), kFewestPoints) << c.curves[g].title << " " << curve.axis;
      for (const CoefficientPoint& p : curve.points) {
        ASSERT_GT(p.sigma, 0.0);
        const double z_truth =
            (p.value - value(truth.model, kinds[g], static_cast<int>(i), p.temp_c)) / p.sigma;
        const double z_fit =
            (p.value - value(fit.calibration->model, kinds[g], static_cast<int>(i), p.temp_c)) / p.sigma;
        EXPECT_LT(std::abs(z_truth), kWorstPointSigmas)
            << c.curves[g].title << " " << curve.axis << " at " << p.temp_c << " degC, segment " << p.segment;
        truth_squares += z_truth * z_truth;
        fit_squares += z_fit * z_fit;
        ++count;
      }
    }
    ASSERT_GT(count, 0u) << c.curves[g].title;
    const double truth_rms = std::sqrt(truth_squares / count), fit_rms = std::sqrt(fit_squares / count);
    std::printf("%-48s %4zu points: normalised RMS against the truth %.2f, against the fit %.2f\n",
                c.curves[g].title.c_str(), count, truth_rms, fit_rms);
    EXPECT_GT(truth_rms, kLowestRms) << c.curves[g].title;
    EXPECT_LT(truth_rms, kHighestRms) << c.curves[g].title;
    EXPECT_GT(fit_rms, kLowestFitRms) << c.curves[g].title << ": the points do not carry the data's scatter";
    EXPECT_LT(fit_rms, kHighestRms) << c.curves[g].title;
  }
}

// A hand session (six faces, a 360 deg turn about each axis) at one temperature: a turn's window is
// judged against its mean rate, and the accelerometer is not judged where gravity turned in the
// body frame (the turns about x and y).
TEST_F(CertificateTest, AHandSessionsTurnsAreJudgedAgainstTheirMeanRate) {
  const std::string plan_path = kFixtures + "/plan_hand_6faces_3turns.yaml";
  const Plan plan = ReadPlan(plan_path);
  SimulationOptions options;
  options.rate_hz = 100.0;
  options.dwell_s = 10.0;
  options.transition_s = 2.0;
  options.gyro_noise_density = 8.7e-5;
  options.accel_noise_density = 1.5e-3;
  options.seed = 4;
  FitRunOptions fit_options;
  fit_options.fit.gyro_temp_order = fit_options.fit.accel_temp_order = 0;
  const FitRunResult fit = FitRun(plan_path, Simulate(plan, options, "hand.csv"), fit_options);
  ASSERT_TRUE(fit.calibration.has_value()) << fit.fit.BriefReport();
  const Certificate c = CertificateOf(fit);
  ASSERT_EQ(c.residual_table.size(), plan.segments.size() + 1);
  int turns = 0;
  for (const ResidualRow& row : c.residual_table) {
    const TableSegment* segment = row.segment < 0 ? nullptr : plan.Find(row.segment);
    if (segment == nullptr || !segment->IsTurn()) continue;
    ++turns;
    EXPECT_EQ(row.motion.rfind("turn 360 deg about ", 0), 0u) << row.motion;
    // Against its mean rate the turn's error is noise (about 1e-4 deg/s), not its 36 deg/s.
    constexpr double kTurnErrorDps = 0.01;
    EXPECT_LT(row.gyro_rms_dps, kTurnErrorDps) << row.motion;
    EXPECT_EQ(row.accel_windows, segment->AxisIsVertical() ? 1 : 0) << row.motion;
  }
  EXPECT_EQ(turns, 3);
  // The run summary counts turns as turns (not as rate segments of 0 deg/s).
  EXPECT_EQ(c.run.static_segments, 6);
  EXPECT_EQ(c.run.turn_segments, 3);
  EXPECT_EQ(c.run.turn_angles_deg, (std::vector<double>{360.0}));
  EXPECT_TRUE(c.run.rates_dps.empty());
  // One temperature: no coefficient curves to draw (they are constants), the errors against time.
  const std::vector<PlotFigure> plots = CertificatePlots(c);
  ASSERT_EQ(plots.size(), 1u);
  ASSERT_EQ(plots[0].panels.size(), 5u);
  for (int p : {0, 1, 3, 4}) {
    EXPECT_EQ(plots[0].panels[p].x_label, "time, s") << plots[0].panels[p].title;
    EXPECT_EQ(plots[0].panels[p].series.at(0).x, c.residuals.time_s);
  }
  // The normalised errors are noise: the turns' accelerometer means are not in them.
  constexpr double kMostNormalisedRms = 3.0;
  EXPECT_LT(c.residuals.normalised_gyro_rms, kMostNormalisedRms);
  EXPECT_LT(c.residuals.normalised_accel_rms, kMostNormalisedRms);
  EXPECT_LT(c.residual_table.back().accel_rms_mg, 1.0);
}

// A run with minute-long static dwells: the certificate's noise section is the analysis `imufit
// allan` runs (ColumnAnalysis per gyro axis), drawn by the same plot module as `imufit allan --plot
// --plot-units deg/h`: tau as the Greek letter, deg/h, the ARW where it is read, the table's figures
// on the plot.
TEST_F(CertificateTest, TheNoiseSectionIsDrawnByTheAllanPlotModule) {
  const std::string plan_path = kFixtures + "/plan_6pos.yaml";
  const Plan plan = ReadPlan(plan_path);
  SimulationOptions options;
  options.soak_temps_c = {25.0};
  options.rate_hz = 20.0;
  options.dwell_s = 70.0;  // above kMinAllanStretchS
  options.transition_s = 1.0;
  options.gyro_noise_density = 8.7e-5;  // 0.299 deg/sqrt(h)
  options.accel_noise_density = 1.5e-3;
  options.seed = 5;
  const std::string samples = Simulate(plan, options, "static.csv");
  FitRunOptions fit_options;
  fit_options.fit.gyro_temp_order = fit_options.fit.accel_temp_order = 0;
  const FitRunResult fit = FitRun(plan_path, samples, fit_options);
  ASSERT_TRUE(fit.calibration.has_value()) << fit.fit.BriefReport();
  CertificateSources sources;
  sources.calibration = *fit.calibration;
  sources.plan = fit.plan;
  sources.run = fit.run;
  sources.inputs = {{"samples", samples, ""}};
  ReadCertificateFiles(&sources);
  const Certificate c = MakeCertificate(sources);
  ASSERT_TRUE(c.noise.computed) << c.noise.why_not;
  ASSERT_EQ(c.noise.columns.size(), 3u);
  ASSERT_EQ(c.noise.axes.size(), 3u);

  const std::vector<PlotFigure> plots = CertificatePlots(c);
  ASSERT_EQ(plots.size(), 2u);  // one temperature: the errors, then the Allan deviation
  const PlotFigure& allan = plots[1];
  const PlotFigure shared = AllanPlot(c.noise.columns, "", AllanPlotUnits::kDegPerHour);
  ASSERT_EQ(allan.panels.size(), 1u);
  ASSERT_EQ(shared.panels.size(), 1u);
  const Plot& panel = allan.panels[0];
  EXPECT_EQ(panel.x_label, "averaging time \xcf\x84 (s)");
  EXPECT_EQ(panel.y_label, "overlapping Allan deviation (\xc2\xb0/h)");
  ASSERT_EQ(panel.series.size(), shared.panels[0].series.size());
  for (size_t i = 0; i < panel.series.size(); ++i) {
    const std::vector<double>&ours = panel.series[i].y, &theirs = shared.panels[0].series[i].y;
    ASSERT_EQ(ours.size(), theirs.size()) << i;
    for (size_t k = 0; k < ours.size(); ++k) {
      // NaN: where a term is not drawn (a gap), in both.
      if (std::isnan(theirs[k])) {
        EXPECT_TRUE(std::isnan(ours[k])) << i << " " << k;
      } else {
        EXPECT_EQ(ours[k], theirs[k]) << i << " " << k;
      }
    }
  }
  // The measured curve of gyro_x in deg/h.
  ASSERT_FALSE(c.noise.columns[0].allan.points.empty());
  EXPECT_NEAR(panel.series[0].y[0], DphFromRadps(c.noise.columns[0].allan.points[0].dev),
              kConversionRelative * panel.series[0].y[0]);
  // Every resolved ARW is marked on the plot with the figure the table prints.
  constexpr double kArwRelative = 0.15;  // 70 s at 20 Hz fixes the white noise to a few percent
  for (size_t a = 0; a < 3; ++a) {
    const NoiseAxis& axis = c.noise.axes[a];
    ASSERT_TRUE(axis.arw_deg_per_sqrt_hr.resolved) << axis.axis;
    EXPECT_NEAR(axis.arw_deg_per_sqrt_hr.value, 0.299, kArwRelative * 0.299) << axis.axis;
    const std::string words =
        "gyro_" + axis.axis + " ARW " + FormatNumber("%.3g", axis.arw_deg_per_sqrt_hr.value);
    bool marked = false;
    for (const PlotNote& n : panel.notes) marked = marked || n.text.rfind(words, 0) == 0;
    EXPECT_TRUE(marked) << words;
  }
}

// The noise section streams the run: the stretch nearest 25 degC (of equally near ones the longer;
// a transition or a rate segment ends a stretch) is analysed exactly as `imufit allan` analyses the
// same rates held at once, and the section is the caller's to measure: MakeCertificate() takes it.
TEST_F(CertificateTest, TheNoiseSectionStreamsTheStretchNearest25C) {
  const Plan plan = ReadPlan(kFixtures + "/plan_6pos.yaml");  // 1..6 static, 7.. rates
  Calibration calibration;
  calibration.model = SensorModel::Identity();
  calibration.model.gyro[kScaleCoefficient * kPolynomialTerms] = 2.0;  // raw x = 2 * rate
  NoiseStretchFinder collector(plan);
  std::vector<double> expected_x;  // the longest stretch's rates, rad/s
  double t = 0.0;
  uint64_t state = 7;
  const auto noise = [&state] {  // a small deterministic generator (the values only need to differ)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
  };
  const auto feed = [&](int segment, int count, double temp_c, bool keep) {
    for (int i = 0; i < count; ++i, t += 1.0) {
      Sample s;
      s.time_s = t;
      s.temp_c = temp_c;
      s.segment = segment;
      s.gyro = Eigen::Vector3d(noise(), noise(), noise());
      if (keep) expected_x.push_back(s.gyro.x() / 2.0);
      collector.Add(s);
    }
  };
  feed(1, 50, 20.0, false);
  feed(2, 80, 30.0, true);  // the longest: 79 s
  feed(kTransitionSegment, 1, 30.0, false);
  feed(2, 80, 40.0, false);   // as long, later
  feed(7, 100, 40.0, false);  // a rate segment: no stretch
  const NoiseSection section = GyroNoise(calibration, collector.Finish());
  ASSERT_TRUE(section.computed) << section.why_not;
  EXPECT_EQ(section.segment, 2);
  EXPECT_EQ(section.duration_s, 79.0);
  EXPECT_EQ(section.temp_c, 30.0);
  ASSERT_EQ(section.columns.size(), 3u);
  std::vector<int64_t> factors;
  AveragingFactors(TauSpec(), AllanEstimator::kOadev, 80, 1.0, &factors);
  AllanOptions options;
  options.threads = 1;
  const ColumnAnalysis held = AnalyseColumn("gyro_x", ColumnKind::kGyro, expected_x, 1.0, factors, options);
  ASSERT_EQ(section.columns[0].allan.points.size(), held.allan.points.size());
  for (size_t i = 0; i < held.allan.points.size(); ++i) {
    EXPECT_EQ(section.columns[0].allan.points[i].dev, held.allan.points[i].dev) << i;  // bit for bit
  }

  // A samples file that cannot be read is said in the section, not thrown.
  const NoiseSection unreadable =
      MeasureGyroNoise(calibration, plan, (dir_ / "missing.csv").string(), SamplesInput(), std::nullopt);
  EXPECT_FALSE(unreadable.computed);
  EXPECT_NE(unreadable.why_not.find("missing.csv"), std::string::npos) << unreadable.why_not;
  // The section comes in with the sources: MakeCertificate() reads no file.
  const FitRunResult fit =
      FitRun(kFixtures + "/plan_6pos.yaml", kFixtures + "/mems_6pos_soak.csv.gz", FitRunOptions());
  ASSERT_TRUE(fit.calibration.has_value());
  CertificateSources sources;
  sources.calibration = *fit.calibration;
  sources.plan = fit.plan;
  sources.run = fit.run;
  sources.inputs = {{"samples", (dir_ / "missing.csv").string(), std::string(64, '0')}};
  sources.noise = section;
  const Certificate c = MakeCertificate(sources);
  EXPECT_EQ(c.noise.segment, 2);
  EXPECT_EQ(c.inputs[0].sha256, std::string(64, '0'));
}

// A plan of many segments (the 24-position tactical soak: 36 segments) prints the segments with
// the largest errors after correction, in segment order, then all; the struct keeps every row.
TEST_F(CertificateTest, ManySegmentsPrintTheWorstOnly) {
  const std::string plan_path = kFixtures + "/plan_24pos.yaml";
  const FitRunResult fit = FitRun(plan_path, kFixtures + "/tactical_24pos_soak.csv.gz", FitRunOptions());
  ASSERT_TRUE(fit.calibration.has_value()) << fit.fit.BriefReport();
  const Certificate c = CertificateOf(fit);
  const size_t segments = fit.plan.segments.size();
  ASSERT_GT(segments, static_cast<size_t>(kMostResidualRowsPrinted));
  ASSERT_EQ(c.residual_table.size(), segments + 1);
  ASSERT_EQ(c.residual_table_printed.size(), static_cast<size_t>(kMostResidualRowsPrinted));
  EXPECT_EQ(c.residual_rows_omitted, static_cast<int>(segments) - (kMostResidualRowsPrinted - 1));
  EXPECT_EQ(c.residual_table_printed.back().segment, -1);
  const ResidualRow& all = c.residual_table.back();
  const auto relative = [&](const ResidualRow& r) {
    return std::max(r.gyro_rms_dps / all.gyro_rms_dps, r.accel_rms_mg / all.accel_rms_mg);
  };
  double least_printed = 1e300;
  std::set<int> printed;
  for (size_t i = 0; i + 1 < c.residual_table_printed.size(); ++i) {
    const ResidualRow& r = c.residual_table_printed[i];
    if (i > 0) {
      EXPECT_LT(c.residual_table_printed[i - 1].segment, r.segment);  // in segment order
    }
    least_printed = std::min(least_printed, relative(r));
    printed.insert(r.segment);
  }
  for (size_t i = 0; i + 1 < c.residual_table.size(); ++i) {
    if (printed.count(c.residual_table[i].segment) == 0) {
      EXPECT_LE(relative(c.residual_table[i]), least_printed) << "segment " << c.residual_table[i].segment;
    }
  }
}

TEST_F(CertificateTest, ASegmentTheRunNeverVisitedIsAWarningAndFailsCoverage) {
  std::string plan = "";
  {
    std::ifstream in(kFixtures + "/plan_6pos.yaml");
    std::stringstream text;
    text << in.rdbuf();
    plan = text.str();
  }
  plan += "  - {id: 99, up: [0, 0, -1]}\n";
  const std::string plan_path = Write("plan.yaml", plan);
  const Certificate c = Make(plan_path, ReadLimits(Write("limits.yaml",
                                                         "format: imufit-limits\nversion: 1\ncriteria:\n"
                                                         "  - {quantity: coverage, max_abs: 1}\n")));
  bool warned = false;
  for (const std::string& w : c.warnings) warned = warned || w.find("plan segment 99") != std::string::npos;
  EXPECT_TRUE(warned);
  ASSERT_TRUE(c.verdict.has_value());
  EXPECT_FALSE(c.verdict->pass);
  EXPECT_EQ(c.verdict->criteria[0].name, "coverage");
  EXPECT_EQ(c.verdict->criteria[0].measured, 1.0);
}

// The settings name the plan's limiting coefficient (the limits' tolerances) predicted on the run's
// windows, next to what the fit achieved with its U, in one row of the page.
TEST_F(CertificateTest, TheSettingsNameThePlansLimitingCoefficient) {
  const Certificate c = Make(kFixtures + "/plan_6pos.yaml", ReadLimits(Write("limits.yaml", kLimits)));
  const LimitingPrediction& p = c.settings.limiting;
  std::printf("%s\n", LimitingPredictionText(p).c_str());
  ASSERT_EQ(p.why_not, "");
  EXPECT_GT(p.tolerance, 0.0);
  EXPECT_NEAR(p.achieved_sigma / p.predicted_sigma, 1.0, kPredictedSigmaTolerance);
  ASSERT_FALSE(p.figure.empty()) << "the limiting coefficient is a key figure with U";
  EXPECT_GE(p.achieved_expanded, kCoverageFactor * p.achieved_sigma);
  const Certificate without =
      CertificateOf(FitRun(kFixtures + "/plan_6pos.yaml", kFixtures + "/mems_6pos_soak.csv.gz", {}));
  EXPECT_EQ(without.settings.limiting.tolerance, 0.0);
  EXPECT_EQ(LimitingPredictionText(without.settings.limiting).rfind("no tolerances given", 0), 0u);
  if (!GnuplotAvailable()) GTEST_SKIP() << "no gnuplot on PATH: the page is not drawn";
  const std::string html = CertificateHtml(c);
  EXPECT_NE(html.find("limiting coefficient"), std::string::npos);
  EXPECT_NE(html.find(LimitingPredictionText(p)), std::string::npos);
}

// In a thermal run every soak has its static dwells: the noise is measured on the stretch nearest
// 25 degC (data sheets quote it there), not on the first long one (the -40 degC soak), streaming
// the simulated run sample by sample; the ARW read there is the simulated white noise.
TEST(NoiseStretchTest, AThermalRunIsMeasuredAtTheSoakNearest25C) {
  const Plan plan = ReadPlanText(
      "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
      "  - {id: 1, up: [0, 0, 1]}\n  - {id: 2, up: [0, 0, 1], rate_dps: 50}\n  - {id: 3, up: [1, 0, 0]}\n",
      "thermal.yaml");
  SimulationOptions sim;
  sim.soak_temps_c = {-40.0, 20.0, 29.0, 85.0};  // 29 degC is the nearest 25 (off by 4; 20 by 5)
  sim.dwell_s = 200.0;
  sim.gyro_noise_density = 2e-4;  // rad/s/sqrt(Hz)
  sim.seed = 5;
  const SensorModel truth = SensorModel::Identity();
  const auto run = [&](const NoiseStretchOptions& options) {
    NoiseStretchFinder finder(plan, options);
    SimulateRun(sim, plan.site, plan.segments, truth,
                [&](const Sample& raw, const SegmentTruth&) { finder.Add(raw); });
    return finder.Finish();
  };
  StaticStretch stretch = run(NoiseStretchOptions());
  EXPECT_EQ(stretch.segment, 1);  // of the two equally near and long, the first
  EXPECT_EQ(stretch.mean_temp_c(), 29.0);
  EXPECT_NE(stretch.chosen.find("of the 8 static stretches at least 60 s long, the one nearest 25 degC"),
            std::string::npos)
      << stretch.chosen;
  Calibration calibration;
  calibration.model = truth;
  const NoiseSection section = GyroNoise(calibration, std::move(stretch));
  ASSERT_TRUE(section.computed) << section.why_not;
  EXPECT_EQ(section.temp_c, 29.0);
  const double arw_true = DegPerSqrtHrFromRadPerSqrtS(sim.gyro_noise_density);
  constexpr double kArwSigmas = 3.0;  // the fit's own sigma, worst case of three axes
  ASSERT_EQ(section.axes.size(), 3u);
  for (const NoiseAxis& axis : section.axes) {
    ASSERT_TRUE(axis.arw_deg_per_sqrt_hr.resolved) << axis.axis;
    EXPECT_NEAR(axis.arw_deg_per_sqrt_hr.value, arw_true, kArwSigmas * axis.arw_deg_per_sqrt_hr.sigma)
        << axis.axis;
  }

  // A segment the user names: its longest stretch (the first of equally long ones: -40 degC).
  NoiseStretchOptions named;
  named.segment = 3;
  const StaticStretch third = run(named);
  EXPECT_EQ(third.segment, 3);
  EXPECT_EQ(third.mean_temp_c(), -40.0);
  EXPECT_TRUE(third.named);
  EXPECT_EQ(third.chosen, "segment 3 as named (--noise-segment), its longest of 4 stretches");
  // A rate segment, or one the plan does not have, is refused naming the plan.
  named.segment = 2;
  EXPECT_THROW(NoiseStretchFinder(plan, named), InputError);
  named.segment = 9;
  try {
    NoiseStretchFinder finder(plan, named);
    ADD_FAILURE() << "segment 9 accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "thermal.yaml: noise_segment: the plan has no segment 9 (--noise-segment)");
  }
  // The option is one entry of the fit's table: the command line and the Python keyword follow.
  const OptionEntry<FitRunOptions>* entry = FitRunOptionTable().Find("noise_segment");
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->flag, "--noise-segment");
  FitRunOptions options;
  EXPECT_EQ(options.Describe().find("noise_segment"), std::string::npos);  // not set: fingerprint unchanged
  options.noise_stretch.segment = 3;
  EXPECT_NE(options.Describe().find("noise_segment=3"), std::string::npos);
}

// A noise term the run does not resolve is given by what was estimated, its interval (estimate -+ 2
// sigma, clipped at 0) and the figure to quote (the upper bound, "at most"), never as "< 2 sigma";
// a resolved one as value +- sigma. The same words on the certificate's table and in imufit allan.
TEST(NoiseFigureTest, AnUnresolvedTermIsItsEstimateIntervalAndAtMost) {
  NoiseFitSummary fit;
  fit.fitted = true;
  fit.value[kBiasInstability] = 2.88 / DphFromRadps(1.0);  // rad/s
  fit.sigma[kBiasInstability] = 2.0 / DphFromRadps(1.0);
  fit.variance[kBiasInstability] = 1.0;  // within 2 of its 1.0 sigma: not resolved
  fit.variance_sigma[kBiasInstability] = 1.0;
  fit.value[kRandomWalk] = 0.3 / DegPerSqrtHrFromRadPerSqrtS(1.0);
  fit.sigma[kRandomWalk] = 0.012 / DegPerSqrtHrFromRadPerSqrtS(1.0);
  fit.variance[kRandomWalk] = 9.0;
  fit.variance_sigma[kRandomWalk] = 1.0;
  constexpr double kRounding = 1e-12;  // relative: the unit conversions' round trip
  const NoiseTermFigure bias = TermFigure(fit, kBiasInstability, DphFromRadps(1.0));
  EXPECT_FALSE(bias.resolved);
  EXPECT_NEAR(bias.value, 2.88, kRounding * 2.88);
  EXPECT_EQ(bias.lower(), 0.0);  // 2.88 - 4 clipped
  EXPECT_NEAR(bias.upper(), 6.88, kRounding * 6.88);
  EXPECT_EQ(bias.quoted(), bias.upper());
  EXPECT_EQ(TermFigureText(bias, "deg/h"),
            "at most 6.9 deg/h (not resolved: estimate 2.88 deg/h, interval 0 to 6.9 deg/h at 2 sigma)");
  const NoiseTermFigure arw = TermFigure(fit, kRandomWalk, DegPerSqrtHrFromRadPerSqrtS(1.0));
  EXPECT_TRUE(arw.resolved);
  EXPECT_EQ(arw.quoted(), arw.value);
  EXPECT_NEAR(arw.lower(), 0.276, 1e-12);
  EXPECT_EQ(TermFigureText(arw, "deg/sqrt(h)"), "0.300 +- 0.012 deg/sqrt(h)");
  // Large figures keep their digits (no exponent).
  NoiseTermFigure large;
  large.value = 1234.0;
  large.sigma = 5000.0;
  EXPECT_EQ(TermFigureText(large, ""),
            "at most 11234 (not resolved: estimate 1234, interval 0 to 11234 at 2 sigma)");

  // On the certificate: the noise figure judged by a limit says the same, and the table's cell.
  Certificate c;
  c.noise.computed = true;
  c.noise.duration_s = 200.0;
  NoiseAxis axis;
  axis.axis = "x";
  axis.fitted = true;
  axis.arw_deg_per_sqrt_hr = arw;
  axis.bias_instability_dph = bias;
  c.noise.axes.push_back(axis);
  const std::vector<Figure> measured = MeasuredFigures(c);  // FindFigure points into it
  const Figure* figure = FindFigure(measured, "gyro_bias_instability_dph.x");
  ASSERT_NE(figure, nullptr);
  EXPECT_NE(figure->unresolved.find("at most 6.9 deg/h (not resolved: estimate 2.88 deg/h"),
            std::string::npos)
      << figure->unresolved;
  const Figure* arw_figure = FindFigure(measured, "gyro_arw_deg_per_sqrt_hr.x");
  ASSERT_NE(arw_figure, nullptr);
  EXPECT_TRUE(arw_figure->unresolved.empty());
}

}  // namespace
}  // namespace imufit
