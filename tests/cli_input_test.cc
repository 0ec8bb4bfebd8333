// End-to-end tests of how samples files are read as a station writes them: the unit of the time
// column (--time-unit, and the sample interval judged against what a plan needs), temperatures an
// IMU cannot report (kelvin, fill values), and the calibration of the right unit.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// `text` (a CSV with '#' comments) with the field `column` of every data row replaced by
// `change(field, data row index)`.
std::string MapColumn(const std::string& text, const std::string& column,
                      const std::function<std::string(const std::string&, int)>& change) {
  std::istringstream lines(text);
  std::string line;
  std::string out;
  int index = -1;
  int row = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') {
      out += line + "\n";
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream split(line);
    std::string field;
    while (std::getline(split, field, ',')) fields.push_back(field);
    if (index < 0) {
      index = static_cast<int>(std::find(fields.begin(), fields.end(), column) - fields.begin());
    } else {
      fields[index] = change(fields[index], row++);
    }
    for (size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + fields[i];
    out += "\n";
  }
  return out;
}

std::string Scaled(const std::string& field, double factor) {
  std::ostringstream text;
  text.precision(17);
  text << std::stod(field) * factor;
  return text.str();
}

// One line on stderr, and it holds `expected`.
void ExpectOneLine(const RunResult& r, const std::string& expected) {
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A calibration file's coefficients and sigmas: from `gyro:` up to the fit record (the header's
// created_utc and the record's file names and hashes differ between two fits of one run).
std::string Coefficients(const std::string& calibration) {
  const size_t from = calibration.find("\ngyro:");
  return calibration.substr(from, calibration.find("\nfit:") - from);
}

class CliInputTest : public CliTest {
 protected:
  // A small labelled run in seconds (raw.csv), as SmallRunArgs makes it.
  std::string RawRun() {
    const std::string raw = Path("raw.csv");
    const RunResult r = Run(SmallRunArgs(raw, {}));
    EXPECT_EQ(r.status, 0) << r.err;
    return raw;
  }
  // The SHA-256 of a file as coreutils' sha256sum gives it (not imufit's own code).
  std::string Sha256OfFileForTest(const std::string& path) const {
    const RunResult r = RunProgram("/usr/bin/sha256sum", {path});
    EXPECT_EQ(r.status, 0) << r.err;
    return r.out.substr(0, 64);
  }
  RunResult Fit(const std::string& samples, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"fit",   "-p", Fixture("plan_6pos.yaml"), "-s",
                                     samples, "-o", Path("cal.yaml"),          "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    return Run(args);
  }

  // docs/troubleshooting.md quotes the line `r` printed (the test's folder left out).
  void ExpectInTroubleshooting(const RunResult& r) const {
    std::string said = r.err.substr(0, r.err.size() - 1);
    const std::string folder = Path("x").substr(0, Path("x").size() - 1);
    for (size_t at = said.find(folder); at != std::string::npos; at = said.find(folder))
      said.erase(at, folder.size());
    EXPECT_NE(ReadBytes(Fixture("../docs/troubleshooting.md")).find("`" + said + "`"), std::string::npos)
        << said;
  }
};

// Time stamps in milliseconds or nanoseconds read as seconds give a sample rate no calibration
// run has: refused with the unit to give; given, the run reads as the one in seconds.
TEST_F(CliInputTest, TimeInMillisecondsOrNanosecondsIsRefusedWithTheUnitToGive) {
  const std::string text = ReadBytes(RawRun());
  struct Case {
    const char* unit;
    double factor;
    const char* hint;
  };
  for (const Case& c : {Case{"ms", 1e3, "time in milliseconds? use --time-unit ms"},
                        Case{"ns", 1e9, "time in nanoseconds? use --time-unit ns"}}) {
    SCOPED_TRACE(c.unit);
    const std::string file =
        Write(std::string("raw_") + c.unit + ".csv",
              MapColumn(text, "time_s", [&](const std::string& f, int) { return Scaled(f, c.factor); }));
    for (const std::string command : {"fit", "apply", "segment"}) {
      RunResult r;
      if (command == "fit") r = Fit(file);
      if (command == "apply") {
        r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", file, "-o", Path("cal.yaml")});
      }
      if (command == "segment") {
        r = Run({"segment", "-p", Fixture("plan_6pos.yaml"), "-s", file, "-o", Path("cal.yaml")});
      }
      EXPECT_EQ(r.status, 2) << command;
      ExpectOneLine(r, c.hint);
      EXPECT_NE(r.err.find("too slow for an IMU run"), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(Path("cal.yaml"))) << command;
    }
    const RunResult fitted = Fit(file, {"--time-unit", c.unit});
    EXPECT_EQ(fitted.status, 0) << fitted.err;
    fs::remove(Path("cal.yaml"));
    // Applied with the unit, the times come out in seconds, as the run in seconds gives them.
    ASSERT_EQ(Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", file, "-o", Path("a.csv"), "--time-unit",
                   c.unit})
                  .status,
              0);
    ASSERT_EQ(
        Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", Path("raw.csv"), "-o", Path("b.csv")}).status,
        0);
    const Table a = ReadTable(Path("a.csv"));
    const Table b = ReadTable(Path("b.csv"));
    ASSERT_EQ(a.rows.size(), b.rows.size());
    for (size_t i = 0; i < a.rows.size(); i += 97) {
      EXPECT_NEAR(a.Number(i, "time_s"), b.Number(i, "time_s"), 1e-9);
      EXPECT_EQ(a.Vector(i, "gyro"), b.Vector(i, "gyro"));
    }
    fs::remove(Path("a.csv"));
  }
  // Seconds declared as milliseconds: at 10 Hz the rate (10 kHz) is one an IMU could have, but the
  // run lasts 0.36 s, too short for the plan's 18 segments each to outlast the 0.5 s trim.
  const RunResult seconds_as_ms = Fit(Path("raw.csv"), {"--time-unit", "ms"});
  EXPECT_EQ(seconds_as_ms.status, 2) << seconds_as_ms.err;
  ExpectOneLine(seconds_as_ms,
                "shorter than the plan's segments can last (9 s): time in seconds? use --time-unit s");
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  // The same without a segment column: the segmentation fails, and the time unit is named as why.
  ASSERT_EQ(Run(SmallRunArgs(Path("unlabelled.csv"), {"--no-segment-column"})).status, 0);
  const RunResult unlabelled = Fit(Path("unlabelled.csv"), {"--time-unit", "ms"});
  EXPECT_EQ(unlabelled.status, 2) << unlabelled.err;
  ExpectOneLine(unlabelled, "time in seconds? use --time-unit s");
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  const RunResult bad = Fit(Path("raw.csv"), {"--time-unit", "min"});
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("is not one of: s, ms, us, ns"), std::string::npos) << bad.err;
  // The correct run is unchanged.
  EXPECT_EQ(Fit(Path("raw.csv")).status, 0);
}

