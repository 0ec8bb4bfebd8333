// SegmentationOptions: its option table (model/option_table.h) and its checks.
#include "imufit/run/segmentation.h"

namespace imufit {
namespace {

OptionTable<SegmentationOptions> MakeSegmentationOptionTable() {
  using O = SegmentationOptions;
  OptionTable<O> t;
  t.Number("segment_window_s", "--segment-window",
           "without a segment column: sliding window whose variance tells rest from motion", "s",
           &O::window_s, Positive());
  t.Number("segment_noise_quantile", "--segment-noise-quantile",
           "without a segment column: the noise level is this quantile of the windows' variances", "",
           &O::noise_quantile, Between(0.0, 1.0, true, true));
  t.Number("segment_threshold_factor", "--segment-threshold-factor",
           "without a segment column: a window is steady below this multiple of the noise level", "",
           &O::threshold_factor, Between(1.0, std::numeric_limits<double>::infinity(), true));
  t.Number("min_steady_s", "--min-steady",
           "without a segment column: rests and constant rates shorter than this count as motion", "s",
           &O::min_steady_s, NonNegative());
  t.Number("direction_tolerance_deg", "--direction-tolerance",
           "without a segment column: how far a measured gravity direction or rotation axis may be from the "
           "plan's",
           "deg", &O::direction_tolerance_deg, Between(0.0, 90.0, true, true));
  t.Number(
      "rate_tolerance", "--rate-tolerance",
      "without a segment column: how far the raw size of a rate or turn may be from the others', relative",
      "", &O::rate_tolerance, Positive());
  t.Number(
      "turn_margin_s", "--turn-margin",
      "without a segment column: how far a turn's label reaches into the rests either side (at most half of "
      "each)",
      "s", &O::turn_margin_s, NonNegative());
  return t;
}

}  // namespace

const OptionTable<SegmentationOptions>& SegmentationOptionTable() {
  static const OptionTable<SegmentationOptions> table = MakeSegmentationOptionTable();
  return table;
}

std::string SegmentationOptions::Validate() const {
  return ValidateOptions(SegmentationOptionTable(), *this);
}

}  // namespace imufit
