// Tests of one unit certified (factory/certify.h) as `imufit fit --limits --report --store` and each
// unit of `imufit batch` certify it: the samples file read at most twice (hashed while read, the
// segmentation and the static stretch handed on), the stretch handed on equal to the one read from
// the file, both software versions named on the certificate, the store row.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "file_open_counter.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/certify.h"
#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/pipeline/static_stretch.h"
#include "imufit/sim/simulator.h"
#include "imufit/store/store.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

const std::string kPlan = std::string(IMUFIT_FIXTURES_DIR) + "/plan_6pos.yaml";
const std::string kTruth = std::string(IMUFIT_FIXTURES_DIR) + "/mems_truth.yaml";

// `imufit fit` reads a file with a segment column once, one without twice (the first pass finds
// the segments): nothing else reads it again.
constexpr long long kReadsWithSegmentColumn = 1;
constexpr long long kReadsWithoutSegmentColumn = 2;

// The software that fits (written into the calibration) and the software that certifies: two
// names, so that the certificate is seen to tell them apart.
constexpr const char* kFittingSoftware = "imufit 9.8.7";
constexpr const char* kCertifyingSoftware = "imufit 1.2.3";

constexpr const char* kLimits = R"(format: imufit-limits
version: 1
name: certify test
nominal: {gyro_scale: 939.65, accel_scale: 208.838}
criteria:
  - {quantity: gyro_bias_dps, max_abs: 5}
)";

// The 6-position plan at one temperature with 70 s dwells (a static stretch long enough for the
// certificate's Allan deviation), written with or without the segment column (the parameter).
class CertifyTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("imufit_certify_test_" + std::to_string(::getpid()) + "_" + std::to_string(GetParam()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    plan_ = ReadPlan(kPlan);
    samples_ = Path(GetParam() ? "labelled.csv" : "unlabelled.csv");
    SimulationOptions simulation;
    simulation.soak_temps_c = {25.0};
    simulation.rate_hz = 20.0;
    simulation.dwell_s = 70.0;  // above kMinAllanStretchS
    simulation.transition_s = 1.0;
    simulation.gyro_noise_density = 8.7e-5;
    simulation.accel_noise_density = 1.5e-3;
    simulation.seed = 5;
    SamplesWriter writer(samples_, SampleColumns{GetParam(), true}, "serial: SN-CERT");
    SimulateRun(simulation, plan_.site, plan_.segments, ReadCalibration(kTruth).model,
                [&](const Sample& raw, const SegmentTruth&) { writer.Write(raw); });
    writer.Commit();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  long long Reads() const { return GetParam() ? kReadsWithSegmentColumn : kReadsWithoutSegmentColumn; }

  // The options `imufit fit --report` fits with (one temperature: orders 0).
  static FitRunOptions FitOptions() {
    FitRunOptions options;
    options.fit.gyro_temp_order = options.fit.accel_temp_order = 0;
    options.software = kFittingSoftware;
    options.keep_static_stretch = true;
    return options;
  }

  fs::path dir_;
  Plan plan_;
  std::string samples_;
};

TEST_P(CertifyTest, FitReportAndStoreReadTheSamplesAtMostTwice) {
  const std::string limits_path = Path("limits.yaml");
  std::ofstream(limits_path) << kLimits;
  const testing::FileOpenCounter reads(samples_);

  // What `imufit fit -p PLAN -s SAMPLES -o CAL --limits L --report R --store S` does.
  const FitRunOptions options = FitOptions();
  ResultsStore store(Path("store.db"));
  CertifySettings settings;
  settings.software = kCertifyingSoftware;
  settings.windows = options.windows;
  settings.samples_input = options.input;
  ReadLimitsAndStation(limits_path, "", &settings);
  settings.store = &store;
  UnitOutcome unit;
  unit.plan_path = kPlan;
  unit.samples_path = samples_;
  unit.fit = FitRun(kPlan, samples_, options);
  ASSERT_TRUE(unit.fit->calibration.has_value()) << unit.fit->fit.BriefReport();
  unit.serial = unit.fit->serial;
  unit.plan_sha256 = unit.fit->plan_sha256;
  unit.samples_sha256 = unit.fit->run.samples_sha256;
  ASSERT_TRUE(
      CertifyUnit(settings, {Path("calibration.yaml"), Path("report.html"), "", Paper::kA4, {}}, &unit))
      << unit.message;

  EXPECT_LE(reads.count(), 2) << "imufit fit --report --store reads the samples at most twice";
  EXPECT_EQ(reads.count(), Reads());

  // The hash made while reading is the file's; the calibration, the certificate and the store
  // record it.
  const std::string sha256 = Sha256OfFile(samples_);
  EXPECT_EQ(unit.samples_sha256, sha256);
  EXPECT_NE(unit.calibration_yaml.find("samples_sha256: " + sha256), std::string::npos);
  std::ifstream report_stream(Path("report.html"));
  std::stringstream report;
  report << report_stream.rdbuf();
  EXPECT_NE(report.str().find("data-sha256=\"samples\">" + sha256 + "<"), std::string::npos);
  const std::vector<StoredFit> rows = store.BySerial("SN-CERT");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].samples_sha256, sha256);
  EXPECT_EQ(rows[0].unit, samples_);
  EXPECT_EQ(rows[0].software, kCertifyingSoftware);
  EXPECT_EQ(rows[0].verdict, "PASS");
  EXPECT_EQ(rows[0].calibration_yaml, unit.calibration_yaml);

  // Committed together: the calibration file is the text recorded; the certificate names the
  // software that made the calibration and the software that made the certificate.
  std::ifstream calibration_stream(Path("calibration.yaml"));
  std::stringstream calibration;
  calibration << calibration_stream.rdbuf();
  EXPECT_EQ(calibration.str(), unit.calibration_yaml);
  EXPECT_NE(report.str().find(std::string("data-key=\"software\">") + kFittingSoftware + "<"),
            std::string::npos);
  EXPECT_NE(report.str().find(std::string("<td>") + kCertifyingSoftware + ", git "), std::string::npos);
  EXPECT_EQ(unit.VerdictText(), std::string("PASS"));
}

