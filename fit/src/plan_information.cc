// The information of a planned run (plan_information.h): the fit's own set-up and Jacobian.
#include "imufit/fit/plan_information.h"

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "thermal_fit_state.h"

namespace imufit {
namespace {

// The fit's words for a direction it cannot see, turned into those for one it sees weakly.
std::string WeakWording(std::string finding) {
  const std::string cannot = "the run cannot separate";
  if (finding.rfind(cannot, 0) == 0) finding.replace(0, cannot.size(), "the plan hardly separates");
  const size_t paren = finding.find(" (a combination");
  if (paren != std::string::npos) finding.erase(paren);
  return finding + " (a combination of them hardly changes any residual)";
}

// One sensor's information from the problem set up and its Jacobian evaluated (CheckRank).
SensorInformation SensorInformationOf(const FitOptions& options, const internal::SensorProblem& sensor,
                                      const TemperatureBasis& basis, const std::vector<int>& time_blocks) {
  SensorInformation info;
  info.is_gyro = sensor.is_gyro;
  info.free = sensor.free;
  info.jacobian = sensor.jacobian;
  info.window_index = sensor.window_index;
  const Eigen::Matrix4d rebase = RebaseTemperaturePolynomial(basis, TemperatureBasis::Reference());
  const int n = static_cast<int>(sensor.free.size());
  info.to_reference = Eigen::MatrixXd::Zero(sensor.parameters, n);
  for (int j = 0; j < n; ++j) {
    const int parameter = sensor.free[j];
    const int first = parameter - parameter % kPolynomialTerms;
    info.to_reference.block(first, j, kPolynomialTerms, 1) =
        rebase.col(parameter % kPolynomialTerms) * sensor.step[parameter];
  }
  const Eigen::MatrixXd fisher = sensor.jacobian.transpose() * sensor.jacobian;
  info.covariance_white = fisher.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  info.covariance = info.covariance_white;
  const double stability =
      sensor.is_gyro ? options.gyro_bias_stability_radps : options.accel_bias_stability_mps2;
  if (stability > 0.0) {
    Eigen::MatrixXd ambient = Eigen::MatrixXd::Zero(sensor.parameters, sensor.parameters);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) ambient(sensor.free[i], sensor.free[j]) = info.covariance_white(i, j);
    }
    const Eigen::MatrixXd added = internal::BiasStabilityCovariance(sensor, ambient, time_blocks, stability);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) info.covariance(i, j) += added(sensor.free[i], sensor.free[j]);
    }
  }
  return info;
}

}  // namespace

PlanInformation ComputePlanInformation(const std::vector<Window>& windows, const TableSite& site,
                                       const std::vector<TableSegment>& segments, const FitOptions& options,
                                       double weak_tolerance) {
  PlanInformation result;
  FitSummary summary;
  internal::ThermalFitState fit;
  const bool set_up = internal::SetUpFit(windows, site, segments, options, &fit, &summary);
  if (!set_up || !internal::CheckRank(options, &fit, &summary)) {
    result.undetermined = summary.undetermined;
    return result;
  }
  FitOptions weak_options = options;
  weak_options.rank_tolerance = weak_tolerance;
  const std::vector<int> time_blocks = internal::TimeBlocks(fit.windows, options.bias_correlation_s);
  result.basis = fit.basis;
  for (const internal::SensorProblem* sensor : fit.Sensors()) {
    if (sensor->IsFullyHeld()) continue;
    for (const std::string& finding : internal::UndeterminedDirections(weak_options, *sensor)) {
      result.weak.push_back(WeakWording(finding));
    }
    (sensor->is_gyro ? result.gyro : result.accel) =
        SensorInformationOf(options, *sensor, fit.basis, time_blocks);
  }
  return result;
}

}  // namespace imufit
