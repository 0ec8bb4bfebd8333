// The option tables of a run (SamplesInput, FitRunOptions), FitRunOptions::Validate() and its
// fingerprint, Describe(): all derived from the tables (model/option_table.h).
#include <algorithm>
#include <iterator>
#include <type_traits>

#include "imufit/base/enum_names.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/pipeline/fit_run.h"

namespace imufit {
namespace {

// The delimiters --delimiter takes, by the name it is typed with.
struct DelimiterName {
  char value;
  const char* name;
};
constexpr DelimiterName kDelimiterNames[] = {{',', ","}, {';', ";"}, {'\t', "tab"}};

// How the fields and numbers of a file are written. Not in the fingerprint: a file reads in one
// dialect only, and to the same samples in it.
OptionTable<CsvDialect> MakeCsvDialectOptionTable() {
  OptionTable<CsvDialect> t;
  OptionEntry<CsvDialect>& delimiter = t.Text(
      "delimiter", "--delimiter",
      "what separates the fields: ',' (default), ';' or tab (a spreadsheet's export in a German or French "
      "locale has ';')",
      [](const CsvDialect& d) { return std::string(NameOf(kDelimiterNames, d.delimiter)); },
      [](const std::string& text, CsvDialect* d) {
        if (text == "\t") d->delimiter = '\t';  // a tab typed as itself
        if (text == "\t" || ValueOf(kDelimiterNames, text, &d->delimiter)) return std::string();
        return "delimiter " + QuoteForMessage(text) + " is not one of: " + AllNames(kDelimiterNames);
      });
  delimiter.fingerprint = Fingerprint::kNone;
  t.Flag("decimal_comma", "--decimal-comma",
         "numbers are written with a decimal comma (1,5); needs --delimiter ';' or tab",
         &CsvDialect::decimal_comma)
      .fingerprint = Fingerprint::kNone;
  return t;
}

// "time_s=Time,temp_c=T" (or one pair a line: --column given several times) as ColumnNames.
std::string SetColumnNames(const std::string& text, SamplesInput* in) {
  in->column_names.clear();
  std::string pair;
  for (size_t start = 0; start <= text.size();) {
    const size_t end = std::min(text.find_first_of(",\n", start), text.size());
    pair = text.substr(start, end - start);
    start = end + 1;
    if (pair.empty()) continue;
    const size_t equals = pair.find('=');
    const std::string name = pair.substr(0, std::min(equals, pair.size()));
    if (equals == std::string::npos || equals + 1 == pair.size()) {
      return "column " + QuoteForMessage(pair) + " is not NAME=COLUMN (e.g. time_s=Time)";
    }
    if (std::find(std::begin(kSamplesColumnNames), std::end(kSamplesColumnNames), name) ==
        std::end(kSamplesColumnNames)) {
      std::string names;
      for (const char* known : kSamplesColumnNames) names += (names.empty() ? "" : ", ") + std::string(known);
      return "column " + QuoteForMessage(name) + " is not one imufit reads: " + names;
    }
    for (const ColumnName& given : in->column_names) {
      if (given.name == name) return "column " + QuoteForMessage(name) + " is mapped twice";
    }
    in->column_names.push_back({name, pair.substr(equals + 1)});
  }
  return "";
}

std::string ColumnNamesText(const SamplesInput& in) {
  std::string text;
  for (const ColumnName& column : in.column_names) {
    text += (text.empty() ? "" : ",") + column.name + "=" + column.in_file;
  }
  return text;
}

OptionTable<SamplesInput> MakeSamplesInputOptionTable() {
  OptionTable<SamplesInput> t;
  t.OptionalNumber("temp_c", "--temp-c",
                   "the temperature of every sample, for samples without a temp_c column (a run without a "
                   "thermometer); a file with the column is refused",
                   "degC", &SamplesInput::temp_c, Between(kMinPlausibleTempC, kMaxPlausibleTempC), "column");
  OptionEntry<SamplesInput>& time_unit = t.Text(
      "time_unit", "--time-unit",
      "the unit of the time_s column: s (default), ms, us or ns (a logger's clock in milliseconds, say); "
      "read as seconds, a finer unit gives an implausible sample rate and is refused",
      [](const SamplesInput& in) { return std::string(NameOf(kTimeUnitNames, in.seconds_per_time_unit)); },
      [](const std::string& text, SamplesInput* in) {
        if (ValueOf(kTimeUnitNames, text, &in->seconds_per_time_unit)) return std::string();
        return "time_unit " + QuoteForMessage(text) + " is not one of: " + AllNames(kTimeUnitNames);
      });
  // In the fingerprint (another unit reads another run), but a run in seconds keeps the fingerprint
  // it had before the option existed.
  time_unit.fingerprint = Fingerprint::kCustom;
  time_unit.describe = [](const SamplesInput& in) {
    return in.seconds_per_time_unit == 1.0
               ? ""
               : "time_unit=" + std::string(NameOf(kTimeUnitNames, in.seconds_per_time_unit));
  };
  t.Include(MakeCsvDialectOptionTable(), &SamplesInput::dialect);
  OptionEntry<SamplesInput>& columns =
      t.Text("column", "--column",
             "a column the file names its own way, NAME=COLUMN (time_s=Time); repeat it, or separate pairs "
             "with ','",
             ColumnNamesText, SetColumnNames);
  columns.repeatable = true;
  // Another map reads other numbers as the same column: in the fingerprint, when given.
  columns.fingerprint = Fingerprint::kCustom;
  columns.describe = [](const SamplesInput& in) {
    return in.column_names.empty() ? "" : "column=" + ColumnNamesText(in);
  };
  t.Include(SegmentationOptionTable(), &SamplesInput::segmentation);
  return t;
}

// The held groups' values: "nominal", or a prior named by a SHA-256 of its numbers, so that an
// edited prior file counts as changed and a copy elsewhere does not.
std::string HeldText(const FitOptions& fit) {
  if (!fit.held) return "nominal";
  std::string values =
      FormatDouble(fit.held->basis.center_c) + " " + FormatDouble(fit.held->basis.half_range_c);
  for (double value : fit.held->gyro) values += " " + FormatDouble(value);
  for (double value : fit.held->accel) values += " " + FormatDouble(value);
  return "prior " + Sha256Hex(values);
}

// The accessors of a path option kept as given.
auto PathGetter(std::string FitRunOptions::*member) {
  return [member](const FitRunOptions& o) { return o.*member; };
}
auto PathSetter(std::string FitRunOptions::*member) {
  return [member](const std::string& path, FitRunOptions* o) {
    o->*member = path;
    return std::string();
  };
}

OptionTable<FitRunOptions> MakeFitRunOptionTable() {
  using O = FitRunOptions;
  OptionTable<O> t;
  t.Include(FitOptionTable(), &O::fit);
  OptionEntry<O>& prior = t.Text(
      "prior", "--prior",
      "calibration YAML whose values the held groups keep (without it: a sensor fitted in part is "
      "refused, a sensor held whole is scale 1, the rest 0, recorded as not calibrated)",
      [](const O&) { return std::string(); },
      [](const std::string& path, O* o) {
        o->fit.held = path.empty() ? std::nullopt : std::optional<SensorModel>(ReadCalibration(path).model);
        return std::string();
      },
      /*path=*/true);
  prior.fingerprint = Fingerprint::kCustom;
  prior.describe = [](const O& o) { return o.fit.Groups(false).empty() ? "" : "held=" + HeldText(o.fit); };
  t.MoveAfter("prior", "fit");
  t.Include(WindowOptionTable(), &O::windows);
  t.Include(SamplesInputOptionTable(), &O::input);
  t.Flag("validate", "--validate",
         "leave each interior temperature out in turn, refit, and report the errors on it", &O::validate);
  OptionEntry<O>& check =
      t.Text("check_samples", "--check-samples", "a held-out run to report the calibration's errors on",
             PathGetter(&O::check_samples), PathSetter(&O::check_samples), /*path=*/true);
  check.fingerprint = Fingerprint::kCustom;
  check.describe = [](const O& o) {
    return o.check_samples.empty() ? "" : "check=" + o.check_samples + " " + o.check_plan;
  };
  OptionEntry<O>& check_plan =
      t.Text("check_plan", "--check-plan", "the plan of check_samples (default: the fitted run's)",
             PathGetter(&O::check_plan), PathSetter(&O::check_plan), /*path=*/true);
  check_plan.fingerprint = Fingerprint::kCustom;  // in `check`
  check_plan.describe = [](const O&) { return std::string(); };
  // In the fingerprint only when set: a lot fitted before the option existed is not redone.
  OptionEntry<O>& write_inconsistent =
      t.Flag("write_inconsistent", "--write-inconsistent",
             "write the calibration even when the fit is inconsistent with the run's noise (reduced "
             "chi-square beyond "
             "noise and model error, or a segment down-weighted at every temperature); it is marked so",
             &O::write_inconsistent);
  write_inconsistent.fingerprint = Fingerprint::kCustom;
  write_inconsistent.describe = [](const O& o) {
    return o.write_inconsistent ? "write_inconsistent=true" : "";
  };
  t.Include(NoiseStretchOptionTable(), &O::noise_stretch);
  t.Flag("allow_serial_mismatch", "--allow-mismatch",
         "fit even when the stated serial (--serial, a batch unit's serial.txt) names another unit than the "
         "samples header (a warning, also on the certificate); without it such a unit is refused",
         &O::allow_serial_mismatch);
  return t;
}

// An option's value as the fingerprint writes it: numbers as the shortest text that reads back
// the same double.
template <typename Options>
std::string ValueText(const OptionEntry<Options>& entry, const Options& options) {
  return std::visit(
      [&options](const auto& kind) -> std::string {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, NumberOption<Options, double>>) {
          return FormatDouble(kind.Get(options));
        } else if constexpr (std::is_same_v<Kind, NumberOption<Options, int>> ||
                             std::is_same_v<Kind, NumberOption<Options, std::uint64_t>>) {
          return std::to_string(kind.Get(options));
        } else if constexpr (std::is_same_v<Kind, FlagOption<Options>>) {
          return kind.Get(options) ? "true" : "false";
        } else if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
          const std::optional<double> value = kind.Get(options);
          return value ? FormatDouble(*value) : kind.absent;
        } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
          std::string text;
          for (double value : kind.Get(options)) text += (text.empty() ? "" : ",") + FormatDouble(value);
          return text;
        } else {
          return kind.Get(options);
        }
      },
      entry.value);
}

}  // namespace

