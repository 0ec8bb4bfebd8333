// End-to-end tests of the factory commands (`imufit batch`, `imufit history`, `imufit report`,
// `imufit fit --limits/--report/--store`) on a simulated lot of five small units made with
// `imufit simulate` from fixtures/mems_truth.yaml (10 Hz, 3 s dwells, 4 temperatures):
//   unit-01, unit-02  good units with their own plan (serials SN-01, SN-02)
//   unit-03           a good unit with samples only: fitted with the shared --plan
//   unit-04           g-sensitivity xx of 0.089 deg/s/g, outside the 0.05 deg/s/g limit (SN-04)
//   unit-05           a corrupt samples file (a number "1.2.3" in the middle)
// The program is run as a user runs it (IMUFIT_EXE); outputs are read back from the files.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include "imufit/io/calibration.h"
#include "imufit/io/sha256.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;

const std::string kFixtures = IMUFIT_FIXTURES_DIR;
// The exit statuses of docs/spec.md section 4.
constexpr int kExitBadInput = 2;
constexpr int kExitNotDone = 1;
constexpr int kExitFailedLimits = 3;
constexpr int kUnits = 5;
// A passing unit's certificate prints on at most this many pages (five since it states its
// uncertainty budget and decision rule).
constexpr int kMostPagesOfAPassingCertificate = 5;

constexpr const char* kLimits = R"(format: imufit-limits
version: 1
name: MEMS-A acceptance
nominal: {gyro_scale: 939.65, accel_scale: 208.838}
criteria:
  - {quantity: gyro_bias_dps, max_abs: 5}
  - {quantity: gyro_scale_error_pct, max_abs: 2}
  - {quantity: gyro_misalignment_mrad, max_abs: 10}
  - {quantity: gyro_g_sensitivity_dpsg, max_abs: 0.05}
  - {quantity: gyro_bias_dps, statistic: sigma, max_abs: 0.01}
  - {quantity: fit_temp_range_c, covers: [-20, 60]}
)";

constexpr const char* kStation = R"(format: imufit-station
version: 1
station: Rate table bench 2
station_id: CB-02
location: Building 4, room 112
operator: J. Smith
rate_table: {model: Acutronic AC1120S, serial: RT-2291}
chamber: {model: Espec SU-262, serial: CH-0117}
reference_calibration_due: 2099-12-31
notes: Rate table calibrated by the national lab, certificate NL-2026-0412.
)";

std::string ReadBytes(const fs::path& path) { return testing::ReadBytes(path.string()); }

// A CSV split into rows of cells (no quoted commas in the cells the tests read).
std::vector<std::map<std::string, std::string>> ReadCsv(const std::string& text) {
  std::vector<std::map<std::string, std::string>> rows;
  std::istringstream lines(text);
  std::string line;
  std::vector<std::string> header;
  const auto split = [](const std::string& l) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : l) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted)
        cells.push_back(std::move(cell)), cell.clear();
      else
        cell += c;
    }
    cells.push_back(cell);
    return cells;
  };
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    if (header.empty()) {
      header = split(line);
      continue;
    }
    const std::vector<std::string> cells = split(line);
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

// The value of data-value on the element with data-figure="name" in a report.
std::string ReportFigure(const std::string& html, const std::string& name) {
  const std::regex pattern("data-figure=\"" + std::regex_replace(name, std::regex("\\."), "\\.") +
                           "\" data-value=\"([^\"]+)\"");
  std::smatch match;
  return std::regex_search(html, match, pattern) ? match[1].str() : "<none>";
}

