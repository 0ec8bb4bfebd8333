// imufit — benchmark of `imufit fit --field` on issue 32's session: 10 minutes at 1 kHz by hand
// (60 rests of 8 s, hand-speed turns, MEMS noise), 600,000 samples.
//
// Figures (best of 3), each beside a yardstick measured here in the same run, so that the ratio
// says what a shared machine's load does not:
//   the fit (FitField, from samples in memory)      target < 1 s; ratio to one parse of its CSV
//   the poses' detection alone (FindFieldPoses)      its share of the fit
//   reading the session's CSV (SamplesReader)        the yardstick: what every fit pays anyway
// Measured, never asserted: this is not a test. It prints the 1-minute load average first.
//
// Usage: field_bench
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bench_timing.h"
#include "imufit/fit/field_fit.h"
#include "imufit/io/calibration.h"
#include "imufit/io/samples.h"
#include "imufit/sim/field_session.h"

using imufit::bench::BestSeconds;

int main() {
  using namespace imufit;
  double load[1] = {0.0};
  if (getloadavg(load, 1) == 1) {
    std::printf("load average (1 min): %.2f%s\n", load[0],
                load[0] > 1.0 ? "  (shared machine: ratios hold better than seconds)" : "");
  }
  SimulationOptions options;
  options.rate_hz = 1000.0;
  options.dwell_s = 8.0;
  options.gyro_noise_density = 2e-4;
  options.accel_noise_density = 1e-3;
  options.quantize = true;
  options.seed = 32;
  FieldSessionOptions session;
  session.poses = 60;
  const SensorModel truth = ReadCalibration(IMUFIT_FIXTURES_DIR "/mems_truth.yaml").model;
  std::vector<Sample> samples;
  SimulateFieldSession(options, session, truth,
                       [&](const Sample& raw, const SegmentTruth&) { samples.push_back(raw); });
  const double duration_s = samples.back().time_s - samples.front().time_s;
  const std::string csv = (std::filesystem::temp_directory_path() / "imufit_field_bench.csv").string();
  {
    SamplesWriter writer(csv, /*with_segment=*/false);
    for (const Sample& s : samples) writer.Write(s);
    writer.Commit();
  }
  std::printf("session: %zu samples, %.0f s at %.0f Hz, %zu MB of CSV\n", samples.size(), duration_s,
              options.rate_hz, static_cast<size_t>(std::filesystem::file_size(csv) >> 20));

  const double parse_s = BestSeconds(3, [&] {
    SamplesReader reader(csv, /*require_segment=*/false);
    Sample sample;
    size_t n = 0;
    while (reader.Next(&sample)) ++n;
    if (n != samples.size()) std::abort();
  });
  FieldFitSummary fit;
  const double fit_s = BestSeconds(3, [&] { fit = FitField(samples, FieldFitOptions{}); });
  const double poses_s = BestSeconds(3, [&] {
    std::vector<FieldPose> poses;
    std::vector<FieldTurn> turns;
    Eigen::Vector3d gyro_noise, accel_noise;
    FindFieldPoses(samples, FieldFitOptions{}, &poses, &turns, &gyro_noise, &accel_noise);
  });
  std::printf("fit: %s\n", fit.BriefReport().c_str());
  std::printf("%-34s %8.3f s   (target < 1 s)   %.2f x the CSV parse\n", "field fit (from memory)", fit_s,
              fit_s / parse_s);
  std::printf("%-34s %8.3f s   %.0f %% of the fit\n", "  of which the poses' detection", poses_s,
              100.0 * poses_s / fit_s);
  std::printf("%-34s %8.3f s   (yardstick)\n", "parse of the session's CSV", parse_s);
  std::filesystem::remove(csv);
  return fit.IsSolutionUsable() ? 0 : 1;
}
