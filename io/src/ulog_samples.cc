// imufit — PX4 ULog reader (ulog_samples.h), written from PX4's "ULog File Format" specification.
#include "imufit/io/ulog_samples.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string_view>

#include "imufit/base/text.h"
#include "imufit/io/error.h"
#include "imufit/io/samples.h"
#include "imufit/io/sha256.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

constexpr size_t kHeaderBytes = 16;
constexpr size_t kMessageHeaderBytes = 3;
constexpr size_t kFlagBitsBytes = 40;        // compat[8], incompat[8], appended_offsets[3]
constexpr int kIncompatDataAppended = 0x01;  // incompat_flags[0] bit 0
constexpr size_t kReadBlockBytes = size_t{1} << 22;
// Times after boot beyond this (over 31 years) are refused: below it, every microsecond is a
// distinct double in seconds, so times that increase stay increasing.
constexpr uint64_t kMaxTimeUs = 1000000000000000ull;
constexpr const char* kAccelTopic = "sensor_accel";
constexpr const char* kGyroTopic = "sensor_gyro";

template <typename T>
T Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof value);  // little endian, as the spec's and this machine's
  return value;
}

// The file's bytes, read forward in blocks, every byte through the digest.
class ByteStream {
 public:
  ByteStream(const std::string& path, Sha256* digest) : path_(path), digest_(digest) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw InputError(path, std::string("cannot open: ") + std::strerror(errno));
    struct stat st;
    if (::fstat(fd_, &st) == 0) size_ = static_cast<long long>(st.st_size);
  }
  ~ByteStream() { ::close(fd_); }
  ByteStream(const ByteStream&) = delete;
  ByteStream& operator=(const ByteStream&) = delete;

  // Makes `n` bytes from the cursor available; false when the file ends first.
  bool Ensure(size_t n) {
    if (end_ - begin_ >= n) return true;
    if (begin_ > 0) {
      std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
      end_ -= begin_;
      begin_ = 0;
    }
    // A block, or the whole of a smaller file (and a byte to see its end): a small log costs little.
    const size_t block =
        size_ >= 0 ? std::min(kReadBlockBytes, static_cast<size_t>(size_) + 1) : kReadBlockBytes;
    if (buffer_.size() < std::max(n, block)) buffer_.resize(std::max(n, block));
    while (end_ < n && !eof_) {
      const ssize_t got = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
      if (got < 0) {
        if (errno == EINTR) continue;
        throw InputError(path_, std::string("cannot read: ") + std::strerror(errno));
      }
      if (got == 0) {
        eof_ = true;
        break;
      }
      if (digest_)
        digest_->Update(std::string_view(reinterpret_cast<const char*>(buffer_.data() + end_), got));
      end_ += static_cast<size_t>(got);
    }
    return end_ - begin_ >= n;
  }
  const uint8_t* data() const { return buffer_.data() + begin_; }
  size_t available() const { return end_ - begin_; }
  void Skip(size_t n) {
    IMUFIT_CHECK(n <= available(), "skips only bytes read");
    begin_ += n;
    offset_ += static_cast<long long>(n);
  }
  // Moves forward to byte `offset` (no further than the end); the bytes between are still hashed.
  void SkipTo(long long offset) {
    while (offset_ < offset) {
      if (available() == 0 && !Ensure(1)) return;
      Skip(static_cast<size_t>(std::min<long long>(offset - offset_, static_cast<long long>(available()))));
    }
  }
  // Reads the rest (for the digest); returns the number of bytes it held.
  long long Drain() {
    long long rest = 0;
    while (Ensure(1)) {
      rest += static_cast<long long>(available());
      Skip(available());
    }
    return rest;
  }
  long long offset() const { return offset_; }
  long long size() const { return size_; }

 private:
  std::string path_;
  Sha256* digest_;
  int fd_ = -1;
  long long size_ = -1;
  std::vector<uint8_t> buffer_;
  size_t begin_ = 0;
  size_t end_ = 0;
  bool eof_ = false;
  long long offset_ = 0;  // file offset of data()
};