// The certificate measures the noise on the stretch the fit kept while it read the run: the same
// samples, and so the same figures, as reading the file again would give.
TEST_P(CertifyTest, TheStretchHandedOnIsTheOneInTheFile) {
  const FitRunResult fit = FitRun(kPlan, samples_, FitOptions());
  ASSERT_TRUE(fit.calibration.has_value()) << fit.fit.BriefReport();
  ASSERT_TRUE(fit.run.static_stretch.has_value());
  EXPECT_EQ(fit.run.segmentation.has_value(), !GetParam());
  const StaticStretch& kept = *fit.run.static_stretch;
  const StaticStretch read = ReadStaticStretch(fit.plan, samples_, SamplesInput(), fit.run.segmentation);
  EXPECT_GT(kept.duration_s(), kMinAllanStretchS);
  EXPECT_EQ(kept.segment, read.segment);
  EXPECT_EQ(kept.start_time_s, read.start_time_s);
  EXPECT_EQ(kept.end_time_s, read.end_time_s);
  EXPECT_EQ(kept.temp_sum_c, read.temp_sum_c);
  for (int axis = 0; axis < 3; ++axis) EXPECT_EQ(kept.gyro[axis], read.gyro[axis]) << axis;

  CertificateSources sources;
  sources.calibration = *fit.calibration;
  sources.plan = fit.plan;
  sources.run = fit.run;
  sources.inputs = {{"samples", samples_, fit.run.samples_sha256}};
  {
    const testing::FileOpenCounter reads(samples_);
    ReadCertificateFiles(&sources);
    EXPECT_EQ(reads.count(), 0) << "the stretch handed on: the file is not read";
  }
  const Certificate handed_on = MakeCertificate(sources);
  sources.run.static_stretch.reset();
  sources.noise.reset();
  const testing::FileOpenCounter reads(samples_);
  ReadCertificateFiles(&sources);
  EXPECT_EQ(reads.count(), 1) << "without the stretch, it is read";
  const Certificate read_again = MakeCertificate(sources);
  ASSERT_TRUE(handed_on.noise.computed) << handed_on.noise.why_not;
  EXPECT_EQ(handed_on.noise.segment, read_again.noise.segment);
  EXPECT_EQ(handed_on.noise.temp_c, read_again.noise.temp_c);
  ASSERT_EQ(handed_on.noise.axes.size(), read_again.noise.axes.size());
  for (size_t axis = 0; axis < handed_on.noise.axes.size(); ++axis) {
    EXPECT_EQ(handed_on.noise.axes[axis].arw_deg_per_sqrt_hr.value,
              read_again.noise.axes[axis].arw_deg_per_sqrt_hr.value);
    EXPECT_EQ(handed_on.noise.axes[axis].bias_instability_dph.value,
              read_again.noise.axes[axis].bias_instability_dph.value);
  }
}

// A run read into windows alone (imufit report, the benchmarks) is read as often, and its hash is
// the file's.
TEST_P(CertifyTest, ReadingARunHashesItOnTheWay) {
  const testing::FileOpenCounter reads(samples_);
  const RunWindows run = ReadRunWindows(plan_, samples_, WindowOptions());
  EXPECT_EQ(reads.count(), Reads());
  EXPECT_EQ(run.samples_sha256, Sha256OfFile(samples_));
  EXPECT_FALSE(run.static_stretch.has_value()) << "kept only when asked";
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutSegmentColumn, CertifyTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return std::string(info.param ? "Labelled" : "Unlabelled");
                         });

}  // namespace
}  // namespace imufit
