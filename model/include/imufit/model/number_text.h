// imufit — a number as a message writes it: one double through a printf format ("%.3g").
#ifndef IMUFIT_MODEL_NUMBER_TEXT_H_
#define IMUFIT_MODEL_NUMBER_TEXT_H_

#include <cstdio>
#include <string>

namespace imufit {

// `value` through `format`, a printf format of one double ("%.3g", "%+.1f").
inline std::string NumberText(const char* format, double value) {
  char text[96];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace imufit

#endif  // IMUFIT_MODEL_NUMBER_TEXT_H_