enum class Basic {
  kNone,
  kInt8,
  kUInt8,
  kInt16,
  kUInt16,
  kInt32,
  kUInt32,
  kInt64,
  kUInt64,
  kFloat,
  kDouble,
  kBool,
  kChar
};

struct BasicTypeName {
  const char* name;
  Basic type;
  size_t bytes;
};
constexpr BasicTypeName kBasicTypes[] = {
    {"int8_t", Basic::kInt8, 1},     {"uint8_t", Basic::kUInt8, 1},   {"int16_t", Basic::kInt16, 2},
    {"uint16_t", Basic::kUInt16, 2}, {"int32_t", Basic::kInt32, 4},   {"uint32_t", Basic::kUInt32, 4},
    {"int64_t", Basic::kInt64, 8},   {"uint64_t", Basic::kUInt64, 8}, {"float", Basic::kFloat, 4},
    {"double", Basic::kDouble, 8},   {"bool", Basic::kBool, 1},       {"char", Basic::kChar, 1}};

const BasicTypeName* FindBasic(const std::string& name) {
  for (const BasicTypeName& basic : kBasicTypes)
    if (name == basic.name) return &basic;
  return nullptr;
}

double LoadNumber(const uint8_t* p, Basic type) {
  switch (type) {
    case Basic::kInt8:
      return Load<int8_t>(p);
    case Basic::kUInt8:
    case Basic::kBool:
    case Basic::kChar:
      return Load<uint8_t>(p);
    case Basic::kInt16:
      return Load<int16_t>(p);
    case Basic::kUInt16:
      return Load<uint16_t>(p);
    case Basic::kInt32:
      return Load<int32_t>(p);
    case Basic::kUInt32:
      return Load<uint32_t>(p);
    case Basic::kInt64:
      return static_cast<double>(Load<int64_t>(p));
    case Basic::kUInt64:
      return static_cast<double>(Load<uint64_t>(p));
    case Basic::kFloat:
      return Load<float>(p);
    case Basic::kDouble:
      return Load<double>(p);
    case Basic::kNone:
      break;
  }
  IMUFIT_CHECK(false, "a basic type");
  return 0.0;
}

struct Field {
  std::string type;  // a basic type or a format's name
  size_t count = 1;  // array length (1 for a scalar)
  bool array = false;
  std::string name;
  size_t offset = 0;  // in the message, once resolved
  const BasicTypeName* basic = nullptr;
};

struct Format {
  std::string name;
  std::vector<Field> fields;
  long long offset = 0;  // of its 'F' message
  enum class State { kNew, kResolving, kResolved } state = State::kNew;
  size_t bytes = 0;      // its size, resolved
  size_t min_bytes = 0;  // without a trailing _padding field (which a writer may leave out)
};

// Where the fields imufit reads lie in a topic's data.
struct TopicLayout {
  size_t time = 0;
  Basic time_type = Basic::kNone;
  const char* time_name = "timestamp_sample";
  size_t xyz[3] = {0, 0, 0};
  Basic xyz_type[3] = {Basic::kNone, Basic::kNone, Basic::kNone};
  size_t temp = 0;
  Basic temp_type = Basic::kNone;  // kNone: no temperature field
  size_t device = 0;
  Basic device_type = Basic::kNone;
};

enum class Topic { kOther, kAccel, kGyro };

// One instance's messages of one topic.
struct Series {
  std::vector<uint64_t> time_us;
  std::vector<Eigen::Vector3d> xyz;
  std::vector<double> temp_c;
  bool stored = false;  // the values are kept (the instance may be read)
  long long messages = 0;
  uint32_t device_id = 0;
  bool has_device = false;
  uint64_t last_time_us = 0;
  enum class Temp { kUnknown, kFinite, kNone } temp = Temp::kUnknown;
};

struct Subscription {
  bool active = false;
  Topic topic = Topic::kOther;
  int multi_id = 0;
  const Format* format = nullptr;
  TopicLayout layout;
  Series* series = nullptr;  // sensor_accel's or sensor_gyro's (the parser's map holds it)
};

class UlogParser {
 public:
  UlogParser(const std::string& path, const UlogOptions& options, Sha256* digest)
      : path_(path), options_(options), in_(path, digest) {}