const OptionTable<SamplesInput>& SamplesInputOptionTable() {
  static const OptionTable<SamplesInput> table = MakeSamplesInputOptionTable();
  return table;
}

const OptionTable<FitRunOptions>& FitRunOptionTable() {
  static const OptionTable<FitRunOptions> table = MakeFitRunOptionTable();
  return table;
}

std::string SamplesInput::Validate() const { return ValidateOptions(SamplesInputOptionTable(), *this); }

std::string FitRunOptions::Validate() const {
  if (std::string problem = fit.Validate(); !problem.empty()) return problem;
  if (std::string problem = windows.Validate(); !problem.empty()) return problem;
  if (std::string problem = input.Validate(); !problem.empty()) return problem;
  if (check_samples.empty() && !check_plan.empty()) return "a check plan needs check samples";
  return "";
}

std::string FitRunOptions::Describe() const {
  std::string text;
  for (const OptionEntry<FitRunOptions>& entry : FitRunOptionTable().entries()) {
    std::string item;
    if (entry.fingerprint == Fingerprint::kValue) item = entry.key + "=" + ValueText(entry, *this);
    if (entry.fingerprint == Fingerprint::kCustom) item = entry.describe(*this);
    if (!item.empty()) text += (text.empty() ? "" : "; ") + item;
  }
  return text;
}

}  // namespace imufit
