// The option tables (base/option_table.h): the fingerprint FitRunOptions::Describe() sees every
// option that can change a fit, and only those; Validate() names the option and its value (the
// fit's, the simulation's, Allan's, the noise fit's, the uniform series', the export's and the
// batch's tables); the export's formats and the options that serve them; the enum name tables
// parse what they print.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <type_traits>

#include "imufit/base/enum_names.h"
#include "imufit/export/export.h"
#include "imufit/factory/batch.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/noise_model.h"
#include "imufit/pipeline/fit_run.h"
#include "imufit/pipeline/series_reader.h"
#include "imufit/sim/simulator.h"

namespace imufit {
namespace {

std::string Fixture(const std::string& name) { return std::string(IMUFIT_FIXTURES_DIR) + "/" + name; }

// Another valid text of each text option (a new text option needs one here).
const std::map<std::string, std::string> kOtherTexts = {
    {"fit", "all"},
    {"loss", "cauchy"},
    {"prior", Fixture("mems_truth.yaml")},
    {"check_samples", "another_run.csv"},
    {"check_plan", "another_plan.yaml"},
    {"time_unit", "ms"},
    {"delimiter", ";"},
    {"column", "time_s=Zeit"},
    {"noise_segment", "4"},
};

// Changes the option of `entry` in `options` to another valid value.
template <typename Options>
void Perturb(const OptionEntry<Options>& entry, Options* options) {
  std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, OptionalNumberOption<Options>>) {
          const std::optional<double> value = kind.Get(*options);
          kind.field(*options) = value ? *value + 1.0 : 30.0;
        } else if constexpr (std::is_same_v<Kind, NumbersOption<Options>>) {
          std::vector<double> numbers = kind.Get(*options);
          if (kind.count > 0) {
            numbers = numbers.empty() ? std::vector<double>(kind.count, 10.0) : std::vector<double>{};
          } else {
            numbers.push_back(numbers.empty() ? 10.0 : numbers.back() + 10.0);
          }
          kind.set(numbers, options);
        } else if constexpr (std::is_same_v<Kind, TextOption<Options>>) {
          ASSERT_EQ(kOtherTexts.count(entry.key), 1u) << entry.key << ": give it another text in kOtherTexts";
          ASSERT_EQ(kind.set(kOtherTexts.at(entry.key), options), "") << entry.key;
        } else if constexpr (std::is_same_v<Kind, FlagOption<Options>>) {
          kind.field(*options) = !kind.Get(*options);
        } else {
          // Numbers: to another value inside the range (orders 0..3 from 0 or 3).
          auto& field = kind.field(*options);
          using T = std::remove_reference_t<decltype(field)>;
          const T up = static_cast<T>(field == T(0) ? T(1) : field * T(2));
          const T down = static_cast<T>(field / T(2));
          field = kind.range.Contains(static_cast<double>(up)) ? up : down;
        }
      },
      entry.value);
}

// A fit whose fingerprint every option can change: a held group (so the prior counts), the gyro
// g-sensitivity fitted (so --no-g-sensitivity counts) and a check run (so its plan counts).
FitRunOptions FingerprintBase() {
  FitRunOptions options;
  std::string error;
  EXPECT_TRUE(ParseFitGroups("gyro,accel-bias", &options.fit, &error)) << error;
  options.check_samples = "held_out.csv";
  return options;
}

TEST(FitRunOptionTable, EveryOptionThatCanChangeAFitChangesTheFingerprint) {
  const FitRunOptions base = FingerprintBase();
  ASSERT_EQ(base.Validate(), "");
  const std::string fingerprint = base.Describe();
  for (const OptionEntry<FitRunOptions>& entry : FitRunOptionTable().entries()) {
    FitRunOptions changed = base;
    Perturb(entry, &changed);
    EXPECT_EQ(changed.Validate(), "") << entry.key;
    if (entry.fingerprint == Fingerprint::kNone) {
      EXPECT_EQ(changed.Describe(), fingerprint) << entry.key << " cannot change a fit";
    } else {
      EXPECT_NE(changed.Describe(), fingerprint) << entry.key << " is not in the fingerprint";
    }
  }
}

TEST(FitRunOptionTable, FingerprintOfTheDefaultsKeepsItsWording) {
  // Batch manifests written before the options had one table hold this text: a lot fitted with
  // the defaults must not be redone because of the wording.
  EXPECT_EQ(
      FitRunOptions().Describe(),
      "fitted=gyro.bias,gyro.scale,gyro.misalignment,gyro.g_sensitivity,accel.bias,accel.scale,"
      "accel.misalignment; gyro_temp_order=3; accel_temp_order=3; loss=huber; loss_scale=3; "
      "gyro_bias_stability_radps=0; accel_bias_stability_mps2=0; bias_correlation_s=100; "
      "max_iterations=50; closed_form_start=true; distinct_temp_c=1; min_excitation_rate_radps=0.1; "
      "rank_tolerance=1e-08; trim_s=0.5; window_temp_span_c=0.5; window_max_duration_s=0; "
      "window_min_samples=20; max_turn_gap_s=0.05; gyro_full_scale_raw=0; accel_full_scale_raw=0; "
      "temp_c=column; segment_window_s=1; segment_noise_quantile=0.1; segment_threshold_factor=8; "
      "min_steady_s=0.5; direction_tolerance_deg=25; rate_tolerance=0.25; turn_margin_s=2; validate=false; "
      "allow_serial_mismatch=false");
  FitRunOptions options = FingerprintBase();
  options.check_plan = "plan.yaml";
  const std::string described = options.Describe();
  EXPECT_EQ(described.rfind("fitted=gyro.bias,gyro.scale,gyro.misalignment,gyro.g_sensitivity,accel.bias; "
                            "held=nominal; gyro_temp_order=3; ",
                            0),
            0u)
      << described;
  EXPECT_NE(described.find("; check=held_out.csv plan.yaml; "), std::string::npos) << described;
}

