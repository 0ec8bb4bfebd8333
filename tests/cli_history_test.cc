// `imufit history` end to end on the backend under test (cli_history_test --backend sqlite|
// postgresql, as store_test): yield by station and month, a station's drift, a serial's fits, as a
// table, CSV and HTML pages, from the store of known content (KnownStore); mistakes in one line, as
// docs/troubleshooting.md quotes them.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "store_test_util.h"
#include "test_util.h"

namespace imufit {
namespace {

testing::RunResult History(const std::vector<std::string>& args) {
  const std::string base = FreshSqliteStore("history_output");
  std::vector<std::string> all = {"history"};
  all.insert(all.end(), args.begin(), args.end());
  return testing::RunProgram(IMUFIT_EXE, all, base + ".out", base + ".err");
}

size_t Lines(const std::string& text) {
  size_t n = 0;
  for (char c : text) n += c == '\n' ? 1 : 0;
  return n;
}

TEST(HistoryTest, TheCommandAnswersAsTableCsvAndHtml) {
  const std::string target = KnownStore("history_cli");
  testing::RunResult r = History({target, "--by", "station", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            "station,units,passed,failed,not_fitted,yield\n"
            "station-1,1,1,0,0,100.00\n"
            "station-2,4,3,0,1,75.00\n");
  r = History({target, "--by", "month"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2026-03"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("50.0%"), std::string::npos) << r.out;
  r = History({target, "--trend", "gyro.bias.x", "--station", "station-2", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Lines(r.out), 4u) << r.out;  // the header and three fits
  r = History({target, "--trend", "gyro.bias.x"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("mean per station and month"), std::string::npos) << r.out;
  r = History({target, "--serial", "SN2", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Lines(r.out), 3u) << r.out;
  EXPECT_NE(r.out.find(",station-1,"), std::string::npos) << r.out;

  const std::filesystem::path pages = std::filesystem::path(FreshSqliteStore("history_pages")).parent_path();
  r = History({target, "--by", "month", "--html", (pages / "months.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string months = testing::ReadBytes((pages / "months.html").string());
  EXPECT_NE(months.find("<tr data-group=\"2026-03\">"), std::string::npos);
  EXPECT_NE(months.find("data-yield=\"50\""), std::string::npos);
  EXPECT_NE(months.find("<svg"), std::string::npos);
  r = History({target, "--trend", "gyro.bias.x", "--html", (pages / "drift.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string drift = testing::ReadBytes((pages / "drift.html").string());
  EXPECT_NE(drift.find("data-station=\"station-2\" data-month=\"2026-02\""), std::string::npos);
  EXPECT_NE(drift.find("data-mean=\"1.75\""), std::string::npos);
  r = History({target, "--serial", "SN2", "--html", (pages / "sn2.html").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string sn2 = testing::ReadBytes((pages / "sn2.html").string());
  size_t rows = 0;
  for (size_t at = sn2.find("<tr data-fit="); at != std::string::npos; at = sn2.find("<tr data-fit=", at + 1))
    ++rows;
  EXPECT_EQ(rows, 2u);

  // Mistakes: one line each, as docs/troubleshooting.md quotes it.
  const std::string troubleshooting =
      testing::ReadBytes(std::string(IMUFIT_FIXTURES_DIR) + "/../docs/troubleshooting.md");
  for (const std::vector<std::string>& mistake : {std::vector<std::string>{target, "--by", "week"},
                                                  {target, "--station", "station-1", "--by", "lot"}}) {
    r = History(mistake);
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    const std::string said = r.err.substr(0, r.err.size() - 1);  // less its newline
    EXPECT_EQ(said.find('\n'), std::string::npos) << r.err;
    EXPECT_NE(troubleshooting.find("`" + said + "`"), std::string::npos) << said;
  }
}

}  // namespace
}  // namespace imufit
