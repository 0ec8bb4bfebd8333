// The fixture of the factory commands' end-to-end tests (cli_factory_util.h).
#include "cli_factory_util.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

namespace imufit {

namespace fs = std::filesystem;
using testing::RunResult;

std::string ReadBytes(const fs::path& path) { return testing::ReadBytes(path.string()); }

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

std::string ReportFigure(const std::string& html, const std::string& name) {
  const std::regex pattern("data-figure=\"" + std::regex_replace(name, std::regex("\\."), "\\.") +
                           "\" data-value=\"([^\"]+)\"");
  std::smatch match;
  return std::regex_search(html, match, pattern) ? match[1].str() : "<none>";
}

std::string Query(const fs::path& path, const std::string& sql) {
  const std::string log =
      (path.parent_path().parent_path() / ("query." + std::to_string(::getpid()))).string();
  const RunResult r = testing::RunProgram("/usr/bin/python3",
                                          {"-c",
                                           "import sqlite3, sys\n"
                                           "for row in sqlite3.connect(sys.argv[1]).execute(sys.argv[2]):\n"
                                           "    print('|'.join(str(c) for c in row))\n",
                                           path.string(), sql},
                                          log + ".out", log + ".err");
  EXPECT_EQ(r.status, 0) << r.err;
  return r.out;
}

void ExecuteSql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

std::string LineWith(const std::string& text, const std::string& start) {
  const size_t at = text.find(start);
  return at == std::string::npos ? "" : text.substr(at, text.find('\n', at) - at);
}

std::vector<std::string> Temporaries(const fs::path& folder) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(entry.path());
  }
  return found;
}

void FactoryCliTest::SetUp() {
  TempDirTest::SetUp();
  fs::create_directories(dir_ / "units");
  Write("limits.yaml", kLimits);
  MakeLot();
}

RunResult FactoryCliTest::Run(const std::vector<std::string>& args) const {
  return RunProgram(IMUFIT_EXE, args);
}

void FactoryCliTest::Simulate(const std::string& plan, const std::string& truth, const std::string& samples,
                              int seed) {
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

std::string FactoryCliTest::UnitPlan(const std::string& unit, const std::string& serial) {
  std::string plan = ReadBytes(kFixtures + "/plan_6pos.yaml");
  plan = std::regex_replace(plan, std::regex("format: imufit-plan\n"),
                            "format: imufit-plan\nserial: " + serial + "\n");
  return Write("units/" + unit + "/plan.yaml", plan);
}

void FactoryCliTest::MakeLot() {
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

std::vector<std::string> FactoryCliTest::BatchArgs(const std::string& out) const {
  return {"batch",   Path("units"),    "--limits", Path("limits.yaml"),
          "-o",      Path(out),        "--plan",   kFixtures + "/plan_6pos.yaml",
          "--store", Path("store.db"), "--lot",    "LOT-A"};
}

int FactoryCliTest::PrintToPdf(const std::string& html, const std::string& name, const std::string& size) {
  for (const char* tool : {"/usr/bin/chromium", "/usr/bin/pdftoppm", "/usr/bin/pdfinfo", "/usr/bin/pdftotext",
                           "/usr/bin/timeout"}) {
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
      RunProgram("/usr/bin/timeout",
                 {"120", "/usr/bin/chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                  "--no-first-run", "--disable-background-networking", "--disable-component-update",
                  "--disable-sync", "--user-data-dir=" + Path("chromium-" + name), "--no-pdf-header-footer",
                  "--print-to-pdf=" + pdf, "file://" + copy});
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

void FactoryCliTest::ExpectTroubleshootingQuotes(std::string said) const {
  for (size_t at; (at = said.find(dir_.string() + "/")) != std::string::npos;)
    said.erase(at, dir_.string().size() + 1);
  if (!said.empty() && said.back() == '\n') said.pop_back();
  EXPECT_NE(ReadBytes(kFixtures + "/../docs/troubleshooting.md").find("`" + said + "`"), std::string::npos)
      << "docs/troubleshooting.md does not quote: " << said;
}

std::map<std::string, std::map<std::string, std::string>> FactoryCliTest::Summary(
    const std::string& out) const {
  std::map<std::string, std::map<std::string, std::string>> by_unit;
  for (const auto& row : ReadCsv(ReadBytes(dir_ / out / "lot_summary.csv"))) by_unit[row.at("unit")] = row;
  return by_unit;
}

}  // namespace imufit
