// `imufit batch` end to end on the lot of cli_factory_util.h: judging, recording, reporting, skipping
// unchanged units, resuming after an interruption or a kill, shared stores, samples found by glob, unit
// lists, static-only lots and fit options.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "cli_factory_util.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;

TEST_F(FactoryCliTest, BatchJudgesRecordsReportsAndSkipsUnchangedUnits) {
  std::vector<std::string> args = BatchArgs("out");
  args.insert(args.end(), {"--jobs", "2"});
  RunResult r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;  // one unit failed, one could not be read
  EXPECT_NE(r.out.find("5 units: 3 passed, 1 failed limits, 0 not fitted, 1 errors; 0 unchanged"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("[5/5]"), std::string::npos) << r.err;  // progress, plain lines when not a terminal

  auto summary = Summary("out");
  ASSERT_EQ(summary.size(), kUnits);
  EXPECT_EQ(summary["unit-01"]["serial"], "SN-01");
  EXPECT_EQ(summary["unit-01"]["verdict"], "PASS");
  EXPECT_EQ(summary["unit-03"]["serial"], "unit-03");  // shared plan without a serial: the folder name
  EXPECT_EQ(summary["unit-03"]["verdict"], "PASS");
  // ... which is said, on stderr and on its certificate; a unit with a serial gets no such warning.
  const std::string not_stated = "serial not stated: the unit folder's name is used";
  EXPECT_NE(r.err.find("imufit: warning: unit-03: " + not_stated), std::string::npos) << r.err;
  ExpectTroubleshootingQuotes(LineWith(r.err, "imufit: warning: unit-03: "));
  EXPECT_EQ(r.err.find("unit-01: " + not_stated), std::string::npos) << r.err;
  const std::string on_page = "serial not stated: the unit folder&#39;s name is used";  // HTML-escaped
  EXPECT_NE(ReadBytes(dir_ / "out" / "unit-03" / "report.html").find(on_page), std::string::npos);
  EXPECT_EQ(ReadBytes(dir_ / "out" / "unit-01" / "report.html").find(on_page), std::string::npos);
  EXPECT_EQ(summary["unit-04"]["status"], "fitted");
  EXPECT_EQ(summary["unit-04"]["verdict"], "FAIL");
  EXPECT_NE(summary["unit-04"]["message"].find("|gyro_g_sensitivity_dpsg.xx|"), std::string::npos);
  EXPECT_GT(std::stod(summary["unit-04"]["gyro_g_sensitivity_dpsg.xx"]), 0.05);
  EXPECT_EQ(summary["unit-05"]["status"], "error");
  EXPECT_NE(summary["unit-05"]["message"].find("samples.csv:"), std::string::npos);
  EXPECT_NE(summary["unit-05"]["message"].find("1.2.3 is not a number"), std::string::npos)
      << summary["unit-05"]["message"];
  EXPECT_FALSE(fs::exists(dir_ / "out" / "unit-05" / "calibration.yaml"));
  // The lot page: yield, and the g-sensitivity of unit-04 flagged as an outlier of the lot.
  const std::string lot = ReadBytes(dir_ / "out" / "lot.html");
  EXPECT_NE(lot.find("data-key=\"yield\">60.0<"), std::string::npos);
  EXPECT_NE(lot.find("data-outlier=\"unit-04\" data-figure=\"gyro_g_sensitivity_dpsg.xx\""),
            std::string::npos);
  for (const char* unit : {"unit-01", "unit-02", "unit-03"}) {
    EXPECT_EQ(
        lot.find("data-outlier=\"" + std::string(unit) + "\" data-figure=\"gyro_g_sensitivity_dpsg.xx\""),
        std::string::npos);
  }

  // The certificate: key values read back out of the HTML agree with the lot summary and inputs.
  const std::string report = ReadBytes(dir_ / "out" / "unit-04" / "report.html");
  EXPECT_EQ(ReportFigure(report, "gyro_g_sensitivity_dpsg.xx"),
            summary["unit-04"]["gyro_g_sensitivity_dpsg.xx"]);
  EXPECT_EQ(ReportFigure(report, "gyro_bias_dps.x"), summary["unit-04"]["gyro_bias_dps.x"]);
  EXPECT_NE(report.find("data-key=\"serial\">SN-04<"), std::string::npos);
  EXPECT_NE(report.find("data-key=\"verdict\">FAIL<"), std::string::npos);
  EXPECT_NE(report.find("data-criterion=\"|gyro_g_sensitivity_dpsg.xx|\" data-pass=\"0\""),
            std::string::npos);
  EXPECT_NE(
      report.find("data-sha256=\"samples\">" + Sha256OfFile(Path("units/unit-04/samples.csv.gz")) + "<"),
      std::string::npos);
  EXPECT_NE(report.find("data-sha256=\"limits\">" + Sha256OfFile(Path("limits.yaml")) + "<"),
            std::string::npos);
  EXPECT_NE(report.find("<svg"), std::string::npos);
  // Residuals before (25 degC scale only) and after correction: the calibration must have fixed
  // something. The "all" row's cells: windows, gyro RMS before, after, max, accel before, after, max.
  const size_t all_row = report.find("data-key=\"residual_all\"");
  ASSERT_NE(all_row, std::string::npos);
  std::vector<double> cells;
  for (size_t at = report.find("<td class=\"num\">", all_row); at < report.find("</tr>", all_row);
       at = report.find("<td class=\"num\">", at + 1)) {
    const std::string text = report.substr(at + 16, report.find('<', at + 16) - at - 16);
    if (!text.empty()) cells.push_back(std::stod(text));
  }
  ASSERT_EQ(cells.size(), 7u);
  EXPECT_GT(cells[1], 10.0 * cells[2]);  // gyro RMS before > 10 x after
  EXPECT_GT(cells[4], 10.0 * cells[5]);  // accel
  // Self-contained: nothing loaded from elsewhere (the only URLs are SVG namespace names).
  EXPECT_EQ(report.find(" src="), std::string::npos);
  EXPECT_EQ(report.find("<link"), std::string::npos);
  EXPECT_EQ(report.find("<script"), std::string::npos);

  // The store: one row per unit of the lot, with the verdicts; the yield.
  r = Run({"history", Path("store.db"), "--lot", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto yields = ReadCsv(r.out);
  ASSERT_EQ(yields.size(), 1u);
  EXPECT_EQ(yields[0]["lot"], "LOT-A");
  EXPECT_EQ(yields[0]["units"], "5");
  EXPECT_EQ(yields[0]["passed"], "3");
  EXPECT_EQ(yields[0]["failed"], "1");
  r = Run({"history", Path("store.db"), "--serial", "SN-04", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto fits = ReadCsv(r.out);
  ASSERT_EQ(fits.size(), 1u);
  EXPECT_EQ(fits[0]["verdict"], "FAIL");
  EXPECT_EQ(fits[0]["samples_sha256"], Sha256OfFile(Path("units/unit-04/samples.csv.gz")));
  EXPECT_EQ(fits[0]["gyro_g_sensitivity_dpsg.xx"], summary["unit-04"]["gyro_g_sensitivity_dpsg.xx"]);
  r = Run({"history", Path("store.db"), "--trend", "gyro.bias.x", "--csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(ReadCsv(r.out).size(), 4u);  // the four fitted units
  // With a store, the lot page compares the lot with every lot recorded (here: itself), and
  // `history --lot --html` draws the store's lots on a page of their own.
  EXPECT_NE(lot.find("<tr data-history-lot=\"LOT-A\" class=\"current\">"), std::string::npos);
  r = Run({"history", Path("store.db"), "--lot", "LOT-A", "--html", Path("lots.html"), "--limits",
           Path("limits.yaml")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string lots = ReadBytes(dir_ / "lots.html");
  EXPECT_NE(lots.find("<tr data-history-lot=\"LOT-A\" class=\"current\">"), std::string::npos);
  EXPECT_NE(lots.find("data-yield=\"60\""), std::string::npos);
  EXPECT_NE(lots.find("<svg"), std::string::npos);
  r = Run({"history", Path("store.db"), "--lot", "LOT-Z", "--html", Path("lots_z.html")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("no lot named \"LOT-Z\""), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "lots_z.html"));
  r = Run({"history", Path("store.db"), "--html", Path("lots_z.html")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("give one of --serial S, --lot [NAME], --by"), std::string::npos) << r.err;

  // Again: nothing changed, nothing redone, same summary, no new rows.
  const std::string first_summary = ReadBytes(dir_ / "out" / "lot_summary.csv");
  r = Run(BatchArgs("out"));
  EXPECT_EQ(r.status, kExitFailedLimits);
  EXPECT_NE(r.out.find("5 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(ReadBytes(dir_ / "out" / "lot_summary.csv"), first_summary);
  EXPECT_EQ(ReadCsv(Run({"history", Path("store.db"), "--serial", "SN-01", "--csv"}).out).size(), 1u);

  // A unit's samples change: that unit alone is fitted again.
  Simulate(Path("units/unit-02/plan.yaml"), kFixtures + "/mems_truth.yaml",
           Path("units/unit-02/samples.csv.gz"), 22);
  r = Run(BatchArgs("out"));
  EXPECT_NE(r.out.find("4 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(ReadCsv(Run({"history", Path("store.db"), "--serial", "SN-02", "--csv"}).out).size(), 2u);
  EXPECT_NE(Summary("out")["unit-02"]["gyro_bias_dps.x"], summary["unit-02"]["gyro_bias_dps.x"]);
}
TEST_F(FactoryCliTest, InterruptedBatchResumesWithoutLoss) {
  // Stopped after the first unit (as a kill would stop it): that unit is finished and recorded,
  // no lot summary yet.
  std::vector<std::string> args = BatchArgs("out");
  args.insert(args.end(), {"--max-units", "1", "--jobs", "1"});
  RunResult r = Run(args);
  EXPECT_EQ(r.status, kExitNotDone) << r.out << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "lot_summary.csv"));
  int manifests = 0;
  for (const auto& unit : fs::directory_iterator(dir_ / "out"))
    manifests += fs::exists(unit.path() / "manifest.yaml");
  EXPECT_EQ(manifests, 1);
  // What a kill leaves behind: a temporary file of an output never committed; and, while another
  // batch holds the output folder, a second one is refused.
  fs::create_directories(dir_ / "out" / "unit-02");
  const fs::path leftover = dir_ / "out" / "unit-02" / ".calibration.yaml.tmp-AbC123";
  std::ofstream(leftover) << "half a calibration";
  {
    const int fd = ::open((dir_ / "out" / ".imufit-batch.lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    r = Run(BatchArgs("out"));
    EXPECT_EQ(r.status, kExitBadInput);
    EXPECT_NE(r.err.find("another imufit batch is writing to this folder"), std::string::npos) << r.err;
    ::close(fd);
  }
  // Resumed: the finished unit is skipped, the others are done, the leftover is gone.
  r = Run(BatchArgs("out"));
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(r.out.find("1 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(Summary("out").size(), kUnits);
  EXPECT_FALSE(fs::exists(leftover));
  // A kill between the store and the manifest: the unit is redone, never lost.
  fs::remove(dir_ / "out" / "unit-02" / "manifest.yaml");
  r = Run(BatchArgs("out"));
  EXPECT_NE(r.out.find("4 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(Summary("out").size(), kUnits);
  // Every unit is in the store; unit-01 once, unit-02 once or twice: the store keys a fit by its
  // content, fit time (to the second) included, so a redo within the same second is the same fit.
  EXPECT_EQ(ReadCsv(Run({"history", Path("store.db"), "--serial", "SN-01", "--csv"}).out).size(), 1u);
  const size_t redone = ReadCsv(Run({"history", Path("store.db"), "--serial", "SN-02", "--csv"}).out).size();
  EXPECT_GE(redone, 1u);
  EXPECT_LE(redone, 2u);
  auto yields = ReadCsv(Run({"history", Path("store.db"), "--lot", "LOT-A", "--csv"}).out);
  ASSERT_EQ(yields.size(), 1u);
  EXPECT_EQ(yields[0]["units"], "5");
}
// The real thing: the batch is killed (SIGKILL, no clean-up) as soon as its first unit is finished.
TEST_F(FactoryCliTest, KilledBatchResumesWithoutLoss) {
  std::vector<std::string> storage = {IMUFIT_EXE};
  for (const std::string& a : BatchArgs("out")) storage.push_back(a);
  storage.insert(storage.end(), {"--jobs", "1", "-q"});
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, IMUFIT_EXE, nullptr, nullptr, argv.data(), environ), 0);
  const fs::path first = dir_ / "out" / "unit-01" / "manifest.yaml";
  constexpr int kPollLimit = 60000;  // x 1 ms
  for (int i = 0; i < kPollLimit && !fs::exists(first); ++i) ::usleep(1000);
  ::kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(fs::exists(first));

  const RunResult r = Run(BatchArgs("out"));
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  std::printf("resumed after the kill: %s", r.out.substr(0, r.out.find('\n') + 1).c_str());
  auto summary = Summary("out");
  ASSERT_EQ(summary.size(), kUnits);
  EXPECT_EQ(summary["unit-04"]["verdict"], "FAIL");
  EXPECT_EQ(summary["unit-05"]["status"], "error");
  for (const char* serial : {"SN-01", "SN-02", "SN-04"}) {
    const size_t rows = ReadCsv(Run({"history", Path("store.db"), "--serial", serial, "--csv"}).out).size();
    EXPECT_GE(rows, 1u) << serial;  // twice for a unit killed between its store row and its manifest
    EXPECT_LE(rows, 2u) << serial;
  }
  EXPECT_EQ(ReadCsv(Run({"history", Path("store.db"), "--serial", "SN-01", "--csv"}).out).size(), 1u);
  for (const auto& unit : fs::directory_iterator(dir_ / "out")) {
    if (!unit.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(unit.path())) {
      EXPECT_EQ(file.path().filename().string().find(".tmp-"), std::string::npos) << file.path();
    }
  }
}
// Ctrl-C during a batch: the batch says how far it got, every unit folder is complete (calibration,
// certificate and manifest together) or holds no calibration, and the same command finishes the lot.
TEST_F(FactoryCliTest, InterruptedBatchSaysSoAndLeavesNoHalfUnit) {
  std::vector<std::string> storage = {IMUFIT_EXE};
  for (const std::string& a : BatchArgs("out")) storage.push_back(a);
  storage.insert(storage.end(), {"--jobs", "2", "-q"});
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 2, Path("batch.err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, IMUFIT_EXE, &files, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&files);
  const fs::path first = dir_ / "out" / "unit-01" / "manifest.yaml";
  constexpr int kPollLimit = 60000;  // x 1 ms
  for (int i = 0; i < kPollLimit && !fs::exists(first); ++i) ::usleep(1000);
  ::kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << status;
  const std::string err = ReadBytes(Path("batch.err"));
  // The count is of the units the batch has tallied: a unit whose outputs were committed a moment
  // before the signal may not be counted yet (at most the units in flight, --jobs 2), never more.
  EXPECT_TRUE(std::regex_search(err, std::regex("imufit: interrupted: [0-5] of 5 units done; run the same "
                                                "command again to finish\n")))
      << err;
  // The page quotes it for a lot of 8 with 3 done.
  ExpectTroubleshootingQuotes(std::regex_replace(err.substr(err.find("imufit: interrupted")),
                                                 std::regex("[0-9]+ of [0-9]+ units"), "3 of 8 units"));
  for (const auto& unit : fs::directory_iterator(dir_ / "out")) {
    if (!unit.is_directory()) continue;
    if (fs::exists(unit.path() / "calibration.yaml")) {
      EXPECT_TRUE(fs::exists(unit.path() / "report.html")) << unit.path();
      EXPECT_TRUE(fs::exists(unit.path() / "manifest.yaml")) << unit.path();
    }
  }
  EXPECT_EQ(Temporaries(dir_ / "out"), std::vector<std::string>{});
  const RunResult r = Run(BatchArgs("out"));
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_EQ(Summary("out").size(), kUnits);
}
// Two batches create the same new store at once: both wait for each other, neither fails; a batch
// with another new store records the units it skips as unchanged; without limits the yield is not
// judged.
TEST_F(FactoryCliTest, BatchesShareANewStoreAndRecordSkippedUnits) {
  const auto spawn = [&](const std::string& out) {
    std::vector<std::string> storage = {IMUFIT_EXE};
    for (const std::string& a : BatchArgs(out)) storage.push_back(a);
    storage.insert(storage.end(), {"--jobs", "1", "-q"});
    std::vector<char*> argv;
    for (std::string& a : storage) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 2, Path(out + ".err").c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    pid_t pid = 0;
    EXPECT_EQ(posix_spawn(&pid, IMUFIT_EXE, &files, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&files);
    return pid;
  };
  const pid_t a = spawn("out_a"), b = spawn("out_b");
  for (const auto& [pid, out] : {std::pair{a, "out_a"}, std::pair{b, "out_b"}}) {
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == kExitFailedLimits)
        << out << ": " << ReadBytes(Path(std::string(out) + ".err"));
  }
  // The same lot again into a new store: every unit is unchanged, and every one is recorded.
  std::vector<std::string> args = BatchArgs("out_a");
  args[std::find(args.begin(), args.end(), "--store") - args.begin() + 1] = Path("new.db");
  RunResult r = Run(args);
  EXPECT_NE(r.out.find("5 unchanged and skipped"), std::string::npos) << r.out;
  r = Run({"history", Path("new.db"), "--lot", "LOT-A", "--csv"});
  auto yields = ReadCsv(r.out);
  ASSERT_EQ(yields.size(), 1u) << r.out << r.err;
  EXPECT_EQ(yields[0]["units"], "5");
  EXPECT_EQ(yields[0]["passed"], "3");
  // No limits: no verdicts, and the yield is "not judged", not 0 %.
  r = Run({"batch", Path("units"), "-o", Path("out_c"), "--plan", kFixtures + "/plan_6pos.yaml", "--store",
           Path("c.db"), "--lot", "LOT-C", "-q"});
  ASSERT_TRUE(fs::exists(Path("out_c/lot.html"))) << r.err;
  EXPECT_NE(ReadBytes(Path("out_c/lot.html")).find("data-key=\"yield\">not judged"), std::string::npos);
  r = Run({"history", Path("c.db"), "--lot"});
  EXPECT_NE(r.out.find("not judged"), std::string::npos) << r.out;
}
// A unit folder's samples named as the logger names them (--samples-glob): exactly one match, else
// the unit's error names what the folder holds.
TEST_F(FactoryCliTest, BatchFindsSamplesByGlobAndSaysWhatAFolderHolds) {
  const std::string samples = ReadBytes(Path("units/unit-01/samples.csv.gz"));
  for (const char* unit : {"u1", "u2", "u3"}) fs::create_directories(dir_ / "logger" / unit);
  Write("logger/u1/plan.yaml", ReadBytes(Path("units/unit-01/plan.yaml")));
  Write("logger/u1/2026-11-24_imu.csv.gz", samples);
  Write("logger/u1/notes.txt", "chamber 2\n");
  Write("logger/u2/a_imu.csv.gz", samples);
  Write("logger/u2/b_imu.csv.gz", samples);
  Write("logger/u3/notes.txt", "no log\n");
  RunResult r = Run({"batch", Path("logger"), "--samples-glob", "*_imu.csv.gz", "-o", Path("out"), "--plan",
                     kFixtures + "/plan_6pos.yaml", "--jobs", "2"});
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  auto summary = Summary("out");
  EXPECT_EQ(summary["u1"]["status"], "fitted") << summary["u1"]["message"];
  EXPECT_EQ(summary["u1"]["serial"], "SN-01");
  // (from stdout: the summary's CSV quotes the quotes)
  EXPECT_NE(r.out.find("  u2 (u2): error: " + Path("logger/u2") +
                       ": --samples-glob \"*_imu.csv.gz\" matches 2 files, one unit's samples are one file: "
                       "a_imu.csv.gz, b_imu.csv.gz\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  u3 (u3): error: " + Path("logger/u3") +
                       ": --samples-glob \"*_imu.csv.gz\" matches no file (it has: notes.txt)\n"),
            std::string::npos)
      << r.out;
  ExpectTroubleshootingQuotes(LineWith(r.out, Path("logger/u2") + ": "));
  ExpectTroubleshootingQuotes(LineWith(r.out, Path("logger/u3") + ": "));
  // Without the pattern, the folder's files are named.
  r = Run({"batch", Path("logger"), "-o", Path("out2"), "--plan", kFixtures + "/plan_6pos.yaml", "-q"});
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_EQ(Summary("out2")["u1"]["message"],
            Path("logger/u1") +
                ": no samples.csv or samples.csv.gz (it has: 2026-11-24_imu.csv.gz, notes.txt, plan.yaml; "
                "--samples-glob names the logger's samples file)");
  ExpectTroubleshootingQuotes(Summary("out2")["u1"]["message"]);
  // A pattern with a units list is refused before any unit.
  Write("list.csv", "SN-1, logger/u1/2026-11-24_imu.csv.gz\n");
  r = Run({"batch", "--units-list", Path("list.csv"), "--samples-glob", "*.gz", "-o", Path("out3")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_EQ(r.err,
            "imufit: imufit batch: --samples-glob names the samples file in unit folders; a --units-list "
            "names each itself\n");
}
// A unit list names each unit's serial, samples and plan (CSV or blank-separated): the serial names
// the unit and its output folder; a bad line is one error before any unit.
TEST_F(FactoryCliTest, BatchFitsTheUnitsOfAUnitList) {
  fs::create_directories(dir_ / "lists");
  Write("lists/units.csv",
        "serial, samples, plan\n"
        "SN-31, ../units/unit-03/samples.csv.gz\n"
        "# a comment\n"
        "SN-01,../units/unit-01/samples.csv.gz,../units/unit-01/plan.yaml\n");
  RunResult r =
      Run({"batch", "--units-list", Path("lists/units.csv"), "-o", Path("out"), "--plan",
           kFixtures + "/plan_6pos.yaml", "--limits", Path("limits.yaml"), "--store", Path("l.db")});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  auto summary = Summary("out");
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary["SN-31"]["serial"], "SN-31");
  EXPECT_EQ(summary["SN-01"]["verdict"], "PASS");
  EXPECT_EQ(YAML::LoadFile(Path("out/SN-31/calibration.yaml"))["serial"].as<std::string>(), "SN-31");
  r = Run({"history", Path("l.db"), "--lot", "--csv"});
  EXPECT_EQ(ReadCsv(r.out).at(0)["lot"], "units");  // the list's name

  // Blank-separated; a listed file that is not there is that unit's error, naming the list's line.
  Write("units.txt", "SN-77   missing.csv.gz\n");
  r = Run({"batch", "--units-list", Path("units.txt"), "-o", Path("out2"), "--plan",
           kFixtures + "/plan_6pos.yaml", "-q"});
  EXPECT_EQ(r.status, kExitFailedLimits);
  EXPECT_EQ(Summary("out2")["SN-77"]["message"],
            Path("missing.csv.gz") + ": no such file (" + Path("units.txt") + " line 1)");
  ExpectTroubleshootingQuotes(Summary("out2")["SN-77"]["message"]);

  // Bad lines: one line each, exit 2, nothing written.
  const std::pair<std::string, std::string> bad[] = {
      {"SN-1\n", ":1:1: a unit is \"serial, samples file[, plan]\"; this line has 1 field"},
      {"SN-1 a.csv\nSN-1 b.csv\n", ":2:1: serial \"SN-1\" is listed twice (lines 1 and 2)"},
      {"../x a.csv\n", ":1:1: serial \"../x\" cannot name the unit's output folder"}};
  for (const auto& [text, said] : bad) {
    Write("bad.txt", text);
    r = Run({"batch", "--units-list", Path("bad.txt"), "-o", Path("out_bad"), "--plan",
             kFixtures + "/plan_6pos.yaml"});
    EXPECT_EQ(r.status, kExitBadInput) << text;
    EXPECT_EQ(r.err, "imufit: " + Path("bad.txt") + said + "\n") << text;
    ExpectTroubleshootingQuotes(r.err);
    EXPECT_FALSE(fs::exists(Path("out_bad/lot_summary.csv")));
  }
}
// A static-only lot (six faces, no rotation) needs `--fit accel`: batch takes every fit option of
// `imufit fit` and passes it to each unit, and the manifest records them, so a batch run again with
// other options redoes the units (their results would change) while the same options skip them.
TEST_F(FactoryCliTest, BatchFitsAStaticOnlyLotWithFitAccelAndRedoesUnitsWhenTheOptionsChange) {
  const std::string plan = kFixtures + "/plan_6faces_static.yaml";
  const std::string limits = Write("accel_limits.yaml",
                                   "format: imufit-limits\nversion: 1\n"
                                   "nominal: {accel_scale: 208.838}\n"
                                   "criteria:\n"
                                   "  - {quantity: accel_bias_mg, max_abs: 50}\n"
                                   "  - {quantity: accel_scale_error_pct, max_abs: 2}\n"
                                   "  - {quantity: fit_temp_range_c, covers: [-20, 60]}\n");
  for (int unit = 1; unit <= 2; ++unit) {
    const std::string folder = "static_lot/s" + std::to_string(unit);
    fs::create_directories(dir_ / folder);
    Simulate(plan, kFixtures + "/mems_truth.yaml", Path(folder + "/samples.csv"), 30 + unit);
  }
  const auto batch = [&](const std::string& out, const std::vector<std::string>& options) {
    std::vector<std::string> args = {"batch", Path("static_lot"), "--plan", plan, "--limits", limits,
                                     "-o",    Path(out),          "--jobs", "1"};
    args.insert(args.end(), options.begin(), options.end());
    return Run(args);
  };
  const auto manifest = [&](const std::string& out, const std::string& unit) {
    return ReadBytes(dir_ / out / unit / "manifest.yaml");
  };
  const auto fit_block = [&](const std::string& out, const std::string& unit) {
    return ReadBytes(dir_ / out / unit / "calibration.yaml");
  };

  // The whole model: the gyro scale is undetermined without rotation.
  RunResult r = batch("out", {});
  EXPECT_EQ(r.status, kExitFailedLimits) << r.err;
  EXPECT_EQ(Summary("out")["s1"]["status"], "not-fitted");
  EXPECT_NE(Summary("out")["s1"]["message"].find("--fit accel"), std::string::npos);

  // --fit accel: every unit fitted and passing, with the options in its calibration and manifest.
  r = batch("out", {"--fit", "accel"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto summary = Summary("out");
  for (const char* unit : {"s1", "s2"}) {
    EXPECT_EQ(summary[unit]["status"], "fitted") << unit << ": " << summary[unit]["message"];
    EXPECT_EQ(summary[unit]["verdict"], "PASS") << unit << ": " << summary[unit]["message"];
    EXPECT_NE(fit_block("out", unit).find("fitted: [accel.bias, accel.scale, accel.misalignment]"),
              std::string::npos);
    EXPECT_NE(manifest("out", unit)
                  .find("fit_options: \"fitted=accel.bias,accel.scale,accel.misalignment; "
                        "held=nominal; "),
              std::string::npos)
        << manifest("out", unit);
  }
  EXPECT_TRUE(fs::exists(dir_ / "out" / "s1" / "report.html"));
  // The same options: nothing redone.
  r = batch("out", {"--fit", "accel"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2 unchanged and skipped"), std::string::npos) << r.out;

  // Other options: every unit redone, with them.
  r = batch("out", {"--fit", "accel", "--loss", "cauchy", "--window-temp-span", "0.25"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_NE(fit_block("out", "s1").find("loss: cauchy"), std::string::npos);
  EXPECT_NE(manifest("out", "s2").find("; loss=cauchy; "), std::string::npos);
  EXPECT_NE(manifest("out", "s2").find("; window_temp_span_c=0.25; "), std::string::npos);

  // A prior names the held values: its numbers are part of the options, so editing the prior file
  // redoes the units (and the held gyro scale follows it), a copy of it does not.
  std::string prior_text = ReadBytes(kFixtures + "/mems_truth.yaml");
  const std::string prior = Write("prior.yaml", prior_text);
  const std::vector<std::string> with_prior = {"--fit", "gyro-bias,accel", "--prior", prior};
  r = batch("out", with_prior);
  ASSERT_EQ(r.status, 0) << r.err;
  const YAML::Node held = YAML::Load(fit_block("out", "s1"));
  EXPECT_EQ(held["gyro"]["scale"]["x"][0].as<double>(),
            YAML::Load(prior_text)["gyro"]["scale"]["x"][0].as<double>());
  EXPECT_EQ(held["fit"]["held_values"].as<std::string>(), "prior");
  EXPECT_NE(manifest("out", "s1").find("held=prior "), std::string::npos);
  const std::string copy = Write("prior_copy.yaml", "# the same numbers elsewhere\n" + prior_text);
  r = batch("out", {"--fit", "gyro-bias,accel", "--prior", copy});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("2 unchanged and skipped"), std::string::npos) << r.out;
  const std::string scale_x = YAML::Load(prior_text)["gyro"]["scale"]["x"][0].as<std::string>();
  prior_text.replace(prior_text.find(scale_x), scale_x.size(), "950.5");
  Write("prior.yaml", prior_text);
  r = batch("out", with_prior);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(YAML::Load(fit_block("out", "s1"))["gyro"]["scale"]["x"][0].as<double>(), 950.5);

  // A manifest of an imufit that recorded no options: that unit is done again.
  std::string old_manifest = manifest("out", "s2");
  old_manifest.erase(old_manifest.find("fit_options:"));
  Write("out/s2/manifest.yaml", old_manifest);
  r = batch("out", with_prior);
  EXPECT_NE(r.out.find("1 unchanged and skipped"), std::string::npos) << r.out;
  // Units done without reports and run again with them: redone, so that every unit has its report.
  r = batch("out_no_report", {"--fit", "accel", "--no-report"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out_no_report" / "s1" / "report.html"));
  r = batch("out_no_report", {"--fit", "accel"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out_no_report" / "s1" / "report.html"));

  // A lot logged without a thermometer or segment labels (one soak, 70 s on each face): --temp-c and
  // the segmentation reach every unit and its certificate, which reads the samples again for the
  // gyro noise of the longest static stretch.
  fs::create_directories(dir_ / "bare_lot" / "b1");
  r = Run({"simulate",
           "--plan",
           plan,
           "--calibration",
           kFixtures + "/mems_truth.yaml",
           "-o",
           Path("bare_lot/b1/samples.csv"),
           "--rate",
           "10",
           "--dwell",
           "70",
           "--temps",
           "25",
           "--gyro-noise-density",
           "2e-4",
           "--accel-noise-density",
           "2e-3",
           "--no-temp-column",
           "--no-segment-column",
           "--seed",
           "40",
           "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"batch", Path("bare_lot"), "--plan", plan, "-o", Path("bare_out"), "--jobs", "1", "-q", "--fit",
           "accel", "--temp-c", "25"});
  ASSERT_EQ(r.status, 0) << r.err << ReadBytes(dir_ / "bare_out" / "lot_summary.csv");
  EXPECT_EQ(Summary("bare_out")["b1"]["status"], "fitted");
  const std::string report = ReadBytes(dir_ / "bare_out" / "b1" / "report.html");
  EXPECT_NE(report.find("data-figure=\"gyro_arw_deg_per_sqrt_hr.x\""), std::string::npos);
  EXPECT_NE(manifest("bare_out", "b1").find("; temp_c=25; "), std::string::npos);
  // --temp-c with a temperature order above 0 is refused before any unit, as by imufit fit.
  r = Run({"batch", Path("bare_lot"), "--plan", plan, "-o", Path("bare_out2"), "--fit", "accel", "--temp-c",
           "25", "--accel-temp-order", "2"});
  EXPECT_EQ(r.status, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("--temp-c: one temperature for the whole run determines only order-0"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "bare_out2"));
}

}  // namespace
}  // namespace imufit

namespace imufit {
namespace {

namespace fs = std::filesystem;

// BatchArgs(out) with `option`'s value replaced (--store, --lot).
std::vector<std::string> WithOption(std::vector<std::string> args, const std::string& option,
                                    const std::string& value) {
  const auto at = std::find(args.begin(), args.end(), option);
  EXPECT_NE(at, args.end()) << option;
  if (at != args.end()) *(at + 1) = value;
  return args;
}

// Issue 28: the manifest is written by the one machine-text writer; PyYAML's safe_load (YAML 1.1)
// and yaml-cpp read it back alike, every value a string (version an integer), the outcome the lot
// summary's. `--shard` writes no lot_summary.csv and does not say it wrote one (issue 29 item 6).
TEST_F(FactoryCliTest, ManifestReadsBackAlikeInEveryReaderAndAShardClaimsNoLotSummary) {
  std::vector<std::string> args = BatchArgs("out");
  args.insert(args.end(), {"--no-report", "--jobs", "2"});
  RunResult r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  auto summary = Summary("out");
  for (const char* unit : {"unit-01", "unit-04", "unit-05"}) {
    const std::string path = (dir_ / "out" / unit / "manifest.yaml").string();
    const RunResult py =
        RunProgram("/usr/bin/python3",
                   {"-c",
                    "import sys, yaml\n"
                    "m = yaml.safe_load(open(sys.argv[1]))\n"
                    "assert m['version'] == 1 and type(m['version']) is int, m\n"
                    "for k, v in m.items():\n"
                    "    if k == 'judged':\n"
                    "        assert all(type(u) is float for u in v['expanded_u'].values()), v\n"
                    "        assert all(type(c[0]) is str and type(c[2]) is bool for c in v['criteria']), v\n"
                    "        continue\n"
                    "    assert k == 'version' or type(v) is str, (k, v)\n"
                    "    print('%s=%s' % (k, v))\n",
                    path});
    ASSERT_EQ(py.status, 0) << py.err;
    const YAML::Node node = YAML::LoadFile(path);
    for (const auto& entry : node) {
      const std::string key = entry.first.as<std::string>();
      if (key == "judged") continue;  // numbers and lists, checked by type above
      EXPECT_NE(py.out.find(key + "=" + entry.second.as<std::string>() + "\n"), std::string::npos)
          << key << " in " << py.out;
    }
    EXPECT_EQ(node["format"].as<std::string>(), "imufit-unit-manifest");
    EXPECT_EQ(node["status"].as<std::string>(), summary[unit]["status"]) << unit;
    EXPECT_EQ(node["verdict"].as<std::string>(), summary[unit]["verdict"]) << unit;
    // (The test's CSV reader keeps a quoted cell's doubled quotes as one: compare without them.)
    const auto unquoted = [](std::string text) {
      text.erase(std::remove(text.begin(), text.end(), '"'), text.end());
      return text;
    };
    EXPECT_EQ(unquoted(node["message"].as<std::string>()), unquoted(summary[unit]["message"])) << unit;
  }

  std::vector<std::string> shard = WithOption(BatchArgs("shard_out"), "--store", Path("shard.db"));
  shard.insert(shard.end(), {"--no-report", "--shard", "1/2"});
  r = Run(shard);
  EXPECT_TRUE(r.status == 0 || r.status == kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(r.out.find("imufit batch: "), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "shard_out" / "lot_summary.csv"));
  EXPECT_EQ(r.out.find("lot_summary.csv"), std::string::npos) << r.out;
}

// Issue 29 item 6 end to end: the store's rows of a batch hold the fit options and the files
// committed; a unit skipped as unchanged and recorded in another store keeps its calibration's time,
// so that merging that store back adds no second fit; a batch under a new --lot on runs recorded
// under another lot refuses them, saying so, and records nothing under the new lot.
TEST_F(FactoryCliTest, StoreRowsHoldTheSpecAndARunKeepsItsLot) {
  const std::string station =
      Write("station_u.yaml", std::string(kStation) +
                                  "uncertainty:\n"
                                  "  rate_accuracy: {u: 10, unit: ppm, source: table cert}\n");
  std::vector<std::string> args = BatchArgs("out");
  args.insert(args.end(), {"--no-report", "--station", station});
  RunResult r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  const std::string first_summary = ReadBytes(dir_ / "out" / "lot_summary.csv");
  // The U of a gyro scale carries the station's 10 ppm (2 x sigma alone is far below it).
  auto rows = Summary("out");
  const double scale = std::stod(rows["unit-01"]["gyro_scale_per_dps.x"]);
  EXPECT_GE(std::stod(rows["unit-01"]["gyro_scale_per_dps.x.U"]) / scale, 20e-6 * 0.999);
  const fs::path store = dir_ / "store.db";
  const std::string options =
      Query(store, "SELECT count(*) FROM fits WHERE fit_options = '' OR fit_options IS NULL");
  EXPECT_EQ(options, "0\n") << "every fit records its options";
  const std::string sn01 =
      Query(store,
            "SELECT a.kind, a.path, a.sha256, f.time_utc FROM attachments a JOIN fits f ON "
            "f.id = a.fit_id JOIN runs r ON r.run_key = f.run_key WHERE r.serial = 'SN-01'");
  const std::string calibration = (dir_ / "out" / "unit-01" / "calibration.yaml").string();
  EXPECT_NE(sn01.find("calibration|" + calibration + "|" + Sha256OfFile(calibration) + "|"),
            std::string::npos)
      << sn01;
  const std::string fit_time = Query(store,
                                     "SELECT f.time_utc FROM fits f JOIN runs r ON r.run_key = f.run_key "
                                     "WHERE r.serial = 'SN-01'");

  // The same lot again, into a new store: every unit unchanged, recorded there at its fit's time.
  args = WithOption(BatchArgs("out"), "--store", Path("other.db"));
  args.insert(args.end(), {"--no-report", "--station", station});
  r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(r.out.find("5 unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(ReadBytes(dir_ / "out" / "lot_summary.csv"), first_summary)
      << "a unit skipped as unchanged states the U and the verdict it was judged with";
  EXPECT_EQ(
      Query(dir_ / "other.db",
            "SELECT f.time_utc FROM fits f JOIN runs r ON r.run_key = f.run_key WHERE r.serial = 'SN-01'"),
      fit_time);
  r = Run({"store", "merge", Path("other.db"), "--into", store.string()});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(Query(store,
                  "SELECT count(*) FROM fits f JOIN runs r ON r.run_key = f.run_key WHERE r.serial IN "
                  "('SN-01', 'SN-02', 'SN-04')"),
            "3\n")
      << "one calibration is one fit after the merge";

  // The same runs under a new lot: refused, said, nothing recorded under it.
  const std::string fits_before = Query(store, "SELECT count(*) FROM fits");
  args = WithOption(BatchArgs("out_b"), "--lot", "LOT-B");
  args.insert(args.end(), {"--no-report", "--station", station});
  r = Run(args);
  EXPECT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(r.out.find("is recorded in lot \"LOT-A\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("give --lot LOT-A, or another --store"), std::string::npos) << r.out;
  EXPECT_EQ(Query(store, "SELECT count(*) FROM runs WHERE lot = 'LOT-B'"), "0\n");
  EXPECT_EQ(Query(store, "SELECT count(*) FROM fits"), fits_before) << "nothing recorded";
}

}  // namespace
}  // namespace imufit
