// imufit — the Allan deviation plot of analysed columns, as a figure of the plotting module.
//
// One log-log panel per kind of column (gyro, accelerometer, other: their units differ). In each,
// per column: the curve with its confidence bars, and over Allan-variance curves (adev, oadev,
// totdev: the IEEE 952 model is the Allan variance's) the fitted model (solid) and its terms
// (dashed, where they carry at least a hundredth of the model's variance), annotated:
//   - the angle (velocity) random walk N where it is read, on the -1/2 slope line at tau = 1 s
//     (sigma(1 s) = N; a filled point), labelled "ARW 0.299 ± 0.0004 °/√h";
//   - the bias-instability floor: the flat term sqrt(2 ln 2 / pi) B = 0.664 B at the model's
//     minimum (a diamond), labelled "bias instability 2.99 ± 0.39 °/h" (B, not the floor's height).
// A term the fit does not resolve is said in words at the panel's foot. Labels carry the column's
// name when a panel has more than one column.
#ifndef IMUFIT_REPORT_ALLAN_PLOT_H_
#define IMUFIT_REPORT_ALLAN_PLOT_H_

#include <string>
#include <vector>

#include "imufit/noise/column_analysis.h"
#include "imufit/report/plot.h"

namespace imufit {

// The unit of the gyro panels' deviation axis. With deg/s or deg/h the accelerometer panels are in
// micro-g, the unit their bias instability is printed in; other columns keep their own unit.
enum class AllanPlotUnits {
  kNative,        // "native" or "rad/s": the columns' own unit (rad/s for a corrected file)
  kDegPerSecond,  // "deg/s"
  kDegPerHour,    // "deg/h": the unit bias instability is quoted in
};
// Parses "native", "rad/s", "deg/s", "deg/h"; false (and `units` untouched) for anything else.
bool ParseAllanPlotUnits(const std::string& text, AllanPlotUnits* units);
// "native, rad/s, deg/s, deg/h", for messages and help.
const char* AllanPlotUnitsNames();

// `imufit allan --plot`: the figure described above, titled `title`.
PlotFigure AllanPlot(const std::vector<ColumnAnalysis>& results, const std::string& title,
                     AllanPlotUnits units = AllanPlotUnits::kNative);

}  // namespace imufit

#endif  // IMUFIT_REPORT_ALLAN_PLOT_H_
