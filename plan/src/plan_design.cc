// `imufit plan design` (plan_design.h): greedy selection by information per second, then exchange.
#include "imufit/plan/plan_design.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

// A pivot of the data's information below this fraction of the largest: a direction it does not
// determine (without the prior).
constexpr double kSingularPivot = 1e-12;
// Temperatures over the range at which the toleranced values are looked at.
constexpr int kDesignTemps = 9;
// Each time the checked design still misses, the white-noise target tightens by this factor.
constexpr double kTargetStep = 0.9;
constexpr int kTargetSteps = 12;
// Set-points within this are one.
constexpr double kSameSetPointC = 0.01;

// One sensor's share: the information of every element, the prior, and the toleranced rows.
struct SensorTerms {
  int n = 0;
  std::vector<Eigen::MatrixXd> element;  // [segment * soaks + soak]
  Eigen::MatrixXd prior;
  Eigen::MatrixXd rows;  // z * factor / tolerance * the value row, at kDesignTemps temperatures
};

struct Problem {
  int segments = 0;
  int soaks = 0;
  std::vector<SensorTerms> sensors;
  double segment_cost_s = 0.0;  // at one soak
  double soak_cost_s = 0.0;     // settling alone
};

struct Selection {
  std::vector<bool> segment, soak;
  std::vector<Eigen::MatrixXd> data;  // per sensor, without the prior
};

Eigen::MatrixXd ElementSum(const Problem& p, const Selection& s, int sensor, int segment, int soak) {
  const SensorTerms& terms = p.sensors[sensor];
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(terms.n, terms.n);
  for (int i = 0; i < p.segments; ++i) {
    for (int t = 0; t < p.soaks; ++t) {
      const bool here = segment >= 0 ? (i == segment && s.soak[t]) : (t == soak && s.segment[i]);
      if (here) sum += terms.element[i * p.soaks + t];
    }
  }
  return sum;
}

// phi with the prior (always finite), or the largest ratio without it (inf where undetermined).
double Phi(const Problem& p, const std::vector<Eigen::MatrixXd>& data) {
  double phi = 0.0;
  for (size_t k = 0; k < p.sensors.size(); ++k) {
    const SensorTerms& terms = p.sensors[k];
    if (terms.rows.rows() == 0) continue;
    const Eigen::MatrixXd x = (terms.prior + data[k]).ldlt().solve(terms.rows.transpose());
    phi += (terms.rows.array() * x.transpose().array()).sum();
  }
  return phi;
}

double LargestRatio(const Problem& p, const std::vector<Eigen::MatrixXd>& data) {
  double largest = 0.0;
  for (size_t k = 0; k < p.sensors.size(); ++k) {
    const SensorTerms& terms = p.sensors[k];
    if (terms.rows.rows() == 0) continue;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(data[k]);
    const Eigen::VectorXd d = ldlt.vectorD();
    if (d.size() == 0 || !(d.minCoeff() > kSingularPivot * d.maxCoeff())) {
      return std::numeric_limits<double>::infinity();
    }
    const Eigen::MatrixXd x = ldlt.solve(terms.rows.transpose());
    largest = std::max(largest, (terms.rows.array() * x.transpose().array()).rowwise().sum().maxCoeff());
  }
  return std::sqrt(largest);
}

double Cost(const Problem& p, const Selection& s) {
  const auto count = [](const std::vector<bool>& v) {
    return static_cast<double>(std::count(v.begin(), v.end(), true));
  };
  const double soaks = count(s.soak);
  return soaks * p.soak_cost_s + soaks * count(s.segment) * p.segment_cost_s;
}

// Toggles segment `segment` (or soak `soak`) in `s`, updating the information.
void Toggle(const Problem& p, Selection* s, int segment, int soak) {
  const bool adding = segment >= 0 ? !s->segment[segment] : !s->soak[soak];
  for (size_t k = 0; k < p.sensors.size(); ++k) {
    const Eigen::MatrixXd block = ElementSum(p, *s, static_cast<int>(k), segment, soak);
    s->data[k] += adding ? block : -block;
  }
  if (segment >= 0) {
    s->segment[segment] = adding;
  } else {
    s->soak[soak] = adding;
  }
}

