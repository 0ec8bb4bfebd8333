#include "imufit/factory/lot_summary.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "imufit/base/text.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/git_revision.h"
#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"

namespace imufit {

std::vector<RobustZ> RobustZScores(const std::vector<double>& values, const std::vector<double>& sigmas) {
  std::vector<RobustZ> scores(values.size());
  if (values.size() < 3) return scores;
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  const double m = median(values);
  std::vector<double> deviations;
  for (double v : values) deviations.push_back(std::abs(v - m));
  const double mad = median(deviations);
  for (size_t i = 0; i < values.size(); ++i) {
    if (!(mad > 0.0)) continue;  // half the lot identical: no spread to judge by
    scores[i].z = 0.6745 * (values[i] - m) / mad;
    const bool beyond_own_sigma =
        i >= sigmas.size() || !(sigmas[i] > 0.0) || std::abs(values[i] - m) > kOutlierOwnSigmas * sigmas[i];
    scores[i].outlier = std::abs(scores[i].z) > kOutlierRobustZ && beyond_own_sigma;
  }
  return scores;
}

std::optional<std::array<double, 2>> CapabilityInterval(double ppk, int n) {
  if (n < 2) return std::nullopt;
  const double half = kCapabilityZ * std::sqrt(1.0 / (9.0 * n) + ppk * ppk / (2.0 * (n - 1)));
  return std::array<double, 2>{ppk - half, ppk + half};
}

std::vector<std::string> LotFigureNames(const BatchResult& batch) {
  std::vector<std::string> names;
  for (const UnitOutcome& u : batch.units) {
    for (const Figure& f : u.figures) {
      if (std::find(names.begin(), names.end(), f.name) == names.end()) names.push_back(f.name);
    }
  }
  return names;
}

namespace {

// A number's cell: empty when it is not finite or (`known`) not known.
std::string NumberCell(double value, bool known = true) {
  return known && std::isfinite(value) ? FormatDouble(value) : "";
}

}  // namespace

std::string LotSummaryCsv(const BatchResult& batch) {
  const std::vector<std::string> names = LotFigureNames(batch);
  std::string csv = "unit,serial,status,verdict,message,calibrated_utc";
  for (const std::string& name : names) csv += "," + name + "," + name + ".sigma," + name + ".U";
  csv += "\n";
  for (const UnitOutcome& u : batch.units) {
    csv += CsvCell(u.unit) + "," + CsvCell(u.serial) + "," + CsvCell(u.StatusText()) + "," +
           CsvCell(u.VerdictText()) + "," + CsvCell(u.message) + "," + CsvCell(u.calibrated_utc);
    for (const std::string& name : names) {
      const Figure* f = FindFigure(u.figures, name);
      if (f == nullptr) {
        csv += ",,,";
        continue;
      }
      csv += "," + NumberCell(f->value) + "," + NumberCell(f->sigma, f->sigma >= 0.0) + "," +
             NumberCell(f->expanded, f->sigma >= 0.0 && f->expanded >= 0.0);
    }
    csv += "\n";
  }
  return csv;
}

namespace {

// Whether `unit` failed a criterion about the figure `name`: "|name|", "sigma(name)" or "name".
bool FailedOn(const UnitOutcome& unit, const std::string& name) {
  if (!unit.verdict) return false;
  for (const CriterionResult& c : unit.verdict->criteria) {
    if (c.pass) continue;
    if (c.name == name || c.name == "|" + name + "|" || c.name == "sigma(" + name + ")") return true;
  }
  return false;
}

// The longest prefix every name shares, cut back to a boundary (after a character that is not a
// letter or digit, or between a letter and a digit) and leaving every name at least one character:
// "unit-01", "unit-02" -> "unit-"; "SN1001", "SN1002" -> "SN"; "a", "b" -> "".
std::string SharedPrefix(const std::vector<std::string>& names) {
  if (names.size() < 2) return "";
  size_t length = names.front().size();
  for (const std::string& n : names) {
    length = std::min(length, n.size() - (n.empty() ? 0 : 1));
    size_t i = 0;
    while (i < length && n[i] == names.front()[i]) ++i;
    length = i;
  }
  const std::string& first = names.front();
  const auto alnum = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; };
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  while (length > 0) {
    const char before = first[length - 1];
    const char after = first[length];
    if (!alnum(before) || (!digit(before) && digit(after))) break;
    --length;
  }
  return first.substr(0, length);
}

// One key figure over the lot: a value per unit that has it, its spread, capability and outliers.
LotFigure FigureOverLot(const std::string& name, const BatchResult& batch,
                        const std::optional<Limits>& limits) {
  LotFigure f;
  f.name = name;
  if (limits) f.limits = FigureLimits(name, *limits);
  f.plotted = std::find(kSummaryFigures.begin(), kSummaryFigures.end(), name) != kSummaryFigures.end();
  for (size_t row = 0; row < batch.units.size(); ++row) {
    const UnitOutcome& u = batch.units[row];
    const Figure* figure = FindFigure(u.figures, name);
    if (figure == nullptr) continue;
    f.unit = figure->unit;
    f.units.push_back(u.unit);
    f.row.push_back(static_cast<int>(row));
    f.value.push_back(figure->value);
    f.sigma.push_back(figure->sigma);
    f.failed.push_back(u.verdict && !u.verdict->pass);
    f.outside_limits.push_back(f.limits && ((f.limits->lower && !(figure->value > *f.limits->lower)) ||
                                            (f.limits->upper && !(figure->value < *f.limits->upper))));
    f.plotted = f.plotted || f.outside_limits.back() || FailedOn(u, name);
  }
  if (f.value.empty()) return f;
  f.z = RobustZScores(f.value, f.sigma);
  const MeanSigma m = MeanAndSigma(f.value);
  f.mean = m.mean;
  f.stdev = m.sigma;
  f.three_sigma = {f.mean - 3.0 * f.stdev, f.mean + 3.0 * f.stdev};
  f.stdev_within = WithinSigma(f.value);
  if (f.limits) {
    f.ppk = Capability(f.mean, f.stdev, *f.limits);
    f.cpk = Capability(f.mean, f.stdev_within, *f.limits);
  }
  const int n = static_cast<int>(f.value.size());
  f.few_units = n < kCapabilityMinUnits;
  if (f.ppk) f.ppk_interval = CapabilityInterval(*f.ppk, n);
  const auto [low, high] = std::minmax_element(f.value.begin(), f.value.end());
  f.view = ViewWithLimits(std::min(*low, f.three_sigma[0]), std::max(*high, f.three_sigma[1]), f.limits);
  return f;
}

}  // namespace