// Temperatures no IMU reports are refused where they stand: a kelvin column at its first row, a
// fill value at its own row.
TEST_F(CliInputTest, TemperaturesOutsideWhatAnImuReportsAreRefusedAtTheirRow) {
  const std::string text = ReadBytes(RawRun());
  const auto header_line = [&text]() {
    std::istringstream lines(text);
    std::string line;
    int n = 0;
    while (std::getline(lines, line)) {
      ++n;
      if (!line.empty() && line[0] != '#') return n;
    }
    return 0;
  };
  const int first_row_line = header_line() + 1;
  struct Case {
    const char* name;
    std::function<std::string(const std::string&, int)> change;
    int row;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"kelvin",
       [](const std::string& f, int) {
         std::ostringstream out;
         out.precision(17);
         out << std::stod(f) + 273.15;
         return out.str();
       },
       0, "the column is in kelvin? ("},
      {"absolute zero", [](const std::string& f, int row) { return row == 500 ? "-273.15" : f; }, 500,
       "-273.15 degC is outside -100..200 degC, what an IMU can report: absolute zero, a logger's fill "
       "value"},
      {"1e6", [](const std::string& f, int row) { return row == 700 ? "1e6" : f; }, 700,
       "1e+06 degC is outside -100..200 degC, what an IMU can report: a fill value or a broken reading?"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string file = Write("t.csv", MapColumn(text, "temp_c", c.change));
    for (const bool apply : {false, true}) {
      const RunResult r =
          apply ? Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", file, "-o", Path("cal.yaml")})
                : Fit(file);
      EXPECT_EQ(r.status, 2);
      const std::string place = "t.csv:" + std::to_string(first_row_line + c.row) + ":2: temp_c: ";
      ExpectOneLine(r, place);
      EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(Path("cal.yaml")));
    }
  }
  // A fixed temperature is judged the same way.
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", Path("raw.csv"), "-o",
                           Path("x.csv"), "--temp-c", "298"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(Path("x.csv")));
}

