// The rank backstop's analysis (thermal_fit_state.h): the directions of the fit's parameters the
// residuals do not see, from an SVD of the Jacobian, each named by its parameters. Apart from the
// solving stages (thermal_fit_solve.cc) because an SVD is most of what they took to compile. The
// SVD is Eigen's two-sided Jacobi on the R of a column-pivoting QR (the Jacobian is tall, at most 84
// columns): as exact as BDCSVD, and a third of its compile time, which kept this object near the
// build's 25 s limit.
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/SVD>

#include "thermal_fit_state.h"

namespace imufit::internal {
namespace {

// A direction of the Jacobian names the parameters whose share of it is at least this.
constexpr double kDirectionShare = 0.3;

// "gyro scale x (linear term)"
std::string ParameterName(const SensorProblem& sensor, int parameter) {
  const CoefficientName& name = kCoefficientNames[parameter / kPolynomialTerms];
  const int k = parameter % kPolynomialTerms;
  return std::string(sensor.name) + " " + name.group + " " + name.axis +
         (k == 0   ? ""
          : k == 1 ? " (linear term)"
          : k == 2 ? " (quadratic term)"
                   : " (cubic term)");
}

}  // namespace

// The directions of q the residuals do not see: right singular vectors of the column-normalised
// Jacobian (each column scaled to unit norm, so that units and steps do not decide the rank)
// whose singular value is below rank_tolerance times the largest, each named by the parameters
// that make it up.
std::vector<std::string> UndeterminedDirections(const FitOptions& options, const SensorProblem& sensor) {
  Eigen::MatrixXd jacobian = sensor.jacobian;
  const Eigen::VectorXd column_norm = jacobian.colwise().norm().transpose();
  for (int c = 0; c < jacobian.cols(); ++c) {
    if (column_norm(c) > 0.0) jacobian.col(c) /= column_norm(c);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd, Eigen::ColPivHouseholderQRPreconditioner> svd(jacobian,
                                                                                        Eigen::ComputeThinV);
  const Eigen::VectorXd& singular = svd.singularValues();
  std::vector<std::string> findings;
  for (int d = 0; d < singular.size(); ++d) {
    if (singular(d) > options.rank_tolerance * singular(0)) continue;
    const Eigen::VectorXd direction = svd.matrixV().col(d);
    std::string names;
    for (int c = 0; c < direction.size(); ++c) {
      if (std::abs(direction(c)) < kDirectionShare) continue;
      names += (names.empty() ? "" : ", ") + ParameterName(sensor, sensor.free[c]);
    }
    findings.push_back("the run cannot separate " + names +
                       " (a combination of them does not change any residual)");
  }
  return findings;
}

}  // namespace imufit::internal
