// WindowOptions: its option table (model/option_table.h) and its checks.
#include "imufit/run/windows.h"

namespace imufit {
namespace {

OptionTable<WindowOptions> MakeWindowOptionTable() {
  using O = WindowOptions;
  OptionTable<O> t;
  t.Number("trim_s", "--trim",
           "time dropped at the start of each segment occurrence, while the table settles", "s", &O::trim_s,
           NonNegative());
  t.Number("window_temp_span_c", "--window-temp-span",
           "a window closes when its temperature has moved this far", "degC", &O::max_temp_span_c,
           Positive());
  t.Number("window_max_duration_s", "--window-max-duration", "a window closes after this long (0: never)",
           "s", &O::max_duration_s, NonNegative());
  t.Number("window_min_samples", "--window-min-samples", "windows with fewer samples are dropped", "",
           &O::min_samples, AtLeast(2));
  t.Number(
      "max_turn_gap_s", "--max-turn-gap",
      "a turn whose time stamps have a longer gap (lost samples in a row) is dropped: integrating across it "
      "would bias the angle",
      "s", &O::max_turn_gap_s, NonNegative());
  t.Number(
      "gyro_full_scale_raw", "--gyro-full-scale",
      "the gyro's full scale, raw units (e.g. 32767 counts): windows with a sample at or beyond it are left "
      "out (0: found only where an output sits at the run's extreme)",
      "", &O::gyro_full_scale_raw, NonNegative());
  t.Number("accel_full_scale_raw", "--accel-full-scale",
           "the accelerometer's full scale, raw units, as gyro_full_scale_raw", "", &O::accel_full_scale_raw,
           NonNegative());
  return t;
}

}  // namespace

const OptionTable<WindowOptions>& WindowOptionTable() {
  static const OptionTable<WindowOptions> table = MakeWindowOptionTable();
  return table;
}

std::string WindowOptions::Validate() const { return ValidateOptions(WindowOptionTable(), *this); }

}  // namespace imufit
