// imufit — each raw channel checked before the fit: dead, stuck or at its rail.
//
// A gyro axis that reads 0 in every row, or an accelerometer axis stuck at its rail, leaves the
// fit nothing to determine that axis with: it would end in non-finite steps or in a list of
// coefficients it cannot separate, naming nothing. CheckChannels() names the channel and the
// evidence instead:
//
//  - a channel with one value in every sample is at its rail when that value is at the full scale
//    given (WindowOptions::gyro_full_scale_raw, accel_full_scale_raw) or a converter's limit
//    (+-(2^k - 1), -2^k for k = 7 .. 31), else stuck;
//  - channels that respond to another axis than their own: each sensor's raw window means fitted
//    as offset + K truth over every window whose truth the plan knows; when every channel follows
//    one planned axis (kAxisShare of its response) with a clear slope, and that signed axis map
//    is not the identity, the finding says so in a person's terms (two channels exchanged, a sign
//    inverted, the unit mounted rotated when both sensors are turned alike) with the remedy (a
//    column map, the mounting), instead of calling the channels dead;
//  - a channel that does not respond: the slope of its raw window means against the planned truth
//    along its axis (a straight line: faces at 1 g and corners at 0.58 g lie on it) is within
//    kResponseSigmas standard errors of 0 (the scatter of the means about the line and their noise),
//    when the plan drives its axis both ways.
#ifndef IMUFIT_RUN_CHANNEL_CHECK_H_
#define IMUFIT_RUN_CHANNEL_CHECK_H_

#include <string>
#include <vector>

#include "imufit/model/rate_table.h"
#include "imufit/run/windows.h"

namespace imufit {

// Windows with a planned truth along the axis of at least this share of the largest count.
inline constexpr double kResponseShare = 0.5;
// A response smaller than this many scatters of the window means is none.
inline constexpr double kResponseSigmas = 6.0;

// Whether a raw value is a converter's limit, +-(2^k - 1) or -2^k for k = 7 .. 31 (a saturated
// integer channel; the field fit drops a turn that touches one).
bool ConverterLimit(double value);

// The dead, stuck or railed channels of a run (raw units; `stats` over every sample, `windows` those
// the fit gets), one line ("" when every channel is live).
std::string CheckChannels(const std::vector<Window>& windows, const WindowStats& stats, const TableSite& site,
                          const std::vector<TableSegment>& segments, const WindowOptions& options);

}  // namespace imufit

#endif  // IMUFIT_RUN_CHANNEL_CHECK_H_
