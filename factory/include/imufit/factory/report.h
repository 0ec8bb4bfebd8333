// imufit — the documents factory renders, each from a struct computed elsewhere and in a file of
// its own: the certificate (certificate_page.h), the lot page (lot_page.h) and the lots of a results
// store (history_page.h). Markup is built with the escaping HTML builder (html.h), plots are drawn
// through the plotting module (plot.h); the renderers format and draw, they compute nothing.
#ifndef IMUFIT_FACTORY_REPORT_H_
#define IMUFIT_FACTORY_REPORT_H_

#include <string>

#include "imufit/factory/certificate_page.h"
#include "imufit/factory/history_page.h"
#include "imufit/factory/lot_page.h"

namespace imufit {

// `value` through a printf format of one number (text around the conversion allowed). A value that
// prints as zero prints without a sign: a held-out temperature of -0.02 degC through "%.1f" is
// "0.0", not "-0.0", and 0 through "%+g" is "0", not "+0" (zero is on neither side).
std::string FormatNumber(const char* format, double value);

// A value and its uncertainty as a certificate prints them (GUM 7.2.6): the uncertainty to two
// significant digits, the value to the same decimal place (`sign`: "+" before a positive value),
// both with FormatNumber(). An uncertainty that is not > 0 leaves the value at 6 significant
// digits and the uncertainty "".
struct RoundedValue {
  std::string value, uncertainty;
  int decimals = 0;  // places after the point (negative: rounded to tens, hundreds, ...)
};
RoundedValue RoundToUncertainty(double value, double uncertainty, bool sign = false);
// `value` rounded to `decimals` places after the point (RoundedValue::decimals).
std::string AtDecimals(double value, int decimals, bool sign = false);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_REPORT_H_
