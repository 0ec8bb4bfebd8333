// imufit — the samples of a CSV or a ULog (log_samples.h).
#include "imufit/io/log_samples.h"

#include <utility>

#include "imufit/io/error.h"
#include "imufit/io/ulog_samples.h"

namespace imufit {

LogSamples ReadLogSamples(const std::string& path, const LogOptions& options, Sha256* digest) {
  LogSamples log;
  if (IsUlogFile(path)) {
    const SamplesFormat& csv = options.csv;
    const char* csv_only = csv.seconds_per_time_unit != 1.0 ? "--time-unit"
                           : !csv.column_names.empty()      ? "--column"
                           : csv.dialect.delimiter != ','   ? "--delimiter"
                           : csv.dialect.decimal_comma      ? "--decimal-comma"
                                                            : nullptr;
    if (csv_only) throw InputError(path, std::string(csv_only) + " reads a CSV; this file is a PX4 ULog");
    UlogSamples ulog = ReadUlogSamples(path, UlogOptions{options.ulog_instance, csv.temp_c}, digest);
    log.format = LogFormat::kUlog;
    log.samples = std::move(ulog.samples);
    log.notes = UlogNotes(path, ulog);
    return log;
  }
  if (options.ulog_instance)
    throw InputError(path, "--instance chooses a PX4 ULog's sensors; this file is a CSV");
  SamplesReader reader(path, /*require_segment=*/false, options.csv, digest);
  Sample sample;
  while (reader.Next(&sample)) log.samples.push_back(sample);
  log.header_comments = reader.header_comments();
  log.serial = reader.located_serial();
  return log;
}

}  // namespace imufit
