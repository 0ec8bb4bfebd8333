// imufit — the verdict vocabulary: what became of a unit (UnitStatus), where a judged value lies
// against its limit (Outcome), and the unit's and a criterion's acceptance, each with its name
// table (enum_names.h). The names are what the results store's columns, the batch manifest and
// lot_summary.csv hold (docs/spec.md section 5); everywhere else the values are compared, never
// the text. Pure data, in base so that the store (below factory) writes the same names.
#ifndef IMUFIT_BASE_VERDICT_H_
#define IMUFIT_BASE_VERDICT_H_

#include "imufit/base/enum_names.h"

namespace imufit {

// What became of a unit of `imufit fit` or `imufit batch`.
enum class UnitStatus {
  kFitted,     // a calibration was written
  kNotFitted,  // the run does not determine the model
  kError,      // bad input, or the store refused the unit's row
};
inline constexpr EnumName<UnitStatus> kUnitStatusNames[] = {
    {UnitStatus::kFitted, "fitted"}, {UnitStatus::kNotFitted, "not-fitted"}, {UnitStatus::kError, "error"}};

// Where a value lies against its limit with its expanded uncertainty U (ILAC-G8): clear of the
// limit by more than U on either side, or within U of it.
enum class Outcome { kPass, kConditionalPass, kConditionalFail, kFail };
inline constexpr EnumName<Outcome> kOutcomeNames[] = {{Outcome::kPass, "PASS"},
                                                      {Outcome::kConditionalPass, "conditional pass"},
                                                      {Outcome::kConditionalFail, "conditional fail"},
                                                      {Outcome::kFail, "FAIL"}};

// A unit's verdict against its limits, passed or not, as the manifest, the store and the tables
// write it ("PASS", "FAIL"; a unit without a verdict writes "").
inline constexpr EnumName<bool> kVerdictNames[] = {{true, "PASS"}, {false, "FAIL"}};
// A criterion's acceptance under the decision rule, as the store keeps it per figure ("pass",
// "fail"; a figure not judged: "").
inline constexpr EnumName<bool> kCriterionAcceptanceNames[] = {{true, "pass"}, {false, "fail"}};

// "PASS" or "FAIL".
inline const char* VerdictName(bool pass) { return NameOf(kVerdictNames, pass); }

}  // namespace imufit

#endif  // IMUFIT_BASE_VERDICT_H_
