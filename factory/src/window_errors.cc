// The errors of the windows before and after correction (Certificate::residuals, residual_table).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "certificate_sections.h"
#include "imufit/report/engineering_units.h"

namespace imufit::internal {
namespace {

constexpr double kHistogramHalfWidth = 5.0;  // normalised errors binned over [-5, 5]
constexpr int kHistogramBins = 20;

// "+z" for a body axis, else "[x, y, z]".
std::string DirectionText(const Eigen::Vector3d& v) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(std::abs(v(axis)) - 1.0) < 1e-12 && std::abs(v.norm() - 1.0) < 1e-12) {
      return std::string(v(axis) > 0 ? "+" : "-") + "xyz"[axis];
    }
  }
  char text[96];
  std::snprintf(text, sizeof text, "[%.3g, %.3g, %.3g]", v.x(), v.y(), v.z());
  return text;
}

// What the table did in a segment: "static", "+100 deg/s" (with " about +x" when the axis is not
// up), "turn 360 deg about +x".
std::string MotionText(const TableSegment& segment) {
  char text[64];
  if (segment.IsTurn()) {
    std::snprintf(text, sizeof text, "turn %g deg about ", *segment.angle_rad * kRadToDeg);
    return text + DirectionText(segment.RotationAxis());
  }
  if (segment.IsStatic()) return "static";
  std::snprintf(text, sizeof text, "%+g deg/s", DpsFromRadps(segment.rate_radps));
  return segment.axis && !segment.AxisIsVertical() ? text + (" about " + DirectionText(*segment.axis)) : text;
}

}  // namespace

SensorModel ScaleOnly(const Calibration& cal) {
  SensorModel scale_only = SensorModel::Identity();
  for (int axis = 0; axis < 3; ++axis) {
    const int c0 = (kScaleCoefficient + axis) * kPolynomialTerms;
    const double x = cal.model.basis.Argument(kFigureTempC);
    scale_only.gyro[c0] = EvaluateTemperaturePolynomial(cal.model.gyro.data() + c0, x);
    scale_only.accel[c0] = EvaluateTemperaturePolynomial(cal.model.accel.data() + c0, x);
  }
  return scale_only;
}

