// imufit — what `imufit history` answers across stations, as numbers and as HTML pages: yield by
// lot, station or month (ResultsStore::YieldBy), a key figure over time and each station's drift of
// it (its mean per month), and every calibration of one serial. The pages are built as the lot page
// is (html.h, plot.h: self-contained, plots drawn by gnuplot; without gnuplot the page says why).
//
// Drift of a station: per month (YYYY-MM of the fit time, UTC) the mean and sample standard
// deviation of the figure over the station's fits in that month (every fit, a refit too: a
// station's drift shows in what it measured, not in which fit a unit kept).
#ifndef IMUFIT_FACTORY_STORE_HISTORY_H_
#define IMUFIT_FACTORY_STORE_HISTORY_H_

#include <string>
#include <vector>

#include "imufit/factory/batch.h"
#include "imufit/store/store.h"

namespace imufit {

struct MonthlyMean {
  std::string station, month;  // station "" when not given
  int count = 0;
  double mean = 0.0, sigma = 0.0;  // sigma 0 below two fits
  std::string unit;
};
// The figure's mean per station and month, by station, then month.
std::vector<MonthlyMean> MonthlyMeans(const std::vector<TrendPoint>& points);

// A group's yield as the pages and tables print it: passed / units in percent, or NaN when no
// unit of the group was judged (no limits).
double YieldPct(const GroupYield& y);

// `imufit history DB --by GROUP --html`: the groups' yields as a table and bars.
std::string YieldPageHtml(const std::string& store, YieldGroup by, const std::vector<GroupYield>& yields);
// `imufit history DB --trend FIGURE [--station S] [--serial S] --html`: the figure over time (a
// point per fit, a colour per station) and each station's monthly means.
std::string TrendPageHtml(const std::string& store, const std::string& figure,
                          const std::vector<TrendPoint>& points);
// `imufit history DB --serial S --html`: every calibration of the serial, oldest first.
std::string SerialPageHtml(const std::string& store, const std::string& serial,
                           const std::vector<StoredFit>& fits);

// A lot as its batch found it, from the store (`imufit lot --store`, after a sharded batch): each
// unit by its latest fit in the lot, in unit order, with its status, verdict, message, key figures
// and calibration time, and the criteria its figures were judged on (pass or fail; whether a
// judgement was conditional is not stored). MakeLotSummary() and LotSummaryCsv() take it as they
// take a batch's own result.
BatchResult StoredLot(ResultsStore* store, const std::string& lot);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_STORE_HISTORY_H_
