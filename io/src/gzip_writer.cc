#include "gzip_writer.h"

#include <isa-l/igzip_lib.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "imufit/io/error.h"
#include "imufit/model/check.h"

namespace imufit {
namespace {

constexpr size_t kOutBytes = 1 << 20;

}  // namespace

void WriteAll(int fd, std::string_view data, const std::string& path) {
  while (!data.empty()) {
    const ssize_t written = ::write(fd, data.data(), data.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      throw InputError(path, std::string("write failed: ") + std::strerror(errno));
    }
    data.remove_prefix(static_cast<size_t>(written));
  }
}

// ISA-L's state and the work buffer of the level (kept out of the header: both are large).
struct GzipWriter::Stream {
  isal_zstream zstream{};
  std::vector<uint8_t> level_buffer = std::vector<uint8_t>(ISAL_DEF_LVL1_DEFAULT);
};

GzipWriter::GzipWriter(int fd, std::string path)
    : fd_(fd), path_(std::move(path)), stream_(std::make_unique<Stream>()), out_(kOutBytes) {
  isal_zstream& z = stream_->zstream;
  isal_deflate_init(&z);
  z.gzip_flag = IGZIP_GZIP;
  z.level = 1;
  z.level_buf = stream_->level_buffer.data();
  z.level_buf_size = static_cast<uint32_t>(stream_->level_buffer.size());
  z.flush = NO_FLUSH;
  z.end_of_stream = 0;
  thread_ = std::thread([this] { Compress(); });
}

GzipWriter::~GzipWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void GzipWriter::Compress() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || finishing_ || !pending_.empty(); });
    if (stop_) break;
    const bool end = pending_.empty();  // and finishing_
    std::string data;
    if (!end) {
      data = std::move(pending_.front());
      pending_.pop_front();
    }
    lock.unlock();
    try {
      constexpr size_t kMaxChunk = 1u << 30;  // avail_in is 32 bits
      for (std::string_view rest = data; !rest.empty(); rest.remove_prefix(std::min(rest.size(), kMaxChunk)))
        Deflate(rest.substr(0, kMaxChunk));
      if (end) {
        stream_->zstream.end_of_stream = 1;
        Deflate(std::string_view());
      }
    } catch (...) {
      lock.lock();
      error_ = std::current_exception();
      break;
    }
    lock.lock();
    if (end) break;
    data.clear();
    free_.push_back(std::move(data));
    changed_.notify_all();  // room for a Write()
  }
  done_ = true;
  changed_.notify_all();
}

void GzipWriter::Deflate(std::string_view data) {
  isal_zstream& z = stream_->zstream;
  z.next_in = reinterpret_cast<uint8_t*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uint32_t>(data.size());
  do {
    z.next_out = out_.data();
    z.avail_out = static_cast<uint32_t>(out_.size());
    const int status = isal_deflate(&z);
    IMUFIT_CHECK(status == COMP_OK, "ISA-L deflate failed");
    const size_t produced = out_.size() - z.avail_out;
    WriteAll(fd_, std::string_view(reinterpret_cast<const char*>(out_.data()), produced), path_);
  } while (z.avail_in > 0 || z.avail_out == 0 || (z.end_of_stream && z.internal_state.state != ZSTATE_END));
}

void GzipWriter::Write(std::string* data) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return error_ != nullptr || pending_.size() < kMaxPending; });
  if (error_) std::rethrow_exception(error_);
  pending_.push_back(std::move(*data));
  data->clear();
  if (!free_.empty()) {
    data->swap(free_.back());
    free_.pop_back();
  }
  changed_.notify_all();
}

void GzipWriter::Finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  finishing_ = true;
  changed_.notify_all();
  changed_.wait(lock, [this] { return done_; });
  if (error_) std::rethrow_exception(error_);
}

}  // namespace imufit
