#include "imufit/io/rosbag_samples.h"

#include <console_bridge/console.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Temperature.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <map>
#include <new>
#include <set>
#include <vector>

#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"

namespace imufit {
namespace {

constexpr int64_t kNsPerS = 1000000000;

// A header stamp in nanoseconds, from its fields as stored (a fuzzed nsec beyond 1e9 is summed, not
// normalised by ros::Time, which throws on overflow).
int64_t StampNs(const ros::Time& stamp) {
  return static_cast<int64_t>(stamp.sec) * kNsPerS + static_cast<int64_t>(stamp.nsec);
}

std::string StampText(int64_t ns) {
  char text[48];
  std::snprintf(text, sizeof text, "%lld.%09lld s", static_cast<long long>(ns / kNsPerS),
                static_cast<long long>(ns % kNsPerS));
  return text;
}

// The topics of `types` in the bag, each once, in the bag's order, and the whole list as text.
struct Topics {
  std::map<std::string, std::string> type_of;  // topic -> datatype
  std::vector<std::string> Of(const std::string& type) const {
    std::vector<std::string> topics;
    for (const auto& entry : type_of) {
      if (entry.second == type) topics.push_back(entry.first);
    }
    return topics;
  }
  std::string Listed() const {
    std::string text;
    for (const auto& entry : type_of) {
      text += (text.empty() ? "" : ", ") + QuoteForMessage(entry.first) + " (" + entry.second + ")";
    }
    return text.empty() ? "none" : text;
  }
};

std::string Joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + QuoteForMessage(name);
  return text;
}

// The topic to read: `chosen` (checked to be of `type`), else the bag's only one of `type`. "" when
// `optional` and the bag has none.
std::string ChooseTopic(const std::string& path, const Topics& topics, const std::string& chosen,
                        const char* type, const char* option, bool optional) {
  if (!chosen.empty()) {
    const auto found = topics.type_of.find(chosen);
    if (found == topics.type_of.end())
      throw InputError(path, option + std::string(" ") + QuoteForMessage(chosen) +
                                 ": no such topic in the bag; its topics: " + topics.Listed());
    if (found->second != type)
      throw InputError(path, option + std::string(" ") + QuoteForMessage(chosen) + ": the topic holds " +
                                 found->second + ", not " + type);
    return chosen;
  }
  const std::vector<std::string> of_type = topics.Of(type);
  if (of_type.size() == 1) return of_type.front();
  if (of_type.empty()) {
    if (optional) return "";
    throw InputError(path, std::string("no ") + type + " topic in the bag; its topics: " + topics.Listed());
  }
  throw InputError(path, std::to_string(of_type.size()) + " " + type + " topics (" + Joined(of_type) +
                             "): choose one with " + option);
}

// A message of a topic: its place in error messages, built only when one is thrown (a bag has
// millions of messages).
struct MessageAt {
  const std::string& path;
  const std::string& topic;
  long long index;  // 1-based
  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(
        path, "topic " + QuoteForMessage(topic) + ", message " + std::to_string(index) + ": " + message);
  }
};

// Fails unless `value` is finite.
void CheckFinite(const MessageAt& at, const char* field, const char* axis, double value) {
  if (!std::isfinite(value))
    at.Fail(std::string(field) + axis + ": " + FormatDouble(value) + " is not a finite number");
}

void CheckVector(const MessageAt& at, const char* field, const geometry_msgs::Vector3& v,
                 const boost::array<double, 9>& covariance) {
  // sensor_msgs/Imu: covariance element 0 = -1 says the driver has no such data.
  if (covariance[0] == -1.0)
    at.Fail(std::string(field) + "_covariance[0] is -1: the driver publishes no " + field +
            " (sensor_msgs/Imu), so it cannot be calibrated");
  CheckFinite(at, field, ".x", v.x);
  CheckFinite(at, field, ".y", v.y);
  CheckFinite(at, field, ".z", v.z);
}

struct TemperatureReading {
  int64_t stamp_ns;
  double temp_c;
};