WindowResiduals Residuals(const Calibration& cal, const Plan& plan, const std::vector<Window>& windows,
                          const std::vector<WindowError>& after, const std::vector<WindowError>& before) {
  WindowResiduals r;
  std::vector<double> gyro_normalised, accel_normalised;
  for (size_t i = 0; i < after.size(); ++i) {
    const WindowError& e = after[i];
    const Window& w = windows[e.window];
    const TableSegment* segment = plan.Find(e.segment);
    r.time_s.push_back(0.5 * (w.start_s + w.end_s));
    r.temp_c.push_back(e.temp_c);
    r.segment.push_back(e.segment);
    r.is_static.push_back(segment != nullptr && segment->IsStatic());
    const Eigen::Vector3d gyro_noise_raw = w.NoiseOfMean(true), accel_noise_raw = w.NoiseOfMean(false);
    const double x = cal.model.basis.Argument(w.temp_c);
    for (int axis = 0; axis < 3; ++axis) {
      const double gyro_scale = EvaluateTemperaturePolynomial(
          cal.model.gyro.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
      const double accel_scale = EvaluateTemperaturePolynomial(
          cal.model.accel.data() + (kScaleCoefficient + axis) * kPolynomialTerms, x);
      const double gyro_noise = DpsFromRadps(gyro_noise_raw(axis) / std::abs(gyro_scale));
      const double accel_noise = MgFromMps2(accel_noise_raw(axis) / std::abs(accel_scale));
      r.gyro_dps[axis].push_back(DpsFromRadps(e.gyro_radps(axis)));
      r.gyro_before_dps[axis].push_back(DpsFromRadps(before[i].gyro_radps(axis)));
      r.gyro_noise_dps[axis].push_back(gyro_noise);
      const double unknown = std::numeric_limits<double>::quiet_NaN();
      r.accel_mg[axis].push_back(e.specific_force_known ? MgFromMps2(e.accel_mps2(axis)) : unknown);
      r.accel_before_mg[axis].push_back(e.specific_force_known ? MgFromMps2(before[i].accel_mps2(axis))
                                                               : unknown);
      r.accel_noise_mg[axis].push_back(accel_noise);
      if (gyro_noise > 0.0) gyro_normalised.push_back(r.gyro_dps[axis].back() / gyro_noise);
      if (accel_noise > 0.0 && e.specific_force_known)
        accel_normalised.push_back(r.accel_mg[axis].back() / accel_noise);
    }
  }
  const double bin = 2.0 * kHistogramHalfWidth / kHistogramBins;
  r.gyro_histogram.assign(kHistogramBins, 0.0);
  r.accel_histogram.assign(kHistogramBins, 0.0);
  for (int b = 0; b < kHistogramBins; ++b)
    r.histogram_center.push_back(-kHistogramHalfWidth + (b + 0.5) * bin);
  const auto fill = [&](const std::vector<double>& values, std::vector<double>* counts, double* rms) {
    double sum = 0.0;
    for (double v : values) {
      sum += v * v;
      const int b = static_cast<int>(std::floor(
          (std::clamp(v, -kHistogramHalfWidth, kHistogramHalfWidth - 1e-9) + kHistogramHalfWidth) / bin));
      (*counts)[std::clamp(b, 0, kHistogramBins - 1)] += 1.0;
    }
    *rms = values.empty() ? 0.0 : std::sqrt(sum / values.size());
  };
  fill(gyro_normalised, &r.gyro_histogram, &r.normalised_gyro_rms);
  fill(accel_normalised, &r.accel_histogram, &r.normalised_accel_rms);
  return r;
}

std::vector<ResidualRow> ResidualTable(const Plan& plan, const std::vector<WindowError>& after,
                                       const std::vector<WindowError>& before) {
  std::vector<ErrorStats> stats = ErrorsBySegment(after);
  stats.push_back(SummariseErrors(after));
  std::vector<ErrorStats> stats_before = ErrorsBySegment(before);
  stats_before.push_back(SummariseErrors(before));
  std::vector<ResidualRow> rows;
  for (size_t i = 0; i < stats.size(); ++i) {
    const ErrorStats& s = stats[i];
    const ErrorStats& b = stats_before[i];  // the same segments, in the same order
    ResidualRow row;
    row.segment = s.segment;
    if (const TableSegment* seg = s.segment < 0 ? nullptr : plan.Find(s.segment)) {
      row.up = DirectionText(seg->up);
      row.rate_dps = DpsFromRadps(seg->rate_radps);
      row.motion = MotionText(*seg);
    }
    row.windows = s.windows;
    row.accel_windows = s.accel_windows;
    row.gyro_rms_before_dps = DpsFromRadps(b.gyro_rms_radps);
    row.gyro_rms_dps = DpsFromRadps(s.gyro_rms_radps);
    row.gyro_max_dps = DpsFromRadps(s.gyro_max_radps);
    row.accel_rms_before_mg = MgFromMps2(b.accel_rms_mps2);
    row.accel_rms_mg = MgFromMps2(s.accel_rms_mps2);
    row.accel_max_mg = MgFromMps2(s.accel_max_mps2);
    rows.push_back(row);
  }
  return rows;
}

// The rows the certificate prints (Certificate::residual_table_printed).
std::vector<ResidualRow> PrintedResidualRows(const std::vector<ResidualRow>& table, int* omitted) {
  *omitted = 0;
  const int segments = static_cast<int>(table.size()) - 1;  // the last row is "all"
  if (segments <= kMostResidualRowsPrinted) return table;
  const ResidualRow& all = table.back();
  const auto relative = [&](const ResidualRow& r) {
    return std::max(all.gyro_rms_dps > 0.0 ? r.gyro_rms_dps / all.gyro_rms_dps : 0.0,
                    all.accel_rms_mg > 0.0 ? r.accel_rms_mg / all.accel_rms_mg : 0.0);
  };
  std::vector<size_t> order(segments);
  for (int i = 0; i < segments; ++i) order[i] = i;
  const int kept = kMostResidualRowsPrinted - 1;
  std::partial_sort(order.begin(), order.begin() + kept, order.end(),
                    [&](size_t a, size_t b) { return relative(table[a]) > relative(table[b]); });
  order.resize(kept);
  std::sort(order.begin(), order.end());
  std::vector<ResidualRow> rows;
  for (size_t i : order) rows.push_back(table[i]);
  rows.push_back(all);
  *omitted = segments - kept;
  return rows;
}

}  // namespace imufit::internal
