// imufit — the lot page of a batch (OUT_DIR/lot.html): a LotSummary (lot_summary.h) as
// self-contained HTML, as the certificate page is made (certificate_page.h): the units, their
// verdicts and outliers, the key figures over the lot with their capability, a strip plot per
// figure, and the lots of the results store across lots (history_page.h) when there is one.
#ifndef IMUFIT_FACTORY_LOT_PAGE_H_
#define IMUFIT_FACTORY_LOT_PAGE_H_

#include <string>
#include <vector>

#include "imufit/factory/lot_summary.h"
#include "imufit/report/plot.h"

namespace imufit {

// The lot page's strip plots, one per key figure of LotSummary::figures: a point per unit, the
// limits, mean and 3 sigma.
std::vector<PlotFigure> LotPlots(const LotSummary& lot);
std::string LotPageHtml(const LotSummary& lot);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_LOT_PAGE_H_