TEST(FitRunOptionTable, KeysAndFlagsAreUnique) {
  std::map<std::string, int> keys, flags;
  for (const OptionEntry<FitRunOptions>& entry : FitRunOptionTable().entries()) {
    ++keys[entry.key];
    if (!entry.flag.empty()) ++flags[entry.flag];
    EXPECT_FALSE(entry.help.empty()) << entry.key;
  }
  for (const auto& [key, count] : keys) EXPECT_EQ(count, 1) << key;
  for (const auto& [flag, count] : flags) EXPECT_EQ(count, 1) << flag;
}

// Sets the number of `entry` just outside its range; false when it has none.
template <typename Options>
bool PutOutsideRange(const OptionEntry<Options>& entry, Options* options) {
  return std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, NumberOption<Options, double>> ||
                      std::is_same_v<Kind, NumberOption<Options, int>>) {
          if (!std::isfinite(kind.range.min)) return false;
          kind.field(*options) = static_cast<std::remove_reference_t<decltype(kind.field(*options))>>(
              kind.range.min_open ? kind.range.min : kind.range.min - 1.0);
          return true;
        } else {
          return false;
        }
      },
      entry.value);
}

// Every option of `table` with a range, put outside it in otherwise valid options (`valid`), makes
// Validate() name it first; at least `min_checked` of them.
template <typename Options>
void ExpectEveryRangeNamedWhenBroken(const OptionTable<Options>& table, int min_checked = 11,
                                     const Options& valid = Options()) {
  int checked = 0;
  ASSERT_EQ(valid.Validate(), "");
  for (const OptionEntry<Options>& entry : table.entries()) {
    Options options = valid;
    if (!PutOutsideRange(entry, &options)) continue;
    const std::string problem = options.Validate();
    EXPECT_EQ(problem.rfind(entry.key + " = ", 0), 0u) << entry.key << ": " << problem;
    ++checked;
  }
  EXPECT_GE(checked, min_checked);
}

// Keys and flags unique, every option described, and every text option reads back what it prints
// for the defaults.
template <typename Options>
void ExpectWellFormed(const OptionTable<Options>& table) {
  std::map<std::string, int> keys, flags;
  const Options defaults;
  for (const OptionEntry<Options>& entry : table.entries()) {
    ++keys[entry.key];
    if (!entry.flag.empty()) ++flags[entry.flag];
    EXPECT_FALSE(entry.help.empty()) << entry.key;
    if (const auto* text = std::get_if<TextOption<Options>>(&entry.value)) {
      Options read = defaults;
      const std::string shown = text->Get(defaults);
      if (!shown.empty()) {
        EXPECT_EQ(text->set(shown, &read), "") << entry.key;
      }
      EXPECT_EQ(text->Get(read), shown) << entry.key;
    }
  }
  for (const auto& [key, count] : keys) EXPECT_EQ(count, 1) << key;
  for (const auto& [flag, count] : flags) EXPECT_EQ(count, 1) << flag;
}

BatchOptions ValidBatch() {
  BatchOptions batch;
  batch.units_dir = "units";
  batch.output_dir = "out";
  return batch;
}

TEST(OptionTables, TheAllanNoiseSeriesExportAndBatchTablesAreWellFormedAndNameWhatIsWrong) {
  ExpectWellFormed(AllanOptionTable());
  ExpectWellFormed(NoiseFitOptionTable());
  ExpectWellFormed(UniformSeriesOptionTable());
  ExpectWellFormed(ExportOptionTable());
  ExpectWellFormed(BatchOptionTable());
  ExpectEveryRangeNamedWhenBroken(AllanOptionTable(), 2);
  ExpectEveryRangeNamedWhenBroken(NoiseFitOptionTable(), 2);
  ExpectEveryRangeNamedWhenBroken(UniformSeriesOptionTable(), 1);
  ExpectEveryRangeNamedWhenBroken(ExportOptionTable(), 4);
  ExpectEveryRangeNamedWhenBroken(BatchOptionTable(), 2, ValidBatch());

  AllanOptions allan;
  allan.confidence = 1.0;
  EXPECT_EQ(allan.Validate().rfind("confidence = 1: must lie in (0, 1) (", 0), 0u) << allan.Validate();
  UniformSeriesOptions series;
  series.time_tolerance = 0.5;
  EXPECT_EQ(series.Validate().rfind("time_tolerance = 0.5: must lie in (0, 0.5) (", 0), 0u)
      << series.Validate();
}