  UlogSamples Read();

 private:
  [[noreturn]] void Fail(long long offset, char type, const std::string& what,
                         const std::string& message) const {
    const std::string kind =
        type >= 0x20 && type < 0x7f ? FormatText("'%c'", type) : FormatText("type 0x%02x", type & 0xff);
    throw InputError(path_, FormatText("byte %lld: %s%s%s: ", offset, kind.c_str(), what.empty() ? "" : " ",
                                       what.c_str()) +
                                message);
  }
  void ReadHeader();
  void FlagBits(const uint8_t* p, size_t size, long long offset);
  void ParseFormat(const uint8_t* p, size_t size, long long offset);
  void Resolve(Format* format);
  void ResolveAll();
  void Subscribe(const uint8_t* p, size_t size, long long offset);
  void Data(const uint8_t* p, size_t size, long long offset);
  void Info(const uint8_t* p, size_t size, long long offset, char type);
  TopicLayout LayoutOf(const Format& format) const;
  Series& SeriesOf(Topic topic, int multi_id) { return (topic == Topic::kAccel ? accel_ : gyro_)[multi_id]; }
  bool Stores(int multi_id) const { return !options_.instance || *options_.instance == multi_id; }
  int ChooseInstance() const;
  void Merge(const Series& accel, const Series& gyro, UlogSamples* out) const;

  std::string path_;
  UlogOptions options_;
  ByteStream in_;
  UlogSamples result_;
  std::map<std::string, Format> formats_;
  bool formats_checked_ = false;
  std::vector<Subscription> subscriptions_;  // by msg_id
  std::set<std::string> subscribed_;         // the topics subscribed, for the message naming them
  std::vector<long long> appended_;          // pending appended data offsets, increasing
  std::map<int, Series> accel_, gyro_;       // by multi_id
  double last_time_s_ = 0.0;
};

void UlogParser::ReadHeader() {
  if (!in_.Ensure(kHeaderBytes)) {
    if (in_.available() < sizeof kUlogMagic || std::memcmp(in_.data(), kUlogMagic, sizeof kUlogMagic) != 0)
      throw InputError(path_, "byte 0: not a ULog file (it does not start with \"ULog\" 01 12 35)");
    throw InputError(
        path_, FormatText("byte %zu: the ULog header is cut short (16 bytes expected)", in_.available()));
  }
  if (std::memcmp(in_.data(), kUlogMagic, sizeof kUlogMagic) != 0)
    throw InputError(path_, "byte 0: not a ULog file (it does not start with \"ULog\" 01 12 35)");
  result_.version = in_.data()[7];
  result_.start_time_s = static_cast<double>(Load<uint64_t>(in_.data() + 8)) * 1e-6;
  in_.Skip(kHeaderBytes);
}

void UlogParser::FlagBits(const uint8_t* p, size_t size, long long offset) {
  if (offset != static_cast<long long>(kHeaderBytes))
    Fail(offset, 'B', "", "the flag bits message must be the first message, after the header");
  if (size < kFlagBitsBytes)
    Fail(offset, 'B', "", FormatText("%zu bytes, at least 40 expected (message cut short)", size));
  const uint8_t* incompat = p + 8;
  for (int i = 0; i < 8; ++i) {
    const int unknown = incompat[i] & (i == 0 ? ~kIncompatDataAppended : 0xff);
    if (unknown != 0)
      Fail(offset, 'B', "",
           FormatText("incompat_flags[%d] has the unknown bits 0x%02x: the log holds something this "
                      "reader does not know, and the ULog specification says to refuse it",
                      i, unknown));
  }
  if ((incompat[0] & kIncompatDataAppended) == 0) return;
  long long previous = offset + static_cast<long long>(kMessageHeaderBytes + size);
  for (int i = 0; i < 3; ++i) {
    const uint64_t appended = Load<uint64_t>(p + 16 + 8 * i);
    if (appended == 0) continue;
    if (appended < static_cast<uint64_t>(previous) ||
        (in_.size() >= 0 && appended > static_cast<uint64_t>(in_.size())))
      Fail(offset, 'B', "",
           FormatText("appended_offsets[%d] %llu lies %s", i, static_cast<unsigned long long>(appended),
                      appended < static_cast<uint64_t>(previous)
                          ? "before the data section or an earlier offset"
                          : "beyond the end of the file"));
    appended_.push_back(static_cast<long long>(appended));
    previous = static_cast<long long>(appended);
  }
}

