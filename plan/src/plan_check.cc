// `imufit plan check` (plan_check.h): the planned windows, the fit's information and what it says.
#include "imufit/plan/plan_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

// Temperatures at which the largest sigma over a range is looked for.
constexpr int kRangeSamples = 41;
// A downdate leaving less than this of a direction's information removes it (the segment is essential).
constexpr double kEssentialPivot = 1e-9;
// Pairs shown, at most.
constexpr size_t kPairsShown = 5;
constexpr size_t kCarriersShown = 5;

std::string GroupOf(bool gyro, int coefficient) {
  return std::string(gyro ? "gyro." : "accel.") + kCoefficientNames[coefficient].group;
}

std::string TermName(int term) {
  return term == 0 ? "" : term == 1 ? " (linear term)" : term == 2 ? " (quadratic term)" : " (cubic term)";
}

// The row of p_ref (powers of dT) of coefficient c's value at `temp_c`, in q.
Eigen::RowVectorXd ValueRow(const SensorInformation& info, int coefficient, double temp_c) {
  const double dt = temp_c - kReferenceTempC;
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(info.to_reference.cols());
  double power = 1.0;
  for (int k = 0; k < kPolynomialTerms; ++k, power *= dt) {
    row += power * info.to_reference.row(coefficient * kPolynomialTerms + k);
  }
  return row;
}

double Sigma(const Eigen::RowVectorXd& row, const Eigen::MatrixXd& covariance) {
  return std::sqrt(std::max(0.0, (row * covariance * row.transpose())(0, 0)));
}

double LargestOver(const SensorInformation& info, int coefficient, std::array<double, 2> range,
                   const Eigen::MatrixXd& covariance) {
  double largest = 0.0;
  for (int i = 0; i < kRangeSamples; ++i) {
    const double t = range[0] + (range[1] - range[0]) * i / (kRangeSamples - 1.0);
    largest = std::max(largest, Sigma(ValueRow(info, coefficient, t), covariance));
  }
  return largest;
}

// The covariance without the rows of `segment` (Woodbury: C + C U^T (I - U C U^T)^-1 U C), or an
// empty matrix when the segment carries a direction nothing else does.
Eigen::MatrixXd WithoutSegment(const SensorInformation& info, const std::vector<Window>& windows,
                               int segment) {
  std::vector<int> rows;
  for (size_t w = 0; w < info.window_index.size(); ++w) {
    if (windows[info.window_index[w]].segment != segment) continue;
    for (int axis = 0; axis < 3; ++axis) rows.push_back(3 * static_cast<int>(w) + axis);
  }
  const Eigen::MatrixXd& c = info.covariance_white;
  if (rows.empty()) return c;
  Eigen::MatrixXd u(rows.size(), info.jacobian.cols());
  for (size_t r = 0; r < rows.size(); ++r) u.row(r) = info.jacobian.row(rows[r]);
  const Eigen::MatrixXd cu = c * u.transpose();
  const Eigen::MatrixXd pivot = Eigen::MatrixXd::Identity(u.rows(), u.rows()) - u * cu;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(pivot);
  if (eigen.eigenvalues().minCoeff() < kEssentialPivot) return Eigen::MatrixXd();
  return c + cu * pivot.ldlt().solve(cu.transpose());
}

struct RowRef {
  const SensorInformation* info;
  int coefficient;
  int term;
};

void AddRows(const SensorInformation& info, const PlanCheckOptions& options, std::array<double, 2> plan_range,
             std::array<double, 2> spec_range, std::vector<PlanRow>* rows, std::vector<RowRef>* refs) {
  if (info.jacobian.cols() == 0) return;
  const int coefficients = info.is_gyro ? kGyroCoefficients : kAccelCoefficients;
  for (int c = 0; c < coefficients; ++c) {
    const std::string group = GroupOf(info.is_gyro, c);
    const double factor = PlanGroupFactor(group);
    const auto tolerance = options.tolerances.find(group);
    for (int k = 0; k < kPolynomialTerms; ++k) {
      const Eigen::RowVectorXd a = info.to_reference.row(c * kPolynomialTerms + k);
      if (a.squaredNorm() == 0.0) continue;  // held
      PlanRow row;
      row.name = std::string(info.is_gyro ? "gyro " : "accel ") + kCoefficientNames[c].group + " " +
                 kCoefficientNames[c].axis + TermName(k);
      row.group = group;
      row.gyro = info.is_gyro;
      row.coefficient = c;
      row.term = k;
      row.unit = PlanGroupUnit(group) + (k == 0 ? "" : k == 1 ? "/degC" : "/degC^" + std::to_string(k));
      row.sigma = Sigma(a, info.covariance) * factor;
      const double white = Sigma(a, info.covariance_white) * factor;
      row.white_share = row.sigma > 0.0 ? std::min(1.0, white * white / (row.sigma * row.sigma)) : 1.0;
      row.sigma_range = k == 0 ? LargestOver(info, c, plan_range, info.covariance) * factor : row.sigma;
      row.sigma_spec = k == 0 ? LargestOver(info, c, spec_range, info.covariance) * factor : row.sigma;
      if (k == 0 && tolerance != options.tolerances.end()) {
        row.tolerance = tolerance->second;
        row.ratio = options.z * std::max(row.sigma_range, row.sigma_spec) / row.tolerance;
      }
      rows->push_back(row);
      refs->push_back(RowRef{&info, c, k});
    }
  }
}