// The temperature at `stamp_ns`: interpolated between the readings around it, held at the nearest
// one outside them; nullopt when the nearest is farther than kMaxTemperatureGapS.
std::optional<double> TemperatureAt(const std::vector<TemperatureReading>& readings, int64_t stamp_ns,
                                    size_t* cursor, int64_t* gap_ns) {
  while (*cursor < readings.size() && readings[*cursor].stamp_ns <= stamp_ns) ++*cursor;
  // readings[*cursor - 1] <= stamp < readings[*cursor]
  const TemperatureReading* before = *cursor > 0 ? &readings[*cursor - 1] : nullptr;
  const TemperatureReading* after = *cursor < readings.size() ? &readings[*cursor] : nullptr;
  const int64_t gap_before = before ? stamp_ns - before->stamp_ns : INT64_MAX;
  const int64_t gap_after = after ? after->stamp_ns - stamp_ns : INT64_MAX;
  *gap_ns = std::min(gap_before, gap_after);
  if (static_cast<double>(*gap_ns) > kMaxTemperatureGapS * static_cast<double>(kNsPerS)) return std::nullopt;
  if (before == nullptr) return after->temp_c;
  if (after == nullptr) return before->temp_c;
  const double share =
      static_cast<double>(gap_before) / static_cast<double>(after->stamp_ns - before->stamp_ns);
  return before->temp_c + share * (after->temp_c - before->temp_c);
}

// The structure of a bag (format 2.0, wiki.ros.org/Bags/Format/2.0) checked before rosbag reads it:
// rosbag allocates whatever a record's length field says (a corrupted length of 2 GB is a 2 GB
// allocation) and seeks wherever the file header and the chunk infos point. Every top-level
// record's lengths must lie within the file, its header fields within the header, the index and
// every chunk must start at a record, and a chunk may not claim more than kMaxChunkBytes unpacked.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;  // rosbag writes chunks of about 768 kB
constexpr std::string_view kRosbagV2Magic = "#ROSBAG V2.0\n";