void UlogParser::ParseFormat(const uint8_t* p, size_t size, long long offset) {
  const std::string text(reinterpret_cast<const char*>(p), size);
  const size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0)
    Fail(offset, 'F', "", "format " + QuoteForMessage(text) + " is not `name:type field;...`");
  Format format;
  format.name = text.substr(0, colon);
  format.offset = offset;
  if (FindBasic(format.name)) Fail(offset, 'F', format.name, "a format may not be named as a basic type");
  size_t start = colon + 1;
  while (start < text.size()) {
    size_t end = text.find(';', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const size_t space = item.find(' ');
    if (space == std::string::npos || space == 0 || space + 1 == item.size())
      Fail(offset, 'F', format.name, "field " + QuoteForMessage(item) + " is not `type name`");
    Field field;
    field.type = item.substr(0, space);
    field.name = item.substr(space + 1);
    const size_t bracket = field.type.find('[');
    if (bracket != std::string::npos) {
      const std::string count = field.type.substr(bracket + 1);
      char* after = nullptr;
      const unsigned long n = std::strtoul(count.c_str(), &after, 10);
      if (count.empty() || !std::isdigit(static_cast<unsigned char>(count[0])) || std::string(after) != "]" ||
          n == 0 || n > 65535)
        Fail(offset, 'F', format.name, "field " + QuoteForMessage(item) + ": bad array length");
      field.count = n;
      field.array = true;
      field.type.resize(bracket);
    }
    field.basic = FindBasic(field.type);
    format.fields.push_back(std::move(field));
  }
  if (format.fields.empty()) Fail(offset, 'F', format.name, "a format needs at least one field");
  if (formats_.count(format.name)) Fail(offset, 'F', format.name, "the format is defined twice");
  formats_.emplace(format.name, std::move(format));
}

void UlogParser::Resolve(Format* format) {
  if (format->state == Format::State::kResolved) return;
  if (format->state == Format::State::kResolving)
    Fail(format->offset, 'F', format->name, "the format contains itself (circular nesting)");
  format->state = Format::State::kResolving;
  size_t bytes = 0;
  for (Field& field : format->fields) {
    size_t element = 0;
    if (field.basic) {
      element = field.basic->bytes;
    } else {
      const auto nested = formats_.find(field.type);
      if (nested == formats_.end())
        Fail(format->offset, 'F', format->name,
             "field " + field.name + " has the type " + QuoteForMessage(field.type) +
                 ", neither a basic type nor a format the log defines");
      Resolve(&nested->second);
      element = nested->second.bytes;
    }
    field.offset = bytes;
    bytes += element * field.count;
    if (bytes > 65535) Fail(format->offset, 'F', format->name, "the format is larger than a message can be");
  }
  format->bytes = bytes;
  const Field& last = format->fields.back();
  format->min_bytes = last.name.rfind("_padding", 0) == 0 ? last.offset : bytes;
  format->state = Format::State::kResolved;
}

void UlogParser::ResolveAll() {
  for (auto& entry : formats_) Resolve(&entry.second);
  formats_checked_ = true;
}

