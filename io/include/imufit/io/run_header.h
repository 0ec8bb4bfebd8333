// imufit — what a samples file's header says about the run beside its serial (samples.h): the
// comment lines before the column names
//
//   # serial: SN0001
//   # acquired: 2026-11-20T14:03:00Z      when the run was recorded, ISO 8601 UTC
//   # model: IMU-9X rev B                 the product's model or part number
//   # firmware: 2.4.1                     the unit's firmware
//   # ambient: 23.1 degC, 41 %RH          the laboratory's conditions, as text
//
// Each is optional; a key given twice with two values, an empty value, a control character and an
// `acquired` that is not a UTC time are errors located at the header's line and column. The
// certificate prints them; the fit records them (fit record `acquired_utc`, `unit_model`,
// `unit_firmware`, `ambient`).
#ifndef IMUFIT_IO_RUN_HEADER_H_
#define IMUFIT_IO_RUN_HEADER_H_

#include <string>
#include <vector>

#include "imufit/io/csv_reader.h"

namespace imufit {

struct RunHeader {
  std::string acquired_utc;  // "YYYY-MM-DDTHH:MM:SSZ"; "" when not stated
  std::string model, firmware, ambient;
};

// The run header of the comment lines `comments` of the samples file `path` (for messages).
RunHeader RunHeaderOf(const std::string& path, const std::vector<CsvReader::Comment>& comments);

// The run header of the samples file `path` (its header only is read).
RunHeader ReadRunHeader(const std::string& path);

// True for a date written YYYY-MM-DD that exists in the Gregorian calendar.
bool IsIsoDate(const std::string& text);

// `text`, an ISO 8601 time in UTC ("2026-11-20T14:03:00Z", "...T14:03Z", "...T14:03:00.250Z",
// "...+00:00", a space for the T), as "YYYY-MM-DDTHH:MM:SSZ" (fractions of a second dropped);
// "" when it is not one.
std::string NormalisedUtc(const std::string& text);

}  // namespace imufit

#endif  // IMUFIT_IO_RUN_HEADER_H_
