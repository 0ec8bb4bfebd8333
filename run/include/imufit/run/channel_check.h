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
//  - a channel that does not respond: between the windows whose planned truth lies along its axis
//    (at least half the largest, kResponseShare) with either sign, its raw means differ by no more
//    than kResponseSigmas times their scatter (the noise and the temperature drift of the means).
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
