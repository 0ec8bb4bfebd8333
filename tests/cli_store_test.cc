// `imufit store merge` end to end on the backend under test (cli_store_test --backend sqlite|
// postgresql, as store_test): two stations' stores merged twice change nothing the second time; a
// missing source is exit 2.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

testing::RunResult Imufit(const std::vector<std::string>& args) {
  const std::string base = FreshSqliteStore("imufit_output");
  return testing::RunProgram(IMUFIT_EXE, args, base + ".out", base + ".err");
}

TEST(StoreTest, MergeCommandRunTwiceChangesNothing) {
  const std::string into = FreshStore("merge_cli");
  std::vector<std::string> args = {"store", "merge"};
  for (const std::string& source : TwoStationStores()) args.push_back(source);
  args.insert(args.end(), {"--into", into});
  const testing::RunResult first = Imufit(args);
  ASSERT_EQ(first.status, 0) << first.out;
  EXPECT_NE(first.out.find(": 2 fits, 1 new"), std::string::npos) << first.out;
  const testing::RunResult second = Imufit(args);
  ASSERT_EQ(second.status, 0) << second.out;
  EXPECT_NE(second.out.find(": 2 fits, 0 new"), std::string::npos) << second.out;
  EXPECT_EQ(second.out.find(", 1 new"), std::string::npos) << second.out;
  EXPECT_EQ(second.out.find(", 2 new"), std::string::npos) << second.out;
  const testing::RunResult missing = Imufit({"store", "merge", "no_such.db", "--into", into});
  EXPECT_EQ(missing.status, 2) << missing.err;
  EXPECT_NE(missing.err.find("no_such.db: no such results store to merge"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace imufit
