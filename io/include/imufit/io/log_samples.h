// imufit — a session's samples from whatever log a user has: imufit's samples CSV (.csv, .csv.gz)
// or a PX4 ULog (ulog_samples.h), told apart by the file's first bytes, not its name.
#ifndef IMUFIT_IO_LOG_SAMPLES_H_
#define IMUFIT_IO_LOG_SAMPLES_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/io/csv_reader.h"
#include "imufit/io/samples.h"
#include "imufit/model/sample.h"

namespace imufit {

class Sha256;

enum class LogFormat { kCsv, kUlog };

struct LogOptions {
  // How a CSV is read; its temp_c also stands for a ULog's missing temperatures. The CSV-only
  // parts (time unit, delimiter, decimal comma, column names) are refused for a ULog.
  SamplesFormat csv;
  // A ULog's sensor instance (multi_id, --instance); refused for a CSV.
  std::optional<int> ulog_instance;
};

struct LogSamples {
  LogFormat format = LogFormat::kCsv;
  std::vector<Sample> samples;  // in time order
  // A CSV's header comment lines and its `# serial:` line (none for a ULog).
  std::vector<CsvReader::Comment> header_comments;
  SamplesSerial serial;
  // What a user should know about the reading (a ULog's dropouts, ...), one line each.
  std::vector<std::string> notes;
};

// Reads the whole log at `path` (every byte through `digest` when not null: the file's SHA-256 as
// on disk). The segment column of a CSV is read when present. Throws InputError.
LogSamples ReadLogSamples(const std::string& path, const LogOptions& options, Sha256* digest);

}  // namespace imufit

#endif  // IMUFIT_IO_LOG_SAMPLES_H_
