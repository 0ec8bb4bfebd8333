#include "byte_source.h"

#include <fcntl.h>
#include <isa-l/igzip_lib.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string_view>

#include "imufit/io/error.h"
#include "imufit/io/path.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

constexpr size_t kRawBytes = 1 << 16;
constexpr size_t kTrailerBytes = 8;  // CRC-32 and length (mod 2^32), little-endian

uint32_t LittleEndian32(const char* bytes) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes);
  return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

bool IsGzipMagic(const char* bytes) {
  return static_cast<unsigned char>(bytes[0]) == 0x1f && static_cast<unsigned char>(bytes[1]) == 0x8b;
}

std::string InflateError(int status) {
  switch (status) {
    case ISAL_INVALID_BLOCK:
      return "invalid deflate block";
    case ISAL_INVALID_SYMBOL:
      return "invalid deflate symbol";
    case ISAL_INVALID_LOOKBACK:
      return "invalid distance too far back";
    case ISAL_INVALID_WRAPPER:
      return "invalid gzip header";
    case ISAL_UNSUPPORTED_METHOD:
      return "unknown compression method";
    default:
      return "error " + std::to_string(status);
  }
}

}  // namespace

// ISA-L's state, which is large (tens of KiB): kept out of the header and off the stack.
struct ByteSource::Inflater {
  inflate_state state{};
  isal_gzip_header header{};
  enum class Phase { kMagic, kHeader, kBody, kTrailer } phase = Phase::kMagic;
  long members = 0;
};

