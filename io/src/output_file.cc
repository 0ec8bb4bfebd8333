#include "imufit/io/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "imufit/io/error.h"
#include "imufit/io/path.h"

namespace imufit {
namespace {

constexpr size_t kFlushBytes = 1 << 20;

}  // namespace

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
  namespace fs = std::filesystem;
  const fs::path destination(path_);
  if (!destination.has_filename()) throw InputError(path_, "not a file name");
  std::error_code ec;
  if (fs::is_directory(destination, ec)) throw InputError(path_, "is a directory");
  const fs::path folder = destination.parent_path().empty() ? fs::path(".") : destination.parent_path();
  std::string pattern = (folder / ("." + destination.filename().string() + ".tmp-XXXXXX")).string();
  fd_ = ::mkstemp(pattern.data());
  if (fd_ < 0) {
    throw InputError(path_, std::string("cannot create a file in ") + folder.string() + ": " +
                                std::strerror(errno));
  }
  temp_path_ = pattern;
  // mkstemp creates mode 0600; give the result the permissions an ordinary new file would get.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd_, 0666 & ~mask);
  if (IsGzipPath(path_)) {
    gz_ = gzdopen(fd_, "wb6");
    if (gz_ == nullptr) {
      ::close(fd_);
      ::unlink(temp_path_.c_str());
      fd_ = -1;
      throw InputError(path_, "cannot start gzip compression");
    }
  }
  buffer_.reserve(kFlushBytes + 4096);
}

OutputFile::~OutputFile() {
  if (committed_) return;
  if (gz_ != nullptr) {
    gzclose(static_cast<gzFile>(gz_));  // also closes fd_
  } else if (fd_ >= 0) {
    ::close(fd_);
  }
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
}

void OutputFile::Write(std::string_view text) {
  buffer_.append(text);
  if (buffer_.size() >= kFlushBytes) Flush();
}

void OutputFile::WriteNumber(double value) {
  char digits[32];
  if (!std::isfinite(value)) {
    Write(FormatDouble(value));
    return;
  }
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  Write(std::string_view(digits, result.ptr - digits));
}

void OutputFile::Flush() {
  if (buffer_.empty()) return;
  if (gz_ != nullptr) {
    const int written = gzwrite(static_cast<gzFile>(gz_), buffer_.data(),
                                static_cast<unsigned>(buffer_.size()));
    if (written != static_cast<int>(buffer_.size())) {
      throw InputError(path_, "write failed (gzip)");
    }
  } else {
    const char* data = buffer_.data();
    size_t left = buffer_.size();
    while (left > 0) {
      const ssize_t written = ::write(fd_, data, left);
      if (written < 0) {
        if (errno == EINTR) continue;
        throw InputError(path_, std::string("write failed: ") + std::strerror(errno));
      }
      data += written;
      left -= static_cast<size_t>(written);
    }
  }
  buffer_.clear();
}

void OutputFile::Commit() {
  Flush();
  if (gz_ != nullptr) {
    // gzclose closes the descriptor too, so sync through a second descriptor afterwards.
    const int status = gzclose(static_cast<gzFile>(gz_));
    gz_ = nullptr;
    fd_ = -1;
    if (status != Z_OK) throw InputError(path_, "write failed (gzip close)");
    const int sync_fd = ::open(temp_path_.c_str(), O_RDONLY);
    if (sync_fd >= 0) {
      ::fsync(sync_fd);
      ::close(sync_fd);
    }
  } else {
    if (::fsync(fd_) != 0 && errno != EINVAL) {
      throw InputError(path_, std::string("sync failed: ") + std::strerror(errno));
    }
    ::close(fd_);
    fd_ = -1;
  }
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    throw InputError(path_, std::string("cannot replace the file: ") + std::strerror(errno));
  }
  committed_ = true;
}

void WriteFileAtomically(const std::string& path, std::string_view text) {
  OutputFile file(path);
  file.Write(text);
  file.Commit();
}

void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs) {
  std::error_code ec;
  if (!std::filesystem::exists(output, ec)) return;
  for (const std::string& input : inputs) {
    if (std::filesystem::equivalent(output, input, ec)) {
      throw InputError(output, "is also an input (" + input +
                                   "); choose another output file, imufit never replaces its input");
    }
  }
}

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  return std::string(digits, result.ptr - digits);
}

}  // namespace imufit
