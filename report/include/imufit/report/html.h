// imufit — a small HTML builder that escapes by construction: text and attribute values go in
// escaped, element names are string literals, and the only markup taken as it is comes from the
// plotting module (Svg). Elements close in order (Close() checks the name), so a renderer cannot
// leave a table open or emit markup from data.
//
//   Html h;
//   h.Open("table", {{"class", "verdict"}});
//   h.Open("tr").Element("td", name).Element("td", value, {{"class", "num"}}).Close("tr");
//   h.Close("table");
#ifndef IMUFIT_REPORT_HTML_H_
#define IMUFIT_REPORT_HTML_H_

#include <string>
#include <utility>
#include <vector>

#include "imufit/report/plot.h"

namespace imufit {

// Escapes text for HTML content and attribute values (& < > " ').
std::string HtmlEscape(const std::string& text);

using HtmlAttributes = std::vector<std::pair<const char*, std::string>>;

class Html {
 public:
  // <tag attributes...>; `tag` and attribute names are literals, values are escaped.
  Html& Open(const char* tag, const HtmlAttributes& attributes = {});
  // </tag>; aborts (always-on check) when `tag` is not the innermost open element.
  Html& Close(const char* tag);
  // <tag attributes>text</tag>, the text escaped.
  Html& Element(const char* tag, const std::string& text, const HtmlAttributes& attributes = {});
  // A void element: <meta ...>, <br>.
  Html& Void(const char* tag, const HtmlAttributes& attributes = {});
  // Escaped text.
  Html& Text(const std::string& text);
  // A plot drawn by the plotting module.
  Html& Figure(const Svg& svg);
  // A <style> block: `css` must be a literal of the renderer (never data).
  Html& Style(const char* css);
  // A <style> block of @page rules for print: a running header (left and right texts, escaped as
  // CSS strings) and "page x of y" in the footer; `size` is "auto", "A4" or "letter".
  Html& PageStyle(const std::string& header_left, const std::string& header_right, const std::string& size);
  // The document; aborts when an element is still open.
  std::string Finish();

 private:
  std::string text_;
  std::vector<const char*> open_;
};

}  // namespace imufit

#endif  // IMUFIT_REPORT_HTML_H_
