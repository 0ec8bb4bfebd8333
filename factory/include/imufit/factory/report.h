// imufit — rendering a Certificate and a LotSummary (certificate.h) as self-contained HTML: inline
// CSS, plots as inline SVG drawn through the plotting module (plot.h), no network; prints to PDF
// on A4 or Letter with a running header (serial) and "page x of y". Markup is built with the
// escaping HTML builder (html.h). The renderer formats and draws; it computes nothing.
//
// Key numbers carry machine-readable attributes (data-figure="gyro_bias_dps.x" data-value="...",
// data-key, data-sha256, data-criterion), so tools can read a certificate back. Without gnuplot on
// PATH the page says so in place of each plot.
#ifndef IMUFIT_FACTORY_REPORT_H_
#define IMUFIT_FACTORY_REPORT_H_

#include <string>
#include <vector>

#include "imufit/factory/certificate.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/factory/plot.h"

namespace imufit {

// `value` through a printf format of one number (text around the conversion allowed). A value that
// prints as zero prints without a sign: a held-out temperature of -0.02 degC through "%.1f" is
// "0.0", not "-0.0", and 0 through "%+g" is "0", not "+0" (zero is on neither side).
std::string FormatNumber(const char* format, double value);

// The plots of a certificate, in page order (coefficients against temperature, residuals,
// temperature against time, histogram, Allan deviation).
std::vector<PlotFigure> CertificatePlots(const Certificate& certificate);
std::string CertificateHtml(const Certificate& certificate);
// Writes it atomically.
void WriteCertificate(const std::string& path, const Certificate& certificate);

// The lot page's strip plots, one per key figure: a point per unit, the limits, mean and 3 sigma.
std::vector<PlotFigure> LotPlots(const LotSummary& lot);
// Across lots: the yield per lot (bars, this lot highlighted), then, from two lots on, per trend
// figure the lots' means with their sigma.
std::vector<PlotFigure> LotHistoryPlots(const LotHistory& history);
std::string LotPageHtml(const LotSummary& lot);
// The lots of a results store on a page of their own (`imufit history DB --lot --html`).
std::string LotHistoryHtml(const LotHistory& history);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_REPORT_H_
