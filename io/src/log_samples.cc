#include "imufit/io/log_samples.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <thread>

#include "imufit/io/error.h"
#include "imufit/io/ulog_samples.h"

namespace imufit {
namespace {

using File = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

File OpenOrThrow(const std::string& path) {
  File file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  return file;
}

// Hashes the file's bytes as they are on disk.
void HashFile(const std::string& path, Sha256* digest) {
  File file = OpenOrThrow(path);
  std::vector<char> block(1 << 20);
  while (const size_t read = std::fread(block.data(), 1, block.size(), file.get()))
    digest->Update(std::string_view(block.data(), read));
  if (std::ferror(file.get())) throw InputError(path, std::string("cannot read: ") + std::strerror(errno));
}

// The CSV option given that a bag or a ULog cannot take, or null.
const char* CsvOnlyOption(const SamplesFormat& csv) {
  return csv.seconds_per_time_unit != 1.0 ? "--time-unit"
         : !csv.column_names.empty()      ? "--column"
         : csv.dialect.delimiter != ','   ? "--delimiter"
         : csv.dialect.decimal_comma      ? "--decimal-comma"
                                          : nullptr;
}

// A bag is read by topics, not columns: the CSV's options mean nothing to it.
void RefuseCsvOptions(const std::string& path, const SamplesFormat& csv) {
  if (const char* option = CsvOnlyOption(csv))
    throw InputError(path, std::string("is a ROS bag: ") + option +
                               " is for CSV samples (a bag's stamps are in seconds and its fields named)");
}

// The option of another format given, or null.
const char* OtherFormatsOption(LogFormat format, const LogSamplesOptions& options) {
  if (format != LogFormat::kRosbag && !options.topic.empty()) return "--topic";
  if (format != LogFormat::kRosbag && !options.temp_topic.empty()) return "--temp-topic";
  if (format != LogFormat::kUlog && options.ulog_instance) return "--instance";
  return nullptr;
}

}  // namespace

LogFormat LogFormatOf(const std::string& path) {
  File file = OpenOrThrow(path);
  char head[16] = {};
  const size_t read = std::fread(head, 1, sizeof head, file.get());
  if (LooksLikeRosbag(std::string_view(head, read))) return LogFormat::kRosbag;
  return IsUlogFile(path) ? LogFormat::kUlog : LogFormat::kSamplesCsv;
}

LogSamples ReadLogSamples(const std::string& path, const LogSamplesOptions& options, Sha256* digest) {
  LogSamples log;
  log.format = LogFormatOf(path);
  if (const char* option = OtherFormatsOption(log.format, options)) {
    if (option[2] == 't')  // --topic, --temp-topic
      throw InputError(path, std::string("is not a ROS bag (no \"#ROSBAG V\" at its start): ") + option +
                                 " is for a bag's topics");
    throw InputError(path, std::string(option) + " chooses a PX4 ULog's sensors; this file is a " +
                               (log.format == LogFormat::kRosbag ? "ROS bag" : "CSV"));
  }
  if (log.format == LogFormat::kUlog) {
    if (const char* option = CsvOnlyOption(options.csv))
      throw InputError(path, std::string(option) + " reads a CSV; this file is a PX4 ULog");
    UlogSamples ulog = ReadUlogSamples(path, UlogOptions{options.ulog_instance, options.csv.temp_c}, digest);
    log.samples = std::move(ulog.samples);
    log.notes = UlogNotes(path, ulog);
    return log;
  }
  if (log.format == LogFormat::kRosbag) {
    RefuseCsvOptions(path, options.csv);
    // The file is hashed by a thread of its own while rosbag parses it: a bag is about three times
    // the size of the same samples as CSV, and its hash would cost as much as the parse.
    std::exception_ptr hash_error;
    std::thread hasher;
    if (digest != nullptr) {
      hasher = std::thread([&] {
        try {
          HashFile(path, digest);
        } catch (...) {
          hash_error = std::current_exception();
        }
      });
    }
    RosbagSamples bag;
    try {
      bag = ReadRosbagSamples(path, {options.topic, options.temp_topic, options.csv.temp_c});
    } catch (...) {
      if (hasher.joinable()) hasher.join();
      throw;
    }
    if (hasher.joinable()) hasher.join();
    if (hash_error) std::rethrow_exception(hash_error);
    log.samples = std::move(bag.samples);
    log.topic = std::move(bag.topic);
    log.temp_topic = std::move(bag.temp_topic);
    return log;
  }
  SamplesReader reader(path, /*require_segment=*/false, options.csv, digest);
  Sample sample;
  while (reader.Next(&sample)) log.samples.push_back(sample);
  log.header_comments = reader.header_comments();
  log.serial = reader.located_serial();
  return log;
}

}  // namespace imufit