// Every segment's effect on every sigma (white noise), the limiting row's carriers and the cuttable.
void SegmentEffects(const std::vector<TableSegment>& segments, const std::vector<Window>& windows,
                    const PlanInformation& info, const RowRef& limiting, const PlanCheckOptions& options,
                    PlanCheck* check) {
  const double infinite = std::numeric_limits<double>::infinity();
  for (const TableSegment& segment : segments) {
    PlanSegmentEffect effect{segment.id, 0.0, 0.0};
    for (const SensorInformation* sensor : {&info.gyro, &info.accel}) {
      if (sensor->jacobian.cols() == 0) continue;
      const Eigen::MatrixXd without = WithoutSegment(*sensor, windows, segment.id);
      for (int p = 0; p < sensor->to_reference.rows(); ++p) {
        const Eigen::RowVectorXd a = sensor->to_reference.row(p);
        const double before = Sigma(a, sensor->covariance_white);
        if (before <= 0.0) continue;
        const double loss = without.size() == 0 ? infinite : Sigma(a, without) / before - 1.0;
        effect.worst_loss = std::max(effect.worst_loss, loss);
        if (sensor == limiting.info && p == limiting.coefficient * kPolynomialTerms + limiting.term) {
          effect.limiting_loss = loss;
        }
      }
    }
    check->segments.push_back(effect);
    if (effect.worst_loss < options.cut_loss) check->cuttable.push_back(segment.id);
  }
  std::vector<PlanSegmentEffect> sorted = check->segments;
  std::stable_sort(sorted.begin(), sorted.end(), [](const PlanSegmentEffect& a, const PlanSegmentEffect& b) {
    return a.limiting_loss > b.limiting_loss;
  });
  for (const PlanSegmentEffect& e : sorted) {
    if (check->carriers.size() < kCarriersShown && e.limiting_loss >= options.cut_loss) {
      check->carriers.push_back(e.segment);
    }
  }
}

void CorrelatedPairs(const PlanInformation& info, PlanCheck* check) {
  for (const SensorInformation* sensor : {&info.gyro, &info.accel}) {
    if (sensor->jacobian.cols() == 0) continue;
    const int coefficients = sensor->is_gyro ? kGyroCoefficients : kAccelCoefficients;
    for (int a = 0; a < coefficients; ++a) {
      const Eigen::RowVectorXd ra = sensor->to_reference.row(a * kPolynomialTerms);
      for (int b = a + 1; b < coefficients; ++b) {
        const Eigen::RowVectorXd rb = sensor->to_reference.row(b * kPolynomialTerms);
        const double sa = Sigma(ra, sensor->covariance);
        const double sb = Sigma(rb, sensor->covariance);
        if (sa <= 0.0 || sb <= 0.0) continue;
        const double r = (ra * sensor->covariance * rb.transpose())(0, 0) / (sa * sb);
        const std::string prefix = sensor->is_gyro ? "gyro " : "accel ";
        check->correlated.push_back({prefix + kCoefficientNames[a].group + " " + kCoefficientNames[a].axis,
                                     prefix + kCoefficientNames[b].group + " " + kCoefficientNames[b].axis,
                                     r});
      }
    }
  }
  std::sort(check->correlated.begin(), check->correlated.end(),
            [](const PlanCheck::Pair& x, const PlanCheck::Pair& y) {
              return std::abs(x.correlation) > std::abs(y.correlation);
            });
  if (check->correlated.size() > kPairsShown) check->correlated.resize(kPairsShown);
}

