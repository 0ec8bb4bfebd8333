#include "imufit/io/file_reads.h"

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <vector>

#include "imufit/io/error.h"

namespace imufit {
namespace {

// The counters alive, under a lock: readers run on several threads at once (imufit batch).
struct WatchList {
  std::mutex mutex;
  std::vector<FileReadCounter*> counters;
  std::atomic<int> size{0};  // read without the lock: no counter, nothing to do
};

WatchList& Watched() {
  static WatchList list;
  return list;
}

}  // namespace

FileReadCounter::FileReadCounter(const std::string& path) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0)
    throw InputError(path, std::string("cannot stat: ") + std::strerror(errno));
  device_ = status.st_dev;
  inode_ = status.st_ino;
  WatchList& list = Watched();
  const std::lock_guard<std::mutex> lock(list.mutex);
  list.counters.push_back(this);
  list.size = static_cast<int>(list.counters.size());
}

FileReadCounter::~FileReadCounter() {
  WatchList& list = Watched();
  const std::lock_guard<std::mutex> lock(list.mutex);
  list.counters.erase(std::remove(list.counters.begin(), list.counters.end(), this), list.counters.end());
  list.size = static_cast<int>(list.counters.size());
}

long long FileReadCounter::count() const {
  const std::lock_guard<std::mutex> lock(Watched().mutex);
  return count_;
}

void CountOpenedForReading(const std::string& path) {
  WatchList& list = Watched();
  if (list.size.load() == 0) return;
  struct stat status;
  if (::stat(path.c_str(), &status) != 0) return;
  const std::lock_guard<std::mutex> lock(list.mutex);
  for (FileReadCounter* counter : list.counters) {
    if (counter->device_ == status.st_dev && counter->inode_ == status.st_ino) ++counter->count_;
  }
}

}  // namespace imufit