class BagStructure {
 public:
  explicit BagStructure(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "rb")) {
    if (file_ == nullptr) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
  }
  ~BagStructure() { std::fclose(file_); }
  BagStructure(const BagStructure&) = delete;
  BagStructure& operator=(const BagStructure&) = delete;

  void Check() {
    std::fseek(file_, 0, SEEK_END);
    const long end = std::ftell(file_);
    if (end < 0) throw InputError(path_, "cannot read its size");
    size_ = static_cast<uint64_t>(end);
    std::string magic(kRosbagV2Magic.size(), '\0');
    std::fseek(file_, 0, SEEK_SET);
    if (std::fread(magic.data(), 1, magic.size(), file_) != magic.size() || magic != kRosbagV2Magic) {
      const size_t line = magic.find('\n');
      throw InputError(path_, "a ROS bag of format " + QuoteForMessage(magic.substr(0, line)) +
                                  ": imufit reads format 2.0 (#ROSBAG V2.0, every ROS 1 since 2010)");
    }
    uint64_t index_pos = 0;
    std::set<uint64_t> chunk_starts;
    std::vector<uint64_t> chunk_pointers;
    for (uint64_t pos = kRosbagV2Magic.size(); pos < size_;) {
      const uint64_t header_len = ReadLength(pos, "a record's header length");
      const std::map<std::string, std::string> fields = ReadHeader(pos + 4, header_len);
      const uint64_t data_at = pos + 4 + header_len;
      const uint64_t data_len = ReadLength(data_at, "a record's data length");
      const auto op = fields.find("op");
      if (op == fields.end() || op->second.size() != 1) Fail(pos, "a record without its op field");
      const char code = op->second[0];
      if (code == 0x03) index_pos = Field64(fields, "index_pos", pos);
      if (code == 0x05) {
        chunk_starts.insert(pos);
        if (Field32(fields, "size", pos) > kMaxChunkBytes)
          Fail(pos, "a chunk claims " + std::to_string(Field32(fields, "size", pos)) + " bytes unpacked");
      }
      if (code == 0x06) chunk_pointers.push_back(Field64(fields, "chunk_pos", pos));
      record_starts_.insert(pos);
      pos = data_at + 4 + data_len;
    }
    if (index_pos != 0 && record_starts_.count(index_pos) == 0)
      Fail(13, "the file header's index_pos " + std::to_string(index_pos) + " is not at a record");
    for (uint64_t chunk : chunk_pointers) {
      if (chunk_starts.count(chunk) == 0)
        Fail(index_pos, "a chunk info points at " + std::to_string(chunk) + ", where no chunk starts");
    }
  }

 private:
  [[noreturn]] void Fail(uint64_t at, const std::string& message) const {
    throw InputError(path_, "not a readable ROS bag: at byte " + std::to_string(at) + ": " + message);
  }

  // The 4-byte little-endian length at `pos`, whose bytes must follow it within the file.
  uint64_t ReadLength(uint64_t pos, const char* what) {
    unsigned char bytes[4];
    if (pos + 4 > size_ || std::fseek(file_, static_cast<long>(pos), SEEK_SET) != 0 ||
        std::fread(bytes, 1, 4, file_) != 4)
      Fail(pos, std::string(what) +
                    " past the end of the file (cut short? `rosbag reindex` may repair a recording that was "
                    "not closed)");
    const uint64_t length = bytes[0] | bytes[1] << 8 | bytes[2] << 16 | uint64_t{bytes[3]} << 24;
    if (length > size_ - pos - 4)
      Fail(pos, std::string(what) + " of " + std::to_string(length) +
                    " bytes, past the end of the file (cut short? `rosbag reindex` may repair a recording "
                    "that was not closed)");
    return length;
  }

  std::map<std::string, std::string> ReadHeader(uint64_t pos, uint64_t length) {
    std::string header(length, '\0');
    if (std::fread(header.data(), 1, length, file_) != length) Fail(pos, "cannot read a record's header");
    std::map<std::string, std::string> fields;
    for (size_t at = 0; at < header.size();) {
      if (header.size() - at < 4) Fail(pos + at, "a header field's length cut short");
      const auto* b = reinterpret_cast<const unsigned char*>(header.data() + at);
      const uint64_t field_len = b[0] | b[1] << 8 | b[2] << 16 | uint64_t{b[3]} << 24;
      if (field_len > header.size() - at - 4) Fail(pos + at, "a header field longer than its header");
      const std::string field = header.substr(at + 4, field_len);
      const size_t equals = field.find('=');
      if (equals == std::string::npos) Fail(pos + at, "a header field without '='");
      fields[field.substr(0, equals)] = field.substr(equals + 1);
      at += 4 + field_len;
    }
    return fields;
  }

  uint64_t Field(const std::map<std::string, std::string>& fields, const char* name, size_t bytes,
                 uint64_t pos) const {
    const auto found = fields.find(name);
    if (found == fields.end() || found->second.size() != bytes)
      Fail(pos, std::string("a record without its ") + name + " field");
    uint64_t value = 0;
    for (size_t i = 0; i < bytes; ++i)
      value |= uint64_t{static_cast<unsigned char>(found->second[i])} << (8 * i);
    return value;
  }
  uint64_t Field32(const std::map<std::string, std::string>& fields, const char* name, uint64_t pos) const {
    return Field(fields, name, 4, pos);
  }
  uint64_t Field64(const std::map<std::string, std::string>& fields, const char* name, uint64_t pos) const {
    return Field(fields, name, 8, pos);
  }

  const std::string& path_;
  std::FILE* file_;
  uint64_t size_ = 0;
  std::set<uint64_t> record_starts_;
};

class BagReading {
 public:
  BagReading(const std::string& path, const RosbagOptions& options) : path_(path), options_(options) {}