// Greedy: the element with the largest fall of phi per second, until the target is met.
bool Greedy(const Problem& p, double target, Selection* s) {
  while (LargestRatio(p, s->data) > target) {
    const double phi = Phi(p, s->data);
    const double cost = Cost(p, *s);
    double best = 0.0;
    int best_segment = -1, best_soak = -1;
    for (int e = 0; e < p.segments + p.soaks; ++e) {
      const int segment = e < p.segments ? e : -1;
      const int soak = e < p.segments ? -1 : e - p.segments;
      if (segment >= 0 ? s->segment[segment] : s->soak[soak]) continue;
      Selection trial = *s;
      Toggle(p, &trial, segment, soak);
      const double added = Cost(p, trial) - cost;
      const double gain = (phi - Phi(p, trial.data)) / std::max(added, 1.0);
      if (gain > best) {
        best = gain;
        best_segment = segment;
        best_soak = soak;
      }
    }
    if (best_segment < 0 && best_soak < 0) return false;  // nothing left helps
    Toggle(p, s, best_segment, best_soak);
  }
  return true;
}

// One exchange step: the dearest element the target can spare dropped, else the swap of a chosen
// for an unchosen element (of the same kind, no dearer) that lowers phi most. False: none.
bool ExchangeStep(const Problem& p, double target, Selection* s) {
  const double cost = Cost(p, *s);
  double best_saving = 0.0;
  Selection best;
  for (int e = 0; e < p.segments + p.soaks; ++e) {
    const int segment = e < p.segments ? e : -1;
    const int soak = e < p.segments ? -1 : e - p.segments;
    if (!(segment >= 0 ? s->segment[segment] : s->soak[soak])) continue;
    Selection trial = *s;
    Toggle(p, &trial, segment, soak);
    const double saving = cost - Cost(p, trial);
    if (saving > best_saving && LargestRatio(p, trial.data) <= target) {
      best_saving = saving;
      best = trial;
    }
  }
  if (best_saving > 0.0) {
    *s = best;
    return true;
  }
  const double phi = Phi(p, s->data);
  double best_phi = phi * (1.0 - 1e-6);
  bool found = false;
  for (int out = 0; out < p.segments + p.soaks; ++out) {
    const bool is_segment = out < p.segments;
    if (!(is_segment ? s->segment[out] : s->soak[out - p.segments])) continue;
    Selection without = *s;
    Toggle(p, &without, is_segment ? out : -1, is_segment ? -1 : out - p.segments);
    const int first = is_segment ? 0 : p.segments;
    const int last = is_segment ? p.segments : p.segments + p.soaks;
    for (int in = first; in < last; ++in) {
      if (in == out || (is_segment ? s->segment[in] : s->soak[in - p.segments])) continue;
      Selection trial = without;
      Toggle(p, &trial, is_segment ? in : -1, is_segment ? -1 : in - p.segments);
      const double trial_phi = Phi(p, trial.data);
      if (trial_phi < best_phi && Cost(p, trial) <= cost && LargestRatio(p, trial.data) <= target) {
        best_phi = trial_phi;
        best = trial;
        found = true;
      }
    }
  }
  if (found) *s = best;
  return found;
}

// The toleranced value rows of one sensor (scaled so that a row's variance is its ratio squared).
Eigen::MatrixXd ToleranceRows(const SensorInformation& info, const PlanCheckOptions& options,
                              std::array<double, 2> range) {
  std::vector<Eigen::RowVectorXd> rows;
  const int coefficients = info.is_gyro ? kGyroCoefficients : kAccelCoefficients;
  for (int c = 0; c < coefficients; ++c) {
    const std::string group = std::string(info.is_gyro ? "gyro." : "accel.") + kCoefficientNames[c].group;
    const auto tolerance = options.tolerances.find(group);
    if (tolerance == options.tolerances.end()) continue;
    const double scale = options.z * PlanGroupFactor(group) / tolerance->second;
    for (int i = 0; i < kDesignTemps; ++i) {
      const double dt = range[0] + (range[1] - range[0]) * i / (kDesignTemps - 1.0) - kReferenceTempC;
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(info.to_reference.cols());
      double power = 1.0;
      for (int k = 0; k < kPolynomialTerms; ++k, power *= dt) row += power * info.to_reference.row(c * 4 + k);
      if (row.squaredNorm() > 0.0) rows.push_back(scale * row);
    }
  }
  Eigen::MatrixXd out(rows.size(), info.to_reference.cols());
  for (size_t r = 0; r < rows.size(); ++r) out.row(r) = rows[r];
  return out;
}

// The prior in q: the data-sheet sigma of each value, its temperature terms spread over the range.
Eigen::MatrixXd PriorOf(const SensorInformation& info, const std::map<std::string, double>& prior,
                        double half_range_c) {
  const Eigen::MatrixXd& a = info.to_reference;
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(a.rows());
  for (int p = 0; p < a.rows(); ++p) {
    const std::string group =
        std::string(info.is_gyro ? "gyro." : "accel.") + kCoefficientNames[p / kPolynomialTerms].group;
    const double sigma =
        prior.at(group) / PlanGroupFactor(group) / std::pow(half_range_c, p % kPolynomialTerms);
    weight(p) = 1.0 / (sigma * sigma);
  }
  return a.transpose() * weight.asDiagonal() * a;
}

