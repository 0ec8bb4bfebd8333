// A simulated lot of four units through the real batch: one passing, one failing (a gyro bias far
// outside its limit), one whose gyro bias lies within U of its limit (a conditional outcome under
// guarded acceptance) and one whose run is too short to resolve its noise. The certificates and the
// lot page state the uncertainty budget, the decision rule and each verdict with its reason, on the
// structs and on the printed pages (headless Chromium, rasterised by pdftoppm).
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/batch.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/io/calibration.h"
#include "imufit/io/limits.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/report/engineering_units.h"
#include "imufit/report/pdf.h"
#include "imufit/sim/simulator.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::ReadBytes;

const std::string kFixtures = IMUFIT_FIXTURES_DIR;

// Margin of the passing units' gyro bias X below its limit, deg/s: many times its U (~1e-3 deg/s).
constexpr double kClearMarginDps = 0.5;
// The failing unit's gyro bias X is this many limits.
constexpr double kFailingLimits = 3.0;
// A4 is 297 x 210 mm; pdftoppm rounds each side to whole pixels.
constexpr double kA4Ratio = 297.0 / 210.0;
constexpr double kPageRatioTolerance = 0.01;  // absolute
// A rasterised page with text compresses to far more than a blank one (about 1 kB at 30 dpi).
constexpr size_t kMinimumPrintedPagePngBytes = 2500;

double GyroBiasXDps(const SensorModel& model) {
  return EngineeringCoefficient(model, nullptr, Sensor::kGyro, kBiasCoefficient, kFigureTempC).value;
}

// `model` with its gyro bias X at 25 degC moved to `target_dps` (the constant term of the bias
// polynomial shifted: the bias changes by the same amount at every temperature).
SensorModel WithGyroBiasX(SensorModel model, double target_dps) {
  double* constant = model.gyro.data() + kBiasCoefficient * kPolynomialTerms;
  const double before = GyroBiasXDps(model);
  *constant += 1.0;
  const double per_raw = GyroBiasXDps(model) - before;
  *constant += (target_dps - before) / per_raw - 1.0;
  return model;
}

// Width and height of a PNG (its IHDR chunk: bytes 16..23, big-endian).
std::array<uint32_t, 2> PngSize(const std::string& png) {
  const auto word = [&png](size_t at) {
    return (static_cast<uint32_t>(static_cast<unsigned char>(png[at])) << 24) |
           (static_cast<uint32_t>(static_cast<unsigned char>(png[at + 1])) << 16) |
           (static_cast<uint32_t>(static_cast<unsigned char>(png[at + 2])) << 8) |
           static_cast<uint32_t>(static_cast<unsigned char>(png[at + 3]));
  };
  return {word(16), word(20)};
}

class CertificateLotTest : public testing::TempDirTest {
 protected:
  // Simulates a unit's run of the 6-position plan at four soaks into units/<unit>/samples.csv.gz.
  void Simulate(const std::string& unit, const SensorModel& truth, double dwell_s, uint64_t seed) {
    fs::create_directories(dir_ / "units" / unit);
    SimulationOptions sim;
    sim.soak_temps_c = {-20.0, 5.0, 30.0, 60.0};
    sim.rate_hz = 10.0;
    sim.dwell_s = dwell_s;
    sim.gyro_noise_density = 2e-4;  // rad/s/sqrt(Hz): 0.69 deg/sqrt(h)
    sim.accel_noise_density = 2e-3;
    sim.seed = seed;
    SamplesWriter samples(Path("units/" + unit + "/samples.csv.gz"), /*with_segment=*/true,
                          "serial: SN-" + unit);
    SimulateRun(sim, plan_.site, plan_.segments, truth,
                [&](const Sample& raw, const SegmentTruth&) { samples.Write(raw); });
    samples.Commit();
  }

  // The certificate of a unit the batch fitted, made as the batch made it.
  Certificate CertificateOf(const UnitOutcome& unit, const BatchOptions& options, const Limits& limits) {
    CertificateSources sources;
    sources.unit = unit.unit;
    sources.calibration = *unit.fit->calibration;
    sources.plan = unit.fit->plan;
    sources.run = unit.fit->run;
    sources.windows = options.fit.windows;
    sources.samples_input = options.fit.input;
    sources.limits = limits;
    sources.inputs = {{"plan", unit.plan_path, unit.plan_sha256},
                      {"samples", unit.samples_path, unit.samples_sha256}};
    sources.header = RunHeader();
    ReadCertificateFiles(&sources);
    return MakeCertificate(sources);
  }