  // One rosbag::Bag read in order on this thread. Measured and left out (bag_bench's bag, 1e6
  // samples): two time ranges read on two threads, each with its own Bag, took 0.30-0.38 s instead of
  // 0.38-0.44 s of wall clock for 45 % more CPU (each Bag reads the whole index), CPU that the SHA-256
  // thread needs on 2 cores; and Bags made and closed on two threads at once aborted the process in
  // one of two runs (pluginlib's class_loader: LibraryUnloadException, std::terminate).
  RosbagSamples Read() {
    BagStructure(path_).Check();
    bag_.open(path_, rosbag::bagmode::Read);
    Topics topics;
    {
      rosbag::View all(bag_);
      for (const rosbag::ConnectionInfo* connection : all.getConnections())
        topics.type_of.emplace(connection->topic, connection->datatype);
    }
    result_.topic = ChooseTopic(path_, topics, options_.topic, kRosImuType, "--topic", false);
    result_.temp_topic =
        ChooseTopic(path_, topics, options_.temp_topic, kRosTemperatureType, "--temp-topic", true);
    if (!result_.temp_topic.empty() && options_.temp_c)
      throw InputError(path_, "the bag has a temperature topic " + QuoteForMessage(result_.temp_topic) +
                                  ": a fixed temperature (--temp-c) is only for a bag without one");
    if (result_.temp_topic.empty() && !options_.temp_c)
      throw InputError(path_,
                       "no sensor_msgs/Temperature topic in the bag; for a session without a "
                       "thermometer give its temperature (--temp-c)");
    std::vector<std::string> wanted{result_.topic};
    if (!result_.temp_topic.empty()) wanted.push_back(result_.temp_topic);
    {
      const size_t messages = rosbag::View(bag_, rosbag::TopicQuery(result_.topic)).size();  // from the index
      result_.samples.reserve(messages);
      imu_stamps_ns_.reserve(messages);
    }
    rosbag::View view(bag_, rosbag::TopicQuery(wanted));
    for (const rosbag::MessageInstance& message : view) {
      if (message.getTopic() == result_.topic) {
        ReadImu(message);
      } else {
        ReadTemperature(message);
      }
    }
    if (result_.samples.empty())
      throw InputError(path_, "topic " + QuoteForMessage(result_.topic) + ": no messages");
    if (!result_.temp_topic.empty()) SetTemperatures();
    return std::move(result_);
  }

 private:
  // A message's serialized bytes, copied out of rosbag's chunk buffer into a buffer reused for every
  // message (the Stream that MessageInstance::write fills).
  struct Bytes {
    std::vector<uint8_t> data;  // grows to the largest message, never shrinks
    uint32_t size = 0;
    uint8_t* advance(uint32_t message_size) {
      if (data.size() < message_size) data.resize(message_size);
      size = message_size;
      return data.data();
    }
  };

  // Decodes `message` into `read` (reused from message to message: no allocation per message) with
  // ros::serialization, as MessageInstance::instantiate would, after the same type check. Its bytes
  // are taken with MessageInstance::write (as rosbag play takes them), which costs a quarter less
  // than instantiate<>(): that also looks the record header's connection up in its parsed map and
  // allocates a message. The message's connection is then the index's, as for rosbag play.
  template <typename Message>
  void Decode(const rosbag::MessageInstance& message, const MessageAt& at, Message* read) {
    if (message.getMD5Sum() != ros::message_traits::MD5Sum<Message>::value())
      at.Fail("a " + message.getDataType() + " (definition md5 " + message.getMD5Sum() + ") where " +
              ros::message_traits::DataType<Message>::value() + " (md5 " +
              ros::message_traits::MD5Sum<Message>::value() + ") was expected");
    bytes_.size = 0;  // write() does not call advance() for an empty message
    message.write(bytes_);
    ros::serialization::IStream stream(bytes_.data.data(), bytes_.size);
    ros::serialization::deserialize(stream, *read);
  }

  void ReadImu(const rosbag::MessageInstance& message) {
    ++imu_messages_;
    const MessageAt at{path_, result_.topic, imu_messages_};
    Decode(message, at, &imu_);
    const sensor_msgs::Imu* imu = &imu_;
    const int64_t stamp_ns = StampNs(imu->header.stamp);
    if (imu_messages_ == 1) first_ns_ = stamp_ns;
    if (imu_messages_ > 1 && stamp_ns <= last_ns_)
      at.Fail("header.stamp " + StampText(stamp_ns) + " is not after the previous message's " +
              StampText(last_ns_) + " (the samples' time must increase)");
    last_ns_ = stamp_ns;
    CheckVector(at, "angular_velocity", imu->angular_velocity, imu->angular_velocity_covariance);
    CheckVector(at, "linear_acceleration", imu->linear_acceleration, imu->linear_acceleration_covariance);
    Sample sample;
    sample.time_s = static_cast<double>(stamp_ns - first_ns_) * 1e-9;
    sample.gyro << imu->angular_velocity.x, imu->angular_velocity.y, imu->angular_velocity.z;
    sample.accel << imu->linear_acceleration.x, imu->linear_acceleration.y, imu->linear_acceleration.z;
    sample.temp_c = options_.temp_c.value_or(0.0);
    result_.samples.push_back(sample);
    imu_stamps_ns_.push_back(stamp_ns);
  }

