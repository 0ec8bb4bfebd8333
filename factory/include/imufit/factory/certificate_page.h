// imufit — the certificate page: a Certificate (certificate.h) as self-contained HTML (inline CSS,
// plots as inline SVG drawn through the plotting module, plot.h; no network), printing to PDF on
// A4 or Letter with a running header (serial) and "page x of y". It formats and draws; it computes
// nothing. Key numbers carry machine-readable attributes (data-figure="gyro_bias_dps.x"
// data-value="...", data-key, data-sha256, data-criterion), so tools can read a certificate back.
// Without gnuplot on PATH the page says so in place of the plots.
#ifndef IMUFIT_FACTORY_CERTIFICATE_PAGE_H_
#define IMUFIT_FACTORY_CERTIFICATE_PAGE_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/factory/certificate.h"
#include "imufit/io/output_file.h"
#include "imufit/report/plot.h"

namespace imufit {

// The plots of a certificate, by what they show.
struct CertificateFigures {
  // Per coefficient group of Certificate::curves, against temperature; none for a run at one
  // temperature (its coefficients are constants).
  std::vector<PlotFigure> coefficients;
  // The windows' errors before and after correction, the run's temperature, the histogram of the
  // normalised errors.
  PlotFigure errors;
  // The gyro's Allan deviation, when the noise section was computed.
  std::optional<PlotFigure> allan;
};
CertificateFigures MakeCertificateFigures(const Certificate& certificate);
// The same in page order: the coefficients, the errors, the Allan deviation.
std::vector<PlotFigure> CertificatePlots(const Certificate& certificate);

std::string CertificateHtml(const Certificate& certificate);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_CERTIFICATE_PAGE_H_
