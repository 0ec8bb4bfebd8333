// imufit — the command-line options of an option table (base/option_table.h): each entry with a
// flag becomes an option of the command (cli.h) with the entry's help, unit and default; after parsing,
// Apply() sets the options given into the struct, converted to SI. Options not given keep the struct's
// defaults, so that the command and the library cannot disagree about them.
#ifndef IMUFIT_APP_CLI_OPTIONS_H_
#define IMUFIT_APP_CLI_OPTIONS_H_

#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "cli.h"
#include "imufit/base/option_table.h"
#include "imufit/io/error.h"
#include "imufit/io/units.h"

namespace imufit {

// The units a number may be typed in on the command line, with io/units.h's conversions.
struct CliUnitConversion {
  CliUnit unit;
  const char* name;
  double (*si_from_cli)(double);
  double (*cli_from_si)(double);
};
inline const CliUnitConversion kCliUnitConversions[] = {
    {CliUnit::kDegPerHour, "deg/h", RadpsFromDph, DphFromRadps},
    {CliUnit::kMicroG, "micro-g", Mps2FromUg, UgFromMps2},
};
inline const CliUnitConversion* FindCliUnit(CliUnit unit) {
  for (const CliUnitConversion& c : kCliUnitConversions) {
    if (c.unit == unit) return &c;
  }
  return nullptr;  // CliUnit::kAsStruct
}
inline double SiFromCli(CliUnit unit, double value) {
  const CliUnitConversion* c = FindCliUnit(unit);
  return c != nullptr ? c->si_from_cli(value) : value;
}
inline double CliFromSi(CliUnit unit, double value) {
  const CliUnitConversion* c = FindCliUnit(unit);
  return c != nullptr ? c->cli_from_si(value) : value;
}
// The name of the unit a value is typed in: `si_unit` unless converted.
inline std::string CliUnitName(CliUnit unit, const std::string& si_unit) {
  const CliUnitConversion* c = FindCliUnit(unit);
  return c != nullptr ? c->name : si_unit;
}

template <typename Options>
class CliOptions {
 public:
  using Entry = OptionEntry<Options>;

  // Adds every entry of `table` that has a flag, but those whose keys are in `except`.
  void Add(CliCommand command, const OptionTable<Options>& table, const std::set<std::string>& except = {}) {
    for (const Entry& entry : table.entries()) {
      if (!entry.flag.empty() && except.count(entry.key) == 0) AddEntry(command, entry);
    }
  }
  // Adds the entry of `key` alone.
  void AddOne(CliCommand command, const OptionTable<Options>& table, const std::string& key) {
    const Entry* entry = table.Find(key);
    if (entry != nullptr && !entry->flag.empty()) AddEntry(command, *entry);
  }

  // The option of `key` (for constraints between options), null when not added.
  CliOption Find(const std::string& key) const {
    for (const auto& b : bindings_) {
      if (b->entry->key == key) return b->option;
    }
    return CliOption();
  }
  // Whether the option of `key` was given on the command line.
  bool Given(const std::string& key) const { return Find(key).Given(); }

  // The text given for the option of `key` (a path, a name), "" when not given.
  std::string GivenText(const std::string& key) const {
    for (const auto& b : bindings_) {
      if (b->entry->key == key) return b->option.Given() ? b->text : "";
    }
    return "";
  }

  // Sets every option given on the command line in `options`, in SI. A text the option refuses
  // (a bad name) throws InputError naming the flag.
  void Apply(Options* options) const {
    for (const auto& b : bindings_) {
      if (b->option.Given()) Set(*b, options);
    }
  }

 private:
  // One option: its entry and where CLI11 puts what it parses.
  struct Binding {
    const Entry* entry = nullptr;
    CliOption option;
    double number = 0.0;
    int integer = 0;
    std::uint64_t unsigned_integer = 0;
    bool flag = false;
    std::string text;
    std::vector<double> numbers;
  };

  template <typename T>
  static std::string Text(const T& value) {
    std::ostringstream text;
    text << value;
    return text.str();
  }

  void AddEntry(CliCommand command, const Entry& entry) {
    auto binding = std::make_shared<Binding>();
    Binding& b = *binding;
    b.entry = &entry;
    const Options defaults{};
    std::visit(
        [&](const auto& kind) {
          using Kind = std::decay_t<decltype(kind)>;
          const auto help = [&entry](const std::string& unit) { return entry.HelpWithUnit(unit); };
          if constexpr (std::is_same_v<Kind, NumberOption<Options, double>>) {
            b.option = command.Option(entry.flag, &b.number, help(CliUnitName(kind.cli_unit, entry.unit)));
            b.option.DefaultText(Text(CliFromSi(kind.cli_unit, kind.Get(defaults))));
          } else if constexpr (std::is_same_v<Kind, NumberOption<Options, int>>) {
            b.option = command.Option(entry.flag, &b.integer, help(entry.unit));
            b.option.DefaultText(Text(kind.Get(defaults)));
          } else if constexpr (std::is_same_v<Kind, NumberOption<Options, std::uint64_t>>) {
            b.option = command.Option(entry.flag, &b.unsigned_integer, help(entry.unit));
            b.option.DefaultText(Text(kind.Get(defaults)));
          } else if constexpr (std::is_same_v<Kind, FlagOption<Options>>) {
            b.option =
                command.Flag(entry.flag, &b.flag, (kind.cli_negates ? "turns off: " : "") + entry.help);
          } else if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
            b.option = command.Option(entry.flag, &b.number, help(entry.unit));
          } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
            std::string shown;
            for (double value : kind.Get(defaults)) shown += (shown.empty() ? "" : ",") + Text(value);
            b.option = command.Option(entry.flag, &b.numbers, help(entry.unit));
            b.option.Delimiter(',');
            if (kind.count > 0) b.option.Expected(static_cast<int>(kind.count));
            if (!shown.empty()) b.option.DefaultText(shown);
          } else {
            b.option = command.Option(entry.flag, &b.text, entry.help);
            if (entry.repeatable) b.option.JoinRepeated();
            if (const std::string shown = kind.Get(defaults); !shown.empty()) b.option.DefaultText(shown);
          }
        },
        entry.value);
    bindings_.push_back(std::move(binding));
  }

  static void Set(const Binding& b, Options* options) {
    std::visit(
        [&](const auto& kind) {
          using Kind = std::decay_t<decltype(kind)>;
          if constexpr (std::is_same_v<Kind, NumberOption<Options, double>>) {
            kind.field(*options) = SiFromCli(kind.cli_unit, b.number);
          } else if constexpr (std::is_same_v<Kind, NumberOption<Options, int>>) {
            kind.field(*options) = b.integer;
          } else if constexpr (std::is_same_v<Kind, NumberOption<Options, std::uint64_t>>) {
            kind.field(*options) = b.unsigned_integer;
          } else if constexpr (std::is_same_v<Kind, FlagOption<Options>>) {
            kind.field(*options) = kind.cli_negates ? !b.flag : b.flag;
          } else if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
            kind.field(*options) = b.number;
          } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
            kind.set(b.numbers, options);
          } else {
            if (const std::string error = kind.set(b.text, options); !error.empty()) {
              throw InputError(b.entry->flag.substr(0, b.entry->flag.find(',')), error);
            }
          }
        },
        b.entry->value);
  }

  // Shared, so that a copy of the arguments (taken after parsing) reads the same values.
  std::vector<std::shared_ptr<Binding>> bindings_;
};

}  // namespace imufit

#endif  // IMUFIT_APP_CLI_OPTIONS_H_
