// imufit — names of the enums a user types (estimator, loss, units, ...): one table per enum, and
// the three lookups every such enum needs, so that a name is spelled in one place and a bad name
// can list the allowed ones.
//
//   struct LossName { RobustLoss value; const char* name; };
//   constexpr LossName kLossNames[] = {{RobustLoss::kNone, "none"}, {RobustLoss::kHuber, "huber"}};
//   NameOf(kLossNames, RobustLoss::kHuber)         -> "huber"
//   ValueOf(kLossNames, "none", &loss)             -> true, loss = kNone
//   AllNames(kLossNames)                           -> "none, huber"
//
// A table is an array of structs with (at least) `value` and `name` members; further members carry
// what else belongs to the value (an Allan noise type's alpha). Several names may map to one value
// (aliases); NameOf gives the first.
#ifndef IMUFIT_BASE_ENUM_NAMES_H_
#define IMUFIT_BASE_ENUM_NAMES_H_

#include <cstddef>
#include <string>
#include <string_view>

namespace imufit {

// The plain table entry, for enums with nothing else to say per value.
template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// The first name of `value`, "?" for a value not in the table.
template <typename Entry, std::size_t kCount, typename Value>
const char* NameOf(const Entry (&table)[kCount], Value value) {
  for (const Entry& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

// Sets `value` to the value named `text` and returns true; false (`value` untouched) for a name not
// in the table.
template <typename Entry, std::size_t kCount, typename Value>
bool ValueOf(const Entry (&table)[kCount], std::string_view text, Value* value) {
  for (const Entry& entry : table) {
    if (text == entry.name) {
      *value = entry.value;
      return true;
    }
  }
  return false;
}

// Every name, comma-separated, in table order: what a message about a bad name lists.
template <typename Entry, std::size_t kCount>
std::string AllNames(const Entry (&table)[kCount]) {
  std::string names;
  for (const Entry& entry : table) names += (names.empty() ? "" : ", ") + std::string(entry.name);
  return names;
}

}  // namespace imufit

#endif  // IMUFIT_BASE_ENUM_NAMES_H_
