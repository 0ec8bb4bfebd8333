#include "file_open_counter.h"

#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstring>
#include <mutex>
#include <vector>

#include <gtest/gtest.h>

extern "C" int __real_open(const char* path, int flags, ...);

// open(2) for the program's own objects (-Wl,--wrap=open): the real one, then counted.
extern "C" int __wrap_open(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (flags & (O_CREAT | O_TMPFILE)) {
    va_list arguments;
    va_start(arguments, flags);
    mode = static_cast<mode_t>(va_arg(arguments, int));
    va_end(arguments);
  }
  const int fd = __real_open(path, flags, mode);
  if (fd >= 0) {
    const int saved = errno;
    imufit::testing::FileOpenCounter::Opened(fd);
    errno = saved;
  }
  return fd;
}

namespace imufit::testing {
namespace {

// The counters alive, under a lock: readers run on several threads at once (imufit batch).
struct WatchList {
  std::mutex mutex;
  std::vector<FileOpenCounter*> counters;
  std::atomic<int> size{0};  // read without the lock: no counter, nothing to do
};

WatchList& Watched() {
  static WatchList list;
  return list;
}

}  // namespace

FileOpenCounter::FileOpenCounter(const std::string& path) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0) {
    ADD_FAILURE() << path << ": cannot stat: " << std::strerror(errno);
    return;
  }
  device_ = status.st_dev;
  inode_ = status.st_ino;
  WatchList& list = Watched();
  const std::lock_guard<std::mutex> lock(list.mutex);
  list.counters.push_back(this);
  list.size = static_cast<int>(list.counters.size());
}

FileOpenCounter::~FileOpenCounter() {
  WatchList& list = Watched();
  const std::lock_guard<std::mutex> lock(list.mutex);
  list.counters.erase(std::remove(list.counters.begin(), list.counters.end(), this), list.counters.end());
  list.size = static_cast<int>(list.counters.size());
}

long long FileOpenCounter::count() const {
  const std::lock_guard<std::mutex> lock(Watched().mutex);
  return count_;
}

void FileOpenCounter::Opened(int fd) {
  WatchList& list = Watched();
  if (list.size.load() == 0) return;
  struct stat status;
  if (::fstat(fd, &status) != 0) return;
  const std::lock_guard<std::mutex> lock(list.mutex);
  for (FileOpenCounter* counter : list.counters) {
    if (counter->device_ == status.st_dev && counter->inode_ == status.st_ino) ++counter->count_;
  }
}

}  // namespace imufit::testing
