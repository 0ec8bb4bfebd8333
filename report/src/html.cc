#include "imufit/report/html.h"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace imufit {
namespace {

// An always-on invariant check (not assert): a renderer bug, never bad input.
void Check(bool condition, const char* what, const char* tag) {
  if (condition) return;
  std::fprintf(stderr, "imufit: internal error: HTML builder: %s <%s>\n", what, tag);
  std::abort();
}

void AppendAttributes(std::string* text, const HtmlAttributes& attributes) {
  for (const auto& [name, value] : attributes)
    *text += std::string(" ") + name + "=\"" + HtmlEscape(value) + "\"";
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&#39;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

Html& Html::Open(const char* tag, const HtmlAttributes& attributes) {
  text_ += std::string("<") + tag;
  AppendAttributes(&text_, attributes);
  text_ += ">";
  open_.push_back(tag);
  return *this;
}

Html& Html::Close(const char* tag) {
  Check(!open_.empty() && std::strcmp(open_.back(), tag) == 0, "closing an element that is not open", tag);
  open_.pop_back();
  text_ += std::string("</") + tag + ">";
  if (std::strcmp(tag, "tr") == 0 || std::strcmp(tag, "table") == 0 || std::strcmp(tag, "div") == 0 ||
      std::strcmp(tag, "section") == 0) {
    text_ += "\n";
  }
  return *this;
}

Html& Html::Element(const char* tag, const std::string& text, const HtmlAttributes& attributes) {
  Open(tag, attributes);
  Text(text);
  return Close(tag);
}

Html& Html::Void(const char* tag, const HtmlAttributes& attributes) {
  text_ += std::string("<") + tag;
  AppendAttributes(&text_, attributes);
  text_ += ">\n";
  return *this;
}

Html& Html::Text(const std::string& text) {
  text_ += HtmlEscape(text);
  return *this;
}

Html& Html::Figure(const Svg& svg) {
  text_ += svg.markup;
  return *this;
}

Html& Html::Style(const char* css) {
  text_ += "<style>";
  text_ += css;
  text_ += "</style>\n";
  return *this;
}

Html& Html::PageStyle(const std::string& header_left, const std::string& header_right,
                      const std::string& size) {
  // A CSS string: every character but letters, digits and spaces as a hex escape, so that no text
  // can end the string, the rule or the <style> element.
  const auto css_string = [](const std::string& text) {
    std::string quoted = "\"";
    char escape[16];
    for (unsigned char c : text) {
      if (std::isalnum(c) || c == ' ' || c >= 0x80) {
        quoted += static_cast<char>(c);
      } else {
        std::snprintf(escape, sizeof escape, "\\%x ", c);
        quoted += escape;
      }
    }
    return quoted + "\"";
  };
  const std::string page_size = size == "A4" ? "A4" : size == "letter" ? "letter" : "auto";
  text_ +=
      "<style>@page { size: " + page_size +
      "; margin: 17mm 13mm 15mm 13mm;\n"
      "  @top-left { content: " +
      css_string(header_left) +
      "; font: 8pt 'DejaVu Sans', sans-serif; color: #444; }\n"
      "  @top-right { content: " +
      css_string(header_right) +
      "; font: 8pt 'DejaVu Sans', sans-serif; color: #444; }\n"
      "  @bottom-right { content: \"page \" counter(page) \" of \" counter(pages); font: 8pt 'DejaVu Sans', "
      "sans-serif; color: #444; } }</style>\n";
  return *this;
}

std::string Html::Finish() {
  Check(open_.empty(), "document finished with an open element", open_.empty() ? "" : open_.back());
  return "<!DOCTYPE html>\n" + text_;
}

}  // namespace imufit
