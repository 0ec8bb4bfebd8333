// `imufit plan check` of a hand procedure (hand_check.h): simulated sessions, fitted by the field fit.
#include "imufit/plan/hand_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "imufit/io/machine_text.h"
#include "imufit/model/check.h"
#include "imufit/model/constants.h"
#include "imufit/model/sensor_model.h"

namespace imufit {
namespace {

std::string Text(const char* format, double a, double b = 0.0, double c = 0.0) {
  char text[200];
  std::snprintf(text, sizeof text, format, a, b, c);
  return text;
}

// One simulated session of `setup` (seed `seed`), fitted.
FieldFitSummary FitOneSession(const HandSetup& setup, std::uint64_t seed, double* session_s) {
  SimulationOptions schedule = setup.schedule;
  schedule.seed = seed;
  std::vector<Sample> samples;
  SimulateFieldSession(schedule, setup.session, SensorModel::Identity(),
                       [&samples](const Sample& raw, const SegmentTruth&) { samples.push_back(raw); });
  *session_s = samples.empty() ? 0.0 : samples.back().time_s - samples.front().time_s;
  return FitField(samples, setup.fit);
}

// A finding without its figures ("turns about z too small ... (they moved gravity by 0.31 rad ...)"
// differs in its figures between sessions): the text before its first " (" that follows a word.
std::string FindingKey(const std::string& finding) {
  const size_t figures = finding.find(" (1 sigma");
  const size_t moved = finding.find(" (they moved");
  return finding.substr(0, std::min(figures, moved));
}

const double* Values(const SensorModel& m, bool gyro) { return gyro ? m.gyro.data() : m.accel.data(); }

double WorstRatio(const std::vector<PlanRow>& rows) {
  double worst = 0.0;
  for (const PlanRow& row : rows) worst = std::max(worst, row.ratio);
  return worst;
}

}  // namespace

HandSetup HandSetupOf(const HandProcedure& hand, const SimulationOptions& noise) {
  HandSetup setup;
  setup.fit.bias_temp_order = hand.bias_temp_order;
  setup.fit.scale_temp_order = hand.scale_temp_order;
  if (hand.gravity_mps2) setup.fit.gravity_mps2 = *hand.gravity_mps2;
  if (hand.latitude_deg) {
    setup.fit.latitude_deg = hand.latitude_deg;
    setup.fit.height_m = hand.height_m;
  }
  setup.session.poses = hand.poses;
  setup.session.turn_s = hand.turn_s;
  setup.session.min_tilt_deg = hand.tilt_deg[0];
  setup.session.max_tilt_deg = hand.tilt_deg[1];
  setup.session.gravity_mps2 = setup.fit.GravityMps2();
  setup.session.warmup_c = hand.warmup_c;
  setup.session.warmup_tau_s = hand.warmup_tau_s;
  setup.session.directions = hand.up;
  setup.session.twist_axes = hand.twist_axes;
  setup.session.min_twist_deg = hand.twist_deg[0];
  setup.session.max_twist_deg = hand.twist_deg[1];
  setup.schedule = SimulationOptions();
  setup.schedule.rate_hz = hand.rate_hz;
  setup.schedule.dwell_s = hand.dwell_s;
  setup.schedule.soak_temps_c = {hand.temp_c};
  setup.schedule.gyro_noise_density = noise.gyro_noise_density;
  setup.schedule.accel_noise_density = noise.accel_noise_density;
  setup.schedule.gyro_bias_instability = noise.gyro_bias_instability;
  setup.schedule.accel_bias_instability = noise.accel_bias_instability;
  setup.schedule.bias_correlation_s = noise.bias_correlation_s;
  setup.schedule.gyro_random_walk = noise.gyro_random_walk;
  setup.schedule.accel_random_walk = noise.accel_random_walk;
  return setup;
}

HandCheck CheckHandProcedure(const HandSetup& setup, const PlanCheckOptions& options, int sessions,
                             bool advise) {
  IMUFIT_CHECK(sessions >= 1, "at least one simulated session");
  HandCheck check;
  check.sessions = sessions;
  std::vector<FieldFitSummary> fits;
  std::map<std::string, std::pair<std::string, int>> findings;  // key -> first text, sessions
  std::vector<std::string> order;
  double total_s = 0.0;
  for (int s = 0; s < sessions; ++s) {
    double session_s = 0.0;
    FieldFitSummary fit =
        FitOneSession(setup, setup.schedule.seed + static_cast<std::uint64_t>(s), &session_s);
    total_s += session_s;
    std::vector<std::string> problems = fit.undetermined;
    if (fit.status == FieldFitStatus::kFailed)
      problems.push_back("the fit did not converge: " + fit.termination);
    for (const std::string& problem : problems) {
      const std::string key = FindingKey(problem);
      if (findings.count(key) == 0) {
        findings[key] = {problem, 0};
        order.push_back(key);
      }
      ++findings[key].second;
    }
    if (fit.IsSolutionUsable()) fits.push_back(std::move(fit));
  }
  check.session_s = total_s / sessions;
  for (const std::string& key : order) {
    const auto& [text, count] = findings[key];
    check.undetermined.push_back(text + " (" + std::to_string(count) + " of " + std::to_string(sessions) +
                                 " sessions)");
  }
  check.fitted = static_cast<int>(fits.size());
  if (fits.empty()) return check;
  check.temp_range_c = fits.front().pose_temp_range_c;
  for (const FieldFitSummary& fit : fits) {
    check.temp_range_c[0] = std::min(check.temp_range_c[0], fit.pose_temp_range_c[0]);
    check.temp_range_c[1] = std::max(check.temp_range_c[1], fit.pose_temp_range_c[1]);
  }
  static const char* const kTermNames[] = {"", " (linear term)", " (quadratic term)", " (cubic term)"};
  std::vector<PlanRow> rows;
  std::vector<double> worsts;
  for (const bool gyro : {true, false}) {
    const int coefficients = gyro ? kGyroCoefficients : kAccelCoefficients;
    for (int c = 0; c < coefficients; ++c) {
      const std::string group = std::string(gyro ? "gyro." : "accel.") + kCoefficientNames[c].group;
      const double factor = PlanGroupFactor(group);
      const auto tolerance = options.tolerances.find(group);
      for (int k = 0; k < kPolynomialTerms; ++k) {
        const int i = c * kPolynomialTerms + k;
        double sum2 = 0.0;
        double range2 = 0.0;
        double low = 1e300;
        double high = 0.0;
        double worst = 0.0;
        for (const FieldFitSummary& fit : fits) {
          const double sigma = Values(fit.sigma, gyro)[i];
          sum2 += sigma * sigma;
          low = std::min(low, sigma);
          high = std::max(high, sigma);
          const double ends =
              k == 0
                  ? std::max({sigma, Values(fit.sigma_at_low, gyro)[i], Values(fit.sigma_at_high, gyro)[i]})
                  : sigma;
          range2 += ends * ends;
          worst = std::max(worst, ends);
        }
        if (!(high > 0.0)) continue;  // held (the body frame's convention, or an order not fitted)
        PlanRow row;
        row.name = std::string(gyro ? "gyro " : "accel ") + kCoefficientNames[c].group + " " +
                   kCoefficientNames[c].axis + kTermNames[k];
        row.group = group;
        row.unit = PlanGroupUnit(group) + (k == 0 ? "" : k == 1 ? "/degC" : "/degC^" + std::to_string(k));
        row.gyro = gyro;
        row.coefficient = c;
        row.term = k;
        const double n = static_cast<double>(fits.size());
        row.sigma = std::sqrt(sum2 / n) * factor;
        row.sigma_range = std::sqrt(range2 / n) * factor;
        row.sigma_spec = row.sigma_range;
        if (k == 0 && tolerance != options.tolerances.end()) {
          row.tolerance = tolerance->second;
          row.ratio = options.z * row.sigma_range / row.tolerance;
          check.tolerance_unmet = check.tolerance_unmet || row.ratio > 1.0;
        }
        if (low > 0.0) check.sigma_variation = std::max(check.sigma_variation, high / low - 1.0);
        rows.push_back(row);
        worsts.push_back(worst * factor);
      }
    }
  }
  std::vector<size_t> order_by_ratio(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) order_by_ratio[r] = r;
  std::stable_sort(order_by_ratio.begin(), order_by_ratio.end(),
                   [&rows](size_t a, size_t b) { return rows[a].ratio > rows[b].ratio; });
  for (size_t r : order_by_ratio) {
    check.rows.push_back(rows[r]);
    check.sigma_worst.push_back(worsts[r]);
  }
  if (!advise || !check.tolerance_unmet || !check.undetermined.empty()) return check;
  // Longer dwells (white noise on the rests averages down) and more poses (more rests and turns).
  for (const double dwell_factor : {2.0, 4.0}) {
    HandSetup longer = setup;
    longer.schedule.dwell_s *= dwell_factor;
    const HandCheck other = CheckHandProcedure(longer, options, sessions, false);
    check.alternatives.push_back({"--dwell " + Text("%g", longer.schedule.dwell_s), other.session_s,
                                  WorstRatio(other.rows),
                                  other.undetermined.empty() && !other.tolerance_unmet,
                                  other.rows.empty() ? "" : other.rows.front().name});
  }
  for (const double pose_factor : {1.5, 2.0}) {
    HandSetup more = setup;
    more.session.poses = static_cast<int>(std::ceil(setup.session.poses * pose_factor));
    const HandCheck other = CheckHandProcedure(more, options, sessions, false);
    check.alternatives.push_back({"--poses " + std::to_string(more.session.poses), other.session_s,
                                  WorstRatio(other.rows),
                                  other.undetermined.empty() && !other.tolerance_unmet,
                                  other.rows.empty() ? "" : other.rows.front().name});
  }
  return check;
}

PlanCheck HandPlanCheck(const HandCheck& check, const HandSetup& setup) {
  PlanCheck plan;
  plan.undetermined = check.undetermined;
  plan.rows = check.rows;
  plan.tolerance_unmet = check.tolerance_unmet;
  plan.longest_static_s = setup.schedule.dwell_s;
  return plan;
}

std::string HandCheckText(const HandCheck& check, const HandSetup& setup, const PlanCheckOptions& options) {
  std::string out = "hand procedure: " + std::to_string(setup.session.poses) + " poses" +
                    Text(", dwell %g s, turns %g s, %g Hz", setup.schedule.dwell_s, setup.session.turn_s,
                         setup.schedule.rate_hz) +
                    Text(": a session of %.1f min; z = %g\n", check.session_s / 60.0, options.z);
  out += "predicted by the field fit of " + std::to_string(check.sessions) + " simulated session" +
         (check.sessions == 1 ? "" : "s");
  out += check.fitted == check.sessions ? "" : " (" + std::to_string(check.fitted) + " accepted)";
  out += check.fitted > 1
             ? Text(": a sigma differs by up to %.0f %% between them (worst: one session's largest)\n",
                    100.0 * check.sigma_variation)
             : "\n";
  for (const std::string& finding : check.undetermined) out += "undetermined: " + finding + "\n";
  if (check.rows.empty()) return out;
  char line[256];
  std::snprintf(line, sizeof line, "%-44s %12s %12s %12s %10s %7s  %s\n", "coefficient", "sigma",
                "sigma_range", "worst", "tolerance", "ratio", "unit");
  out += line;
  for (size_t r = 0; r < check.rows.size(); ++r) {
    const PlanRow& row = check.rows[r];
    const std::string tolerance = row.tolerance > 0.0 ? Text("%.4g", row.tolerance) : "-";
    const std::string ratio = row.tolerance > 0.0 ? Text("%.3g", row.ratio) : "-";
    std::snprintf(line, sizeof line, "%-44s %12.4g %12.4g %12.4g %10s %7s  %s\n", row.name.c_str(), row.sigma,
                  row.sigma_range, check.sigma_worst[r], tolerance.c_str(), ratio.c_str(), row.unit.c_str());
    out += line;
  }
  out += "limiting: " + check.rows.front().name + "\n";
  for (const HandCheck::Alternative& a : check.alternatives) {
    out += "advice: " + a.option +
           Text(": a session of %.1f min, worst ratio %.3g", a.session_s / 60.0, a.worst_ratio) +
           (a.meets ? ": meets the tolerances\n" : ": still short (limiting: " + a.limiting + ")\n");
  }
  const HandCheck::Alternative* shortest = nullptr;
  for (const HandCheck::Alternative& a : check.alternatives) {
    if (a.meets && (shortest == nullptr || a.session_s < shortest->session_s)) shortest = &a;
  }
  if (shortest != nullptr) {
    out += "advice: the shortest session that meets the tolerances: " + shortest->option +
           Text(" (%.1f min)\n", shortest->session_s / 60.0);
  } else if (!check.alternatives.empty()) {
    out += "advice: none of these meets the tolerances: a quieter unit, or a table (imufit plan design)\n";
  }
  return out;
}

std::string HandCheckYaml(const HandCheck& check, const std::vector<PlanCriterion>& criteria, bool json) {
  MachineDoc doc = MachineDoc::Map();
  doc.Add("kind", MachineDoc::Text("hand procedure"));
  doc.Add("sessions", MachineDoc::Integer(check.sessions));
  doc.Add("fitted", MachineDoc::Integer(check.fitted));
  doc.Add("session_s", MachineDoc::Number(check.session_s));
  doc.Add("sigma_variation", MachineDoc::Number(check.sigma_variation));
  doc.Add("undetermined", MachineDoc::Texts(check.undetermined, MachineDoc::Style::kBlock));
  MachineDoc rows = MachineDoc::List(MachineDoc::Style::kBlock);
  for (size_t i = 0; i < check.rows.size(); ++i) {
    const PlanRow& row = check.rows[i];
    MachineDoc r = MachineDoc::Map(MachineDoc::Style::kFlow);
    r.Add("name", MachineDoc::Text(row.name)).Add("group", MachineDoc::Text(row.group));
    r.Add("term", MachineDoc::Integer(row.term)).Add("unit", MachineDoc::Text(row.unit));
    r.Add("sigma", MachineDoc::Number(row.sigma)).Add("sigma_range", MachineDoc::Number(row.sigma_range));
    r.Add("sigma_worst", MachineDoc::Number(check.sigma_worst[i]));
    if (row.tolerance > 0.0) {
      r.Add("tolerance", MachineDoc::Number(row.tolerance)).Add("ratio", MachineDoc::Number(row.ratio));
    }
    rows.Push(std::move(r));
  }
  doc.Add("rows", std::move(rows));
  MachineDoc alternatives = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const HandCheck::Alternative& a : check.alternatives) {
    MachineDoc m = MachineDoc::Map(MachineDoc::Style::kFlow);
    m.Add("option", MachineDoc::Text(a.option)).Add("session_s", MachineDoc::Number(a.session_s));
    m.Add("worst_ratio", MachineDoc::Number(a.worst_ratio)).Add("meets", MachineDoc::Bool(a.meets));
    alternatives.Push(std::move(m));
  }
  doc.Add("alternatives", std::move(alternatives));
  MachineDoc judged = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const PlanCriterion& c : criteria) {
    MachineDoc m = MachineDoc::Map(MachineDoc::Style::kFlow);
    m.Add("name", MachineDoc::Text(c.name)).Add("unit", MachineDoc::Text(c.unit));
    if (c.noise) {
      m.Add("needed_s", MachineDoc::Number(c.needed_s)).Add("stretch_s", MachineDoc::Number(c.stretch_s));
    } else {
      m.Add("tolerance", MachineDoc::Number(c.tolerance)).Add("expanded", MachineDoc::Number(c.expanded));
      m.Add("ratio", MachineDoc::Number(c.ratio));
    }
    m.Add("met", MachineDoc::Bool(c.met));
    judged.Push(std::move(m));
  }
  doc.Add("criteria", std::move(judged));
  return json ? JsonText(doc) : YamlText(doc);
}

}  // namespace imufit
