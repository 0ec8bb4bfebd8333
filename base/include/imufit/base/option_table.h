// imufit — an options struct described once. Each option of a struct (FitOptions, WindowOptions,
// SimulationOptions, ...) is one entry of its table: the key (the Python keyword and the fingerprint
// key), the command-line flag, the help text, the unit, the field, and the values it may take. From
// the table are derived the command's options (app/cli_options.h), the Python keywords
// (python/src/keyword_options.h), the struct's Validate() messages (ValidateOptions below) and the
// batch fingerprint (FitRunOptions::Describe()). (mrcal lists its optimizer flags and lens models
// once, as X-macro lists, for the same reason: a fact kept by hand in several places drifts.)
//
// A table of a struct that holds other option structs includes their tables (Include): an option
// of WindowOptions is described once, in WindowOptionTable(), and reaches FitRunOptions from there.
//
// This header knows no command line, no Python and no file: the values are SI, as the struct holds
// them. An option typed in another unit on the command line names it (CliUnit); the command converts.
#ifndef IMUFIT_BASE_OPTION_TABLE_H_
#define IMUFIT_BASE_OPTION_TABLE_H_

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace imufit {

// How a number is typed on the command line when not in the struct's unit (the struct is SI; the
// conversions are io/units.h's, applied by the command).
enum class CliUnit {
  kAsStruct,    // as the struct holds it
  kDegPerHour,  // the struct holds rad/s
  kMicroG,      // the struct holds m/s^2
};

// A number as option messages show it: "-5", "0.25", "1e-08", "inf", "nan".
inline std::string OptionNumberText(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

// The values a number may take: from `min` to `max`, each bound included unless open. NaN never
// passes; infinity passes only where a bound is an included infinity.
struct OptionRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  bool max_open = false;

  bool Contains(double value) const {
    const bool above = min_open ? value > min : value >= min;
    const bool below = max_open ? value < max : value <= max;
    return above && below;
  }
  // "must be > 0", "must be finite and >= 0", "must lie in [0, 3]".
  std::string Text() const {
    const double inf = std::numeric_limits<double>::infinity();
    const bool has_min = min > -inf;
    const bool has_max = max < inf;
    if (has_min && has_max) {
      return "must lie in " + std::string(min_open ? "(" : "[") + OptionNumberText(min) + ", " +
             OptionNumberText(max) + (max_open ? ")" : "]");
    }
    std::string text = "must be";
    if (!has_max && max_open) text += " finite";
    if (has_min) {
      text += std::string(!has_max && max_open ? " and" : "") + (min_open ? " > " : " >= ") +
              OptionNumberText(min);
    }
    if (has_max) text += (max_open ? " < " : " <= ") + OptionNumberText(max);
    return text;
  }
};

// The ranges most options use.
inline OptionRange Positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
inline OptionRange NonNegative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
inline OptionRange AtLeast(double min) {
  return {min, std::numeric_limits<double>::infinity(), false, false};
}
// Positive and not infinite (a rate or a duration the run is built from).
inline OptionRange PositiveFinite() { return {0.0, std::numeric_limits<double>::infinity(), true, true}; }
inline OptionRange NonNegativeFinite() { return {0.0, std::numeric_limits<double>::infinity(), false, true}; }
inline OptionRange Between(double min, double max, bool min_open = false, bool max_open = false) {
  return {min, max, min_open, max_open};
}

// The kinds of option. Each reads and writes its struct through accessors, and can be lifted into
// a struct that holds its own (Lift: `part` gives the inner struct of the outer).

// A number field (double, int, std::uint64_t) with its range.
template <typename Options, typename T>
struct NumberOption {
  std::function<T&(Options&)> field;
  OptionRange range;
  CliUnit cli_unit = CliUnit::kAsStruct;

  T Get(const Options& options) const { return field(const_cast<Options&>(options)); }
  template <typename Outer>
  NumberOption<Outer, T> Lift(const std::function<Options&(Outer&)>& part) const {
    return {[f = field, part](Outer& o) -> T& { return f(part(o)); }, range, cli_unit};
  }
};

// A bool field. On the command line a flag sets it to true, or to false when `cli_negates` (a flag
// such as --no-g-sensitivity for a field that is true by default).
template <typename Options>
struct FlagOption {
  std::function<bool&(Options&)> field;
  bool cli_negates = false;

  bool Get(const Options& options) const { return field(const_cast<Options&>(options)); }
  template <typename Outer>
  FlagOption<Outer> Lift(const std::function<Options&(Outer&)>& part) const {
    return {[f = field, part](Outer& o) -> bool& { return f(part(o)); }, cli_negates};
  }
};

// A number that may be absent (then `absent` says what stands in for it, e.g. "column").
template <typename Options>
struct OptionalNumberOption {
  std::function<std::optional<double>&(Options&)> field;
  OptionRange range;
  const char* absent = "none";

  std::optional<double> Get(const Options& options) const { return field(const_cast<Options&>(options)); }
  template <typename Outer>
  OptionalNumberOption<Outer> Lift(const std::function<Options&(Outer&)>& part) const {
    return {[f = field, part](Outer& o) -> std::optional<double>& { return f(part(o)); }, range, absent};
  }
};

// A list of numbers: any number of them (count 0), or exactly `count` or none (then the option is
// off: an empty list).
template <typename Options>
struct NumbersOption {
  std::function<std::vector<double>(const Options&)> get;
  std::function<void(const std::vector<double>&, Options*)> set;
  std::size_t count = 0;

  std::vector<double> Get(const Options& options) const { return get(options); }
  template <typename Outer>
  NumbersOption<Outer> Lift(const std::function<Options&(Outer&)>& part) const {
    return {[g = get, part](const Outer& o) { return g(part(const_cast<Outer&>(o))); },
            [s = set, part](const std::vector<double>& v, Outer* o) { s(v, &part(*o)); }, count};
  }
};

// A value typed as text and parsed by the option itself (a name, a list of names, a path). `set`
// returns "" or what is wrong with the text. A `path` is a file name.
template <typename Options>
struct TextOption {
  std::function<std::string(const Options&)> get;
  std::function<std::string(const std::string&, Options*)> set;
  bool path = false;

  std::string Get(const Options& options) const { return get(options); }
  template <typename Outer>
  TextOption<Outer> Lift(const std::function<Options&(Outer&)>& part) const {
    return {[g = get, part](const Outer& o) { return g(part(const_cast<Outer&>(o))); },
            [s = set, part](const std::string& v, Outer* o) { return s(v, &part(*o)); }, path};
  }
};

// What an option adds to the fingerprint of a fit (FitRunOptions::Describe(), the batch manifest's
// record of what a unit was fitted with).
enum class Fingerprint {
  kValue,   // "key=value"
  kCustom,  // OptionEntry::describe: "key=value", or "" when another entry's text holds it
  kNone,    // nothing: the option cannot change what a fit gives (threads)
};

template <typename Options>
struct OptionEntry {
  using Value = std::variant<NumberOption<Options, double>, NumberOption<Options, int>,
                             NumberOption<Options, std::uint64_t>, FlagOption<Options>,
                             OptionalNumberOption<Options>, NumbersOption<Options>, TextOption<Options>>;

  std::string key;   // Python keyword and fingerprint key: snake_case, unit suffix, SI
  std::string flag;  // on the command line, e.g. "--trim"; "" when not on the command line
  std::string help;  // what the option changes, without its unit
  std::string unit;  // the struct's unit, e.g. "s", "rad/s"; "" for counts, ratios and names
  Value value;
  Fingerprint fingerprint = Fingerprint::kValue;
  std::function<std::string(const Options&)> describe;  // with Fingerprint::kCustom
  bool repeatable = false;  // a text option given several times on the command line: its values, a line each

  // The help with the unit: "seconds dropped ..., s".
  std::string HelpWithUnit(const std::string& shown_unit) const {
    return shown_unit.empty() ? help : help + ", " + shown_unit;
  }
};

template <typename Options>
class OptionTable {
 public:
  using Entry = OptionEntry<Options>;

  const std::vector<Entry>& entries() const { return entries_; }
  // The entry of `key`, nullptr when none.
  const Entry* Find(const std::string& key) const {
    for (const Entry& e : entries_) {
      if (e.key == key) return &e;
    }
    return nullptr;
  }

  // Each adder appends one entry and returns it, for the entry's less common fields (fingerprint).
  template <typename T>
  Entry& Number(const char* key, const char* flag, const std::string& help, const char* unit,
                T Options::*member, OptionRange range = {}, CliUnit cli_unit = CliUnit::kAsStruct) {
    return Add(key, flag, help, unit,
               NumberOption<Options, T>{[member](Options& o) -> T& { return o.*member; }, range, cli_unit});
  }
  Entry& Flag(const char* key, const char* flag, const std::string& help, bool Options::*member,
              bool cli_negates = false) {
    return Add(key, flag, help, "",
               FlagOption<Options>{[member](Options& o) -> bool& { return o.*member; }, cli_negates});
  }
  Entry& OptionalNumber(const char* key, const char* flag, const std::string& help, const char* unit,
                        std::optional<double> Options::*member, OptionRange range, const char* absent) {
    return Add(key, flag, help, unit,
               OptionalNumberOption<Options>{
                   [member](Options& o) -> std::optional<double>& { return o.*member; }, range, absent});
  }
  Entry& Numbers(const char* key, const char* flag, const std::string& help, const char* unit,
                 std::function<std::vector<double>(const Options&)> get,
                 std::function<void(const std::vector<double>&, Options*)> set, std::size_t count = 0) {
    return Add(key, flag, help, unit, NumbersOption<Options>{std::move(get), std::move(set), count});
  }
  Entry& Text(const char* key, const char* flag, const std::string& help,
              std::function<std::string(const Options&)> get,
              std::function<std::string(const std::string&, Options*)> set, bool path = false) {
    return Add(key, flag, help, "", TextOption<Options>{std::move(get), std::move(set), path});
  }
  // A text field taken as it is typed (a name, a path, a pattern).
  Entry& String(const char* key, const char* flag, const std::string& help, std::string Options::*member,
                bool path = false) {
    return Text(
        key, flag, help, [member](const Options& o) { return o.*member; },
        [member](const std::string& text, Options* o) {
          o->*member = text;
          return std::string();
        },
        path);
  }

  // Moves the entry of `key` to just after that of `after` (both must exist): a table that includes
  // another places its own entries among the included ones.
  void MoveAfter(const std::string& key, const std::string& after) {
    const auto index = [this](const std::string& k) {
      std::size_t i = 0;
      while (i < entries_.size() && entries_[i].key != k) ++i;
      return i;
    };
    std::size_t from = index(key);
    const std::size_t to = index(after) + 1;
    if (from >= entries_.size() || to > entries_.size()) return;
    Entry moved = std::move(entries_[from]);
    entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(from));
    entries_.insert(entries_.begin() + static_cast<std::ptrdiff_t>(to > from ? to - 1 : to),
                    std::move(moved));
  }

  // Appends every entry of `inner`, the table of the struct `member` of Options.
  template <typename Inner>
  void Include(const OptionTable<Inner>& inner, Inner Options::*member) {
    const std::function<Inner&(Options&)> part = [member](Options& o) -> Inner& { return o.*member; };
    for (const OptionEntry<Inner>& e : inner.entries()) {
      Entry lifted;
      lifted.key = e.key;
      lifted.flag = e.flag;
      lifted.help = e.help;
      lifted.unit = e.unit;
      lifted.value =
          std::visit([&part](const auto& kind) -> typename Entry::Value { return kind.Lift(part); }, e.value);
      lifted.fingerprint = e.fingerprint;
      lifted.repeatable = e.repeatable;
      if (e.describe) {
        lifted.describe = [d = e.describe, part](const Options& o) {
          return d(part(const_cast<Options&>(o)));
        };
      }
      entries_.push_back(std::move(lifted));
    }
  }

 private:
  Entry& Add(const char* key, const char* flag, const std::string& help, const char* unit,
             typename Entry::Value value) {
    Entry e;
    e.key = key;
    e.flag = flag;
    e.help = help;
    e.unit = unit;
    e.value = std::move(value);
    entries_.push_back(std::move(e));
    return entries_.back();
  }
  std::vector<Entry> entries_;
};

