// The thermal fit: its options, FitThermalModel() as its stages in order (thermal_fit_state.h
// lists them and where each lives) and its reports.
#include "imufit/fit/thermal_fit.h"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "coverage.h"
#include "imufit/model/check.h"
#include "imufit/model/constants.h"
#include "thermal_fit_state.h"

namespace imufit {
namespace {}  // namespace

namespace internal {

void MarkUndetermined(FitSummary* summary) {
  summary->status = FitStatus::kUndetermined;
  summary->termination = "the run does not determine the model";
}

namespace {

constexpr char kAxis[] = "xyz";

// Stage: options and basis. The distinct temperatures, the range of the readings (the
// calibration's fit_temp_range_c) and the fit basis x = (T - centre) / half range over the
// windows' mean temperatures, so that x is about [-1, 1] and the powers of x up to 3 are well
// conditioned (the half range is at least 1 degC, for a run at one temperature).
void ChooseBasis(const std::vector<Window>& windows, const FitOptions& options, ThermalFitState* fit,
                 FitSummary* summary) {
  std::vector<double> temps;
  for (const Window& w : windows) temps.push_back(w.temp_c);
  summary->distinct_temps_c = DistinctTemperatures(temps, options.distinct_temp_c);
  if (temps.empty()) return;
  const auto [lo, hi] = std::minmax_element(temps.begin(), temps.end());
  summary->temp_range_c = {windows.front().min_temp_c, windows.front().max_temp_c};
  for (const Window& w : windows) {
    summary->temp_range_c[0] = std::min(summary->temp_range_c[0], w.min_temp_c);
    summary->temp_range_c[1] = std::max(summary->temp_range_c[1], w.max_temp_c);
  }
  fit->basis.center_c = 0.5 * (*lo + *hi);
  fit->basis.half_range_c = std::max(0.5 * (*hi - *lo), 1.0);
}

// Stage: truth. Each window with its segment's truth (model/rate_table.h: Earth rate, gravity,
// lever arm) and its temperature in the fit basis. A turn's truth is its whole occurrence's mean
// rate, so its window must be that occurrence: windows built without the plan would bias the fit.
void AttachTruth(const std::vector<Window>& windows, const TableSite& site,
                 const std::vector<TableSegment>& segments, ThermalFitState* fit, FitSummary* summary) {
  for (const Window& w : windows) {
    const auto segment = std::find_if(segments.begin(), segments.end(),
                                      [&](const TableSegment& s) { return s.id == w.segment; });
    IMUFIT_CHECK(segment != segments.end(), "every window's segment must be in the plan");
    IMUFIT_CHECK(!segment->IsTurn() || w.whole_occurrence,
                 "a window of a turn segment must be its whole occurrence");
    const SegmentTruth truth =
        segment->IsTurn() ? TurnTruth(site, *segment, w.DurationS()) : TruthOf(site, *segment);
    fit->windows.push_back(
        FitWindow{&w, truth, fit->basis.Argument(w.temp_c), segment->SpecificForceIsKnown()});
  }
  summary->windows_used = static_cast<int>(fit->windows.size());
}

// Stage: coverage. Before any solve, each coefficient group the options fit is checked against
// what the run excites (coverage.h: rates about each axis, gravity along +-each axis, distinct
// temperatures for the order), so that a run that cannot determine the model is refused with
// findings that say what data would determine it, not with a rank-deficient solve.
bool CheckRunCoverage(const TableSite& site, const FitOptions& options, const ThermalFitState& fit,
                      FitSummary* summary) {
  summary->undetermined = CheckCoverage(fit.windows, site.gravity_mps2, options);
  if (summary->undetermined.empty()) return true;
  MarkUndetermined(summary);
  return false;
}

// Stage: sign refusal. A negative scale factor corrects every reading of its axis with the wrong
// sign: the unit's (or the plan's) sign convention is the opposite of the body frame's. The fit
// converged, but its model is refused by name, with the convention to check, wherever a scale's
// polynomial is not positive over the run's temperatures.
bool RefuseNegativeScales(FitSummary* summary) {
  for (const bool is_gyro : {true, false}) {
    const double* params = is_gyro ? summary->model.gyro.data() : summary->model.accel.data();
    for (int axis = 0; axis < 3; ++axis) {
      const double* c = params + (kScaleCoefficient + axis) * kPolynomialTerms;
      const PolynomialExtremes e = ExtremesOverRange(c, summary->model.basis.center_c,
                                                     summary->temp_range_c[0], summary->temp_range_c[1]);
      if (e.min_value > 0.0) continue;
      char text[200];
      std::snprintf(text, sizeof text, "%s scale %c %s over the run's temperatures (%.6g at %.4g degC)",
                    is_gyro ? "gyro" : "accel", kAxis[axis],
                    e.max_value < 0.0 ? "is negative" : "changes sign", e.min_value, e.min_at_c);
      summary->refusals.push_back(std::string(text) + "; " + ScaleSignAdvice(is_gyro, axis));
    }
  }
  if (summary->refusals.empty()) return true;
  summary->status = FitStatus::kRefused;
  summary->termination = "a scale factor is negative or changes sign";
  return false;
}

}  // namespace

bool SetUpFit(const std::vector<Window>& windows, const TableSite& site,
              const std::vector<TableSegment>& segments, const FitOptions& options, ThermalFitState* fit,
              FitSummary* summary) {
  ChooseBasis(windows, options, fit, summary);
  AttachTruth(windows, site, segments, fit, summary);
  if (!CheckRunCoverage(site, options, *fit, summary)) return false;
  StartSensors(options, fit);
  BuildProblem(fit);
  return true;
}

}  // namespace internal

using internal::CheckConvergence;
using internal::CheckRank;
using internal::ComputeCovariance;
using internal::ComputeResiduals;
using internal::RefuseNegativeScales;
using internal::RobustPass;
using internal::SolveLeastSquares;
using internal::ThermalFitState;

std::vector<double> DistinctTemperatures(std::vector<double> temps_c, double span_c) {
  std::sort(temps_c.begin(), temps_c.end());
  std::vector<double> centres;
  size_t begin = 0;
  for (size_t i = 1; i <= temps_c.size(); ++i) {
    if (i == temps_c.size() || temps_c[i] > temps_c[begin] + span_c) {
      if (i > begin) {
        centres.push_back(std::accumulate(temps_c.begin() + begin, temps_c.begin() + i, 0.0) /
                          static_cast<double>(i - begin));
      }
      begin = i;
    }
  }
  return centres;
}

// The stages in order (thermal_fit_state.h); each that can end the fit says so by returning false,
// with the summary's status and termination set.
FitSummary FitThermalModel(const std::vector<Window>& windows, const TableSite& site,
                           const std::vector<TableSegment>& segments, const FitOptions& options) {
  const std::string invalid_options = options.Validate();
  IMUFIT_CHECK(invalid_options.empty(), invalid_options.c_str());
  FitSummary summary;
  summary.gyro_fit = options.gyro_fit;
  summary.accel_fit = options.accel_fit;
  ThermalFitState fit;  // what the stages share; fresh for every fit

  if (!internal::SetUpFit(windows, site, segments, options, &fit, &summary)) return summary;
  ceres::Solver::Summary last_pass = SolveLeastSquares(options, &fit, &summary);
  if (options.loss != RobustLoss::kNone && last_pass.termination_type == ceres::CONVERGENCE) {
    last_pass = RobustPass(options, &fit, &summary);
  }
  if (!CheckConvergence(last_pass, &summary)) return summary;
  if (!CheckRank(options, &fit, &summary)) return summary;
  ComputeResiduals(options, fit, &summary);
  if (!ComputeCovariance(options, &fit, &summary)) return summary;
  if (!RefuseNegativeScales(&summary)) return summary;
  summary.status = FitStatus::kConverged;
  return summary;
}

std::string FitSummary::BriefReport() const {
  char text[512];
  switch (status) {
    case FitStatus::kNotRun:
      return "fit not run";
    case FitStatus::kUndetermined:
      std::snprintf(text, sizeof text, "fit refused: the run does not determine the model (%zu finding%s)",
                    undetermined.size(), undetermined.size() == 1 ? "" : "s");
      return text;
    case FitStatus::kNotConverged:
      return "fit did not converge: " + termination;
    case FitStatus::kRefused: {
      std::string text = "fit refused: ";
      for (size_t i = 0; i < refusals.size(); ++i) text += (i ? "; and " : "") + refusals[i];
      return text;
    }
    case FitStatus::kConverged:
      break;
  }
  // A sensor held whole was not fitted: its residual says how far the held values are from the run.
  const char* gyro_note = gyro_fit == SensorFit::kNone ? " (gyro held, not fitted)" : "";
  const char* accel_note = accel_fit == SensorFit::kNone ? " (accel held, not fitted)" : "";
  std::snprintf(text, sizeof text,
                "converged in %d iterations; residual RMS gyro %.3g deg/s%s, accel %.3g mg%s; %d windows (%d "
                "down-weighted) over %zu temperatures",
                iterations, gyro_rms_radps * kRadToDeg, gyro_note,
                accel_rms_mps2 / kStandardGravityMps2 * 1e3, accel_note, windows_used, windows_downweighted,
                distinct_temps_c.size());
  return text;
}

std::string FitSummary::FullReport() const {
  std::string report = BriefReport() + "\n";
  char line[512];
  std::snprintf(line, sizeof line, "  windows: %d used, %d down-weighted by the robust loss\n", windows_used,
                windows_downweighted);
  report += line;
  report += "  temperatures: " + std::to_string(distinct_temps_c.size()) + " distinct (" +
            internal::FormatTemperatures(distinct_temps_c) + ")\n";
  if (status == FitStatus::kConverged) {
    std::snprintf(line, sizeof line, "  reduced chi-square: gyro %.3g, accel %.3g (covariance scale)\n",
                  gyro_reduced_chi2, accel_reduced_chi2);
    report += line;
  }
  for (const std::string& finding : undetermined) report += "  undetermined: " + finding + "\n";
  report += "  termination: " + termination + "\n";
  return report;
}

}  // namespace imufit