SensorTerms TermsOf(const SensorInformation& info, const std::vector<Window>& windows, int soaks,
                    const std::vector<TableSegment>& candidates, const PlanDesignOptions& options,
                    std::array<double, 2> range) {
  SensorTerms terms;
  terms.n = static_cast<int>(info.jacobian.cols());
  if (terms.n == 0) return terms;
  const int count = static_cast<int>(candidates.size());
  terms.element.assign(count * soaks, Eigen::MatrixXd::Zero(terms.n, terms.n));
  for (size_t w = 0; w < info.window_index.size(); ++w) {
    const Window& window = windows[info.window_index[w]];
    int index = 0;
    while (index < count && candidates[index].id != window.segment) ++index;
    const Eigen::MatrixXd rows = info.jacobian.middleRows(3 * static_cast<int>(w), 3);
    terms.element[index * soaks + window.occurrence] += rows.transpose() * rows;
  }
  std::map<std::string, double> prior = DefaultPlanPrior();
  for (const auto& [group, value] : options.prior) prior[group] = value;
  terms.prior = PriorOf(info, prior, 0.5 * (range[1] - range[0]));
  // A group without a tolerance must still beat its data-sheet value: the fit refuses a plan that
  // leaves a direction to the prior (a scale seen through the Earth rate alone, say).
  PlanCheckOptions check = options.check;
  for (const auto& [group, value] : prior) check.tolerances.emplace(group, value);
  terms.rows = ToleranceRows(info, check, range);
  return terms;
}

std::vector<TableSegment> Chosen(const std::vector<TableSegment>& candidates, const Selection& s) {
  std::vector<TableSegment> out;
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (!s.segment[i]) continue;
    out.push_back(candidates[i]);
    out.back().id = static_cast<int>(out.size());
  }
  return out;
}

std::vector<double> ChosenSoaks(const std::vector<double>& set_points, const Selection& s) {
  std::vector<double> out;
  for (size_t t = 0; t < set_points.size(); ++t) {
    if (s.soak[t]) out.push_back(set_points[t]);
  }
  return out;
}

// The set-points, ascending, without repeats.
std::vector<double> SetPoints(const PlanDesignOptions& options) {
  std::vector<double> points = options.set_points_c;
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end(),
                           [](double a, double b) { return std::abs(a - b) < kSameSetPointC; }),
               points.end());
  return points;
}

void Validate(const std::vector<TableSegment>& candidates, const PlanDesignOptions& options) {
  if (options.check.tolerances.empty()) {
    throw std::invalid_argument("give at least one tolerance (--tolerance GROUP=VALUE or --limits)");
  }
  if (SetPoints(options).empty()) throw std::invalid_argument("give at least one temperature set-point");
  for (const TableSegment& s : candidates) {
    if (std::abs(s.rate_radps) > options.max_rate_dps * kDegToRad * (1.0 + 1e-12)) {
      throw std::invalid_argument("segment " + std::to_string(s.id) +
                                  "'s rate exceeds the table's limit of " +
                                  OptionNumberText(options.max_rate_dps) + " deg/s");
    }
  }
}

// A horizontal direction (perpendicular to `up`) to call north.
Eigen::Vector3d NorthFor(const Eigen::Vector3d& up) {
  const Eigen::Vector3d helper = std::abs(up.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  return (helper - helper.dot(up) * up).normalized();
}

}  // namespace

const std::map<std::string, double>& DefaultPlanPrior() {
  static const std::map<std::string, double> prior = {
      {"gyro.bias", 1.0},          {"gyro.scale", 30000.0}, {"gyro.misalignment", 10.0},
      {"gyro.g_sensitivity", 0.1}, {"accel.bias", 50.0},    {"accel.scale", 30000.0},
      {"accel.misalignment", 10.0}};
  return prior;
}

double PlanDesignHours(size_t segments, size_t soaks, const SimulationOptions& schedule,
                       const PlanDesignOptions& options) {
  const double per_segment = schedule.transition_s + schedule.dwell_s;
  return (soaks * options.soak_settle_s + soaks * segments * per_segment) / 3600.0;
}