TopicLayout UlogParser::LayoutOf(const Format& format) const {
  TopicLayout layout;
  const auto find = [&](const char* name) -> const Field* {
    for (const Field& field : format.fields)
      if (field.name == name) return &field;
    return nullptr;
  };
  const auto numeric = [&](const char* name, bool required, size_t* offset, Basic* type) {
    const Field* field = find(name);
    if (!field) {
      if (!required) return;
      std::string names;
      for (const Field& f : format.fields) names += (names.empty() ? "" : ", ") + f.name;
      Fail(format.offset, 'F', format.name,
           std::string("has no field ") + name + " (its fields: " + names + ")");
    }
    if (!field->basic || field->array || field->basic->type == Basic::kChar)
      Fail(format.offset, 'F', format.name,
           std::string("field ") + name + " is " + field->type + (field->array ? "[]" : "") +
               ", not a number");
    *offset = field->offset;
    *type = field->basic->type;
  };
  if (!find("timestamp_sample")) layout.time_name = "timestamp";
  numeric(layout.time_name, true, &layout.time, &layout.time_type);
  if (layout.time_type != Basic::kUInt64)
    Fail(format.offset, 'F', format.name, std::string(layout.time_name) + " is not uint64_t");
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) numeric(axes[i], true, &layout.xyz[i], &layout.xyz_type[i]);
  numeric("temperature", false, &layout.temp, &layout.temp_type);
  numeric("device_id", false, &layout.device, &layout.device_type);
  return layout;
}

void UlogParser::Subscribe(const uint8_t* p, size_t size, long long offset) {
  if (size < 4) Fail(offset, 'A', "", FormatText("%zu bytes, at least 4 expected (message cut short)", size));
  if (!formats_checked_) ResolveAll();
  const int multi_id = p[0];
  const uint16_t msg_id = Load<uint16_t>(p + 1);
  const std::string name(reinterpret_cast<const char*>(p + 3), size - 3);
  const auto format = formats_.find(name);
  if (format == formats_.end())
    Fail(offset, 'A', name, FormatText("msg_id %u subscribes to a topic no format ('F') defines", msg_id));
  Resolve(&format->second);
  if (subscriptions_.size() <= msg_id) subscriptions_.resize(msg_id + size_t{1});
  Subscription& subscription = subscriptions_[msg_id];
  if (subscription.active)
    Fail(offset, 'A', name,
         FormatText("msg_id %u is already subscribed to %s", msg_id, subscription.format->name.c_str()));
  subscription = Subscription();
  subscription.active = true;
  subscription.multi_id = multi_id;
  subscription.format = &format->second;
  subscribed_.insert(name);
  if (name == kAccelTopic || name == kGyroTopic) {
    subscription.topic = name == kAccelTopic ? Topic::kAccel : Topic::kGyro;
    subscription.layout = LayoutOf(format->second);
    subscription.series = &SeriesOf(subscription.topic, multi_id);
    subscription.series->stored = Stores(multi_id);
  }
}

void UlogParser::Data(const uint8_t* p, size_t size, long long offset) {
  if (size < 2) Fail(offset, 'D', "", FormatText("%zu bytes, at least 2 expected (message cut short)", size));
  const uint16_t msg_id = Load<uint16_t>(p);
  if (msg_id >= subscriptions_.size() || !subscriptions_[msg_id].active)
    Fail(offset, 'D', "", FormatText("msg_id %u, which no subscription ('A') defines", msg_id));
  const Subscription& sub = subscriptions_[msg_id];
  const uint8_t* data = p + 2;
  const size_t bytes = size - 2;
  // The topic as messages name it, made only for one (a message's formatting would cost more than
  // its reading).
  const auto topic = [&sub] { return FormatText("%s[%d]", sub.format->name.c_str(), sub.multi_id); };
  if (bytes < sub.format->min_bytes || bytes > sub.format->bytes)
    Fail(offset, 'D', topic(),
         FormatText("%zu data bytes, its format has %zu%s", bytes, sub.format->bytes,
                    bytes < sub.format->min_bytes ? " (message cut short)" : ""));
  if (sub.topic == Topic::kOther) return;
  const TopicLayout& layout = sub.layout;
  Series& series = *sub.series;
  const uint64_t time_us = Load<uint64_t>(data + layout.time);
  if (time_us > kMaxTimeUs)
    Fail(offset, 'D', topic(),
         FormatText("%s %llu us is later than any time since boot (over 31 years)", layout.time_name,
                    static_cast<unsigned long long>(time_us)));
  if (series.messages > 0 && time_us <= series.last_time_us)
    Fail(offset, 'D', topic(),
         FormatText("%s %llu us %s the previous message's %llu us", layout.time_name,
                    static_cast<unsigned long long>(time_us),
                    time_us == series.last_time_us ? "repeats" : "goes back from",
                    static_cast<unsigned long long>(series.last_time_us)));
  Eigen::Vector3d xyz;
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) {
    xyz[i] = LoadNumber(data + layout.xyz[i], layout.xyz_type[i]);
    if (!std::isfinite(xyz[i])) Fail(offset, 'D', topic(), FormatText("%c is %g", axes[i], xyz[i]));
  }
  double temp_c = std::numeric_limits<double>::quiet_NaN();
  if (layout.temp_type != Basic::kNone) temp_c = LoadNumber(data + layout.temp, layout.temp_type);
  // A sensor without a thermometer reports NaN throughout: then the topic has no temperature.
  const Series::Temp temp = std::isfinite(temp_c) ? Series::Temp::kFinite : Series::Temp::kNone;
  if (series.temp != Series::Temp::kUnknown && series.temp != temp)
    Fail(offset, 'D', topic(),
         FormatText("temperature is %g, after messages %s", temp_c,
                    temp == Series::Temp::kNone ? "with a temperature" : "without one"));
  series.temp = temp;
  if (temp == Series::Temp::kFinite) {
    if (const std::string problem = TemperatureProblem(temp_c, series.messages == 0); !problem.empty())
      Fail(offset, 'D', topic(), "temperature: " + problem);
  }
  if (!series.has_device && layout.device_type != Basic::kNone) {
    series.device_id = static_cast<uint32_t>(LoadNumber(data + layout.device, layout.device_type));
    series.has_device = true;
  }
  series.last_time_us = time_us;
  ++series.messages;
  last_time_s_ = std::max(last_time_s_, static_cast<double>(time_us) * 1e-6);
  if (!series.stored) return;
  series.time_us.push_back(time_us);
  series.xyz.push_back(xyz);
  series.temp_c.push_back(temp_c);
}

