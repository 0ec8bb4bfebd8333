// imufit — the lots of a results store on a page of their own (`imufit history DB --lot --html`),
// as the lot page shows them in its "across lots" section: each lot's yield, and the key figures'
// lot means.
#ifndef IMUFIT_FACTORY_HISTORY_PAGE_H_
#define IMUFIT_FACTORY_HISTORY_PAGE_H_

#include <string>
#include <vector>

#include "imufit/factory/lot_history.h"
#include "imufit/report/plot.h"

namespace imufit {

// The plots of the lots, by what they show.
struct LotHistoryFigures {
  PlotFigure yield;                // the yield per lot (bars, the page's lot highlighted)
  std::vector<PlotFigure> trends;  // from two lots on, per trend figure: the lots' means with their sigma
};
LotHistoryFigures MakeLotHistoryFigures(const LotHistory& history);
// The same in page order: the yield, then the trends.
std::vector<PlotFigure> LotHistoryPlots(const LotHistory& history);

std::string LotHistoryHtml(const LotHistory& history);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_HISTORY_PAGE_H_
