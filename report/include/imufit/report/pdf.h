// imufit — a page printed to PDF: the certificate or the lot page as the printer would print it,
// written by headless Chromium (Debian: chromium), on A4 or Letter.
//
// The page's HTML is copied into a private temporary folder with an @page rule for the paper size
// and printed with `--print-to-pdf` (no browser header or footer: the page has its own running
// header and "page x of y"). The PDF is an output like any other: written atomically, in a
// transaction when given. Chromium is found as $IMUFIT_CHROMIUM, else chromium, chromium-browser or
// google-chrome on PATH.
#ifndef IMUFIT_REPORT_PDF_H_
#define IMUFIT_REPORT_PDF_H_

#include <string>

#include "imufit/base/enum_names.h"
#include "imufit/io/output_file.h"

namespace imufit {

enum class Paper { kA4, kLetter };
inline constexpr EnumName<Paper> kPaperNames[] = {{Paper::kA4, "A4"}, {Paper::kLetter, "letter"}};

// Longest a page may take to print before Chromium is stopped.
inline constexpr int kPdfTimeoutS = 120;

// The Chromium that prints, or "" when there is none.
std::string FindChromium();
// "" when a PDF can be printed; else why not (what to install), for a message naming the option.
std::string PdfProblem();
// "out/report.html" -> "out/report.pdf" (any other name: ".pdf" appended).
std::string PdfPathFor(const std::string& html_path);

// Prints `html` (a self-contained page) to `pdf_path` on `paper`; returns the PDF's SHA-256 (hex),
// what names it among a fit's attachments in the store. Throws std::runtime_error when Chromium is
// missing, fails or writes no PDF (then nothing is written at `pdf_path`).
std::string WritePdf(const std::string& html, const std::string& pdf_path, Paper paper,
                     OutputTransaction* transaction = nullptr);

}  // namespace imufit

#endif  // IMUFIT_REPORT_PDF_H_