void UlogParser::Info(const uint8_t* p, size_t size, long long offset, char type) {
  const size_t skip = type == 'M' || type == 'Q' ? 1 : 0;  // is_continued / default_types
  if (size < skip + 1 || size < skip + 1 + p[skip])
    Fail(offset, type, "", FormatText("%zu bytes, too few for its key (message cut short)", size));
  if (type != 'I') return;
  const std::string key(reinterpret_cast<const char*>(p + 1), p[0]);
  const std::string value(reinterpret_cast<const char*>(p + 1 + p[0]), size - 1 - p[0]);
  if (key.rfind("char[", 0) != 0) return;
  const std::string name = key.substr(key.find(' ') == std::string::npos ? key.size() : key.find(' ') + 1);
  if (name == "sys_name") result_.sys_name = value;
  if (name == "ver_hw") result_.ver_hw = value;
}

int UlogParser::ChooseInstance() const {
  const auto describe = [](const std::map<int, Series>& all) {
    std::string text;
    for (const auto& entry : all) {
      if (entry.second.messages == 0) continue;
      text += FormatText("%s%d (device id 0x%x, %lld messages)", text.empty() ? "" : ", ", entry.first,
                         entry.second.device_id, entry.second.messages);
    }
    return text.empty() ? std::string("none with data") : text;
  };
  const auto with_data = [](const std::map<int, Series>& all, int id) {
    const auto it = all.find(id);
    return it != all.end() && it->second.messages > 0;
  };
  if (options_.instance) {
    if (!with_data(accel_, *options_.instance) || !with_data(gyro_, *options_.instance))
      throw InputError(path_,
                       FormatText("--instance %d: sensor_accel has the instances %s; sensor_gyro has %s",
                                  *options_.instance, describe(accel_).c_str(), describe(gyro_).c_str()));
    return *options_.instance;
  }
  std::vector<int> both;
  for (const auto& entry : gyro_)
    if (entry.second.messages > 0 && with_data(accel_, entry.first)) both.push_back(entry.first);
  if (both.size() == 1) return both[0];
  if (both.empty())
    throw InputError(
        path_, FormatText("no instance has both sensor_accel and sensor_gyro data: sensor_accel has the "
                          "instances %s; sensor_gyro has %s",
                          describe(accel_).c_str(), describe(gyro_).c_str()));
  throw InputError(
      path_,
      FormatText("several IMU instances: sensor_accel %s; sensor_gyro %s: choose one with --instance N",
                 describe(accel_).c_str(), describe(gyro_).c_str()));
}

