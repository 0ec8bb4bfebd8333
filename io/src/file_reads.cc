#include "imufit/io/file_reads.h"

#include <sys/stat.h>

#include <map>
#include <mutex>
#include <utility>

namespace imufit {
namespace {

using FileId = std::pair<dev_t, ino_t>;

// Readers run on several threads at once (imufit batch): the count is taken under a lock.
struct Counts {
  std::mutex mutex;
  std::map<FileId, long long> opened;
};

Counts& TheCounts() {
  static Counts counts;
  return counts;
}

bool IdOf(const std::string& path, FileId* id) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0) return false;
  *id = {status.st_dev, status.st_ino};
  return true;
}

}  // namespace

long long TimesOpenedForReading(const std::string& path) {
  FileId id;
  if (!IdOf(path, &id)) return 0;
  Counts& counts = TheCounts();
  const std::lock_guard<std::mutex> lock(counts.mutex);
  const auto found = counts.opened.find(id);
  return found == counts.opened.end() ? 0 : found->second;
}

void CountOpenedForReading(const std::string& path) {
  FileId id;
  if (!IdOf(path, &id)) return;
  Counts& counts = TheCounts();
  const std::lock_guard<std::mutex> lock(counts.mutex);
  ++counts.opened[id];
}

}  // namespace imufit
