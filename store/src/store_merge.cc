// imufit store merge: the outbox pattern — each station keeps its own SQLite store and uploads it
// later, as often as it likes, into the factory's store.
#include <sys/stat.h>

#include "imufit/io/error.h"
#include "imufit/store/store.h"

namespace imufit {

std::vector<MergeResult> MergeStores(const std::vector<std::string>& sources,
                                     const std::string& destination) {
  for (const std::string& source : sources) {
    struct stat info {};
    if (!IsPostgresStore(source) && stat(source.c_str(), &info) != 0) {
      throw InputError(source, "no such results store to merge");
    }
  }
  ResultsStore into(destination);
  std::vector<MergeResult> results;
  for (const std::string& source : sources) {
    ResultsStore from(source);
    const std::vector<StoredFit> fits = from.All();
    results.push_back({from.path(), static_cast<int64_t>(fits.size()), into.RecordAll(fits)});
  }
  return results;
}

}  // namespace imufit