void UlogParser::Merge(const Series& accel, const Series& gyro, UlogSamples* out) const {
  const size_t n = accel.time_us.size();
  std::vector<uint64_t> intervals;
  intervals.reserve(n);
  for (size_t i = 1; i < n; ++i) intervals.push_back(accel.time_us[i] - accel.time_us[i - 1]);
  double max_gap_us = 0.0;
  if (!intervals.empty()) {
    std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
    max_gap_us = kMaxAccelGapIntervals * static_cast<double>(intervals[intervals.size() / 2]);
  }
  const bool gyro_temp = gyro.temp == Series::Temp::kFinite;
  out->gyro_temperature = gyro_temp;
  const bool accel_temp = accel.temp == Series::Temp::kFinite;
  if (!gyro_temp && !accel_temp && !options_.temp_c)
    throw InputError(path_, "neither sensor_gyro nor sensor_accel carries a temperature: give --temp-c");
  if ((gyro_temp || accel_temp) && options_.temp_c)
    throw InputError(
        path_, FormatText("--temp-c: the log has the %s's temperatures; a log with a thermometer is read "
                          "with its own",
                          gyro_temp ? "gyro" : "accelerometer"));
  out->samples.reserve(gyro.time_us.size());
  size_t j = 0;
  for (size_t i = 0; i < gyro.time_us.size(); ++i) {
    const uint64_t t = gyro.time_us[i];
    if (n == 0 || t < accel.time_us[0] || t > accel.time_us[n - 1]) {
      ++out->gyro_without_sample;
      continue;
    }
    while (j + 1 < n && accel.time_us[j + 1] < t) ++j;
    // accel.time_us[j] <= t <= accel.time_us[j + 1], or t is the last accelerometer time.
    const size_t k = std::min(j + 1, n - 1);
    const double span = static_cast<double>(accel.time_us[k] - accel.time_us[j]);
    const bool exact = accel.time_us[j] == t || accel.time_us[k] == t;  // no interpolation: no gap
    if (span > max_gap_us && !exact) {
      ++out->gyro_without_sample;
      continue;
    }
    const double w = span > 0.0 ? static_cast<double>(t - accel.time_us[j]) / span : 0.0;
    Sample sample;
    sample.time_s = static_cast<double>(t) * 1e-6;
    sample.gyro = gyro.xyz[i];
    sample.accel = (1.0 - w) * accel.xyz[j] + w * accel.xyz[k];
    sample.temp_c = gyro_temp    ? gyro.temp_c[i]
                    : accel_temp ? (1.0 - w) * accel.temp_c[j] + w * accel.temp_c[k]
                                 : *options_.temp_c;
    IMUFIT_CHECK(std::isfinite(sample.temp_c) && sample.accel.allFinite(), "interpolated from finite values");
    out->samples.push_back(sample);
  }
}

