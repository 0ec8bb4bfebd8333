// imufit Python module: the keyword options of a function, from an option table
// (model/option_table.h). The keywords are the table's keys, SI as the struct holds them, with
// the table's help and the struct's defaults: a new option of FitOptions, WindowOptions,
// SamplesInput, FitRunOptions or SimulationOptions is a keyword without a line here.
#ifndef IMUFIT_PYTHON_KEYWORD_OPTIONS_H_
#define IMUFIT_PYTHON_KEYWORD_OPTIONS_H_

#include <string>
#include <type_traits>
#include <vector>

#include "binding.h"
#include "imufit/base/option_table.h"

namespace imufit::python {

// Sets `entry`'s option from a Python value. A value of the wrong type throws py::cast_error; a text
// the option refuses an InputError.
template <typename Options>
void SetKeyword(const OptionEntry<Options>& entry, const std::string& function, const py::handle& value,
                Options* options) {
  std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
          kind.field(*options) = value.is_none() ? std::nullopt : std::optional<double>(value.cast<double>());
        } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
          // A list of `count` numbers or None (off); any list without a count.
          std::vector<double> numbers;
          if (kind.count == 0 || !value.is_none()) numbers = value.cast<std::vector<double>>();
          if (kind.count > 0 && !numbers.empty() && numbers.size() != kind.count) throw py::cast_error();
          kind.set(numbers, options);
        } else if constexpr (std::is_same_v<Kind, TextOption<Options>>) {
          // A whole number (a device ID, an instance) is taken as its decimal text.
          const bool whole = py::isinstance<py::int_>(value) && !py::isinstance<py::bool_>(value);
          const std::string text = kind.path ? PathString(value)
                                   : whole   ? std::string(py::str(value))
                                             : value.cast<std::string>();
          if (const std::string error = kind.set(text, options); !error.empty())
            ThrowBadArgument(function, entry.key + " " + error);
        } else {
          kind.field(*options) =
              value.template cast<std::remove_reference_t<decltype(kind.field(*options))>>();
        }
      },
      entry.value);
}

// `entry`'s value in `options` as Python gives it: numbers, bool, None for an absent number or an
// option that is off, a tuple of a fixed count of numbers, a list, a string.
template <typename Options>
py::object KeywordValue(const OptionEntry<Options>& entry, const Options& options) {
  return std::visit(
      [&](const auto& kind) -> py::object {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
          const std::optional<double> value = kind.Get(options);
          return value ? py::cast(*value) : py::none();
        } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
          const std::vector<double> numbers = kind.Get(options);
          if (kind.count == 0) return py::cast(numbers);
          if (numbers.empty()) return py::none();
          return py::tuple(py::cast(numbers));
        } else {
          return py::cast(kind.Get(options));
        }
      },
      entry.value);
}

// Sets the options named in `kwargs`. An unknown name is a TypeError (as for any Python function)
// listing the names; a value of the wrong type an InputError naming the option.
template <typename Options>
void ApplyKeywords(const OptionTable<Options>& table, const std::string& function, const py::dict& kwargs,
                   Options* options) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const OptionEntry<Options>* entry = table.Find(name);
    if (entry == nullptr) {
      std::string names;
      for (const OptionEntry<Options>& e : table.entries()) names += (names.empty() ? "" : ", ") + e.key;
      throw py::type_error(function + "() got an unexpected keyword argument '" + name +
                           "'; the options are: " + names);
    }
    try {
      SetKeyword(*entry, function, value, options);
    } catch (const py::cast_error&) {
      ThrowBadArgument(function, name + "=" + std::string(py::str(py::repr(value))) +
                                     " has the wrong type (" + entry->HelpWithUnit(entry->unit) + ")");
    }
  }
}

// {name: (default, description)} of every keyword.
template <typename Options>
py::dict DescribeKeywords(const OptionTable<Options>& table) {
  const Options defaults{};
  py::dict described;
  for (const OptionEntry<Options>& e : table.entries()) {
    described[py::str(e.key)] = py::make_tuple(KeywordValue(e, defaults), e.HelpWithUnit(e.unit));
  }
  return described;
}

}  // namespace imufit::python

#endif  // IMUFIT_PYTHON_KEYWORD_OPTIONS_H_
