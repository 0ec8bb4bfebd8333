// imufit — the Allan deviation plot of analysed columns, as a figure of the plotting module.
#ifndef IMUFIT_FACTORY_ALLAN_PLOT_H_
#define IMUFIT_FACTORY_ALLAN_PLOT_H_

#include <string>
#include <vector>

#include "imufit/factory/plot.h"
#include "imufit/noise/column_analysis.h"

namespace imufit {

// `imufit allan --plot`: one panel per kind of column (they have different units); in each, per
// column the curve with its confidence bars, the fitted IEEE 952 model (solid), its terms (dashed)
// and the read-out points (open circles); ARW and bias instability printed on the plot. `in_dph`
// shows gyro panels in deg/h instead of rad/s.
PlotFigure AllanPlot(const std::vector<ColumnAnalysis>& results, const std::string& title, bool in_dph);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_ALLAN_PLOT_H_