LotSummary MakeLotSummary(const std::string& lot, const BatchResult& batch, const std::string& software,
                          const std::optional<Limits>& limits) {
  LotSummary s;
  s.lot = lot;
  s.written_utc = UtcNow();
  s.software = software;
  s.git_revision = GitRevision();
  if (limits) {
    s.limits_name = limits->name.empty() ? limits->path : limits->name;
    s.decision_rule = DecisionRuleText(limits->decision_rule, limits->guard_band_u);  // as each certificate
  }
  s.units = static_cast<int>(batch.units.size());
  s.passed = batch.passed;
  s.failed = batch.failed;
  s.not_fitted = batch.not_fitted;
  s.errors = batch.errors;
  // Without limits no unit is judged: the yield is not 0 %, it is not known (nan: "not judged").
  s.yield_pct = !limits ? std::nan("") : s.units > 0 ? 100.0 * batch.passed / s.units : 0.0;
  std::vector<std::string> names;
  for (const UnitOutcome& u : batch.units) {
    names.push_back(u.unit);
    s.conditional += u.verdict && u.verdict->Conditional() > 0 ? 1 : 0;
  }
  s.unit_prefix = SharedPrefix(names);
  for (const UnitOutcome& u : batch.units) {
    s.rows.push_back({u.unit, u.serial, u.StatusText(), u.VerdictText(), u.message,
                      u.status == UnitStatus::kFitted, u.unit.substr(s.unit_prefix.size())});
  }
  s.figure_names = LotFigureNames(batch);
  for (const std::string& name : s.figure_names) {
    LotFigure f = FigureOverLot(name, batch, limits);
    if (f.value.empty()) continue;
    for (size_t i = 0; i < f.value.size(); ++i) {
      if (!f.z[i].outlier) continue;
      s.outliers.push_back({f.units[i], batch.units[f.row[i]].serial, name, f.unit, f.value[i], f.z[i].z});
    }
    s.figures.push_back(std::move(f));
  }
  return s;
}

}  // namespace imufit