  Plan plan_ = ReadPlan(kFixtures + "/plan_6pos.yaml");
};

const CriterionResult* Find(const Verdict& verdict, const std::string& title) {
  for (const CriterionResult& r : verdict.criteria) {
    if (r.title == title) return &r;
  }
  return nullptr;
}

TEST_F(CertificateLotTest, EveryVerdictItsReasonTheRuleAndTheBudgetOnStructsAndPrintedPages) {
  const SensorModel truth = ReadCalibration(kFixtures + "/mems_truth.yaml").model;
  const double bias_dps = GyroBiasXDps(truth);
  const double limit_dps = std::abs(bias_dps) + kClearMarginDps;
  const double sign = bias_dps < 0.0 ? -1.0 : 1.0;
  // A static dwell of 62 s gives the noise its minute; one of 3 s cannot.
  Simulate("unit-a", truth, 62.0, 1);
  Simulate("unit-b", WithGyroBiasX(truth, sign * kFailingLimits * limit_dps), 62.0, 2);
  Simulate("unit-c", WithGyroBiasX(truth, sign * limit_dps), 62.0, 3);  // on the limit: within U
  Simulate("unit-d", truth, 3.0, 4);
  const std::string limits_path =
      Write("limits.yaml",
            "format: imufit-limits\nversion: 1\nname: lot test acceptance\ncriteria:\n"
            "  - {quantity: gyro_bias_dps, max_abs: " +
                FormatDouble(limit_dps) +
                ", axes: [x]}\n"
                "  - {quantity: gyro_arw_deg_per_sqrt_hr, max_abs: 2, axes: [x]}\n"
                "decision_rule: guarded\n");
  const Limits limits = ReadLimits(limits_path);
  BatchOptions options;
  options.units_dir = Path("units");
  options.output_dir = Path("out");
  options.limits_path = limits_path;
  options.shared_plan = kFixtures + "/plan_6pos.yaml";
  const std::string pdf_problem = PdfProblem();
  options.write_pdf = pdf_problem.empty();
  const BatchResult batch = RunBatch(options);
  ASSERT_EQ(batch.units.size(), 4u);

  // Each verdict with its reason.
  const std::string bias_title = "Gyro bias X", arw_title = "Gyro angle random walk X";
  std::vector<Certificate> certificates;
  for (const UnitOutcome& unit : batch.units) {
    ASSERT_EQ(unit.status, UnitStatus::kFitted) << unit.unit << ": " << unit.message;
    certificates.push_back(CertificateOf(unit, options, limits));
  }
  const Verdict& a = *certificates[0].verdict;
  const Verdict& b = *certificates[1].verdict;
  const Verdict& c = *certificates[2].verdict;
  const Verdict& d = *certificates[3].verdict;
  EXPECT_TRUE(a.pass) << a.Table();
  EXPECT_EQ(batch.units[0].VerdictText(), std::string("PASS"));
  ASSERT_NE(Find(a, bias_title), nullptr) << a.Table();
  EXPECT_EQ(Find(a, bias_title)->outcome, Outcome::kPass);
  EXPECT_EQ(Find(a, arw_title)->outcome, Outcome::kPass) << a.Table();

  EXPECT_FALSE(b.pass);
  EXPECT_EQ(batch.units[1].VerdictText(), std::string("FAIL"));
  EXPECT_EQ(Find(b, bias_title)->outcome, Outcome::kFail);
  EXPECT_NE(batch.units[1].message.find("gyro_bias_dps.x"), std::string::npos) << batch.units[1].message;

  const CriterionResult& on_limit = *Find(c, bias_title);
  EXPECT_TRUE(on_limit.outcome == Outcome::kConditionalPass || on_limit.outcome == Outcome::kConditionalFail)
      << OutcomeName(on_limit.outcome) << " " << c.Table();
  EXPECT_LT(std::abs(on_limit.margin), on_limit.expanded);  // within U of the limit
  EXPECT_FALSE(on_limit.pass);                              // guarded: not accepted within the guard band
  EXPECT_NE(on_limit.reason.find("within U"), std::string::npos) << on_limit.reason;
  EXPECT_EQ(c.Conditional(), 1);

  const CriterionResult& unresolved = *Find(d, arw_title);
  EXPECT_FALSE(d.pass);
  EXPECT_EQ(unresolved.measured_text, "not resolved by this run");
  EXPECT_NE(unresolved.reason.find("needs a static stretch of 60 s"), std::string::npos) << unresolved.reason;
  EXPECT_EQ(Find(d, bias_title)->outcome, Outcome::kPass);
  EXPECT_FALSE(certificates[3].noise.computed);
  for (size_t u = 0; u < 3; ++u) {  // a noise measured near 25 degC: the 30 degC soak
    EXPECT_TRUE(certificates[u].noise.computed) << certificates[u].noise.why_not;
    EXPECT_NEAR(certificates[u].noise.temp_c, 30.0, 1e-9) << certificates[u].noise.chosen;
  }

  // The rule and the budget on every certificate.
  for (const Certificate& certificate : certificates) {
    EXPECT_EQ(certificate.verdict->rule, DecisionRule::kGuarded);
    EXPECT_NE(certificate.verdict->RuleText().find("guarded"), std::string::npos);
    EXPECT_FALSE(certificate.budget.covers.empty());
    EXPECT_FALSE(certificate.budget.not_covered.empty());
    ASSERT_NE(certificate.budget.Find("gyro_bias_dps.x"), nullptr);
  }

  // The lot page: every unit's verdict and reason, the conditional unit counted apart.
  const LotSummary lot = MakeLotSummary("lot", batch, "imufit test", limits);
  EXPECT_EQ(lot.units, 4);
  EXPECT_EQ(lot.passed, 1);
  EXPECT_EQ(lot.failed, 3);
  EXPECT_EQ(lot.conditional, 1);
  EXPECT_EQ(lot.decision_rule, certificates[0].verdict->RuleText());
  ASSERT_EQ(lot.rows.size(), 4u);
  for (size_t u = 1; u < 4; ++u) EXPECT_FALSE(lot.rows[u].message.empty()) << lot.rows[u].unit;
  EXPECT_NE(lot.rows[3].message.find("not resolved"), std::string::npos) << lot.rows[3].message;

  // The pages as written: the rule, the budget and the verdicts in words.
  for (const UnitOutcome& unit : batch.units) {
    const std::string html = ReadBytes(Path("out/" + unit.unit + "/report.html"));
    EXPECT_NE(html.find("guarded acceptance"), std::string::npos) << unit.unit;
    EXPECT_NE(html.find("Uncertainty budget"), std::string::npos) << unit.unit;
  }
  EXPECT_NE(ReadBytes(Path("out/unit-c/report.html")).find(OutcomeName(on_limit.outcome)), std::string::npos);
  EXPECT_NE(ReadBytes(Path("out/lot.html")).find("guarded acceptance"), std::string::npos);
  // A noise term the run does not resolve is given as "at most" its upper bound.
  EXPECT_NE(ReadBytes(Path("out/unit-a/report.html")).find("data-at-most"), std::string::npos);

  // The printed pages: one PNG per page, not blank, A4.
  if (!pdf_problem.empty()) GTEST_SKIP() << "no PDF printing here: " << pdf_problem;
  if (!fs::exists("/usr/bin/pdftoppm") || !fs::exists("/usr/bin/pdfinfo")) {
    GTEST_SKIP() << "no pdftoppm or pdfinfo (Debian: poppler-utils): the printed pages are not checked";
  }
  std::vector<std::string> pdfs = {Path("out/lot.pdf")};
  for (const UnitOutcome& unit : batch.units) pdfs.push_back(Path("out/" + unit.unit + "/report.pdf"));
  for (size_t i = 0; i < pdfs.size(); ++i) {
    const testing::RunResult info = RunProgram("/usr/bin/pdfinfo", {pdfs[i]});
    const size_t at = info.out.find("Pages:");
    ASSERT_NE(at, std::string::npos) << pdfs[i] << ": " << info.err;
    const int pages = std::stoi(info.out.substr(at + 6));
    EXPECT_GE(pages, 1) << pdfs[i];
    const std::string prefix = Path("page-" + std::to_string(i));
    ASSERT_EQ(RunProgram("/usr/bin/pdftoppm", {"-r", "30", "-png", pdfs[i], prefix}).status, 0) << pdfs[i];
    int pngs = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("page-" + std::to_string(i) + "-", 0) != 0) continue;
      ++pngs;
      const std::string png = ReadBytes(e.path().string());
      ASSERT_EQ(png.substr(1, 3), "PNG") << name;
      EXPECT_GT(png.size(), kMinimumPrintedPagePngBytes) << name;
      const std::array<uint32_t, 2> size = PngSize(png);
      EXPECT_NEAR(static_cast<double>(size[1]) / size[0], kA4Ratio, kPageRatioTolerance) << name;
    }
    EXPECT_EQ(pngs, pages) << pdfs[i];
  }
}

}  // namespace
}  // namespace imufit
