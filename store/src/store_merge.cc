// imufit store merge: the outbox pattern — each station keeps its own SQLite store and uploads it
// later, as often as it likes, into the factory's store.
#include <sys/stat.h>

#include <filesystem>
#include <system_error>

#include "imufit/io/error.h"
#include "imufit/store/store.h"

namespace imufit {
namespace {

// Whether `source` and `destination` name the same store: the same SQLite file (however the path
// is written), or the same connection string.
bool SameStore(const std::string& source, const std::string& destination) {
  if (IsPostgresStore(source) || IsPostgresStore(destination)) return source == destination;
  std::error_code error;
  return std::filesystem::equivalent(source, destination, error) && !error;
}

}  // namespace

std::vector<MergeResult> MergeStores(const std::vector<std::string>& sources,
                                     const std::string& destination) {
  // Every source is read before the destination is opened: a refused source (missing, truncated,
  // not a store, a newer schema) leaves the destination as it was, or not created at all.
  std::vector<std::pair<std::string, std::vector<StoredFit>>> read;
  for (const std::string& source : sources) {
    struct stat info {};
    if (!IsPostgresStore(source) && stat(source.c_str(), &info) != 0) {
      throw InputError(source, "no such results store to merge");
    }
    if (SameStore(source, destination)) {
      throw InputError(source, "is the store merged into (--into): a store merged into itself gains nothing");
    }
    ResultsStore from(source, StoreAccess::kRead);
    read.emplace_back(from.path(), from.All());
  }
  ResultsStore into(destination);
  std::vector<MergeResult> results;
  for (const auto& [source, fits] : read) {
    results.push_back({source, static_cast<int64_t>(fits.size()), into.RecordAll(fits)});
  }
  return results;
}

}  // namespace imufit
