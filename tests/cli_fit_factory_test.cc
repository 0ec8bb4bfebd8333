// `imufit fit` with the factory options (--limits, --report, --store, --noise-segment) end to end on the lot
// of cli_factory_util.h: a store that cannot record the fit, a closed pipe; part of cli_fit_test.
#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "cli_factory_util.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;

TEST_F(FactoryCliTest, FitWithLimitsReportAndStore) {
  const std::string plan = Path("units/unit-01/plan.yaml");
  RunResult r =
      Run({"fit", "-p", plan, "-s", Path("units/unit-01/samples.csv.gz"), "-o", Path("cal1.yaml"), "--limits",
           Path("limits.yaml"), "--report", Path("unit1.html"), "--store", Path("fit.db")});
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("acceptance MEMS-A acceptance: PASS"), std::string::npos) << r.out;
  EXPECT_NE(ReadBytes(Path("unit1.html")).find("data-key=\"verdict\">PASS<"), std::string::npos);
  EXPECT_EQ(ReadCsv(Run({"history", Path("fit.db"), "--serial", "SN-01", "--csv"}).out).size(), 1u);

  // Fitted but out of limits: the calibration is written, the exit status says so.
  r = Run({"fit", "-p", Path("units/unit-04/plan.yaml"), "-s", Path("units/unit-04/samples.csv.gz"), "-o",
           Path("cal4.yaml"), "--limits", Path("limits.yaml"), "-q"});
  EXPECT_EQ(r.status, kExitFailedLimits) << r.err;
  EXPECT_TRUE(fs::exists(Path("cal4.yaml")));
  EXPECT_NE(r.out.find("|gyro_g_sensitivity_dpsg.xx|"), std::string::npos) << r.out;

  // imufit report from the calibration and its run gives the same figures.
  r = Run({"report", "-c", Path("cal4.yaml"), "-p", Path("units/unit-04/plan.yaml"), "-s",
           Path("units/unit-04/samples.csv.gz"), "--limits", Path("limits.yaml"), "-o", Path("unit4.html")});
  EXPECT_EQ(r.status, kExitFailedLimits) << r.err;
  const std::string report = ReadBytes(Path("unit4.html"));
  EXPECT_NE(report.find("data-key=\"verdict\">FAIL<"), std::string::npos);
  EXPECT_NE(report.find("data-sha256=\"calibration\">" + Sha256OfFile(Path("cal4.yaml")) + "<"),
            std::string::npos);

  // A bad limits file: exit 2 with its location, before any work, nothing written.
  const std::string bad =
      Write("bad_limits.yaml", std::string(kLimits) + "  - {quantity: gyro_bias_dps, max_abs: 0}\n");
  r = Run({"fit", "-p", plan, "-s", Path("units/unit-01/samples.csv.gz"), "-o", Path("cal_bad.yaml"),
           "--limits", bad});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("bad_limits.yaml:12:40: criteria[6].max_abs: \"0\" must be greater than 0"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("cal_bad.yaml")));
  r = Run(std::vector<std::string>{"batch", Path("units"), "--limits", bad, "-o", Path("out_bad")});
  EXPECT_EQ(r.status, kExitBadInput);
  r = Run({"history", Path("fit.db"), "--serial", "NO-SUCH-SERIAL"});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("no calibrations of serial"), std::string::npos) << r.err;
}
// A store that cannot take the fit (not SQLite, read-only, of a newer imufit, refusing the row):
// exit 2 in one line naming it, and neither the calibration nor the certificate is written (an
// existing calibration stays as it was).
TEST_F(FactoryCliTest, FitWritesNothingWhenTheStoreCannotRecordIt) {
  const std::vector<std::string> fit = {"fit",
                                        "-p",
                                        Path("units/unit-01/plan.yaml"),
                                        "-s",
                                        Path("units/unit-01/samples.csv.gz"),
                                        "-o",
                                        Path("cal.yaml"),
                                        "--report",
                                        Path("cal.html"),
                                        "-q",
                                        "--store"};
  const auto run_with = [&](const std::string& store) {
    std::vector<std::string> args = fit;
    args.push_back(store);
    return Run(args);
  };
  ASSERT_EQ(run_with(Path("good.db")).status, 0);
  fs::remove(Path("cal.html"));
  const std::string previous = Write("cal.yaml", "# the calibration flashed last week\n");
  const auto copy_of_good = [&](const std::string& name) {
    fs::copy_file(Path("good.db"), Path(name));
    return Path(name);
  };
  const std::string read_only = copy_of_good("read_only.db");
  fs::permissions(read_only, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const std::string newer = copy_of_good("newer.db");
  ExecuteSql(newer, "PRAGMA user_version = 7");
  const std::string refusing = copy_of_good("refusing.db");
  ExecuteSql(refusing,
             "CREATE TRIGGER refuse BEFORE INSERT ON fits BEGIN SELECT RAISE(ABORT, 'disk quota'); END");
  const std::pair<std::string, std::string> cases[] = {
      {Write("text.db", "this is not a database, just some text long enough to matter\n"),
       "file is not a database"},
      {read_only, "the results store is read-only"},
      {newer, "results store schema version 7 is not supported"},
      {refusing, "disk quota: the fit is not recorded in the results store; nothing written"}};
  for (const auto& [store, message] : cases) {
    const RunResult r = run_with(store);
    EXPECT_EQ(r.status, kExitBadInput) << store;
    EXPECT_EQ(r.err.rfind("imufit: " + store + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    ExpectTroubleshootingQuotes(r.err);
    EXPECT_EQ(ReadBytes(previous), "# the calibration flashed last week\n") << store;
    EXPECT_FALSE(fs::exists(Path("cal.html"))) << store;
  }
  EXPECT_EQ(Temporaries(dir_), std::vector<std::string>{});
  // Nothing was recorded in the refusing store either; the good one still reads.
  RunResult r = Run({"history", refusing, "--serial", "SN-01", "--csv"});
  EXPECT_EQ(ReadCsv(r.out).size(), 1u) << r.err;  // the copy's row only
  // `history` reads a read-only store, and says in one line when there is none.
  r = Run({"history", read_only, "--serial", "SN-01", "--csv"});
  EXPECT_EQ(r.status, 0) << r.err;
  r = Run({"history", Path("missing.db"), "--lot"});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_EQ(r.err, "imufit: " + Path("missing.db") +
                       ": no such results store (imufit fit --store and imufit batch --store create one)\n");
  ExpectTroubleshootingQuotes(r.err);
  EXPECT_FALSE(fs::exists(Path("missing.db")));
}
// A store on a read-only mount (a station's share mounted read-only): exit 2 in one line, and the
// calibration flashed last week stays as it was. Mounting needs CAP_SYS_ADMIN: without it the test
// says so and is skipped.
TEST_F(FactoryCliTest, FitWritesNothingWhenTheStoreIsOnAReadOnlyMount) {
  ASSERT_EQ(Run({"fit", "-p", Path("units/unit-01/plan.yaml"), "-s", Path("units/unit-01/samples.csv.gz"),
                 "-o", Path("cal.yaml"), "-q", "--store", Path("good.db")})
                .status,
            0);
  const std::string mount_point = Path("share");
  fs::create_directories(mount_point);
  const RunResult mounted = RunProgram("/bin/mount", {"-t", "tmpfs", "-o", "size=64m", "tmpfs", mount_point});
  if (mounted.status != 0) {
    GTEST_SKIP() << "cannot mount a file system here (mount needs CAP_SYS_ADMIN): " << mounted.err;
  }
  fs::copy_file(Path("good.db"), mount_point + "/results.db");
  const RunResult read_only = RunProgram("/bin/mount", {"-o", "remount,ro", mount_point});
  const std::string previous = Write("cal.yaml", "# the calibration flashed last week\n");
  RunResult r;
  if (read_only.status == 0) {
    r = Run({"fit", "-p", Path("units/unit-01/plan.yaml"), "-s", Path("units/unit-01/samples.csv.gz"), "-o",
             Path("cal.yaml"), "--report", Path("cal.html"), "-q", "--store", mount_point + "/results.db"});
  }
  RunProgram("/bin/umount", {mount_point});
  ASSERT_EQ(read_only.status, 0) << read_only.err;
  EXPECT_EQ(r.status, kExitBadInput) << r.err;
  EXPECT_EQ(r.err, "imufit: " + mount_point +
                       "/results.db: the results store is read-only: imufit records every fit in it (make it "
                       "writable, or give another --store)\n");
  EXPECT_EQ(ReadBytes(previous), "# the calibration flashed last week\n");
  EXPECT_FALSE(fs::exists(Path("cal.html")));
  EXPECT_EQ(Temporaries(dir_), std::vector<std::string>{});
}
// `imufit fit ... | head -3`: the program stops of SIGPIPE, silently, and leaves no temporary.
TEST_F(FactoryCliTest, FitIntoAClosedPipeLeavesNoTemporaries) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    const RunResult r = RunProgram(
        "/bin/sh", {"-c", std::string("'") + IMUFIT_EXE + "' fit -p '" + Path("units/unit-01/plan.yaml") +
                              "' -s '" + Path("units/unit-01/samples.csv.gz") + "' -o '" + Path("cal.yaml") +
                              "' --report '" + Path("cal.html") + "' --validate | head -3"});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 3) << r.out;
    EXPECT_EQ(r.err, "");
  }
  EXPECT_EQ(Temporaries(dir_), std::vector<std::string>{});
}
// --noise-segment names the certificate's noise stretch: one the plan lacks, or a rate segment, is
// exit 2 naming the plan, before anything is written; a static one is measured and said so.
TEST_F(FactoryCliTest, NoiseSegmentNamesAStaticSegmentOfThePlan) {
  const std::string plan = Write("plan.yaml", ReadBytes(kFixtures + "/plan_6pos.yaml"));
  const std::string samples = Path("units/unit-01/samples.csv.gz");
  for (const char* id : {"99", "7"}) {
    const RunResult r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("noise.yaml"), "--report",
                             Path("noise.html"), "--noise-segment", id, "-q"});
    EXPECT_EQ(r.status, kExitBadInput) << r.err;
    EXPECT_FALSE(fs::exists(Path("noise.yaml")));
    EXPECT_NE(r.err.find("noise_segment: "), std::string::npos) << r.err;
    ExpectTroubleshootingQuotes(r.err);
  }
  const RunResult r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("noise.yaml"), "--report",
                           Path("noise.html"), "--noise-segment", "3", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  // The lot's runs dwell 3 s: too short for the Allan deviation, and the page says which it measured.
  EXPECT_NE(ReadBytes(Path("noise.html")).find("the static stretch of segment 3 (--noise-segment) is"),
            std::string::npos);
}

}  // namespace
}  // namespace imufit