// Hours the tolerances need (white noise: sigma^2 falls as 1/time) and where time cannot help.
void Hours(const SimulationOptions& schedule, size_t segment_count, const FitOptions& fit_options,
           PlanCheck* check) {
  check->plan_hours = static_cast<double>(schedule.SampleCount(segment_count)) / schedule.rate_hz / 3600.0;
  double worst = 0.0;
  for (const PlanRow& row : check->rows) {
    if (row.tolerance <= 0.0) continue;
    const double white = row.ratio * std::sqrt(row.white_share);
    const double wander = row.ratio * std::sqrt(1.0 - row.white_share);
    worst = std::max(worst, white * white);
    if (wander >= 1.0) {
      char text[300];
      std::snprintf(text, sizeof text,
                    "%s: the wandering bias alone gives %.3g of the tolerance; a longer dwell cannot help "
                    "(beyond the Allan minimum, about %.0f s): add repeats or soaks instead",
                    row.name.c_str(), wander, fit_options.bias_correlation_s);
      check->warnings.push_back(text);
    }
  }
  check->needed_hours = worst * check->plan_hours;
  const double dwell_needed = schedule.dwell_s * worst;
  if (worst > 1.0 && dwell_needed > fit_options.bias_correlation_s &&
      (fit_options.gyro_bias_stability_radps > 0.0 || fit_options.accel_bias_stability_mps2 > 0.0)) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "a dwell of %.0f s would be beyond the Allan minimum (about %.0f s): add repeats or soaks "
                  "instead of lengthening the dwell",
                  dwell_needed, fit_options.bias_correlation_s);
    check->warnings.push_back(text);
  }
}

// The mean information of a cubic in x at `xs`.
Eigen::Matrix4d CubicInformation(const std::vector<double>& xs) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  for (double x : xs) {
    const Eigen::Vector4d f(1.0, x, x * x, x * x * x);
    m += f * f.transpose();
  }
  return m / static_cast<double>(xs.size());
}

}  // namespace

double CubicDEfficiency(const std::vector<double>& temps_c, std::array<double, 2> range_c) {
  if (temps_c.empty() || !(range_c[1] > range_c[0])) return 0.0;
  const double centre = 0.5 * (range_c[0] + range_c[1]);
  const double half = 0.5 * (range_c[1] - range_c[0]);
  std::vector<double> xs;
  for (double t : temps_c) xs.push_back((t - centre) / half);
  const double a = 1.0 / std::sqrt(5.0);
  const double optimal = CubicInformation({-1.0, -a, a, 1.0}).determinant();
  return std::pow(std::max(0.0, CubicInformation(xs).determinant() / optimal), 0.25);
}

std::string PlanGroupUnit(const std::string& group) {
  if (group == "gyro.bias") return "deg/s";
  if (group == "accel.bias") return "mg";
  if (group == "gyro.scale" || group == "accel.scale") return "ppm";
  if (group == "gyro.misalignment" || group == "accel.misalignment") return "mrad";
  return "deg/s/g";  // gyro.g_sensitivity
}

double PlanGroupFactor(const std::string& group) {
  // The nominal unit's raw outputs are SI (scale 1): a scale's sigma is its relative sigma.
  if (group == "gyro.bias") return kRadToDeg;
  if (group == "accel.bias") return 1e3 / kStandardGravityMps2;
  if (group == "gyro.scale" || group == "accel.scale") return 1e6;
  if (group == "gyro.misalignment" || group == "accel.misalignment") return 1e3;
  return kRadToDeg * kStandardGravityMps2;
}

std::vector<Window> PlannedWindows(const std::vector<TableSegment>& segments, const TableSite& site,
                                   const SimulationOptions& schedule, const WindowOptions& window_options,
                                   WindowStats* stats) {
  // The run's time stamps, labels and temperatures as `imufit simulate` writes them (no noise, no
  // losses), cut by the fit's own WindowBuilder: the same windows, trims, splits on a ramp, merged
  // remainders and short occurrences left out as the fit will have. The outputs fed are zero (the
  // cuts do not depend on them; a constant output is no saturation where every window is alike).
  SimulationOptions timing = schedule;
  timing.gyro_noise_density = timing.accel_noise_density = 0.0;
  timing.gyro_random_walk = timing.accel_random_walk = 0.0;
  timing.gyro_bias_instability = timing.accel_bias_instability = 0.0;
  timing.temp_noise_c = timing.time_jitter_s = timing.drop_probability = 0.0;
  timing.quantize = false;
  timing.gyro_full_scale_raw = timing.accel_full_scale_raw = 0.0;
  WindowBuilder builder(window_options, segments);
  SimulateRun(timing, site, segments, SensorModel::Identity(),
              [&builder](const Sample& raw, const SegmentTruth&) {
                Sample labelled = raw;
                labelled.gyro.setZero();
                labelled.accel.setZero();
                builder.Add(labelled);
              });
  std::vector<Window> windows = builder.Finish();
  if (stats != nullptr) *stats = builder.stats();
  std::map<int, const TableSegment*> by_id;
  for (const TableSegment& segment : segments) by_id[segment.id] = &segment;
  const double interval = 1.0 / schedule.rate_hz;
  const Eigen::Vector3d gyro_noise =
      Eigen::Vector3d::Constant(schedule.gyro_noise_density / std::sqrt(interval));
  const Eigen::Vector3d accel_noise =
      Eigen::Vector3d::Constant(schedule.accel_noise_density / std::sqrt(interval));
  for (Window& w : windows) {
    // The nominal unit (raw = truth) on the schedule's exact grid, with its white noise.
    const TableSegment& segment = *by_id.at(w.segment);
    w.interval_s = interval;
    const SegmentTruth truth =
        segment.IsTurn() ? TurnTruth(site, segment, w.DurationS()) : TruthOf(site, segment);
    w.gyro_mean = truth.omega_radps;
    w.accel_mean = truth.a_mps2;
    w.gyro_std = w.gyro_noise = gyro_noise;
    w.accel_std = w.accel_noise = accel_noise;
  }
  return windows;
}