class FactoryCliTest : public testing::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    fs::create_directories(dir_ / "units");
    Write("limits.yaml", kLimits);
    MakeLot();
  }

  RunResult Run(const std::vector<std::string>& args) const { return RunProgram(IMUFIT_EXE, args); }

  // Simulates a unit's run with a fixed seed and a little white noise.
  void Simulate(const std::string& plan, const std::string& truth, const std::string& samples, int seed) {
    const RunResult r = Run({"simulate",
                             "--plan",
                             plan,
                             "--calibration",
                             truth,
                             "-o",
                             samples,
                             "--rate",
                             "10",
                             "--dwell",
                             "3",
                             "--temps",
                             "-20,5,30,60",
                             "--gyro-noise-density",
                             "2e-4",
                             "--accel-noise-density",
                             "2e-3",
                             "--seed",
                             std::to_string(seed),
                             "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
  }

  std::string UnitPlan(const std::string& unit, const std::string& serial) {
    std::string plan = ReadBytes(kFixtures + "/plan_6pos.yaml");
    plan = std::regex_replace(plan, std::regex("format: imufit-plan\n"),
                              "format: imufit-plan\nserial: " + serial + "\n");
    return Write("units/" + unit + "/plan.yaml", plan);
  }

  void MakeLot() {
    const std::string truth = kFixtures + "/mems_truth.yaml";
    // A unit whose gyro g-sensitivity xx is 0.15 counts per m/s^2: 0.089 deg/s/g at 25 degC.
    std::string bad_truth = ReadBytes(truth);
    bad_truth = std::regex_replace(bad_truth, std::regex("xx: \\[0\\.0483,"), "xx: [0.15,");
    ASSERT_NE(bad_truth, ReadBytes(truth));
    const std::string bad_truth_path = Write("bad_truth.yaml", bad_truth);
    for (const char* unit : {"unit-01", "unit-02", "unit-03", "unit-04", "unit-05"})
      fs::create_directories(dir_ / "units" / unit);
    Simulate(UnitPlan("unit-01", "SN-01"), truth, Path("units/unit-01/samples.csv.gz"), 1);
    Simulate(UnitPlan("unit-02", "SN-02"), truth, Path("units/unit-02/samples.csv.gz"), 2);
    Simulate(kFixtures + "/plan_6pos.yaml", truth, Path("units/unit-03/samples.csv.gz"), 3);
    Simulate(UnitPlan("unit-04", "SN-04"), bad_truth_path, Path("units/unit-04/samples.csv.gz"), 4);
    Simulate(UnitPlan("unit-05", "SN-05"), truth, Path("units/unit-05/samples.csv"), 5);
    std::string samples = ReadBytes(Path("units/unit-05/samples.csv"));
    const size_t line = samples.find('\n', samples.size() / 2) + 1;
    const size_t comma = samples.find(',', line);
    samples.replace(line, comma - line, "1.2.3");
    Write("units/unit-05/samples.csv", samples);
  }

  std::vector<std::string> BatchArgs(const std::string& out) const {
    return {"batch",   Path("units"),    "--limits", Path("limits.yaml"),
            "-o",      Path(out),        "--plan",   kFixtures + "/plan_6pos.yaml",
            "--store", Path("store.db"), "--lot",    "LOT-A"};
  }

  // Prints `html` to PDF with headless Chromium on paper `size` ("A4", "letter"; the printer's page
  // size: an @page rule added to a copy), rasterises every page with pdftoppm and checks it: not
  // blank, "page x of y" in its footer, text no smaller than kMinimumWordHeightPt. Returns the
  // number of pages (0 when the tools are missing: the caller skips).
  int PrintToPdf(const std::string& html, const std::string& name, const std::string& size) {
    for (const char* tool : {"/usr/bin/chromium", "/usr/bin/pdftoppm", "/usr/bin/pdfinfo",
                             "/usr/bin/pdftotext", "/usr/bin/timeout"}) {
      if (!fs::exists(tool)) return 0;
    }
    std::string text = ReadBytes(html);
    const size_t head = text.find("</head>");
    EXPECT_NE(head, std::string::npos) << html;
    text.insert(head, "<style>@page { size: " + size + "; }</style>");
    const std::string copy = (fs::path(html).parent_path() / (name + ".html")).string();
    std::ofstream(copy, std::ios::binary) << text;  // beside the original: its links still resolve
    const std::string pdf = Path(name + ".pdf");
    const RunResult p =
        RunProgram("/usr/bin/timeout", {"120", "/usr/bin/chromium", "--headless", "--no-sandbox",
                                        "--disable-gpu", "--disable-quic", "--no-first-run",
                                        "--disable-background-networking", "--disable-component-update",
                                        "--disable-sync", "--user-data-dir=" + Path("chromium-" + name),
                                        "--no-pdf-header-footer", "--print-to-pdf=" + pdf, "file://" + copy});
    EXPECT_EQ(p.status, 0) << p.err;
    const RunResult info = RunProgram("/usr/bin/pdfinfo", {pdf});
    std::smatch match;
    int pages = 0;
    if (std::regex_search(info.out, match, std::regex("Pages:\\s+(\\d+)"))) pages = std::stoi(match[1]);
    EXPECT_NE(info.out.find(size == "A4" ? "(A4)" : "(letter)"), std::string::npos) << info.out;
    EXPECT_EQ(RunProgram("/usr/bin/pdftoppm", {"-r", "30", "-png", pdf, Path(name + "-page")}).status, 0);
    for (int page = 1; page <= pages; ++page) {
      // pdftoppm numbers pages with as many digits as the last one needs.
      const std::string png =
          Path(name + "-page-" + (pages >= 10 && page < 10 ? "0" : "") + std::to_string(page) + ".png");
      const std::string image = ReadBytes(png);
      EXPECT_EQ(image.substr(1, 3), "PNG") << png;
      // A page with text compresses to far more than a blank one (about 1 kB at 30 dpi); the last
      // page may hold one table.
      constexpr size_t kMinimumPrintedPagePngBytes = 2500;
      EXPECT_GT(image.size(), kMinimumPrintedPagePngBytes) << png;
      const RunResult words = RunProgram("/usr/bin/pdftotext", {"-f", std::to_string(page), "-l",
                                                                std::to_string(page), pdf, Path("page.txt")});
      EXPECT_EQ(words.status, 0);
      EXPECT_NE(
          ReadBytes(Path("page.txt")).find("page " + std::to_string(page) + " of " + std::to_string(pages)),
          std::string::npos)
          << name << " page " << page;
    }
    // Readable in print: the word boxes pdftotext reports are the font's height (ascent to
    // descent, about 1.03 x its size); 95 % of the words at least kMinimumWordHeightPt, i.e. a
    // 7.3 pt font (tables print at 7.5 pt, plot labels at about 8.4 pt). A page wider than the
    // paper (a long path that cannot wrap) is shrunk by the browser and fails this.
    constexpr double kMinimumWordHeightPt = 7.5;
    EXPECT_EQ(RunProgram("/usr/bin/pdftotext", {"-bbox", pdf, Path("bbox.html")}).status, 0);
    const std::string boxes = ReadBytes(Path("bbox.html"));
    const std::regex word("yMin=\"([0-9.]+)\" xMax=\"[0-9.]+\" yMax=\"([0-9.]+)\"");
    std::vector<double> heights;
    for (std::sregex_iterator it(boxes.begin(), boxes.end(), word), end; it != end; ++it)
      heights.push_back(std::stod((*it)[2]) - std::stod((*it)[1]));
    EXPECT_GT(heights.size(), 100u) << name;
    if (!heights.empty()) {
      std::sort(heights.begin(), heights.end());
      EXPECT_GE(heights[heights.size() / 20], kMinimumWordHeightPt) << name;
    }
    return pages;
  }

  // Expects docs/troubleshooting.md to quote `said`, a line the program printed (its final newline
  // and this test's folder left out, as the page shortens paths), between backquotes.
  void ExpectTroubleshootingQuotes(std::string said) const {
    for (size_t at; (at = said.find(dir_.string() + "/")) != std::string::npos;)
      said.erase(at, dir_.string().size() + 1);
    if (!said.empty() && said.back() == '\n') said.pop_back();
    EXPECT_NE(ReadBytes(kFixtures + "/../docs/troubleshooting.md").find("`" + said + "`"), std::string::npos)
        << "docs/troubleshooting.md does not quote: " << said;
  }

  std::map<std::string, std::map<std::string, std::string>> Summary(const std::string& out) const {
    std::map<std::string, std::map<std::string, std::string>> by_unit;
    for (const auto& row : ReadCsv(ReadBytes(dir_ / out / "lot_summary.csv"))) by_unit[row.at("unit")] = row;
    return by_unit;
  }
};

// Runs `sql` on the SQLite database at `path` (the test's own change to a store).
void ExecuteSql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// The line of `text` from where `start` is found to its end ("" when it is not found).
std::string LineWith(const std::string& text, const std::string& start) {
  const size_t at = text.find(start);
  return at == std::string::npos ? "" : text.substr(at, text.find('\n', at) - at);
}

// The files in `folder` whose names contain ".tmp-" (an output never committed).
std::vector<std::string> Temporaries(const fs::path& folder) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(entry.path());
  }
  return found;
}

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
  EXPECT_TRUE(std::regex_search(err, std::regex("imufit: interrupted: [1-5] of 5 units done; run the same "
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

// A run with a long static stretch gets the Allan deviation and the ARW in its certificate.
TEST_F(FactoryCliTest, ReportShowsTheGyroNoiseOfALongStaticStretch) {
  const std::string plan = Write("static_plan.yaml",
                                 "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
                                 "  - {id: 1, up: [0, 0, 1]}\n");
  constexpr double kGyroNoiseDensity = 2e-4;  // rad/s/sqrt(Hz)
  const RunResult sim = Run({"simulate", "--plan", plan, "--calibration", kFixtures + "/mems_truth.yaml",
                             "-o", Path("static.csv"), "--rate", "10", "--dwell", "120", "--temps", "25",
                             "--gyro-noise-density", "2e-4", "--seed", "9", "-q"});
  ASSERT_EQ(sim.status, 0) << sim.err;
  const RunResult r = Run({"report", "-c", kFixtures + "/mems_truth.yaml", "-p", plan, "-s",
                           Path("static.csv"), "-o", Path("static.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string report = ReadBytes(Path("static.html"));
  // ARW = noise density in deg/sqrt(h); 1200 samples fix it to a few percent (relative, per axis).
  constexpr double kArwRelativeTolerance = 0.15;
  const double expected_arw = kGyroNoiseDensity * 180.0 / M_PI * 60.0;
  for (const char* axis : {"x", "y", "z"}) {
    const std::string value = ReportFigure(report, std::string("gyro_arw_deg_per_sqrt_hr.") + axis);
    ASSERT_NE(value, "<none>") << axis;
    EXPECT_NEAR(std::stod(value), expected_arw, expected_arw * kArwRelativeTolerance) << axis;
  }
}

// imufit allan on raw counts or millisecond timestamps says so; --scale and --time-unit silence it.
TEST_F(FactoryCliTest, AllanWarnsOnRawCountsAndMillisecondTimestamps) {
  const std::string plan = Write("static_plan.yaml",
                                 "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81\nsegments:\n"
                                 "  - {id: 1, up: [0, 0, 1]}\n");
  RunResult r =
      Run({"simulate", "--plan", plan, "--calibration", kFixtures + "/mems_truth.yaml", "-o",
           Path("static.csv"), "--rate", "10", "--dwell", "120", "--temps", "25", "--seed", "9", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  r = Run({"allan", "-s", Path("static.csv"), "-c", "gyro_x", "-o", Path("a.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("gyro_x has a mean of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("raw counts"), std::string::npos) << r.err;
  r = Run(
      {"allan", "-s", Path("static.csv"), "-c", "gyro_x", "-o", Path("b.csv"), "-q", "--scale", "939.65"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  // The same log with time_s in milliseconds.
  std::string text = ReadBytes(Path("static.csv"));
  std::string ms = "time_s,gyro_x\n";
  std::istringstream lines(text);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("time_s", 0) == 0) continue;
    ms += std::to_string(100 * n++) + ",0.001\n";
  }
  Write("ms.csv", ms);
  r = Run({"allan", "-s", Path("ms.csv"), "-c", "gyro_x", "-o", Path("c.csv"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("--time-unit ms"), std::string::npos) << r.err;
  r = Run({"allan", "-s", Path("ms.csv"), "-c", "gyro_x", "-o", Path("d.csv"), "-q", "--time-unit", "ms"});
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(ReadBytes(Path("d.csv")).find("gyro_x,oadev,0.1,"), std::string::npos);
}

// The certificate and the lot page as a quality engineer prints them: a lot with one failing, one
// corrupt and one incomplete unit, printed to PDF by headless Chromium on A4 and on Letter, each
// page rasterised by pdftoppm and checked (PrintToPdf): page count, "page x of y" and the serial
// in the running header, no blank page, readable text.
TEST_F(FactoryCliTest, CertificatesAndLotPagePrintToPdf) {
  if (!fs::exists("/usr/bin/chromium") || !fs::exists("/usr/bin/pdftoppm")) {
    GTEST_SKIP() << "no chromium or pdftoppm (Debian: chromium poppler-utils)";
  }
  // unit-06: a run cut short after its second temperature (the rig stopped).
  fs::create_directories(dir_ / "units" / "unit-06");
  Simulate(UnitPlan("unit-06", "SN-06"), kFixtures + "/mems_truth.yaml", Path("units/unit-06/samples.csv"),
           6);
  const std::string full = ReadBytes(Path("units/unit-06/samples.csv"));
  Write("units/unit-06/samples.csv", full.substr(0, full.find('\n', full.size() * 2 / 5) + 1));
  RunResult r = Run(BatchArgs("out"));
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  auto summary = Summary("out");
  EXPECT_EQ(summary["unit-04"]["verdict"], "FAIL");
  EXPECT_EQ(summary["unit-05"]["status"], "error");
  EXPECT_EQ(summary["unit-06"]["status"], "not-fitted") << summary["unit-06"]["message"];

  // A passing unit prints on at most kMostPagesOfAPassingCertificate pages of either paper size;
  // every page says whose certificate it is.
  for (const char* size : {"A4", "letter"}) {
    const int passing = PrintToPdf(Path("out/unit-01/report.html"), std::string("unit-01-") + size, size);
    EXPECT_GE(passing, 2) << size;
    EXPECT_LE(passing, kMostPagesOfAPassingCertificate) << size;
    EXPECT_EQ(
        RunProgram("/usr/bin/pdftotext",
                   {"-f", "2", "-l", "2", Path(std::string("unit-01-") + size + ".pdf"), Path("p2.txt")})
            .status,
        0);
    EXPECT_NE(ReadBytes(Path("p2.txt")).find("IMU calibration certificate SN-01"), std::string::npos);
  }
  const int failing = PrintToPdf(Path("out/unit-04/report.html"), "unit-04", "A4");
  EXPECT_LE(failing, kMostPagesOfAPassingCertificate + 1);
  EXPECT_EQ(RunProgram("/usr/bin/pdftotext", {"-l", "1", Path("unit-04.pdf"), Path("p1.txt")}).status, 0);
  EXPECT_NE(ReadBytes(Path("p1.txt")).find("FAIL"), std::string::npos);
  // The lot page too: its plots are drawn at the size they print, so nothing is shrunk.
  for (const char* size : {"A4", "letter"}) {
    EXPECT_GE(PrintToPdf(Path("out/lot.html"), std::string("lot-") + size, size), 1) << size;
  }
}

// --pdf prints the certificate itself (fit --report, report) and, in a batch, every certificate and
// the lot page, with headless Chromium on the paper --paper names; checked with pdfinfo and pdftotext.
TEST_F(FactoryCliTest, PdfOptionPrintsTheCertificateAndTheLotPage) {
  // Refused before any work, whatever is installed: a paper imufit does not know, --pdf without --report.
  const std::string plan = Path("units/unit-01/plan.yaml"), samples = Path("units/unit-01/samples.csv.gz");
  RunResult r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal_x.yaml"), "--report", Path("x.html"),
                     "--pdf", "--paper", "legal", "-q"});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_EQ(r.err, "imufit: --paper: is \"legal\"; one of A4, letter\n");
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal_x.yaml"), "--pdf", "-q"});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_EQ(r.err, "imufit: --pdf: prints the certificate: give --report too\n");
  EXPECT_FALSE(fs::exists(Path("cal_x.yaml")));
  if (!fs::exists("/usr/bin/chromium") || !fs::exists("/usr/bin/pdfinfo") ||
      !fs::exists("/usr/bin/pdftotext")) {
    GTEST_SKIP()
        << "no chromium, pdfinfo or pdftotext (Debian: chromium poppler-utils): PDF output not tested";
  }
  const auto info = [&](const std::string& pdf) { return RunProgram("/usr/bin/pdfinfo", {pdf}).out; };
  const auto text = [&](const std::string& pdf) {
    EXPECT_EQ(RunProgram("/usr/bin/pdftotext", {"-layout", pdf, Path("pdf.txt")}).status, 0) << pdf;
    return ReadBytes(Path("pdf.txt"));
  };
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal1.yaml"), "--limits", Path("limits.yaml"),
           "--report", Path("unit1.html"), "--pdf", "--paper", "letter"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + Path("unit1.pdf")), std::string::npos) << r.out;
  EXPECT_NE(info(Path("unit1.pdf")).find("(letter)"), std::string::npos) << info(Path("unit1.pdf"));
  std::string printed = text(Path("unit1.pdf"));
  EXPECT_NE(printed.find("IMU calibration certificate SN-01"), std::string::npos);
  EXPECT_NE(printed.find("PASS"), std::string::npos);
  EXPECT_NE(printed.find("page 1 of"), std::string::npos);  // the page's own footer, not the browser's

  r = Run({"report", "-c", Path("cal1.yaml"), "-p", plan, "-s", samples, "-o", Path("again.html"), "--pdf"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(info(Path("again.pdf")).find("(A4)"), std::string::npos);
  EXPECT_NE(text(Path("again.pdf")).find("IMU calibration certificate SN-01"), std::string::npos);

  std::vector<std::string> args = BatchArgs("out");
  args.push_back("--pdf");
  r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(text(Path("out/unit-04/report.pdf")).find("FAIL"), std::string::npos);
  EXPECT_NE(info(Path("out/lot.pdf")).find("(A4)"), std::string::npos);
  EXPECT_NE(text(Path("out/lot.pdf")).find("Lot LOT-A"), std::string::npos);
  EXPECT_FALSE(fs::exists(Path("out/unit-05/report.pdf")));  // the unit that could not be read
}

// The standard simulated 6-position soak (fixtures/mems_6pos_soak.csv.gz: 18 segments at five
// temperatures), fitted with validation and certified with limits and a station file: a passing
// unit on at most kMostPagesOfAPassingCertificate pages of A4 and of Letter.
TEST_F(FactoryCliTest, StandardSoakCertificatePrintsOnFivePages) {
  if (!fs::exists("/usr/bin/chromium") || !fs::exists("/usr/bin/pdftoppm")) {
    GTEST_SKIP() << "no chromium or pdftoppm (Debian: chromium poppler-utils)";
  }
  const RunResult r =
      Run({"fit", "-p", kFixtures + "/plan_6pos.yaml", "-s", kFixtures + "/mems_6pos_soak.csv.gz", "-o",
           Path("soak.yaml"), "--serial", "SN-SOAK", "--validate", "--limits", Path("limits.yaml"),
           "--station", Write("station.yaml", kStation), "--report", Path("soak.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  for (const char* size : {"A4", "letter"}) {
    const int pages = PrintToPdf(Path("soak.html"), std::string("soak-") + size, size);
    std::printf("standard soak certificate: %d pages on %s\n", pages, size);
    EXPECT_GE(pages, 3) << size;  // not shrunk into nothing
    EXPECT_LE(pages, kMostPagesOfAPassingCertificate) << size;
  }
}

// The station file: on the certificate of fit --report, report and batch, hashed among the inputs;
// a bad one is exit 2 with its location before any work; --station without --report is refused.
TEST_F(FactoryCliTest, StationFileIsShownHashedAndChecked) {
  const std::string station = Write("station.yaml", kStation);
  const std::string plan = Path("units/unit-01/plan.yaml"), samples = Path("units/unit-01/samples.csv.gz");
  RunResult r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal1.yaml"), "--station", station,
                     "--report", Path("unit1.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string sha = Sha256OfFile(station);
  for (const std::string& html : {Path("unit1.html"), Path("unit1_report.html")}) {
    if (html == Path("unit1_report.html")) {
      r = Run(
          {"report", "-c", Path("cal1.yaml"), "-p", plan, "-s", samples, "--station", station, "-o", html});
      ASSERT_EQ(r.status, 0) << r.err;
    }
    const std::string report = ReadBytes(html);
    EXPECT_NE(report.find("data-sha256=\"station\">" + sha + "<"), std::string::npos) << html;
    EXPECT_NE(report.find("data-key=\"station\">Rate table bench 2 (CB-02)<"), std::string::npos) << html;
    EXPECT_NE(report.find("data-key=\"calibrated_by\">J. Smith<"), std::string::npos) << html;
    EXPECT_NE(report.find("data-key=\"rate_table\">Acutronic AC1120S, serial RT-2291<"), std::string::npos);
    EXPECT_NE(report.find("Reviewed by (quality)"), std::string::npos);
  }
  // Reference equipment out of its calibration when the unit was calibrated: a warning.
  std::string overdue = kStation;
  overdue = std::regex_replace(overdue, std::regex("2099-12-31"), "2020-01-31");
  r = Run({"report", "-c", Path("cal1.yaml"), "-p", plan, "-s", samples, "--station",
           Write("overdue.yaml", overdue), "-o", Path("overdue.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(ReadBytes(Path("overdue.html")).find("due for calibration on 2020-01-31"), std::string::npos);

  // A bad station file: exit 2 with file:line:column, nothing written.
  const std::string bad = Write("bad_station.yaml", std::string(kStation) + "operater: A. Typo\n");
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal_bad.yaml"), "--station", bad, "--report",
           Path("bad.html")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("bad_station.yaml:11:1: unknown key \"operater\""), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("cal_bad.yaml")));
  EXPECT_FALSE(fs::exists(Path("bad.html")));
  r = Run({"report", "-c", Path("cal1.yaml"), "-p", plan, "-s", samples, "--station", bad, "-o",
           Path("bad.html")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_FALSE(fs::exists(Path("bad.html")));
  r = Run(std::vector<std::string>{"batch", Path("units"), "--station", bad, "-o", Path("out_bad")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("bad_station.yaml:11:1"), std::string::npos) << r.err;
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal_no_report.yaml"), "--station", station});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("--report"), std::string::npos) << r.err;

  // batch: every certificate shows the station; the manifest records its hash, and another station
  // file redoes the units (their certificates would change).
  std::vector<std::string> args = BatchArgs("out");
  args.insert(args.end(), {"--station", station});
  r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.err;
  EXPECT_NE(ReadBytes(dir_ / "out" / "unit-02" / "report.html").find("data-sha256=\"station\">" + sha + "<"),
            std::string::npos);
  EXPECT_NE(ReadBytes(dir_ / "out" / "unit-02" / "manifest.yaml").find("station_sha256: \"" + sha + "\""),
            std::string::npos);
  r = Run(args);
  EXPECT_NE(r.out.find("5 unchanged and skipped"), std::string::npos) << r.out;
  args.back() = Write("station2.yaml", std::string(kStation) + "# another bench\n");
  r = Run(args);
  EXPECT_NE(r.out.find("0 unchanged and skipped"), std::string::npos) << r.out;
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

// Identity and dates: the samples header's run lines (acquired, model, firmware, ambient) are
// recorded in the calibration apart from the fit's time and printed with the laboratory, the
// customer and a certificate number that the same inputs reproduce; the reference equipment's due
// date is judged against the acquisition, and against the fit's date (said so) without one.
TEST_F(FactoryCliTest, TheCertificateNamesTheRunTheItemAndTheLaboratory) {
  Simulate(UnitPlan("unit-01", "SN-01"), kFixtures + "/mems_truth.yaml", Path("run.csv"), 1);
  const std::string run = ReadBytes(Path("run.csv"));
  // A page's text with its apostrophes as written (the page escapes them).
  const auto page = [&](const std::string& name) {
    return std::regex_replace(ReadBytes(Path(name)), std::regex("&#39;"), "'");
  };
  const auto with_header = [&](const std::string& name, const std::string& lines) {
    return Write(name, lines + run);
  };
  const std::string samples = with_header("acquired.csv",
                                          "# acquired: 2026-01-10T08:15:00Z\n# model: IMU-9X rev B\n"
                                          "# firmware: 2.4.1\n# ambient: 23.1 degC, 41 %RH\n");
  std::string station = std::regex_replace(std::string(kStation), std::regex("2099-12-31"), "2026-01-31");
  station +=
      "laboratory: Acme Inertial Calibration Laboratory, 12 Dock Road, Bristol\n"
      "accreditation: UKAS 1234 (ISO/IEC 17025)\n";
  const std::string station_path = Write("lab.yaml", station);
  const std::string plan = Path("units/unit-01/plan.yaml");
  RunResult r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal.yaml"), "--station", station_path,
                     "--report", Path("cert.html"), "--customer", "Northwind Avionics", "--order", "PO-7731",
                     "--store", Path("acquired.db"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  // The store records the run's acquisition and the unit's model from the header, not the file's time.
  const RunResult stored = Run({"history", Path("acquired.db"), "--serial", "SN-01", "--csv"});
  ASSERT_EQ(stored.status, 0) << stored.err;
  EXPECT_NE(stored.out.find(",2026-01-10T08:15:00Z,IMU-9X rev B"), std::string::npos) << stored.out;
  const Calibration calibration = ReadCalibration(Path("cal.yaml"));
  ASSERT_TRUE(calibration.fit && calibration.fit->acquired_utc);
  EXPECT_EQ(*calibration.fit->acquired_utc, "2026-01-10T08:15:00Z");
  EXPECT_EQ(calibration.fit->unit_firmware.value_or(""), "2.4.1");
  EXPECT_NE(calibration.created_utc.substr(0, 10), "2026-01-10");  // the fit's own time, apart
  const std::string html = ReadBytes(Path("cert.html"));
  const auto shows = [&](const std::string& page, const std::string& key, const std::string& value) {
    EXPECT_NE(page.find("data-key=\"" + key + "\">" + value + "<"), std::string::npos) << key;
  };
  shows(html, "acquired_utc", "2026-01-10T08:15:00Z");
  shows(html, "unit_model", "IMU-9X rev B");
  shows(html, "unit_firmware", "2.4.1");
  shows(html, "ambient", "23.1 degC, 41 %RH");
  shows(html, "customer", "Northwind Avionics");
  shows(html, "order", "PO-7731");
  shows(html, "laboratory", "Acme Inertial Calibration Laboratory, 12 Dock Road, Bristol");
  shows(html, "accreditation", "UKAS 1234 (ISO/IEC 17025)");
  EXPECT_NE(html.find("apply only to the item calibrated"), std::string::npos);
  // Due 2026-01-31, recorded on 2026-01-10 and fitted later: within its calibration.
  EXPECT_EQ(html.find("due for calibration"), std::string::npos);
  const std::regex number_pattern("data-key=\"certificate_number\">(SN-01-20260110-[0-9a-f]{8})<");
  std::smatch number;
  ASSERT_TRUE(std::regex_search(html, number, number_pattern)) << "no certificate number";

  // The same inputs give the same number; another order, another number.
  const auto report_number = [&](const std::string& order) {
    const std::string out = Path("again_" + order + ".html");
    const RunResult again =
        Run({"report", "-c", Path("cal.yaml"), "-p", plan, "-s", samples, "--station", station_path, "-o",
             out, "--customer", "Northwind Avionics", "--order", order});
    EXPECT_EQ(again.status, 0) << again.err;
    const std::string page = ReadBytes(out);
    std::smatch found;
    return std::regex_search(page, found, number_pattern) ? found[1].str() : std::string("none");
  };
  EXPECT_EQ(report_number("PO-7731"), number[1].str());
  EXPECT_NE(report_number("PO-7732"), number[1].str());

  // Recorded after the due date: a warning; no acquisition time: judged against the fit's date.
  r = Run({"fit", "-p", plan, "-s", with_header("late.csv", "# acquired: 2026-02-01 09:00Z\n"), "-o",
           Path("late.yaml"), "--station", station_path, "--report", Path("late.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string overdue =
      "the station's reference equipment was due for calibration on 2026-01-31, before this unit's run was "
      "recorded (2026-02-01)";
  EXPECT_NE(page("late.html").find(overdue), std::string::npos);
  ExpectTroubleshootingQuotes(overdue);
  r = Run({"fit", "-p", plan, "-s", Path("run.csv"), "-o", Path("undated.yaml"), "--station", station_path,
           "--report", Path("undated.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string undated = page("undated.html");
  EXPECT_NE(undated.find("no '# acquired:' time: the fit's date"), std::string::npos);
  EXPECT_NE(undated.find("not stated (no '# acquired:' line in the samples header)"), std::string::npos);

  // A time that is not UTC ISO 8601: exit 2 at its line and column, nothing written.
  r = Run({"fit", "-p", plan, "-s", with_header("bad.csv", "# serial: SN-01\n# acquired: 10/01/2026 08:15\n"),
           "-o", Path("bad.yaml"), "--report", Path("bad.html")});
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_NE(r.err.find("bad.csv:2:13: \"10/01/2026 08:15\" is not a UTC time written as ISO 8601"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("bad.yaml")));
  ExpectTroubleshootingQuotes(r.err);
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("c2.yaml"), "--customer", "X"});
  EXPECT_EQ(r.status, kExitBadInput);
  ExpectTroubleshootingQuotes(r.err);
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