std::vector<TableSegment> DesignCandidates(const PlanDesignOptions& options) {
  std::vector<Eigen::Vector3d> directions, faces;
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        const Eigen::Vector3d v(x, y, z);
        const int nonzero = static_cast<int>(v.cwiseAbs().sum());
        if (nonzero == 1) faces.push_back(v);
        const char* kind = nonzero == 1 ? "faces" : nonzero == 2 ? "edges" : "corners";
        if (nonzero > 0 &&
            ("," + options.positions + ",").find("," + std::string(kind) + ",") != std::string::npos) {
          directions.push_back(v.normalized());
        }
      }
    }
  }
  std::vector<TableSegment> out;
  for (const Eigen::Vector3d& up : directions) {
    TableSegment s;
    s.id = static_cast<int>(out.size()) + 1;
    s.up = up;
    s.north = NorthFor(up);
    out.push_back(s);
  }
  for (const Eigen::Vector3d& axis : options.two_axis ? directions : faces) {
    for (double rate : options.rates_dps) {
      for (double sign : {1.0, -1.0}) {
        TableSegment s;
        s.id = static_cast<int>(out.size()) + 1;
        s.up = axis;
        s.rate_radps = sign * rate * kDegToRad;
        out.push_back(s);
      }
    }
  }
  return out;
}

PlanDesign DesignPlan(std::vector<TableSegment> candidates, const TableSite& site,
                      const SimulationOptions& schedule, const PlanDesignOptions& options) {
  if (candidates.empty()) candidates = DesignCandidates(options);
  Validate(candidates, options);
  const std::vector<double> set_points = SetPoints(options);
  PlanDesignOptions design = options;
  const std::array<double, 2> range = {set_points.front(), set_points.back()};
  if (!design.check.spec_range_c) design.check.spec_range_c = range;  // judged over the whole range
  const std::array<double, 2> spec = *design.check.spec_range_c;
  TableSite planned_site = site;
  if (options.check.latitude_deg) planned_site.latitude_rad = *options.check.latitude_deg * kDegToRad;
  design.check.latitude_deg.reset();

  PlanDesign result;
  result.candidate_segments = static_cast<int>(candidates.size());
  result.candidate_set_points = static_cast<int>(set_points.size());
  SimulationOptions universe = schedule;
  universe.ramp = false;
  universe.soak_temps_c = set_points;
  const std::vector<Window> windows =
      PlannedWindows(candidates, planned_site, universe, options.check.windows);
  const PlanInformation info =
      ComputePlanInformation(windows, planned_site, candidates, options.fit, options.check.weak_tolerance);
  result.undetermined = info.undetermined;
  if (!result.undetermined.empty()) return result;

  Problem problem;
  problem.segments = static_cast<int>(candidates.size());
  problem.soaks = static_cast<int>(set_points.size());
  problem.segment_cost_s = schedule.transition_s + schedule.dwell_s;
  problem.soak_cost_s = options.soak_settle_s;
  for (const SensorInformation* sensor : {&info.gyro, &info.accel}) {
    problem.sensors.push_back(TermsOf(*sensor, windows, problem.soaks, candidates, options, spec));
  }
  Selection s;
  s.segment.assign(problem.segments, false);
  s.soak.assign(problem.soaks, false);
  for (const SensorTerms& terms : problem.sensors) s.data.push_back(Eigen::MatrixXd::Zero(terms.n, terms.n));
  // The first soak: the set-point nearest the reference temperature.
  int first = 0;
  for (int t = 0; t < problem.soaks; ++t) {
    if (std::abs(set_points[t] - kReferenceTempC) < std::abs(set_points[first] - kReferenceTempC)) first = t;
  }
  s.soak[first] = true;

  const auto check_of = [&](const std::vector<TableSegment>& segments, const std::vector<double>& soaks) {
    SimulationOptions run = schedule;
    run.ramp = false;
    run.soak_temps_c = soaks;
    return CheckPlan(segments, planned_site, run, options.fit, design.check);
  };
  double target = 1.0;
  for (int step = 0; step < kTargetSteps; ++step, target *= kTargetStep) {
    const bool reached = Greedy(problem, target, &s);
    if (step == 0) {
      result.greedy = Chosen(candidates, s);
      result.greedy_soaks_c = ChosenSoaks(set_points, s);
      result.greedy_hours =
          PlanDesignHours(result.greedy.size(), result.greedy_soaks_c.size(), schedule, options);
      result.greedy_check = check_of(result.greedy, result.greedy_soaks_c);
    }
    for (int round = 0; reached && round < options.max_exchange_rounds && ExchangeStep(problem, target, &s);)
      ++round;
    result.segments = Chosen(candidates, s);
    result.soaks_c = ChosenSoaks(set_points, s);
    result.hours = PlanDesignHours(result.segments.size(), result.soaks_c.size(), schedule, options);
    result.check = check_of(result.segments, result.soaks_c);
    result.met = result.check.undetermined.empty() && !result.check.tolerance_unmet;
    if (result.met || !reached) break;
  }
  return result;
}

}  // namespace imufit
