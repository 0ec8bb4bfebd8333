#include "imufit/factory/uncertainty_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "imufit/factory/acceptance.h"
#include "imufit/factory/report.h"
#include "imufit/fit/thermal_fit.h"
#include "imufit/fit/truth_perturbation.h"
#include "imufit/pipeline/fit_run.h"

namespace imufit {
namespace {

// One component of a source: its name and the perturbation of one standard uncertainty.
struct Component {
  std::string name;
  TruthPerturbation one_u;
};

const StationInfluenceInfo& Info(StationInfluence influence) {
  for (const StationInfluenceInfo& info : kStationUncertainties) {
    if (info.influence == influence) return info;
  }
  return kStationUncertainties[0];
}

std::vector<Component> Components(const StationUncertainty& source, const Plan& plan) {
  const std::string title = Info(source.influence).title;
  const double u = source.u_si;
  std::vector<Component> components;
  const auto vector_components = [&](const char* const names[3], const char* word,
                                     Eigen::Vector3d TruthPerturbation::*member) {
    for (int i = 0; i < 3; ++i) {
      Component c{title + " " + word + " " + names[i], {}};
      (c.one_u.*member)[i] = u;
      components.push_back(c);
    }
  };
  static const char* const kAxes[3] = {"x", "y", "z"};
  static const char* const kPairs[3] = {"xy", "xz", "yz"};
  switch (source.influence) {
    case StationInfluence::kRateAccuracy:
      components.push_back({title, {}});
      components.back().one_u.rate_scale = u;
      break;
    case StationInfluence::kTableAxisTilt:  // in the lab: about north and about east
      for (int i = 0; i < 2; ++i) {
        components.push_back({title + (i == 0 ? " about north" : " about east"), {}});
        components.back().one_u.tilt_rad[i] = u;
      }
      break;
    case StationInfluence::kFixtureOrthogonality:
      vector_components(kPairs, "", &TruthPerturbation::orthogonality_rad);
      break;
    case StationInfluence::kFixtureAlignment:
      vector_components(kAxes, "about", &TruthPerturbation::alignment_rad);
      break;
    case StationInfluence::kLocalGravity:
      components.push_back({title, {}});
      components.back().one_u.gravity_scale = u / plan.site.gravity_mps2;
      break;
    case StationInfluence::kThermometer:
      components.push_back({title, {}});
      components.back().one_u.temp_offset_c = u;
      break;
  }
  for (Component& c : components) {
    if (const size_t twice = c.name.find("  "); twice != std::string::npos) c.name.erase(twice, 1);
  }
  return components;
}

// A perturbation times a number (a draw in units of u).
TruthPerturbation Scaled(const TruthPerturbation& p, double z) {
  TruthPerturbation s;
  s.rate_scale = p.rate_scale * z;
  s.gravity_scale = p.gravity_scale * z;
  s.tilt_rad = p.tilt_rad * z;
  s.orthogonality_rad = p.orthogonality_rad * z;
  s.alignment_rad = p.alignment_rad * z;
  s.temp_offset_c = p.temp_offset_c * z;
  return s;
}

TruthPerturbation Sum(const TruthPerturbation& a, const TruthPerturbation& b) {
  TruthPerturbation s;
  s.rate_scale = a.rate_scale + b.rate_scale;
  s.gravity_scale = a.gravity_scale + b.gravity_scale;
  s.tilt_rad = a.tilt_rad + b.tilt_rad;
  s.orthogonality_rad = a.orthogonality_rad + b.orthogonality_rad;
  s.alignment_rad = a.alignment_rad + b.alignment_rad;
  s.temp_offset_c = a.temp_offset_c + b.temp_offset_c;
  return s;
}

// The settings the calibration was fitted with (its `fit:` record), the held groups at their values.
FitOptions RefitOptions(const Calibration& calibration) {
  FitOptions options = FitOptionsOfRecord(*calibration.fit);
  options.held = calibration.model;
  options.num_threads = 1;
  return options;
}

bool IsCoefficient(const Figure& f) {
  return f.coefficient.rfind("gyro.", 0) == 0 || f.coefficient.rfind("accel.", 0) == 0;
}

// The model the fit gives under the truth perturbed by `p`; nullopt when that fit is not usable.
std::optional<SensorModel> Refit(const Plan& plan, const std::vector<Window>& windows,
                                 const FitOptions& options, const TruthPerturbation& p) {
  TableSite site = plan.site;
  std::vector<TableSegment> segments = plan.segments;
  std::vector<Window> perturbed = windows;
  PerturbTruth(p, &site, &segments, &perturbed);
  const FitSummary fit = FitThermalModel(perturbed, site, segments, options);
  if (!fit.IsSolutionUsable()) return std::nullopt;
  return fit.model;
}

// The coefficient key figures at `temp_c` of `calibration` with `model` in place of its own.
std::vector<double> CoefficientValues(const Calibration& calibration, const SensorModel& model,
                                      double temp_c) {
  Calibration refitted = calibration;
  refitted.model = model;
  std::vector<double> values;
  for (const Figure& f : KeyFigures(refitted, temp_c)) {
    if (IsCoefficient(f)) values.push_back(f.value);
  }
  return values;
}

// The coefficient key figures of the model the fit gives under the truth perturbed by `p`; empty
// when that fit is not usable.
std::vector<double> RefitFigures(const Calibration& calibration, const Plan& plan,
                                 const std::vector<Window>& windows, const FitOptions& options,
                                 const TruthPerturbation& p) {
  const std::optional<SensorModel> model = Refit(plan, windows, options, p);
  return model ? CoefficientValues(calibration, *model, kFigureTempC) : std::vector<double>();
}

// The budgets of `calibration`'s coefficient figures at `temp_c`: Type A from its sigmas there, Type B
// the differences of `budget`'s moved models from its re-solved one there; combined and expanded.
std::vector<FigureBudget> FigureBudgets(const UncertaintyBudget& budget, const Calibration& calibration,
                                        double temp_c) {
  std::vector<FigureBudget> figures;
  for (const Figure& f : KeyFigures(calibration, temp_c)) {
    if (!IsCoefficient(f)) continue;
    FigureBudget b;
    b.name = f.name;
    b.unit = f.unit;
    b.value = f.value;
    b.type_a = std::max(f.sigma, 0.0);
    figures.push_back(b);
  }
  if (budget.resolved) {
    const std::vector<double> base = CoefficientValues(calibration, *budget.resolved, temp_c);
    for (const auto& [line, model] : budget.moved) {
      const std::vector<double> moved = CoefficientValues(calibration, model, temp_c);
      if (moved.size() != figures.size() || base.size() != figures.size()) continue;
      for (size_t i = 0; i < base.size(); ++i) {
        BudgetLine contribution = line;
        contribution.contribution = moved[i] - base[i];
        figures[i].type_b.push_back(contribution);
      }
    }
  }
  for (FigureBudget& f : figures) {
    double variance = f.type_a * f.type_a;
    for (const BudgetLine& line : f.type_b) variance += line.contribution * line.contribution;
    std::sort(f.type_b.begin(), f.type_b.end(), [](const BudgetLine& a, const BudgetLine& b) {
      return std::abs(a.contribution) > std::abs(b.contribution);
    });
    f.combined = std::sqrt(variance);
    f.expanded = budget.coverage_factor * f.combined;
  }
  return figures;
}

std::string InputText(const StationUncertainty& s) {
  char text[96];
  std::snprintf(text, sizeof text, "%.4g %s%s", s.written, s.unit.c_str(),
                s.rectangular ? " (half width, rectangular)" : "");
  return text;
}

std::vector<BudgetClass> Classes(const std::vector<FigureBudget>& figures) {
  std::vector<BudgetClass> classes;
  std::map<std::string, double> sums;
  int axes = 0;
  const auto close = [&]() {
    if (classes.empty()) return;
    BudgetClass& c = classes.back();
    c.type_a_rms = std::sqrt(c.type_a_rms / axes);
    for (const auto& [source, sum] : sums) c.top.push_back({source, std::sqrt(sum / axes)});
    std::sort(c.top.begin(), c.top.end(),
              [](const BudgetClassLine& a, const BudgetClassLine& b) { return a.rms > b.rms; });
    if (c.top.size() > kBudgetTopContributors) c.top.resize(kBudgetTopContributors);
  };
  for (const FigureBudget& f : figures) {
    const std::string quantity = f.name.substr(0, f.name.rfind('.'));
    if (classes.empty() || classes.back().quantity != quantity) {
      close();
      classes.push_back({quantity, f.unit, 0.0, {}});
      sums.clear();
      axes = 0;
    }
    ++axes;
    classes.back().type_a_rms += f.type_a * f.type_a;
    // A source's components together (the three of a tilt are one source's).
    std::map<std::string, double> by_source;
    for (const BudgetLine& line : f.type_b) {
      by_source[line.source.substr(0, line.source.find(" about "))] += line.contribution * line.contribution;
    }
    for (const auto& [source, sum] : by_source) sums[source] += sum;
  }
  close();
  return classes;
}

void Statements(UncertaintyBudget* budget) {
  std::string covers = "U (k = 2, about 95 %) covers the fit's statistical uncertainty (white noise";
  covers +=
      budget->bias_stability_included ? " and the stated bias stability)" : " only: no bias stability given)";
  if (budget->inputs.empty()) {
    covers += "; the station declares no Type B source, so none is included";
  } else {
    covers += " and the station's Type B sources:";
    for (size_t i = 0; i < budget->inputs.size(); ++i) {
      covers += std::string(i == 0 ? " " : ", ") + Info(budget->inputs[i].influence).title;
    }
  }
  budget->covers = covers + ".";
  budget->not_covered =
      "U does not cover the unit's drift after calibration, its hysteresis and repeatability between runs, "
      "terms the model does not have, the table's position (turn angle) accuracy, or any source the station "
      "does not declare.";
}

}  // namespace

const FigureBudget* UncertaintyBudget::Find(const std::string& name) const {
  for (const FigureBudget& f : figures) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

std::vector<FigureBudget> UncertaintyBudget::At(const Calibration& calibration, double temp_c) const {
  if (temp_c == kFigureTempC) return figures;
  return FigureBudgets(*this, calibration, temp_c);
}

UncertaintyBudget ComputeBudget(const Calibration& calibration, const Plan& plan,
                                const std::vector<Window>& windows,
                                const std::vector<StationUncertainty>& sources) {
  UncertaintyBudget budget;
  budget.bias_stability_included =
      calibration.fit && (calibration.fit->gyro_bias_stability_radps.value_or(0.0) > 0.0 ||
                          calibration.fit->accel_bias_stability_mps2.value_or(0.0) > 0.0);
  if (calibration.fit && !windows.empty() && !sources.empty()) {
    const FitOptions options = RefitOptions(calibration);
    budget.resolved = Refit(plan, windows, options, {});
    if (budget.resolved) {
      budget.inputs = sources;
      for (const StationUncertainty& source : sources) {
        for (const Component& c : Components(source, plan)) {
          if (std::optional<SensorModel> moved = Refit(plan, windows, options, c.one_u)) {
            budget.moved.push_back({{c.name, source.source, InputText(source), 0.0}, std::move(*moved)});
          }
        }
      }
    }
  }
  budget.figures = FigureBudgets(budget, calibration, kFigureTempC);
  budget.classes = Classes(budget.figures);
  Statements(&budget);
  return budget;
}

namespace {

// The local gravity of a calibration by hand as a Type B source (ComputeFieldBudget); none for a
// stated value (taken as exact) or a record that does not say.
std::optional<StationUncertainty> FieldGravitySource(const FieldRecord& field) {
  const std::string source = field.gravity_source.value_or("");
  StationUncertainty u;
  u.influence = StationInfluence::kLocalGravity;
  u.key = "local_gravity";
  u.unit = "m/s^2";
  if (source == kGravityStandard) {
    u.written = kStandardGravityHalfWidthMps2;
    u.rectangular = true;
    u.u_si = kStandardGravityHalfWidthMps2 / std::sqrt(3.0);
    u.source =
        "standard gravity 9.80665 m/s^2 (no local gravity given): Earth's normal gravity from the equator to "
        "the poles, sea level to 1000 m";
  } else if (source == kGravityFromLatitude) {
    u.written = kNormalGravityAnomalyMps2;
    u.u_si = kNormalGravityAnomalyMps2;
    u.source = "WGS-84 normal gravity at the latitude and height given: the site's gravity anomaly (50 mGal)";
  } else {
    return std::nullopt;
  }
  return u;
}

}  // namespace

UncertaintyBudget ComputeFieldBudget(const Calibration& calibration) {
  UncertaintyBudget budget;
  const FieldRecord field =
      calibration.fit && calibration.fit->field ? *calibration.fit->field : FieldRecord();
  const double gravity = field.gravity_mps2.value_or(kStandardGravityMps2);
  const std::optional<StationUncertainty> source = FieldGravitySource(field);
  if (source) {
    budget.inputs = {*source};
    budget.resolved = calibration.model;
    SensorModel moved = calibration.model;
    const double shrink = 1.0 / (1.0 + source->u_si / gravity);
    for (int c = 0; c < kPolynomialTerms * 3; ++c)
      moved.accel[kScaleCoefficient * kPolynomialTerms + c] *= shrink;
    for (int c = 0; c < kPolynomialTerms * 9; ++c)
      moved.gyro[kGSensitivityCoefficient * kPolynomialTerms + c] *= shrink;
    char input[64];
    std::snprintf(input, sizeof input, "%.4g m/s^2%s", source->written,
                  source->rectangular ? " (half width, rectangular)" : "");
    budget.moved.push_back({{"Local gravity", source->source, input, 0.0}, std::move(moved)});
  }
  budget.figures = FigureBudgets(budget, calibration, kFigureTempC);
  budget.classes = Classes(budget.figures);
  const std::string gravity_text = FormatNumber("%.6g m/s^2", gravity);
  budget.covers =
      "U (k = 2, about 95 %) covers the fit's statistical uncertainty from this session by hand: the white "
      "noise of the rests and the turns and, where the session scattered beyond it (hand tremor, drift "
      "during the session), that larger scatter as the fit estimated it (its noise scales)";
  if (!source) {
    budget.covers += field.gravity_source.value_or("") == kGravityStated
                         ? "; the local gravity " + gravity_text +
                               " was stated (--gravity-mps2) and is taken as exact: its own uncertainty is "
                               "not included"
                         : "; the calibration does not record where its gravity " + gravity_text +
                               " came from, so its uncertainty is not included";
  } else {
    budget.covers += "; and the uncertainty of the local gravity " + gravity_text + " (" + source->source +
                     "), which the accelerometer's scale factors and the gyro's g-sensitivity are "
                     "proportional to";
  }
  budget.covers += ".";
  budget.not_covered =
      "No reference table or known rate was used: the scale and misalignment references are gravity and "
      "the turns the gyro integrated, so U includes no table's or station's errors (there are none to "
      "include). U does not cover the unit's turn-on to turn-on repeatability, its drift after the "
      "session or over time, hysteresis, Earth's rotation (up to 0.004 deg/s, not modelled), terms the "
      "model does not have, or temperatures outside the session's.";
  return budget;
}

std::vector<double> MonteCarloTypeB(const Calibration& calibration, const Plan& plan,
                                    const std::vector<Window>& windows,
                                    const std::vector<StationUncertainty>& sources, int trials,
                                    unsigned seed) {
  const FitOptions options = RefitOptions(calibration);
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-std::sqrt(3.0), std::sqrt(3.0));  // unit variance
  std::vector<std::vector<double>> draws;
  for (int trial = 0; trial < trials; ++trial) {
    TruthPerturbation draw;
    for (const StationUncertainty& source : sources) {
      for (const Component& c : Components(source, plan)) {
        draw = Sum(draw, Scaled(c.one_u, source.rectangular ? uniform(random) : normal(random)));
      }
    }
    std::vector<double> values = RefitFigures(calibration, plan, windows, options, draw);
    if (!values.empty()) draws.push_back(std::move(values));
  }
  std::vector<double> spread(draws.empty() ? 0 : draws[0].size(), 0.0);
  for (size_t i = 0; i < spread.size() && draws.size() > 1; ++i) {
    double mean = 0.0, variance = 0.0;
    for (const std::vector<double>& d : draws) mean += d[i] / static_cast<double>(draws.size());
    for (const std::vector<double>& d : draws) variance += (d[i] - mean) * (d[i] - mean);
    spread[i] = std::sqrt(variance / static_cast<double>(draws.size() - 1));
  }
  return spread;
}

}  // namespace imufit