PlanCheck CheckWindows(const std::vector<Window>& windows, const std::vector<TableSegment>& segments,
                       const TableSite& site, const FitOptions& fit, const PlanCheckOptions& options) {
  const PlanInformation info = ComputePlanInformation(windows, site, segments, fit, options.weak_tolerance);
  PlanCheck check;
  check.undetermined = info.undetermined;
  if (!check.undetermined.empty()) return check;
  check.weak = info.weak;
  check.plan_range_c = {windows.front().temp_c, windows.front().temp_c};
  for (const Window& w : windows) {
    check.plan_range_c = {std::min(check.plan_range_c[0], w.temp_c),
                          std::max(check.plan_range_c[1], w.temp_c)};
  }
  const std::array<double, 2> spec = options.spec_range_c.value_or(check.plan_range_c);
  std::vector<RowRef> refs;
  AddRows(info.gyro, options, check.plan_range_c, spec, &check.rows, &refs);
  AddRows(info.accel, options, check.plan_range_c, spec, &check.rows, &refs);
  // The limiting row: the largest ratio; without tolerances the term-0 row that grows most outside.
  std::vector<size_t> order(check.rows.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const PlanRow& x = check.rows[a];
    const PlanRow& y = check.rows[b];
    if (x.ratio != y.ratio) return x.ratio > y.ratio;
    return (x.term == 0 ? x.sigma_spec / x.sigma : 0.0) > (y.term == 0 ? y.sigma_spec / y.sigma : 0.0);
  });
  std::vector<PlanRow> rows;
  for (size_t i : order) rows.push_back(check.rows[i]);
  check.rows = rows;
  check.tolerance_unmet = !rows.empty() && rows.front().ratio > 1.0;
  check.extrapolation_factor = 1.0;
  for (const PlanRow& row : rows) {
    if (row.term == 0 && row.sigma_range > 0.0) {
      check.extrapolation_factor = std::max(check.extrapolation_factor, row.sigma_spec / row.sigma_range);
    }
  }
  const double centre = 0.5 * (spec[0] + spec[1]);
  const double half = 0.5 * (spec[1] - spec[0]);
  check.best_soaks_c = {spec[0], centre - half / std::sqrt(5.0), centre + half / std::sqrt(5.0), spec[1]};
  std::vector<double> temps;
  for (const Window& w : windows) temps.push_back(w.temp_c);
  check.temperature_efficiency = CubicDEfficiency(temps, spec);
  if (!refs.empty()) {
    SegmentEffects(segments, windows, info, refs[order.front()], options, &check);
  }
  CorrelatedPairs(info, &check);
  return check;
}

PlanCheck CheckPlan(const std::vector<TableSegment>& segments, const TableSite& site,
                    const SimulationOptions& schedule, const FitOptions& fit_options,
                    const PlanCheckOptions& options) {
  FitOptions fit = fit_options;
  if (schedule.gyro_bias_instability > 0.0) fit.gyro_bias_stability_radps = schedule.gyro_bias_instability;
  if (schedule.accel_bias_instability > 0.0) fit.accel_bias_stability_mps2 = schedule.accel_bias_instability;
  fit.bias_correlation_s = schedule.bias_correlation_s;
  TableSite planned_site = site;
  if (options.latitude_deg) planned_site.latitude_rad = *options.latitude_deg * kDegToRad;
  WindowStats stats;
  const std::vector<Window> windows =
      PlannedWindows(segments, planned_site, schedule, options.windows, &stats);
  if (windows.empty()) {
    PlanCheck check;
    check.undetermined.push_back("the fit would have no window: " + LeftOutNote(stats, options.windows));
    return check;
  }
  PlanCheck check = CheckWindows(windows, segments, planned_site, fit, options);
  if (stats.short_samples + stats.saturated_samples + stats.gap_turn_samples > 0) {
    check.left_out = LeftOutNote(stats, options.windows);
  }
  for (const TableSegment& segment : segments) {
    if (segment.IsStatic()) check.longest_static_s = schedule.dwell_s;
  }
  if (check.undetermined.empty()) Hours(schedule, segments.size(), fit, &check);
  return check;
}

}  // namespace imufit