ByteSource::ByteSource(std::string path, Sha256* digest) : path_(std::move(path)), digest_(digest) {
  fd_ = ::open(path_.c_str(), O_RDONLY);
  if (fd_ < 0) throw InputError(path_, std::string("cannot open: ") + std::strerror(errno));
  raw_.resize(kRawBytes);
  // Close the descriptor if the first read throws: the destructor does not run for a constructor
  // that throws.
  try {
    const bool magic = Fill(2) && IsGzipMagic(in_);
    if (IsGzipPath(path_) || magic) {
      inflater_ = std::make_unique<Inflater>();
      isal_inflate_init(&inflater_->state);
    }
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

ByteSource::~ByteSource() {
  if (fd_ >= 0) ::close(fd_);
}

size_t ByteSource::ReadRaw(char* data, size_t size) {
  for (;;) {
    const ssize_t n = ::read(fd_, data, size);
    if (n >= 0) {
      if (digest_ != nullptr) digest_->Update(std::string_view(data, static_cast<size_t>(n)));
      if (n == 0) raw_eof_ = true;
      compressed_bytes_ += n;
      return static_cast<size_t>(n);
    }
    if (errno != EINTR) throw InputError(path_, std::string("cannot read: ") + std::strerror(errno));
  }
}

bool ByteSource::Fill(size_t need) {
  if (in_left_ >= need) return true;
  if (in_left_ > 0) std::memmove(raw_.data(), in_, in_left_);
  in_ = raw_.data();
  while (in_left_ < need && !raw_eof_) in_left_ += ReadRaw(raw_.data() + in_left_, raw_.size() - in_left_);
  return in_left_ >= need;
}

size_t ByteSource::Read(char* data, size_t size) {
  if (inflater_ != nullptr) return Inflate(data, size);
  if (in_left_ > 0) {  // the bytes read to look for the magic
    const size_t n = std::min(size, in_left_);
    std::memcpy(data, in_, n);
    in_ += n;
    in_left_ -= n;
    return n;
  }
  return raw_eof_ ? 0 : ReadRaw(data, size);
}

void ByteSource::Truncated() const {
  throw InputError(path_, "truncated gzip stream: the file ends before the stream does (after " +
                              std::to_string(compressed_bytes_) + " compressed bytes)");
}

// A member starts with the gzip magic bytes 1f 8b; anything else is not gzip (at the start) or
// garbage after the stream (after a complete member).
void ByteSource::StartMember() {
  Inflater& inflater = *inflater_;
  if (!Fill(2) || !IsGzipMagic(in_)) {
    if (inflater.members == 0) {
      if (in_left_ == 0) throw InputError(path_, "empty file, not a gzip stream (the name ends in .gz)");
      throw InputError(path_, "not a gzip stream (the name ends in .gz, the bytes are not gzip)");
    }
    throw InputError(path_, "trailing garbage after the gzip stream (at compressed byte " +
                                std::to_string(compressed_bytes_ - static_cast<long long>(in_left_)) + ")");
  }
  isal_inflate_reset(&inflater.state);
  inflater.state.crc_flag = ISAL_GZIP_NO_HDR;  // the header and trailer are read here
  isal_gzip_header_init(&inflater.header);
  inflater.phase = Inflater::Phase::kHeader;
}

void ByteSource::CheckTrailer() {
  if (!Fill(kTrailerBytes)) Truncated();
  const inflate_state& state = inflater_->state;
  const char* reason = nullptr;
  if (LittleEndian32(in_) != state.crc) {
    reason = "incorrect data check";
  } else if (LittleEndian32(in_ + 4) != state.total_out) {
    reason = "incorrect length check";
  }
  if (reason != nullptr) {
    throw InputError(path_, std::string("corrupt gzip stream: ") + reason +
                                " (the CRC-32 or length in its trailer does not match the data)");
  }
  in_ += kTrailerBytes;
  in_left_ -= kTrailerBytes;
  ++inflater_->members;
  inflater_->phase = Inflater::Phase::kMagic;
}

// At the end of a member's deflate data, ISA-L holds the whole bytes it read past it (the start of
// the trailer) in its bit buffer: they go back in front of the unread bytes.
void ByteSource::GiveBackUnusedBytes() {
  inflate_state& state = inflater_->state;
  const size_t count = static_cast<size_t>(state.read_in_length) / 8;
  const uint64_t bytes = state.read_in >> (state.read_in_length % 8);
  if (raw_.size() < in_left_ + count) raw_.resize(in_left_ + count);
  std::memmove(raw_.data() + count, in_, in_left_);
  for (size_t i = 0; i < count; ++i) raw_[i] = static_cast<char>(bytes >> (8 * i));
  in_ = raw_.data();
  in_left_ += count;
  state.read_in = 0;
  state.read_in_length = 0;
}

size_t ByteSource::Inflate(char* data, size_t size) {
  using Phase = Inflater::Phase;
  Inflater& inflater = *inflater_;
  inflate_state& state = inflater.state;
  const uint32_t want = static_cast<uint32_t>(std::min<size_t>(size, 1u << 30));
  for (;;) {
    switch (inflater.phase) {
      case Phase::kMagic:
        if (inflater.members > 0 && !Fill(1)) return 0;  // the end, after a complete member
        StartMember();
        break;
      case Phase::kTrailer:
        CheckTrailer();
        break;
      case Phase::kHeader:
      case Phase::kBody: {
        if (in_left_ == 0) Fill(1);  // at the end, ISA-L may still hold output
        state.next_in = reinterpret_cast<uint8_t*>(const_cast<char*>(in_));
        state.avail_in = static_cast<uint32_t>(in_left_);
        state.next_out = reinterpret_cast<uint8_t*>(data);
        state.avail_out = want;
        const int status = inflater.phase == Phase::kHeader ? isal_read_gzip_header(&state, &inflater.header)
                                                            : isal_inflate(&state);
        in_ = reinterpret_cast<const char*>(state.next_in);
        in_left_ = state.avail_in;
        if (status < 0) throw InputError(path_, "corrupt gzip stream: " + InflateError(status));
        const bool finished = inflater.phase == Phase::kHeader ? status == ISAL_DECOMP_OK
                                                               : state.block_state == ISAL_BLOCK_FINISH;
        const size_t produced = want - state.avail_out;
        if (finished && inflater.phase == Phase::kBody) GiveBackUnusedBytes();
        if (finished) inflater.phase = inflater.phase == Phase::kHeader ? Phase::kBody : Phase::kTrailer;
        if (produced > 0) return produced;
        if (!finished && in_left_ == 0 && raw_eof_) Truncated();
        break;
      }
    }
  }
}

}  // namespace imufit