TEST(OptionTables, ExportFormatsAndTheOptionsThatServeThem) {
  EXPECT_EQ(ExportFormatFromString("PX4"), ExportFormat::kPx4);
  EXPECT_EQ(ExportFormatFromString("ArduPilot"), ExportFormat::kArduPilot);
  EXPECT_EQ(ExportFormatFromString("px"), std::nullopt);
  EXPECT_EQ(ExportFormatFromString("px4 "), std::nullopt);
  ExportOptions options;
  const auto& format = std::get<TextOption<ExportOptions>>(ExportOptionTable().Find("format")->value);
  EXPECT_EQ(format.set("Kalibr", &options), "");
  EXPECT_EQ(options.format, ExportFormat::kKalibr);
  EXPECT_EQ(format.set("mavlink", &options), "\"mavlink\" is not a format (" + ExportFormatNames() + ")");
  EXPECT_TRUE(ExportOptionServes("device_id", ExportFormat::kPx4));
  EXPECT_FALSE(ExportOptionServes("device_id", ExportFormat::kJson));
  EXPECT_TRUE(ExportOptionServes("full_scale_dps", ExportFormat::kJson));
  EXPECT_EQ(ExportOptionFormats("temp_c"), "kalibr, imucal");
  EXPECT_EQ(ExportOptionFormats("max_g"), "");
  // The help of an option that serves some formats names them, from the same table.
  for (const OptionEntry<ExportOptions>& entry : ExportOptionTable().entries()) {
    const std::string formats = ExportOptionFormats(entry.key);
    if (!formats.empty()) {
      EXPECT_EQ(entry.help.rfind(formats + ": ", 0), 0u) << entry.key;
    }
  }
}

TEST(OptionTables, ValidateNamesTheOptionAndItsValue) {
  ExpectEveryRangeNamedWhenBroken(FitRunOptionTable());
  ExpectEveryRangeNamedWhenBroken(SimulationOptionTable());

  FitOptions fit;
  fit.loss_scale = -1.0;
  EXPECT_EQ(fit.Validate(),
            "loss_scale = -1: must be > 0 (where the robust loss acts, in robust spreads of the windows' "
            "normalised residuals)");
  SegmentationOptions segmentation;
  segmentation.noise_quantile = 1.5;
  EXPECT_EQ(segmentation.Validate().rfind("segment_noise_quantile = 1.5: must lie in (0, 1) (", 0), 0u)
      << segmentation.Validate();
  SimulationOptions simulation;
  simulation.rate_hz = std::numeric_limits<double>::infinity();
  EXPECT_EQ(simulation.Validate(), "rate_hz = inf: must be finite and > 0 (sample rate, Hz)");
  simulation = SimulationOptions();
  simulation.soak_temps_c = {25.0, std::nan("")};
  EXPECT_EQ(simulation.Validate(),
            "soak_temps_c = nan: temperatures must be numbers between -273.15 and 1000 degC");
}

TEST(OptionRange, TextSaysWhatPasses) {
  EXPECT_EQ(Positive().Text(), "must be > 0");
  EXPECT_EQ(NonNegative().Text(), "must be >= 0");
  EXPECT_EQ(PositiveFinite().Text(), "must be finite and > 0");
  EXPECT_EQ(Between(0, 3).Text(), "must lie in [0, 3]");
  EXPECT_EQ(Between(0, 1, false, true).Text(), "must lie in [0, 1)");
  EXPECT_FALSE(Positive().Contains(std::nan("")));
  EXPECT_FALSE(PositiveFinite().Contains(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(Positive().Contains(std::numeric_limits<double>::infinity()));
}

TEST(EnumNames, NameValueAndTheList) {
  enum class Colour { kRed, kGreen };
  constexpr EnumName<Colour> kColours[] = {
      {Colour::kRed, "red"}, {Colour::kGreen, "green"}, {Colour::kRed, "r"}};
  EXPECT_STREQ(NameOf(kColours, Colour::kRed), "red");  // the first of its names
  Colour colour = Colour::kRed;
  EXPECT_TRUE(ValueOf(kColours, "green", &colour));
  EXPECT_EQ(colour, Colour::kGreen);
  EXPECT_TRUE(ValueOf(kColours, "r", &colour));
  EXPECT_EQ(colour, Colour::kRed);
  EXPECT_FALSE(ValueOf(kColours, "blue", &colour));
  EXPECT_EQ(colour, Colour::kRed);
  EXPECT_EQ(AllNames(kColours), "red, green, r");
}

TEST(FitGroups, TextReadsBack) {
  for (const char* text :
       {"all", "gyro", "accel", "gyro-bias", "accel-bias", "gyro-bias,accel", "gyro,accel-bias"}) {
    FitOptions options;
    std::string error;
    ASSERT_TRUE(ParseFitGroups(text, &options, &error)) << error;
    EXPECT_EQ(FitGroupsText(options), text);
  }
}

}  // namespace
}  // namespace imufit
