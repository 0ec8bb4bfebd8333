#include "imufit/io/log_samples.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <thread>

#include "imufit/io/error.h"

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

// A bag is read by topics, not columns: the CSV's options mean nothing to it.
void RefuseCsvOptions(const std::string& path, const SamplesFormat& csv) {
  const char* option = csv.seconds_per_time_unit != 1.0 ? "--time-unit"
                       : !csv.column_names.empty()      ? "--column"
                       : csv.dialect.delimiter != ','   ? "--delimiter"
                       : csv.dialect.decimal_comma      ? "--decimal-comma"
                                                        : nullptr;
  if (option != nullptr)
    throw InputError(path, std::string("is a ROS bag: ") + option +
                               " is for CSV samples (a bag's stamps are in seconds and its fields named)");
}

}  // namespace

LogFormat LogFormatOf(const std::string& path) {
  File file = OpenOrThrow(path);
  char head[16] = {};
  const size_t read = std::fread(head, 1, sizeof head, file.get());
  return LooksLikeRosbag(std::string_view(head, read)) ? LogFormat::kRosbag : LogFormat::kSamplesCsv;
}

LogSamples ReadLogSamples(const std::string& path, const LogSamplesOptions& options, Sha256* digest) {
  LogSamples log;
  log.format = LogFormatOf(path);
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
  const char* bag_option = !options.topic.empty()        ? "--topic"
                           : !options.temp_topic.empty() ? "--temp-topic"
                                                         : nullptr;
  if (bag_option != nullptr)
    throw InputError(path, std::string("is not a ROS bag (no \"#ROSBAG V\" at its start): ") + bag_option +
                               " is for a bag's topics");
  SamplesReader reader(path, /*require_segment=*/false, options.csv, digest);
  Sample sample;
  while (reader.Next(&sample)) log.samples.push_back(sample);
  log.header_comments = reader.header_comments();
  log.serial = reader.located_serial();
  return log;
}

}  // namespace imufit