  void ReadTemperature(const rosbag::MessageInstance& message) {
    const MessageAt at{path_, result_.temp_topic, ++result_.temp_readings};
    Decode(message, at, &temperature_);
    const sensor_msgs::Temperature* reading = &temperature_;
    const int64_t stamp_ns = StampNs(reading->header.stamp);
    if (!temps_.empty() && stamp_ns <= temps_.back().stamp_ns)
      at.Fail("header.stamp " + StampText(stamp_ns) + " is not after the previous message's " +
              StampText(temps_.back().stamp_ns) + " (the readings' time must increase)");
    CheckFinite(at, "temperature", "", reading->temperature);
    if (const std::string problem = TemperatureProblem(reading->temperature, temps_.empty());
        !problem.empty())
      at.Fail("temperature: " + problem);
    temps_.push_back({stamp_ns, reading->temperature});
  }

  void SetTemperatures() {
    if (temps_.empty())
      throw InputError(path_, "topic " + QuoteForMessage(result_.temp_topic) +
                                  ": no messages (no temperature for the samples)");
    size_t cursor = 0;
    for (size_t i = 0; i < result_.samples.size(); ++i) {
      int64_t gap_ns = 0;
      const std::optional<double> temp_c = TemperatureAt(temps_, imu_stamps_ns_[i], &cursor, &gap_ns);
      if (!temp_c)
        MessageAt{path_, result_.topic, static_cast<long long>(i) + 1}.Fail(
            "header.stamp " + StampText(imu_stamps_ns_[i]) + " is " +
            FormatDouble(static_cast<double>(gap_ns) * 1e-9) + " s from the nearest reading of " +
            QuoteForMessage(result_.temp_topic) + " (at most " + FormatDouble(kMaxTemperatureGapS) +
            " s): its temperature is unknown");
      result_.samples[i].temp_c = *temp_c;
    }
  }

  const std::string& path_;
  const RosbagOptions& options_;
  rosbag::Bag bag_;
  RosbagSamples result_;
  long long imu_messages_ = 0;
  int64_t first_ns_ = 0;
  int64_t last_ns_ = 0;
  std::vector<int64_t> imu_stamps_ns_;
  std::vector<TemperatureReading> temps_;
  Bytes bytes_;
  sensor_msgs::Imu imu_;
  sensor_msgs::Temperature temperature_;
};

}  // namespace

bool LooksLikeRosbag(std::string_view head) { return head.substr(0, kRosbagMagic.size()) == kRosbagMagic; }

RosbagSamples ReadRosbagSamples(const std::string& path, const RosbagOptions& options) {
  // The library reports through console_bridge as well as by throwing: one line is ours to print.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  try {
    return BagReading(path, options).Read();
  } catch (const InputError&) {
    throw;
  } catch (const rosbag::BagUnindexedException& e) {
    throw InputError(path, std::string("the bag has no index (a recording cut short?): ") + e.what() +
                               "; `rosbag reindex` repairs it");
  } catch (const rosbag::BagException& e) {
    throw InputError(path, std::string("not a readable ROS bag (rosbag: ") + e.what() +
                               "); if the recording was cut short, `rosbag reindex` may repair it");
  } catch (const std::bad_alloc&) {
    throw InputError(path, "not a readable ROS bag: a record claims more memory than there is");
  } catch (const std::exception& e) {
    throw InputError(path, std::string("not a readable ROS bag (rosbag: ") + e.what() + ")");
  } catch (...) {
    throw InputError(path, "not a readable ROS bag (rosbag failed without a message)");
  }
}

}  // namespace imufit