// apply and allan --calibration correct a unit's log only with that unit's calibration; the
// corrected file says what corrected it and is never corrected again.
TEST_F(CliInputTest, ApplyAndAllanCorrectOnlyWithTheUnitsOwnCalibration) {
  const std::string cal = Fixture("mems_truth.yaml");  // serial MEMS-TRUTH-0001
  ASSERT_EQ(Run(SmallRunArgs(Path("other.csv"), {"--serial", "SN-2"})).status, 0);
  ASSERT_EQ(Run(SmallRunArgs(Path("own.csv"), {"--serial", "MEMS-TRUTH-0001"})).status, 0);
  const std::string refused = "names the unit \"SN-2\", the calibration " + cal +
                              " names it \"MEMS-TRUTH-0001\": are these that unit's samples?";
  RunResult r = Run({"apply", "-c", cal, "-s", Path("other.csv"), "-o", Path("out.csv")});
  EXPECT_EQ(r.status, 2);
  ExpectOneLine(r, "other.csv:2:11: the samples header of " + Path("other.csv") + " " + refused);
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  r = Run(
      {"allan", "-s", Path("other.csv"), "--calibration", cal, "-c", "gyro_x", "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2);
  ExpectOneLine(r, refused);
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // --allow-mismatch corrects it, with a warning.
  r = Run({"apply", "-c", cal, "-s", Path("other.csv"), "-o", Path("out.csv"), "--allow-mismatch", "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the samples header of"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(allowed with --allow-mismatch)"), std::string::npos) << r.err;
  // The unit's own calibration: the output names the log's serial and what corrected it.
  r = Run({"apply", "-c", cal, "-s", Path("own.csv"), "-o", Path("own_corrected.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const std::string corrected = ReadBytes(Path("own_corrected.csv"));
  EXPECT_NE(corrected.find("# serial: MEMS-TRUTH-0001\n# corrected by: serial MEMS-TRUTH-0001, calibration "
                           "sha256 " +
                           Sha256OfFileForTest(cal) + ", software imufit "),
            std::string::npos)
      << corrected.substr(0, 300);
  // A corrected file is not corrected again: exit 1, naming the line.
  for (const bool allan : {false, true}) {
    r = allan ? Run({"allan", "-s", Path("own_corrected.csv"), "--calibration", cal, "-c", "gyro_x", "-o",
                     Path("again.csv"), "-q"})
              : Run({"apply", "-c", cal, "-s", Path("own_corrected.csv"), "-o", Path("again.csv")});
    EXPECT_EQ(r.status, 1);
    ExpectOneLine(r, "own_corrected.csv:2: is corrected already (corrected by: serial MEMS-TRUTH-0001");
    EXPECT_FALSE(fs::exists(Path("again.csv")));
  }
}

// A header as a spreadsheet or another logger writes it: named columns matched without regard to
// case, every absent one named at once with a near name, a ';' export said to be one, "+1" read as 1.
TEST_F(CliInputTest, HeadersAsSpreadsheetsAndLoggersWriteThem) {
  const std::string cal = Fixture("mems_truth.yaml");
  const std::string rows = "0,25,+1,23,-41,12,35,-18,2100\n0.01,25,+1,24,-42,13,36,-19,2101\n";
  // Case: read as the lower-case names; "+1" is segment 1.
  Write("upper.csv", "Time_S,TEMP_C,Segment,Gyro_X,Gyro_Y,Gyro_Z,Accel_X,Accel_Y,Accel_Z\n" + rows);
  RunResult r = Run({"apply", "-c", cal, "-s", Path("upper.csv"), "-o", Path("out.csv"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(ReadTable(Path("out.csv")).rows.at(1).at(2), "1");
  // Every absent column at once, with the near names.
  Write("near.csv", "time,temp_c,segment,gyro x,gyro_y,gyro_z,accel_x,accel_y,acc_z\n" + rows);
  r = Run({"apply", "-c", cal, "-s", Path("near.csv"), "-o", Path("out2.csv")});
  EXPECT_EQ(r.status, 2);
  ExpectOneLine(r,
                "near.csv:1: no columns \"time_s\", \"gyro_x\" and \"accel_z\" in the header (it has: "
                "time,temp_c,segment,gyro x,gyro_y,gyro_z,accel_x,accel_y,acc_z); did you mean \"time\" for "
                "\"time_s\", \"gyro x\" for \"gyro_x\", \"acc_z\" for \"accel_z\"");
  EXPECT_FALSE(fs::exists(Path("out2.csv")));
  // A German-locale export: ';' between fields, decimal commas, CRLF.
  Write("de.csv",
        "time_s;temp_c;segment;gyro_x;gyro_y;gyro_z;accel_x;accel_y;accel_z\r\n0;25,5;1;23;-41;12;35;-18;"
        "2100\r\n");
  r = Run({"apply", "-c", cal, "-s", Path("de.csv"), "-o", Path("out2.csv")});
  EXPECT_EQ(r.status, 2);
  ExpectOneLine(r, "de.csv:1: the header is separated by ';', not ',': give --delimiter ';'");
  ExpectInTroubleshooting(r);
  EXPECT_FALSE(fs::exists(Path("out2.csv")));
}

// `text`, a plain samples CSV, as a spreadsheet in a German locale saves it: ';' between fields,
// decimal commas, CRLF line ends (comments kept as they are).
std::string GermanLocale(const std::string& text) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] != '#') {
      std::replace(line.begin(), line.end(), ',', ';');
      std::replace(line.begin(), line.end(), '.', ',');
    }
    out += line + "\r\n";
  }
  return out;
}

// The calibration's lines that hold numbers of the fit (not the input's path, hash or date).
std::vector<std::string> FittedLines(const std::string& path) {
  std::istringstream lines(ReadBytes(path));
  std::vector<std::string> kept;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("samples") == std::string::npos && line.find("sha256") == std::string::npos &&
        line.find("date") == std::string::npos && line.find("created") == std::string::npos &&
        line.find("options") == std::string::npos) {
      kept.push_back(line);
    }
  }
  return kept;
}

// A German-locale export fits with --delimiter ';' --decimal-comma to the numbers of the plain file
// (the labelled file is parsed in parallel blocks: the dialect travels with them); without the
// options each mistake is named with the option to give.
TEST_F(CliInputTest, GermanLocaleExportFitsWithItsDialectToTheSameNumbers) {
  const std::string raw = RawRun();
  ASSERT_EQ(Fit(raw).status, 0);
  const std::vector<std::string> plain = FittedLines(Path("cal.yaml"));
  fs::remove(Path("cal.yaml"));
  const std::string de = Write("de.csv", GermanLocale(ReadBytes(raw)));
  const RunResult fitted = Fit(de, {"--delimiter", ";", "--decimal-comma"});
  ASSERT_EQ(fitted.status, 0) << fitted.err;
  EXPECT_EQ(FittedLines(Path("cal.yaml")), plain);
  fs::remove(Path("cal.yaml"));
  // The same through segment, which reads the file twice without its segment column.
  EXPECT_EQ(Run({"segment", "-p", Fixture("plan_6pos.yaml"), "-s", de, "-o", Path("seg.csv"), "-q",
                 "--delimiter", ";", "--decimal-comma"})
                .status,
            0);
  for (const auto& [options, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{}, "the header is separated by ';', not ',': give --delimiter ';' (and --decimal-comma"},
           {{"--delimiter", ";"}, "is not a number (a decimal comma? give --decimal-comma)"},
           {{"--decimal-comma"}, "--decimal-comma needs --delimiter ';' or tab"},
           {{"--delimiter", "|"}, "delimiter \"|\" is not one of: ,, ;, tab"}}) {
    const RunResult r = Fit(de, options);
    EXPECT_EQ(r.status, 2) << message;
    ExpectOneLine(r, message);
    if (options.size() == 2 && options[1] == ";") ExpectInTroubleshooting(r);
    EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  }
  // A tab-separated file the same way.
  std::string tabs = ReadBytes(raw);
  std::replace(tabs.begin(), tabs.end(), ',', '\t');
  ASSERT_EQ(Fit(Write("tabs.tsv", tabs), {"--delimiter", "tab"}).status, 0);
  EXPECT_EQ(FittedLines(Path("cal.yaml")), plain);
}

// A logger that names its columns its own way: --column NAME=COLUMN (repeated, or pairs joined by
// ','), and the fit is the plain file's.
TEST_F(CliInputTest, ColumnMapReadsALoggersOwnNames) {
  const std::string raw = RawRun();
  ASSERT_EQ(Fit(raw).status, 0);
  const std::vector<std::string> plain = FittedLines(Path("cal.yaml"));
  fs::remove(Path("cal.yaml"));
  std::string text = ReadBytes(raw);
  const size_t header = text.find("time_s,temp_c,");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"time_s,", "Zeit,"}, {"temp_c,", "T (degC),"}, {"gyro_y,", "rate y,"}}) {
    const size_t at = text.find(from, header);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  const std::string logger = Write("logger.csv", text);
  RunResult r = Fit(logger, {"--column", "time_s=Zeit", "--column", "temp_c=T (degC),gyro_y=rate y"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(FittedLines(Path("cal.yaml")), plain);
  fs::remove(Path("cal.yaml"));
  // A name imufit does not read, a pair without '=', a column read twice.
  for (const auto& [map, message] : std::vector<std::pair<std::string, std::string>>{
           {"speed=Zeit", "column \"speed\" is not one imufit reads: time_s, temp_c, segment"},
           {"time_s", "column \"time_s\" is not NAME=COLUMN (e.g. time_s=Time)"},
           {"time_s=Zeit,temp_c=T (degC),gyro_y=rate y,gyro_x=rate y",
            "column \"rate y\" is read as two columns"}}) {
    r = Fit(logger, {"--column", map});
    EXPECT_EQ(r.status, 2) << map;
    ExpectOneLine(r, message);
    EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  }
  // Without the map, the file's names are said, with a near name where one is.
  r = Fit(logger);
  EXPECT_EQ(r.status, 2);
  ExpectOneLine(r, "no columns \"time_s\", \"gyro_y\" and \"temp_c\" in the header");
}

// Two units' logs in one file: a `# serial:` line among the samples naming another unit, or the
// column names again (two files joined with cat), is refused at its line; a unit folder with both
// samples.csv and samples.csv.gz is the unit's error, not a guess. The correct log still fits.
TEST_F(CliInputTest, ALogOfTwoUnitsIsRefusedWhereTheSecondBegins) {
  ASSERT_EQ(Run(SmallRunArgs(Path("a.csv"), {"--serial", "SN-A", "--seed", "3"})).status, 0);
  ASSERT_EQ(Run(SmallRunArgs(Path("b.csv"), {"--serial", "SN-B", "--seed", "4"})).status, 0);
  const std::string a = ReadBytes(Path("a.csv")), b = ReadBytes(Path("b.csv"));
  const long a_lines = std::count(a.begin(), a.end(), '\n');
  // b's samples shifted after a's in time, as a logger that keeps running writes them.
  const std::string b_later = MapColumn(b, "time_s", [](const std::string& t, int) {
    std::ostringstream text;
    text.precision(17);
    text << std::stod(t) + 100000.0;
    return text.str();
  });
  // The second log's header kept (comments, then the column names), as `cat a.csv b.csv` gives.
  std::ofstream(Path("cat.csv")) << a << b_later;
  RunResult r = Fit(Path("cat.csv"));
  EXPECT_EQ(r.status, 2) << r.err;
  // The error is at b's `# serial:` line, its second.
  const long b_serial_line = a_lines + 1 + std::count(b.begin(), b.begin() + b.find("# serial:"), '\n');
  ExpectOneLine(r,
                "cat.csv:" + std::to_string(b_serial_line) +
                    ":11: a second unit \"SN-B\" begins here, among the samples (the header names "
                    "\"SN-A\"): two logs in one file? Split it at this line and fit each unit's log alone");
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  // Without the second header's comments: the column names among the samples.
  std::string b_rows = b_later.substr(b_later.find("time_s"));
  std::ofstream(Path("joined.csv")) << a << b_rows;
  r = Fit(Path("joined.csv"));
  EXPECT_EQ(r.status, 2) << r.err;
  ExpectOneLine(r, "joined.csv:" + std::to_string(a_lines + 1) +
                       ":1: time_s: the column names again, among the samples: two logs in one file?");
  // apply and allan read the same way.
  r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", Path("cat.csv"), "-o", Path("out.csv"),
           "--allow-mismatch"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("a second unit \"SN-B\" begins here"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // The same serial repeated among the samples (a logger that repeats its header) is one unit.
  std::string repeated = a;
  const size_t middle = repeated.find('\n', repeated.size() / 2) + 1;
  repeated.insert(middle, "# serial: SN-A\n");
  std::ofstream(Path("repeated.csv")) << repeated;
  r = Fit(Path("repeated.csv"));
  EXPECT_EQ(r.status, 0) << r.err;

  // A batch unit folder with both files: that unit's error, naming both.
  const fs::path units = Path("units");
  fs::create_directories(units / "u1");
  fs::copy_file(Fixture("plan_6pos.yaml"), units / "u1" / "plan.yaml");
  fs::copy_file(Path("a.csv"), units / "u1" / "samples.csv");
  ASSERT_EQ(Run(SmallRunArgs((units / "u1" / "samples.csv.gz").string(), {"--serial", "SN-A", "--seed", "9"}))
                .status,
            0);
  r = Run({"batch", units.string(), "-o", Path("batch_out"), "-q"});
  EXPECT_NE(r.status, 0) << r.err;
  const std::string summary = ReadBytes(Path("batch_out") + "/lot_summary.csv");
  EXPECT_NE(summary.find("holds both samples.csv and samples.csv.gz: which is this unit's run?"),
            std::string::npos)
      << summary << r.err;
}

// Files as other tools write them: pandas' to_csv() puts an index column with an empty name first;
// it is another column, ignored, and the fit is the one of the file without it.
TEST_F(CliInputTest, PandasIndexColumnIsIgnored) {
  const std::string raw = RawRun();
  std::istringstream lines(ReadBytes(raw));
  std::string line, pandas;
  long row = -1;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    pandas += (row < 0 ? std::string(",") : std::to_string(row) + ",") + line + "\n";
    ++row;
  }
  std::ofstream(Path("pandas.csv")) << pandas;
  ASSERT_EQ(Fit(raw).status, 0);
  const std::string plain = ReadBytes(Path("cal.yaml"));
  const RunResult r = Fit(Path("pandas.csv"));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string indexed = ReadBytes(Path("cal.yaml"));
  // The same coefficients (the record names another file, with another hash).
  EXPECT_EQ(Coefficients(indexed), Coefficients(plain));
}

// A plan segment the log never visits is named by the fit (a warning; the calibration's record
// lists it), and the fit goes on with the others.
TEST_F(CliInputTest, APlanSegmentTheLogNeverVisitsIsNamed) {
  const std::string raw = RawRun();
  std::string plan = ReadBytes(Fixture("plan_6pos.yaml"));
  plan += "  - {id: 40, up: [0.6, 0, 0.8], north: [0.8, 0, -0.6]}\n";
  std::ofstream(Path("plan_extra.yaml")) << plan;
  const RunResult r = Run({"fit", "-p", Path("plan_extra.yaml"), "-s", raw, "-o", Path("cal.yaml"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "imufit: warning: " + raw + ": plan segment 40 of " + Path("plan_extra.yaml") +
                       " has no usable window in the log (never visited, or every visit too short): fitted "
                       "without it\n");
  EXPECT_NE(ReadBytes(Path("cal.yaml")).find("segments_without_windows: [40]"), std::string::npos);
}

// A units list as a spreadsheet saves it (a UTF-8 byte order mark, quoted fields, a comma inside
// a quoted path) is read as CSV; a batch whose output folder lies inside its units folder does not
// take that folder for a unit when it runs again.
TEST_F(CliInputTest, AUnitsListAsSpreadsheetsSaveItAndAnOutputFolderAmongTheUnits) {
  const fs::path lot = Path("lot");
  fs::create_directories(lot / "u1");
  fs::copy_file(Fixture("plan_6pos.yaml"), lot / "u1" / "plan.yaml");
  ASSERT_EQ(Run(SmallRunArgs((lot / "u1" / "run, first.csv").string(), {"--serial", "SN1"})).status, 0);
  std::ofstream(Path("units.csv")) << "\xEF\xBB\xBFserial,samples,plan\r\n"
                                      "\"SN1\",\"lot/u1/run, first.csv\",\"lot/u1/plan.yaml\"\r\n";
  RunResult r = Run({"batch", "--units-list", Path("units.csv"), "-o", Path("list_out"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  const std::string listed = ReadBytes(Path("list_out") + "/lot_summary.csv");
  EXPECT_NE(listed.find("\nSN1,"), std::string::npos) << listed;
  EXPECT_EQ(listed.find("serial,"), listed.rfind("serial,"))
      << "one header, no unit called serial: " << listed;
  EXPECT_EQ(std::count(listed.begin(), listed.end(), '\n'), 2) << listed;

  fs::rename(lot / "u1" / "run, first.csv", lot / "u1" / "samples.csv");
  for (int run = 0; run < 2; ++run) {
    r = Run({"batch", lot.string(), "-o", (lot / "out").string(), "-q"});
    EXPECT_EQ(r.status, 0) << "run " << run << ": " << r.err;
    const std::string summary = ReadBytes((lot / "out" / "lot_summary.csv").string());
    EXPECT_EQ(summary.find("\nout,"), std::string::npos) << "run " << run << ": " << summary;
    EXPECT_EQ(std::count(summary.begin(), summary.end(), '\n'), 2) << "run " << run << ": " << summary;
  }
}

// `text` with the header's column names renamed by `names` (old -> new, all at once).
std::string RenameColumns(const std::string& text, const std::map<std::string, std::string>& names) {
  const size_t header = text.find("time_s");
  const size_t end = text.find('\n', header);
  std::istringstream fields(text.substr(header, end - header));
  std::string field, renamed;
  while (std::getline(fields, field, ',')) {
    const auto found = names.find(field);
    renamed += (renamed.empty() ? "" : ",") + (found == names.end() ? field : found->second);
  }
  return text.substr(0, header) + renamed + text.substr(end);
}

std::string Negated(const std::string& field, int) { return Scaled(field, -1.0); }

// Channels that respond, but to another axis than their own, are not called dead: two exchanged
// gyro channels (with the column map that reads them back, which then fits as the log as planned),
// an inverted sign, the unit mounted rotated 90 deg about z (both sensors turned alike).
TEST_F(CliInputTest, ChannelsSwappedInvertedOrRotatedAreSaidSoNotDead) {
  const std::string raw = RawRun();
  const std::string text = ReadBytes(raw);
  ASSERT_EQ(Fit(raw).status, 0);
  const std::string planned = ReadBytes(Path("cal.yaml"));
  fs::remove(Path("cal.yaml"));

  std::ofstream(Path("swapped.csv")) << RenameColumns(text, {{"gyro_x", "gyro_y"}, {"gyro_y", "gyro_x"}});
  RunResult r = Fit(Path("swapped.csv"));
  EXPECT_EQ(r.status, 1) << r.err;
  ExpectOneLine(r,
                "swapped.csv: gyro x and y look exchanged; the logger's channel map? read them back with "
                "--column gyro_x=gyro_y --column gyro_y=gyro_x (the accelerometer follows the plan: not "
                "the mounting); nothing written");
  EXPECT_EQ(r.err.find("dead"), std::string::npos) << r.err;
  r = Fit(Path("swapped.csv"), {"--column", "gyro_x=gyro_y", "--column", "gyro_y=gyro_x"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string mapped = ReadBytes(Path("cal.yaml"));
  EXPECT_EQ(Coefficients(mapped), Coefficients(planned));

  std::ofstream(Path("inverted.csv")) << MapColumn(text, "gyro_y", Negated);
  r = Fit(Path("inverted.csv"));
  EXPECT_EQ(r.status, 1) << r.err;
  ExpectOneLine(
      r,
      "inverted.csv: gyro_y reads with its sign inverted against the plan (the logger's channel "
      "sign, or the plan's rates and turns about y of the wrong sign: the right-hand rule) (a "
      "left-handed frame?); fix the logger's channel map and signs, or the plan's (the accelerometer "
      "follows the plan: not the mounting); nothing written");

  // Mounted turned 90 deg about z: the unit's x is the plan's y, its y the plan's -x.
  std::string rotated = text;
  for (const char* sensor : {"gyro", "accel"}) {
    const std::string x = std::string(sensor) + "_x", y = std::string(sensor) + "_y";
    rotated = MapColumn(rotated, x, Negated);
    rotated = RenameColumns(rotated, {{x, y}, {y, x}});
  }
  std::ofstream(Path("rotated.csv")) << rotated;
  r = Fit(Path("rotated.csv"));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("both sensors read the plan's axes turned (gyro_x follows the plan's +y axis, gyro_y "
                       "follows the plan's -x axis; accel_x follows the plan's +y axis, accel_y follows the "
                       "plan's -x axis): the unit looks mounted rotated 90 deg about (+1z)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("dead"), std::string::npos) << r.err;
}

// A lever arm written in millimetres is said to be one, at its place in the plan.
TEST_F(CliInputTest, ALeverArmInMillimetresIsNamed) {
  std::string plan = ReadBytes(Fixture("plan_6pos.yaml"));
  for (size_t at = plan.find("[0.012, -0.008, 0.005]"); at != std::string::npos;
       at = plan.find("[0.012, -0.008, 0.005]")) {
    plan.replace(at, std::strlen("[0.012, -0.008, 0.005]"), "[12, -8, 5]");
  }
  std::ofstream(Path("plan_mm.yaml")) << plan;
  const RunResult r = Run({"fit", "-p", Path("plan_mm.yaml"), "-s", RawRun(), "-o", Path("cal.yaml"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  ExpectOneLine(r,
                "plan_mm.yaml:18:56: segments[6].lever_arm_m: the sensor lies 15.264337522473747 m from "
                "the table's axis: millimetres? lever_arm_m is in metres (0.012, -0.008, 0.005 if these "
                "are mm)");
}

// Each channel is judged against what the plan predicts for each of its windows: faces at 1 g and
// corners at 0.58 g lie on one line, so a plan of faces and corners is not taken for a dead axis.
TEST_F(CliInputTest, APlanOfFacesAndCornersIsNotADeadAxis) {
  std::string plan = "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81274\nsegments:\n";
  int id = 1;
  for (int axis = 0; axis < 3; ++axis) {
    for (const int sign : {1, -1}) {
      std::string up = "[0, 0, 0]";
      up[1 + 3 * axis] = sign > 0 ? '1' : '-';
      if (sign < 0) up = up.substr(0, 1 + 3 * axis) + "-1" + up.substr(2 + 3 * axis);
      plan += "  - {id: " + std::to_string(id++) + ", up: " + up + "}\n";
    }
  }
  for (const int x : {1, -1})
    for (const int y : {1, -1})
      for (const int z : {1, -1})
        plan += "  - {id: " + std::to_string(id++) + ", up: [" + std::to_string(x) + ", " +
                std::to_string(y) + ", " + std::to_string(z) + "]}\n";
  for (const char* up : {"[1, 0, 0]", "[0, 1, 0]", "[0, 0, 1]"}) {
    for (const int rate : {200, -200}) {
      plan +=
          "  - {id: " + std::to_string(id++) + ", up: " + up + ", rate_dps: " + std::to_string(rate) + "}\n";
    }
  }
  std::ofstream(Path("corners.yaml")) << plan;
  ASSERT_EQ(Run({"simulate",
                 "--plan",
                 Path("corners.yaml"),
                 "--calibration",
                 Fixture("mems_truth.yaml"),
                 "-o",
                 Path("corners.csv"),
                 "--temps=-20,10,40,70",
                 "--rate",
                 "20",
                 "--dwell",
                 "3",
                 "--transition",
                 "1",
                 "--gyro-noise-density",
                 "8.7e-5",
                 "--accel-noise-density",
                 "1.5e-3",
                 "--quantize",
                 "-q"})
                .status,
            0);
  const RunResult r = Run({"fit", "-p", Path("corners.yaml"), "-s", Path("corners.csv"), "-o",
                           Path("cal.yaml"), "-q", "--gyro-temp-order", "1", "--accel-temp-order", "1"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("does not respond"), std::string::npos) << r.err;
}

// A gyro logged in deg/s (a logger that converts with its datasheet's 16.4 LSB per deg/s) fitted
// with --fit gyro-bias,accel against a prior in counts: the held scale cannot be absorbed by the
// bias, and the run is refused naming deg/s instead of correcting a spin to a sixteenth of itself.
// The raw log with the same options fits as before.
TEST_F(CliInputTest, AGyroInDegPerSecondAgainstAPriorInCountsIsNamed) {
  const std::string raw = RawRun();
  const std::vector<std::string> subset = {"--fit", "gyro-bias,accel", "--prior", Fixture("mems_truth.yaml")};
  ASSERT_EQ(Fit(raw, subset).status, 0);
  const std::string correct = ReadBytes(Path("cal.yaml"));
  fs::remove(Path("cal.yaml"));
  constexpr double kDatasheetLsbPerDps = 16.4;
  std::string text = ReadBytes(raw);
  for (const char* column : {"gyro_x", "gyro_y", "gyro_z"})
    text = MapColumn(text, column,
                     [](const std::string& f, int) { return Scaled(f, 1.0 / kDatasheetLsbPerDps); });
  std::ofstream(Path("dps.csv")) << text;
  RunResult r = Fit(Path("dps.csv"), subset);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("the gyro looks logged in deg/s, while the held values are raw counts"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  // The whole model fits the scale: the deg/s log calibrates (gain 1), as before.
  EXPECT_EQ(Fit(Path("dps.csv")).status, 0);
  // The correct log, the same options: the same calibration.
  ASSERT_EQ(Fit(raw, subset).status, 0);
  EXPECT_EQ(Coefficients(ReadBytes(Path("cal.yaml"))), Coefficients(correct));
}

// A subset that holds part of a sensor without --prior holds it at scale 1 raw per rad/s: refused,
// naming --prior, before any work.
TEST_F(CliInputTest, ASubsetHoldingAScaleNobodyGaveIsRefused) {
  const std::string raw = RawRun();
  for (const char* subset : {"gyro-bias,accel", "gyro,accel-bias"}) {
    const RunResult r = Fit(raw, {"--fit", subset});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("--fit " + std::string(subset) + " holds"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("give them with --prior CAL.yaml"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  }
  EXPECT_EQ(Fit(raw, {"--fit", "gyro-bias,accel", "--prior", Fixture("mems_truth.yaml")}).status, 0);
}

// A sensor held whole without a prior (--fit accel) is recorded as not calibrated; apply, allan and
// export refuse it (or pass it through marked, --allow-uncalibrated); a file of an older imufit
// without the key is read the same from its held groups.
TEST_F(CliInputTest, AnUncalibratedSensorIsRecordedAndNeverUsedAsFitted) {
  const std::string raw = RawRun();
  RunResult r = Fit(raw, {"--fit", "accel"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("holds the gyro whole at nominal values (no --prior)"), std::string::npos) << r.err;
  const YAML::Node cal = YAML::LoadFile(Path("cal.yaml"));
  EXPECT_EQ(cal["fit"]["uncalibrated_sensors"].as<std::vector<std::string>>(),
            std::vector<std::string>{"gyro"});
  std::string old = ReadBytes(Path("cal.yaml"));
  old.erase(old.find("  uncalibrated_sensors:"),
            old.find('\n', old.find("  uncalibrated_sensors:")) + 1 - old.find("  uncalibrated_sensors:"));
  std::ofstream(Path("old.yaml")) << old;
  for (const std::string& calibration : {Path("cal.yaml"), Path("old.yaml")}) {
    r = Run({"apply", "-c", calibration, "-s", raw, "-o", Path("corrected.csv"), "-q"});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find(": the gyro is not calibrated (held at scale 1 raw per rad/s and 0 by a fit of the "
                         "accelerometer alone, without --prior): correcting would write its raw output as if "
                         "it were in SI units"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(Path("corrected.csv")));
    r = Run({"export", "-c", calibration, "--format", "json", "-o", Path("cal.json"), "-q"});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("an export would hand its nominal values on as a calibration"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(Path("cal.json")));
  }
  // A certificate marks it (a warning on the page), never certifies it as fitted.
  r = Run({"report", "-c", Path("cal.yaml"), "-p", Fixture("plan_6pos.yaml"), "-s", raw, "-o",
           Path("cert.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(
      ReadBytes(Path("cert.html")).find("Warning: " + Path("cal.yaml") + ": the gyro is not calibrated"),
      std::string::npos);
  r = Run({"apply", "-c", Path("cal.yaml"), "-s", raw, "-o", Path("corrected.csv"), "-q",
           "--allow-uncalibrated"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(ReadBytes(Path("corrected.csv")).find("# uncalibrated: gyro (as logged, not corrected)"),
            std::string::npos);
  // A whole calibration is used as before.
  ASSERT_EQ(Fit(raw).status, 0);
  EXPECT_EQ(Run({"apply", "-c", Path("cal.yaml"), "-s", raw, "-o", Path("whole.csv"), "-q"}).status, 0);
  EXPECT_EQ(ReadBytes(Path("whole.csv")).find("uncalibrated"), std::string::npos);
}

// The plan's soak set-points (soak_temps_c): a log in Fahrenheit is refused with the hint; without
// set-points a log above 125 degC is warned about; the log in degC fits as without set-points.
TEST_F(CliInputTest, TemperaturesInFahrenheitDisagreeWithTheSoakSetPoints) {
  const std::string raw = RawRun();
  ASSERT_EQ(Fit(raw).status, 0);
  const std::string without = ReadBytes(Path("cal.yaml"));
  std::string plan = ReadBytes(Fixture("plan_6pos.yaml"));
  plan.insert(plan.find("segments:"), "soak_temps_c: [-20, 5, 30, 60]\n");
  std::ofstream(Path("plan_soaks.yaml")) << plan;
  const auto fit = [this](const std::string& plan_path, const std::string& samples) {
    return Run({"fit", "-p", plan_path, "-s", samples, "-o", Path("cal.yaml"), "-q"});
  };
  RunResult r = fit(Path("plan_soaks.yaml"), raw);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Coefficients(ReadBytes(Path("cal.yaml"))), Coefficients(without));
  fs::remove(Path("cal.yaml"));
  std::ofstream(Path("fahrenheit.csv")) << MapColumn(ReadBytes(raw), "temp_c", [](const std::string& f, int) {
    std::ostringstream out;
    out.precision(17);
    out << std::stod(f) * 9.0 / 5.0 + 32.0;
    return out.str();
  });
  r = fit(Path("plan_soaks.yaml"), Path("fahrenheit.csv"));
  EXPECT_EQ(r.status, 1) << r.err;
  ExpectOneLine(r,
                "degC (soak_temps_c; the unit's thermometer within 15 degC of them at the coldest and "
                "warmest): Fahrenheit? (");
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  r = fit(Fixture("plan_6pos.yaml"), Path("fahrenheit.csv"));
  EXPECT_NE(r.err.find("above any IMU's rating (125 degC): Fahrenheit?"), std::string::npos) << r.err;
}

// An unlabelled log piped through /dev/stdin is read once (its samples kept for the two passes):
// the same calibration as from the file.
TEST_F(CliInputTest, AnUnlabelledLogThroughAPipeIsReadOnce) {
  // Dwells long enough at 50 Hz for the segmentation to find them.
  ASSERT_EQ(Run({"simulate", "--plan=" + Fixture("plan_6pos.yaml"),
                 "--calibration=" + Fixture("mems_truth.yaml"), "--output=" + Path("unlabelled.csv"),
                 "--rate=50", "--dwell=5", "--transition=1", "--temps=-20,5,30,60",
                 "--gyro-noise-density=2e-4", "--accel-noise-density=2e-3", "--no-segment-column", "-q"})
                .status,
            0);
  ASSERT_EQ(Fit(Path("unlabelled.csv")).status, 0);
  const std::string from_file = ReadBytes(Path("cal.yaml"));
  const RunResult r = RunProgram("/bin/sh", {"-c", "cat '" + Path("unlabelled.csv") + "' | '" + IMUFIT_EXE +
                                                       "' fit -p '" + Fixture("plan_6pos.yaml") +
                                                       "' -s /dev/stdin -o '" + Path("piped.yaml") + "' -q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Coefficients(ReadBytes(Path("piped.yaml"))), Coefficients(from_file));
  const YAML::Node piped = YAML::LoadFile(Path("piped.yaml"));
  EXPECT_EQ(piped["fit"]["samples_sha256"].as<std::string>(),
            YAML::LoadFile(Path("cal.yaml"))["fit"]["samples_sha256"].as<std::string>());
}

// imufit segment on a pipe reads it once too (its samples kept for the two passes): the same labelled
// file as from the file, with and without a temp_c column.
TEST_F(CliInputTest, SegmentOfAPipeIsReadOnce) {
  ASSERT_EQ(
      Run({"simulate", "--plan=" + Fixture("plan_6pos.yaml"), "--calibration=" + Fixture("mems_truth.yaml"),
           "--output=" + Path("unlabelled.csv"), "--rate=50", "--dwell=5", "--transition=1", "--temps=-20,30",
           "--gyro-noise-density=2e-4", "--accel-noise-density=2e-3", "--no-segment-column", "-q"})
          .status,
      0);
  // The same run without its temp_c column: segment needs no temperature.
  std::istringstream lines(ReadBytes(Path("unlabelled.csv")));
  std::ofstream no_temp(Path("no_temp.csv"), std::ios::binary);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') {
      no_temp << line << "\n";
      continue;
    }
    const size_t first = line.find(','), second = line.find(',', first + 1);
    no_temp << line.substr(0, first) << line.substr(second) << "\n";
  }
  no_temp.close();
  for (const std::string name : {"unlabelled.csv", "no_temp.csv"}) {
    SCOPED_TRACE(name);
    ASSERT_EQ(
        Run({"segment", "-p", Fixture("plan_6pos.yaml"), "-s", Path(name), "-o", Path("from_file.csv"), "-q"})
            .status,
        0);
    const RunResult r = RunProgram(
        "/bin/sh", {"-c", "cat '" + Path(name) + "' | '" + IMUFIT_EXE + "' segment -p '" +
                              Fixture("plan_6pos.yaml") + "' -s /dev/stdin -o '" + Path("piped.csv") + "'"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("6 segments found"), std::string::npos) << r.out;
    EXPECT_EQ(ReadBytes(Path("piped.csv")), ReadBytes(Path("from_file.csv")));
  }
  EXPECT_EQ(ReadBytes(Path("piped.csv")).find("temp_c"), std::string::npos);
}

// fit --check-samples with another unit's run is refused as apply refuses it (its header's serial),
// unless --allow-mismatch.
TEST_F(CliInputTest, CheckSamplesOfAnotherUnitAreRefusedAsApplyRefusesThem) {
  const std::string raw = RawRun();
  std::ofstream(Path("mine.csv")) << "# serial: SN0001\n" << ReadBytes(raw);
  std::ofstream(Path("other.csv")) << "# serial: SN0002\n" << ReadBytes(raw);
  RunResult r = Fit(Path("mine.csv"), {"--check-samples", Path("other.csv")});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("other.csv:1:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("SN0002"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
  ASSERT_EQ(Fit(Path("mine.csv")).status, 0);
  const RunResult apply =
      Run({"apply", "-c", Path("cal.yaml"), "-s", Path("other.csv"), "-o", Path("c.csv")});
  EXPECT_EQ(apply.status, r.status) << apply.err;
  r = Fit(Path("mine.csv"), {"--check-samples", Path("other.csv"), "--allow-mismatch"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("SN0002"), std::string::npos) << r.err;
  EXPECT_EQ(Fit(Path("mine.csv"), {"--check-samples", Path("mine.csv")}).status, 0);
}

// A two-axis plan whose spin axes x and y were exchanged in the plan (the log as the table turned):
// said as channels that follow another axis, never a dead gyro.
TEST_F(CliInputTest, ATwoAxisPlanWithItsSpinAxesExchangedIsNotADeadGyro) {
  std::string plan = "format: imufit-plan\nversion: 1\ngravity_mps2: 9.81274\nsegments:\n";
  const char* faces[] = {"[0, 0, 1]", "[0, 0, -1]", "[1, 0, 0]", "[-1, 0, 0]", "[0, 1, 0]", "[0, -1, 0]"};
  int id = 1;
  for (const char* up : faces) plan += "  - {id: " + std::to_string(id++) + ", up: " + up + "}\n";
  std::string spins;
  for (const char* axis : {"[1, 0, 0]", "[0, 1, 0]", "[0, 0, 1]"}) {
    for (const int rate : {90, -90})
      spins += "  - {id: " + std::to_string(id++) + ", up: [0, 0, 1], rate_dps: " + std::to_string(rate) +
               ", axis: " + axis + "}\n";
  }
  std::ofstream(Path("two_axis.yaml")) << plan + spins;
  std::string exchanged = spins;
  for (size_t at = exchanged.find("[1, 0, 0]"); at != std::string::npos;
       at = exchanged.find("[1, 0, 0]", at + 1))
    exchanged.replace(at, 9, "[0, 9, 0]");
  for (size_t at = exchanged.find("[0, 1, 0]"); at != std::string::npos;
       at = exchanged.find("[0, 1, 0]", at + 1))
    exchanged.replace(at, 9, "[1, 0, 0]");
  for (size_t at = exchanged.find("[0, 9, 0]"); at != std::string::npos;
       at = exchanged.find("[0, 9, 0]", at + 1))
    exchanged.replace(at, 9, "[0, 1, 0]");
  std::ofstream(Path("two_axis_exchanged.yaml")) << plan + exchanged;
  const std::string raw = Path("two_axis.csv");
  ASSERT_EQ(Run({"simulate", "--plan=" + Path("two_axis.yaml"), "--calibration=" + Fixture("mems_truth.yaml"),
                 "--output=" + raw, "--rate=20", "--dwell=8", "--temps=-20,5,30,60",
                 "--gyro-noise-density=2e-4", "--accel-noise-density=2e-3", "-q"})
                .status,
            0);
  RunResult r = Run({"fit", "-p", Path("two_axis.yaml"), "-s", raw, "-o", Path("cal.yaml"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  fs::remove(Path("cal.yaml"));
  r = Run({"fit", "-p", Path("two_axis_exchanged.yaml"), "-s", raw, "-o", Path("cal.yaml"), "-q"});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("gyro x and y look exchanged"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("dead"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("cal.yaml")));
}

}  // namespace
}  // namespace imufit::testing
