#include "imufit/run/label_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include <Eigen/Dense>

#include "imufit/base/text.h"
#include "imufit/model/constants.h"

namespace imufit {
namespace {

// The planned truths left must span the three axes: the smallest singular value of [truth / max|truth|, 1]
// over sqrt(rows) at least this.
constexpr double kMinSpread = 0.05;
// A measurement is "along" a planned vector within this angle, deg, and "of its size" within this fraction.
constexpr double kSameDirectionDeg = 15.0;
constexpr double kSameSize = 0.1;
// A gyro whose planned truths are all below this (a static-only plan: the Earth rate at most) is
// not checked, rad/s: the fit does not determine its scale either (the coverage check's 0.1 rad/s).
constexpr double kMinGyroTruthRadps = 0.1;
// More distinct temperatures than this are given as a range.
constexpr size_t kTemperaturesListed = 6;

// One window of one sensor: its truth (SI), raw mean and the noise of that mean.
struct Row {
  const Window* window = nullptr;
  const TableSegment* segment = nullptr;
  double x = 0.0;  // temperature, scaled to [-1, 1] over the sensor's windows
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  Eigen::Vector3d raw = Eigen::Vector3d::Zero();
  double sigma = 0.0;
};

struct Sensor {
  bool gyro = false;
  int terms = 1;
  std::vector<Row> rows;
  double max_truth = 0.0;
};

// raw = K(x) truth + V(x): coefficients (4 * terms) x 3, blocks truth x, y, z and 1, each `terms` powers of
// x.
struct Model {
  Eigen::MatrixXd coef;
  int terms = 1;
  Eigen::Matrix3d K(double x) const {
    Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
    for (int j = 0; j < 3; ++j) {
      double power = 1.0;
      for (int t = 0; t < terms; ++t, power *= x) k.col(j) += power * coef.row(j * terms + t).transpose();
    }
    return k;
  }
  Eigen::Vector3d V(double x) const {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double power = 1.0;
    for (int t = 0; t < terms; ++t, power *= x) v += power * coef.row(3 * terms + t).transpose();
    return v;
  }
  Eigen::Vector3d Predict(const Row& row) const { return K(row.x) * row.truth + V(row.x); }
  // The truth a raw mean stands for, SI.
  Eigen::Vector3d Measured(const Row& row) const { return K(row.x).inverse() * (row.raw - V(row.x)); }
};

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if (a.norm() == 0.0 || b.norm() == 0.0) return 180.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

std::string Vec(const Eigen::Vector3d& v, const char* format = "%+.2f") {
  return "(" + NumberText(format, v(0)) + ", " + NumberText(format, v(1)) + ", " + NumberText(format, v(2)) +
         ")";
}

Sensor Rows(const std::vector<Window>& windows, const TableSite& site,
            const std::vector<TableSegment>& segments, bool gyro, int order) {
  std::map<int, const TableSegment*> by_id;
  for (const TableSegment& segment : segments) by_id[segment.id] = &segment;
  Sensor sensor;
  sensor.gyro = gyro;
  sensor.terms = order + 1;
  for (const Window& w : windows) {
    const auto found = by_id.find(w.segment);
    if (found == by_id.end()) continue;
    const TableSegment& segment = *found->second;
    if (!gyro && (segment.IsTurn() || !segment.SpecificForceIsKnown())) continue;
    if (segment.IsTurn() && (!w.whole_occurrence || w.DurationS() <= 0.0)) continue;
    const SegmentTruth truth =
        segment.IsTurn() ? TurnTruth(site, segment, w.DurationS()) : TruthOf(site, segment);
    Row row;
    row.window = &w;
    row.segment = &segment;
    row.x = w.temp_c;
    row.truth = gyro ? truth.omega_radps : truth.a_mps2;
    row.raw = gyro ? w.gyro_mean : w.accel_mean;
    row.sigma = w.NoiseOfMean(gyro).norm();
    sensor.max_truth = std::max(sensor.max_truth, row.truth.norm());
    sensor.rows.push_back(row);
  }
  if (sensor.rows.empty()) return sensor;
  double lo = sensor.rows.front().x;
  double hi = lo;
  for (const Row& row : sensor.rows) {
    lo = std::min(lo, row.x);
    hi = std::max(hi, row.x);
  }
  for (Row& row : sensor.rows) row.x = hi > lo ? (2.0 * row.x - lo - hi) / (hi - lo) : 0.0;
  return sensor;
}

// Do the planned truths of the rows outside `excluded` determine K and V?
bool Determined(const Sensor& sensor, const std::set<int>& excluded) {
  if (sensor.max_truth <= 0.0) return false;
  std::vector<Eigen::Vector4d> rows;
  for (const Row& row : sensor.rows) {
    if (excluded.count(row.window->segment) != 0) continue;
    const Eigen::Vector3d truth = row.truth / sensor.max_truth;
    rows.emplace_back(truth(0), truth(1), truth(2), 1.0);
  }
  if (rows.size() < 4) return false;
  Eigen::MatrixXd design(rows.size(), 4);
  for (size_t r = 0; r < rows.size(); ++r) design.row(static_cast<long>(r)) = rows[r].transpose();
  const double smallest = Eigen::JacobiSVD<Eigen::MatrixXd>(design).singularValues()(3);
  return smallest / std::sqrt(static_cast<double>(rows.size())) >= kMinSpread;
}

Model FitModel(const Sensor& sensor, const std::set<int>& excluded) {
  const int n = 4 * sensor.terms;
  std::vector<const Row*> used;
  for (const Row& row : sensor.rows) {
    if (excluded.count(row.window->segment) == 0) used.push_back(&row);
  }
  Eigen::MatrixXd design(used.size(), n);
  Eigen::MatrixXd rhs(used.size(), 3);
  for (size_t r = 0; r < used.size(); ++r) {
    const Eigen::Vector4d regressor(used[r]->truth(0), used[r]->truth(1), used[r]->truth(2), 1.0);
    double power = 1.0;
    for (int t = 0; t < sensor.terms; ++t, power *= used[r]->x) {
      for (int b = 0; b < 4; ++b) design(static_cast<long>(r), b * sensor.terms + t) = regressor(b) * power;
    }
    rhs.row(static_cast<long>(r)) = used[r]->raw.transpose();
  }
  // Columns normalised; one that is zero (a single temperature) stays as it is and gets 0.
  const Eigen::VectorXd norm =
      design.colwise().norm().transpose().unaryExpr([](double v) { return v > 0.0 ? v : 1.0; });
  const Eigen::MatrixXd scaled = design * norm.cwiseInverse().asDiagonal();
  Model model;
  model.terms = sensor.terms;
  model.coef = norm.cwiseInverse().asDiagonal() * scaled.completeOrthogonalDecomposition().solve(rhs);
  return model;
}

// How far a row is beyond its tolerance (> 1: it disagrees).
double Excess(const Sensor& sensor, const Model& model, const Row& row) {
  const Eigen::Matrix3d k = model.K(row.x);
  const double tolerance = kLabelNoiseSigmas * row.sigma + kLabelSignalFraction * (k * row.truth).norm() +
                           kLabelRangeFraction * k.norm() / std::sqrt(3.0) * sensor.max_truth;
  return (row.raw - model.Predict(row)).norm() / tolerance;
}

// A disagreeing segment: what it measured (mean over its disagreeing windows) against its plan.
struct Finding {
  const TableSegment* segment = nullptr;
  bool gyro = false;
  Eigen::Vector3d measured = Eigen::Vector3d::Zero();
  Eigen::Vector3d planned = Eigen::Vector3d::Zero();
  double duration_s = 0.0;  // a turn's mean duration
  std::set<long> temps_c;   // rounded, where it disagrees
  std::set<long> all_temps_c;
};

std::vector<Finding> CheckSensor(const Sensor& sensor) {
  std::vector<Finding> findings;
  if (sensor.rows.empty() || !Determined(sensor, {})) return findings;
  if (sensor.gyro && sensor.max_truth < kMinGyroTruthRadps) return findings;
  std::set<int> excluded;
  Model model = FitModel(sensor, excluded);
  std::set<int> ids;
  for (const Row& row : sensor.rows) ids.insert(row.window->segment);
  while (excluded.size() < ids.size() / 2) {
    std::map<int, double> worst;
    for (const Row& row : sensor.rows) {
      if (excluded.count(row.window->segment) == 0)
        worst[row.window->segment] = std::max(worst[row.window->segment], Excess(sensor, model, row));
    }
    const auto it = std::max_element(worst.begin(), worst.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
    if (it == worst.end() || it->second <= 1.0) break;
    std::set<int> next = excluded;
    next.insert(it->first);
    if (!Determined(sensor, next)) break;
    excluded = next;
    model = FitModel(sensor, excluded);
  }
  std::map<int, Finding> by_id;
  std::map<int, int> counts;
  for (const Row& row : sensor.rows) {
    const long temp = std::lround(row.window->temp_c);
    Finding& finding = by_id[row.window->segment];
    finding.all_temps_c.insert(temp);
    if (Excess(sensor, model, row) <= 1.0) continue;
    finding.segment = row.segment;
    finding.gyro = sensor.gyro;
    finding.temps_c.insert(temp);
    finding.measured += model.Measured(row);
    finding.planned += row.truth;
    finding.duration_s += row.window->DurationS();
    ++counts[row.window->segment];
  }
  for (auto& [id, finding] : by_id) {
    if (finding.segment == nullptr) continue;
    const double n = counts[id];
    finding.measured /= n;
    finding.planned /= n;
    finding.duration_s /= n;
    findings.push_back(finding);
  }
  return findings;
}

bool Same(const Eigen::Vector3d& measured, const Eigen::Vector3d& planned) {
  return AngleDeg(measured, planned) <= kSameDirectionDeg &&
         std::abs(measured.norm() / planned.norm() - 1.0) <= kSameSize;
}

// What a finding measured against what was planned, in the plan's terms.
std::string Describe(const Finding& f) {
  const TableSegment& s = *f.segment;
  const std::string id = "segment " + std::to_string(s.id);
  if (!f.gyro) {
    return id + " (up " + Vec(s.up, "%+.0f") + ") measures gravity along " + Vec(f.measured.normalized()) +
           ", " + NumberText("%.0f", AngleDeg(f.measured, f.planned)) + " deg from its up";
  }
  const Eigen::Vector3d axis = s.RotationAxis();
  if (s.IsTurn()) {
    const double measured_deg = f.measured.dot(axis) * f.duration_s * kRadToDeg;
    return id + " (turn " + NumberText("%+.1f", *s.angle_rad * kRadToDeg) + " deg about " +
           Vec(axis, "%+.0f") + ") measures a turn of " +
           NumberText("%.1f", f.measured.norm() * f.duration_s * kRadToDeg) + " deg about " +
           Vec(f.measured.normalized()) + " (" + NumberText("%+.1f", measured_deg) + " deg about its axis)";
  }
  const std::string planned = s.IsStatic() ? "static"
                                           : "rate " + NumberText("%+.4g", s.rate_radps * kRadToDeg) +
                                                 " deg/s about " + Vec(axis, "%+.0f");
  return id + " (" + planned + ") measures " + NumberText("%.4g", f.measured.norm() * kRadToDeg) +
         " deg/s about " + Vec(f.measured.normalized()) + " (" +
         NumberText("%+.4g", f.measured.dot(axis) * kRadToDeg) + " deg/s about its axis)";
}

std::string Temperatures(const Finding& f) {
  const auto list = [](const std::set<long>& temps) {
    if (temps.size() > kTemperaturesListed)
      return std::to_string(*temps.begin()) + " .. " + std::to_string(*temps.rbegin());
    std::string text;
    for (long t : temps) text += (text.empty() ? "" : ", ") + std::to_string(t);
    return text;
  };
  if (f.temps_c == f.all_temps_c) return " at every temperature (" + list(f.temps_c) + " degC)";
  return " at " + list(f.temps_c) + " degC (of " + list(f.all_temps_c) + ")";
}

std::string Cause(const Finding& f, const std::vector<Finding>& all) {
  for (const Finding& other : all) {
    if (other.segment != f.segment && other.gyro == f.gyro && Same(f.measured, other.planned) &&
        Same(other.measured, f.planned)) {
      return "ids exchanged between segments " + std::to_string(std::min(f.segment->id, other.segment->id)) +
             " and " + std::to_string(std::max(f.segment->id, other.segment->id)) +
             " (in the plan or by the controller)?";
    }
  }
  if (Same(f.measured, -f.planned)) return "a lost sign?";
  const char* what = f.segment->IsTurn() ? "angle" : "rate";
  if (f.gyro && !f.segment->IsStatic() && AngleDeg(f.measured, f.planned) <= kSameDirectionDeg) {
    return std::string("a typo in the ") + what + "?";
  }
  return f.gyro ? "the table turned otherwise than the plan says?" : "the unit was in another position?";
}

}  // namespace

std::string CheckLabels(const std::vector<Window>& windows, const TableSite& site,
                        const std::vector<TableSegment>& segments, int gyro_temp_order,
                        int accel_temp_order) {
  std::vector<Finding> findings = CheckSensor(Rows(windows, site, segments, true, gyro_temp_order));
  const std::vector<Finding> accel = CheckSensor(Rows(windows, site, segments, false, accel_temp_order));
  // A segment that disagrees in both is described once, by its motion when it has one.
  for (const Finding& f : accel) {
    const bool described = std::any_of(findings.begin(), findings.end(), [&](const Finding& g) {
      return g.segment == f.segment && !f.segment->IsStatic();
    });
    if (!described) findings.push_back(f);
  }
  findings.erase(std::remove_if(findings.begin(), findings.end(),
                                [&](const Finding& f) {
                                  return f.gyro && f.segment->IsStatic() &&
                                         std::any_of(accel.begin(), accel.end(), [&](const Finding& a) {
                                           return a.segment == f.segment;
                                         });
                                }),
                 findings.end());
  std::string message;
  for (const Finding& f : findings) {
    const std::string cause = Cause(f, findings);
    const bool repeated = message.find(cause) != std::string::npos;
    message += (message.empty() ? "" : "; ") + Describe(f) + Temperatures(f) + (repeated ? "" : ": " + cause);
  }
  return message;
}

}  // namespace imufit