UlogSamples UlogParser::Read() {
  ReadHeader();
  while (true) {
    const long long offset = in_.offset();
    const long long boundary = appended_.empty() ? std::numeric_limits<long long>::max() : appended_.front();
    if (offset == boundary) {  // appended data starts here: read on
      appended_.erase(appended_.begin());
      continue;
    }
    if (!in_.Ensure(kMessageHeaderBytes)) break;
    const size_t size = Load<uint16_t>(in_.data());
    const char type = static_cast<char>(in_.data()[2]);
    const long long end = offset + static_cast<long long>(kMessageHeaderBytes + size);
    if (end > boundary) {  // cut short where the appended data starts
      result_.discarded_bytes += boundary - offset;
      in_.SkipTo(boundary);
      continue;
    }
    if (!in_.Ensure(kMessageHeaderBytes + size)) break;
    const uint8_t* p = in_.data() + kMessageHeaderBytes;
    switch (type) {
      case 'B':
        FlagBits(p, size, offset);
        break;
      case 'F':
        ParseFormat(p, size, offset);
        break;
      case 'I':
      case 'M':
      case 'P':
      case 'Q':
        Info(p, size, offset, type);
        break;
      case 'A':
        Subscribe(p, size, offset);
        break;
      case 'R':
        if (size < 2) Fail(offset, 'R', "", "fewer than 2 bytes (message cut short)");
        if (Load<uint16_t>(p) < subscriptions_.size()) subscriptions_[Load<uint16_t>(p)].active = false;
        break;
      case 'D':
        Data(p, size, offset);
        break;
      case 'L':
      case 'C':
        if (size < (type == 'L' ? 9u : 11u))
          Fail(offset, type, "", FormatText("%zu bytes, too few (message cut short)", size));
        break;
      case 'S':
        break;
      case 'O':
        if (size < 2) Fail(offset, 'O', "", "fewer than 2 bytes (message cut short)");
        result_.dropouts.push_back({offset, last_time_s_, Load<uint16_t>(p) * 1e-3});
        break;
      default:
        ++result_.unknown_messages;
        break;  // the spec: ignore unknown messages
    }
    in_.Skip(kMessageHeaderBytes + size);
  }
  result_.discarded_bytes += in_.Drain();  // a message cut short at the end: discarded, as the spec says
  ResolveAll();                            // the formats defined after the first subscription too
  for (const char* topic : {kAccelTopic, kGyroTopic}) {
    if (subscribed_.count(topic)) continue;
    std::string present;
    for (const std::string& name : subscribed_) present += (present.empty() ? "" : ", ") + name;
    throw InputError(path_,
                     std::string("no ") + topic +
                         " topic (the log has: " + (present.empty() ? std::string("no topics") : present) +
                         "); PX4 logs the raw sensor_accel and sensor_gyro in its thermal calibration and "
                         "sensor comparison logging profiles (SDLOG_PROFILE)");
  }
  const int instance = ChooseInstance();
  const Series& accel = accel_.at(instance);
  const Series& gyro = gyro_.at(instance);
  result_.instance = instance;
  result_.accel_device_id = accel.device_id;
  result_.gyro_device_id = gyro.device_id;
  result_.accel_messages = accel.messages;
  result_.gyro_messages = gyro.messages;
  Merge(accel, gyro, &result_);
  if (result_.samples.empty())
    throw InputError(
        path_, FormatText("sensor_gyro[%d] and sensor_accel[%d] do not overlap in time: no sample", instance,
                          instance));
  return std::move(result_);
}

}  // namespace

bool IsUlogFile(const std::string& path) {
  ByteStream in(path, nullptr);
  return in.Ensure(kUlogNameBytes) && std::memcmp(in.data(), kUlogMagic, kUlogNameBytes) == 0;
}

UlogSamples ReadUlogSamples(const std::string& path, const UlogOptions& options, Sha256* digest) {
  if (options.instance && (*options.instance < 0 || *options.instance > 255))
    throw InputError(path, FormatText("--instance %d: a ULog multi_id is 0..255", *options.instance));
  return UlogParser(path, options, digest).Read();
}

std::vector<std::string> UlogNotes(const std::string& path, const UlogSamples& log) {
  std::vector<std::string> notes;
  if (!log.dropouts.empty()) {
    double total_s = 0.0;
    for (const UlogDropout& dropout : log.dropouts) total_s += dropout.duration_s;
    notes.push_back(
        FormatText("%s: %zu logging dropouts ('O'), %.3g s in all, the first after %.6f s: the samples lost "
                   "are gaps in the session",
                   path.c_str(), log.dropouts.size(), total_s, log.dropouts.front().time_s));
  }
  if (log.gyro_without_sample > 0)
    notes.push_back(
        FormatText("%s: %lld of %lld gyro messages outside the accelerometer's span or in a gap of it: no "
                   "sample made",
                   path.c_str(), log.gyro_without_sample, log.gyro_messages));
  if (log.discarded_bytes > 0)
    notes.push_back(FormatText("%s: %lld bytes of a message cut short discarded (a log that ended abruptly)",
                               path.c_str(), log.discarded_bytes));
  return notes;
}

}  // namespace imufit