// "" when every number of `options` lies in its entry's range, else the first that does not, naming
// the option and its value: "loss_scale = -1: must be > 0 (where the robust loss acts, ...)".
template <typename Options>
std::string ValidateOptions(const OptionTable<Options>& table, const Options& options) {
  const auto problem = [](const OptionEntry<Options>& e, double value,
                          const OptionRange& range) -> std::string {
    if (range.Contains(value)) return "";
    return e.key + " = " + OptionNumberText(value) + ": " + range.Text() + " (" + e.HelpWithUnit(e.unit) +
           ")";
  };
  for (const OptionEntry<Options>& e : table.entries()) {
    const std::string found = std::visit(
        [&](const auto& kind) -> std::string {
          using Kind = std::decay_t<decltype(kind)>;
          if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
            const std::optional<double> value = kind.Get(options);
            return value ? problem(e, *value, kind.range) : "";
          } else if constexpr (std::is_same_v<Kind, NumberOption<Options, double>> ||
                               std::is_same_v<Kind, NumberOption<Options, int>> ||
                               std::is_same_v<Kind, NumberOption<Options, std::uint64_t>>) {
            return problem(e, static_cast<double>(kind.Get(options)), kind.range);
          } else {
            return "";
          }
        },
        e.value);
    if (!found.empty()) return found;
  }
  return "";
}

}  // namespace imufit

#endif  // IMUFIT_BASE_OPTION_TABLE_H_
