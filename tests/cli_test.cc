// End-to-end tests of the `imufit` program as a whole (docs/spec.md, "The command line"): help,
// bad invocations, bad and hostile input (status 2, one located line, nothing written), and how
// outputs are written (whole or not at all, never through a link, never a non-finite number).
// The commands' own tests are in cli_*_test.cc (cli_util.h lists them).
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------ help

// The subcommands listed by `imufit --help` (CLI11 lists them under "Subcommands:").
std::vector<std::string> SubcommandsIn(const std::string& help) {
  std::vector<std::string> names;
  std::stringstream lines(help);
  std::string line;
  bool in_list = false;
  while (std::getline(lines, line)) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
    } else if (in_list && line.size() > 2 && line[0] == ' ') {
      std::stringstream words(line);
      std::string name;
      words >> name;
      names.push_back(name);
    } else if (in_list) {
      in_list = !line.empty() && line[0] == ' ';
    }
  }
  return names;
}

TEST_F(CliTest, HelpOfTheProgramAndOfEverySubcommandExitsZero) {
  const RunResult help = Run({"--help"});
  EXPECT_EQ(help.status, 0) << help.err;
  const std::vector<std::string> commands = SubcommandsIn(help.out);
  EXPECT_NE(std::find(commands.begin(), commands.end(), "apply"), commands.end()) << help.out;
  EXPECT_NE(std::find(commands.begin(), commands.end(), "simulate"), commands.end()) << help.out;
  for (const std::string& command : commands) {
    const RunResult r = Run({command, "--help"});
    EXPECT_EQ(r.status, 0) << command << ": " << r.err;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << command << ": " << r.out;
  }
  const RunResult version = Run({"--version"});
  EXPECT_EQ(version.status, 0);
  EXPECT_NE(version.out.find("imufit"), std::string::npos);
}

// The rows of the table that follows `heading` in `page`: each row's first cell, unquoted.
std::vector<std::string> FirstCellsOfTable(const std::string& page, const std::string& heading) {
  std::vector<std::string> cells;
  const size_t start = page.find(heading);
  if (start == std::string::npos) return cells;
  std::stringstream lines(page.substr(start));
  std::string line;
  bool in_table = false;
  while (std::getline(lines, line)) {
    if (line.rfind("|", 0) != 0) {
      if (in_table) break;
      continue;
    }
    in_table = true;
    std::string cell = line.substr(1, line.find('|', 1) - 1);
    cell.erase(std::remove(cell.begin(), cell.end(), '`'), cell.end());
    cell.erase(0, cell.find_first_not_of(' '));
    cell.erase(cell.find_last_not_of(' ') + 1);
    if (cell.empty() || cell.find("---") != std::string::npos) continue;
    cells.push_back(cell);
  }
  return cells.size() > 0 ? std::vector<std::string>(cells.begin() + 1, cells.end()) : cells;  // no header
}

TEST_F(CliTest, SpecListsTheCommandsAndExitStatusesOfTheProgram) {
  // The program's help is derived from its command table and its exit-status table (app/main.cc,
  // app/exit_status.h); docs/spec.md section 4 must list the same.
  const std::string spec = ReadFile(Fixture("../docs/spec.md"));
  const RunResult help = Run({"--help"});
  ASSERT_EQ(help.status, 0) << help.err;
  std::set<std::string> documented;
  for (const std::string& cell : FirstCellsOfTable(spec, "## 4. The command line")) {
    std::stringstream words(cell);
    std::string program, command;
    words >> program >> command;
    EXPECT_EQ(program, "imufit") << cell;
    documented.insert(command);
  }
  const std::vector<std::string> listed = SubcommandsIn(help.out);
  EXPECT_EQ(documented, std::set<std::string>(listed.begin(), listed.end()));

  std::set<std::string> documented_statuses;
  for (const std::string& cell : FirstCellsOfTable(spec, "### Exit statuses"))
    documented_statuses.insert(cell);
  // "Exit status: 0 done, 1 the job could not be done, ...": the number starting each item.
  std::string text = help.out.substr(help.out.find("Exit status: ") + 13);
  text = text.substr(0, text.find('.'));
  std::set<std::string> helped_statuses;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    std::stringstream words(item);
    std::string status;
    words >> status;
    helped_statuses.insert(status);
  }
  EXPECT_EQ(documented_statuses, helped_statuses) << help.out;
  EXPECT_EQ(documented_statuses, (std::set<std::string>{"0", "1", "2", "3"}));
}

TEST_F(CliTest, ParseErrorsAreOneImufitLineNamingTheCommand) {
  // CLI11 words them; the program puts them on one line, as every other error (issue 31 item 7).
  const RunResult loss = Run({"export", "-c", Fixture("mems_truth.yaml"), "--format", "json", "-o",
                              Path("out.json"), "--max-loss", "1"});
  EXPECT_EQ(loss.status, 2);
  EXPECT_EQ(loss.err, "imufit: export: --max-loss: At least 2 required but received 1\n");
  EXPECT_EQ(loss.out, "");
  const RunResult missing = Run({"plan", "check"});
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.err, "imufit: plan check: plan is required\n");
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"apply", "--no-such-option"},
           {"allan", "-s", "x.csv", "-o", Path("a.csv"), "--confidence", "x"},
           {"no-such-command"},
           {}}) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("imufit: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    if (!args.empty() && args[0] != "no-such-command") {
      EXPECT_EQ(r.err.rfind("imufit: " + args[0] + ": ", 0), 0u) << r.err;
    }
  }
  EXPECT_EQ(Listing(), std::set<std::string>{});
}

TEST_F(CliTest, ExportTakesFormatNamesInAnyCaseAndRefusesOptionsTheFormatDoesNotUse) {
  // The export option table says which formats an option serves (issue 30 item 7).
  const std::string calibration = Fixture("mems_truth.yaml");
  RunResult r = Run({"export", "-c", calibration, "-f", "JSON", "-o", Path("unit.json"), "-q"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(Path("unit.json")));
  r = Run({"export", "-c", calibration, "-f", "json", "-o", Path("x.json"), "--device-id", "7"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "imufit: --device-id: only px4, ardupilot use it, not json\n");
  r = Run({"export", "-c", calibration, "-f", "Px4", "-o", Path("x.params"), "--device-id", "7", "--temp-c",
           "20"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "imufit: --temp-c: only kalibr, imucal use it, not px4\n");
  r = Run({"export", "-c", calibration, "-f", "c", "-o", Path("x.h"), "--rostopic", "/imu1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--rostopic: only kalibr use it"), std::string::npos) << r.err;
  // The help lists the formats from the format table, and each option the formats it serves.
  const RunResult help = Run({"export", "--help"});
  EXPECT_NE(help.out.find("c, bin, px4, ardupilot, kalibr, imucal, json"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("px4, ardupilot: the device ID of both sensors"), std::string::npos) << help.out;
  EXPECT_EQ(Listing(), std::set<std::string>{"unit.json"});
}

TEST_F(CliTest, BadInvocationsExitTwo) {
  EXPECT_EQ(Run({}).status, 2);
  EXPECT_EQ(Run({"no-such-command"}).status, 2);
  EXPECT_EQ(Run({"apply", "--samples", "x.csv"}).status, 2);  // --calibration and -o missing
  EXPECT_EQ(Run({"apply", "--no-such-option"}).status, 2);
  const RunResult r = Run({"simulate", "--plan", Fixture("plan_6pos.yaml"), "--calibration",
                           Fixture("mems_truth.yaml"), "-o", Path("s.csv"), "--rate", "-5"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("sample rate"), std::string::npos) << r.err;
  EXPECT_EQ(Listing(), std::set<std::string>{});
}

TEST_F(CliTest, GzipInputsAndOutputsWork) {
  const std::vector<std::string> simulate = {"simulate",
                                             "--plan",
                                             Fixture("plan_6pos.yaml"),
                                             "--calibration",
                                             Fixture("mems_truth.yaml"),
                                             "--rate",
                                             "20",
                                             "--dwell",
                                             "2",
                                             "--gyro-noise-density",
                                             "1e-4",
                                             "--seed",
                                             "5",
                                             "-q",
                                             "-o"};
  const auto with = [](std::vector<std::string> args, const std::string& last) {
    args.push_back(last);
    return args;
  };
  ASSERT_EQ(Run(with(simulate, Path("raw.csv"))).status, 0);
  ASSERT_EQ(Run(with(simulate, Path("raw.csv.gz"))).status, 0);
  const std::string gz = ReadBytes(Path("raw.csv.gz"));
  ASSERT_GT(gz.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(gz[0]), 0x1f);  // gzip magic
  EXPECT_EQ(static_cast<unsigned char>(gz[1]), 0x8b);
  EXPECT_LT(gz.size(), ReadBytes(Path("raw.csv")).size() / 2);
  EXPECT_EQ(ReadFile(Path("raw.csv.gz")), ReadBytes(Path("raw.csv")));

  const auto apply = [&](const std::string& in, const std::string& out) {
    const RunResult r =
        Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", Path(in), "-o", Path(out), "-q"});
    EXPECT_EQ(r.status, 0) << r.err;
  };
  apply("raw.csv", "plain_plain.csv");
  apply("raw.csv.gz", "gz_gz.csv.gz");
  apply("raw.csv.gz", "gz_plain.csv");
  const std::string expected = ReadBytes(Path("plain_plain.csv"));
  EXPECT_GT(expected.size(), 1000u);
  EXPECT_EQ(ReadFile(Path("gz_gz.csv.gz")), expected);
  EXPECT_EQ(ReadBytes(Path("gz_plain.csv")), expected);
  EXPECT_EQ(static_cast<unsigned char>(ReadBytes(Path("gz_gz.csv.gz"))[0]), 0x1f);
}

// ------------------------------------------------------------------------------------------ bad input

struct BadInput {
  const char* what;     // test case name
  const char* file;     // which input is bad: plan, samples or calibration
  const char* from;     // text in the good file ...
  const char* to;       // ... replaced by this
  long line;            // the line the message must name (0: only the file)
  const char* message;  // a piece of the expected message
};

const char kGoodPlan[] =
    "# a plan\n"
    "format: imufit-plan\n"
    "version: 1\n"
    "gravity_mps2: 9.81\n"
    "latitude_deg: 52.27\n"
    "segments:\n"
    "  - id: 1\n"
    "    up: [0, 0, 1]\n"
    "    north: [1, 0, 0]\n"
    "  - id: 2\n"
    "    up: [1, 0, 0]\n"
    "    rate_dps: 100\n"
    "    lever_arm_m: [0.01, 0, 0]\n";

const char kGoodSamples[] =
    "# raw samples\n"
    "time_s,temp_c,segment,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n"
    "0,25,1,23,-41,12,35,-18,2100\n"
    "0.01,25,1,24,-42,13,36,-19,2101\n"
    "0.02,25,-1,25,-43,14,37,-20,2102\n"
    "0.03,25,2,1600,-44,15,38,-21,2103\n";

const BadInput kBadInputs[] = {
    // plan
    {"plan_malformed_number", "plan", "gravity_mps2: 9.81", "gravity_mps2: 9.8.1", 4,
     "\"9.8.1\" is not a number"},
    {"plan_unknown_key", "plan", "gravity_mps2: 9.81", "gravity: 9.81", 4, "unknown key \"gravity\""},
    {"plan_unknown_segment_key", "plan", "    rate_dps: 100\n", "    rate_dps: 100\n    speed: 3\n", 13,
     "unknown key \"speed\""},
    {"plan_north_not_horizontal", "plan", "north: [1, 0, 0]", "north: [1, 0, 0.1]", 9, "not horizontal"},
    {"plan_repeated_id", "plan", "id: 2", "id: 1", 10, "repeats"},
    {"plan_wrong_format", "plan", "format: imufit-plan", "format: imufit-calibration", 2, "imufit-plan"},
    {"plan_wrong_version", "plan", "version: 1", "version: 2", 3, "not supported"},
    {"plan_zero_vector", "plan", "up: [1, 0, 0]", "up: [0, 0, 0]", 11, "zero"},
    {"plan_two_numbers", "plan", "up: [1, 0, 0]", "up: [1, 0]", 11, "3 numbers"},
    {"plan_rate_not_a_number", "plan", "rate_dps: 100", "rate_dps: fast", 12, "\"fast\" is not a number"},
    {"plan_latitude_out_of_range", "plan", "latitude_deg: 52.27", "latitude_deg: 95", 5, "latitude"},
    // yaml-cpp reports where it noticed the unclosed list: the next line.
    {"plan_yaml_syntax", "plan", "up: [0, 0, 1]", "up: [0, 0, 1", 9, "YAML"},
    {"plan_missing_gravity", "plan", "gravity_mps2: 9.81\n", "", 2, "gravity_mps2: missing"},
    {"plan_negative_id", "plan", "id: 2", "id: -2", 10, "id"},
    // samples
    {"samples_malformed_number", "samples", "24,-42", "24,-4.2.2", 4, "gyro_y: \"-4.2.2\" is not a number"},
    {"samples_missing_column", "samples", "gyro_z,accel_x", "accel_x", 2, "no column \"gyro_z\""},
    {"samples_time_not_increasing", "samples", "0.02,25,-1", "0.01,25,-1", 5, "does not increase"},
    {"samples_short_row", "samples", "37,-20,2102", "37,-20", 5, "fields"},
    {"samples_not_finite", "samples", "0.03,25,2,1600", "0.03,25,2,inf", 6, "not a finite number"},
    {"samples_bad_segment", "samples", "0.02,25,-1", "0.02,25,-3", 5, "not a segment id"},
    {"samples_segment_not_integer", "samples", "0.02,25,-1", "0.02,25,x", 5, "not an integer"},
    {"samples_empty_value", "samples", "0.01,25,1,24", "0.01,,1,24", 4, "temp_c: empty value"},
    {"samples_duplicate_column", "samples", "accel_x,accel_y", "accel_x,accel_x", 2, "appears twice"},
    // calibration
    {"calibration_wrong_format", "calibration", "format: imufit-calibration", "format: imufit-plan", 8,
     "imufit-calibration"},
    {"calibration_higher_version", "calibration", "version: 1", "version: 2", 9, "not supported"},
    {"calibration_malformed_number", "calibration", "x: [23.4, 0.118,", "x: [23.4, 0.1.18,", 18,
     "\"0.1.18\" is not a number"},
    {"calibration_three_terms", "calibration", "y: [931.52, -0.0895, -0.00017, 2.6e-06]",
     "y: [931.52, -0.0895, -0.00017]", 23, "4 numbers"},
    {"calibration_wrong_unit", "calibration", "unit: rad/s", "unit: deg/s", 16, "deg/s"},
    {"calibration_zero_scale", "calibration", "z: [209.97,", "z: [0,", 51,
     "scale.z: the scale factor changes sign"},
    {"calibration_missing_group", "calibration", "  misalignment:\n    xy: [-0.00214",
     "  misalign:\n    xy: [-0.00214", 43,
     "accel.misalignment: missing"},  // the line where the `accel` mapping starts
    {"calibration_reversed_range", "calibration", "fit_temp_range_c: [-40, 85]",
     "fit_temp_range_c: [85, -40]", 14, "range"},
};

void PrintTo(const BadInput& input, std::ostream* os) { *os << input.what; }

class BadInputTest : public CliTest, public ::testing::WithParamInterface<BadInput> {};

TEST_P(BadInputTest, ExitsTwoWithFileAndLineAndWritesNothing) {
  const BadInput& c = GetParam();
  const std::string kind = c.file;
  std::string text = kind == "plan"      ? std::string(kGoodPlan)
                     : kind == "samples" ? std::string(kGoodSamples)
                                         : ReadBytes(Fixture("mems_truth.yaml"));
  const size_t at = text.find(c.from);
  ASSERT_NE(at, std::string::npos) << c.from;
  text.replace(at, std::strlen(c.from), c.to);
  const std::string bad = Write(kind == "samples" ? "bad.csv" : "bad.yaml", text);
  const std::string plan = kind == "plan" ? bad : Write("plan.yaml", kGoodPlan);
  const std::string samples = kind == "samples" ? bad : Write("samples.csv", kGoodSamples);
  const std::string calibration = kind == "calibration" ? bad : Fixture("mems_truth.yaml");

  // A plan is read by simulate; samples and calibrations by apply (calibrations by both).
  std::vector<std::vector<std::string>> commands;
  if (kind != "samples") {
    commands.push_back(
        {"simulate", "--plan", plan, "--calibration", calibration, "-o", Path("out.csv"), "--dwell", "0.1"});
  }
  if (kind != "plan") commands.push_back({"apply", "-c", calibration, "-s", samples, "-o", Path("out.csv")});
  const std::set<std::string> before = Listing();
  for (const auto& command : commands) {
    SCOPED_TRACE(command[0]);
    const RunResult r = Run(command);
    EXPECT_EQ(r.status, 2) << r.err;
    const std::string location = bad + ":" + std::to_string(c.line) + ":";
    EXPECT_EQ(r.err.rfind("imufit: " + location, 0), 0u) << "expected " << location << " in: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_EQ(Listing(), before) << "nothing written";
  }
}

INSTANTIATE_TEST_SUITE_P(EveryBadInput, BadInputTest, ::testing::ValuesIn(kBadInputs),
                         [](const ::testing::TestParamInfo<BadInput>& info) { return info.param.what; });

TEST_F(CliTest, MissingOrEmptyInputFilesExitTwoNamingTheFile) {
  const std::string plan = Write("plan.yaml", kGoodPlan);
  const std::string samples = Write("samples.csv", kGoodSamples);
  const std::string missing = Path("no-such-file.yaml");
  const std::string missing_csv = Path("no-such-file.csv");
  const std::string empty = Write("empty.csv", "# nothing but a comment\n");
  const std::string cal = Fixture("mems_truth.yaml");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"simulate", "-p", missing, "-c", cal, "-o", Path("o.csv")}, missing},
      {{"simulate", "-p", plan, "-c", missing, "-o", Path("o.csv")}, missing},
      {{"apply", "-c", missing, "-s", samples, "-o", Path("o.csv")}, missing},
      {{"apply", "-c", cal, "-s", missing_csv, "-o", Path("o.csv")}, missing_csv},
      {{"apply", "-c", cal, "-s", missing_csv + ".gz", "-o", Path("o.csv")}, missing_csv + ".gz"},
      {{"apply", "-c", cal, "-s", empty, "-o", Path("o.csv")}, empty},
      {{"apply", "-c", cal, "-s", samples, "-o", Path("no-such-folder/o.csv")}, Path("no-such-folder/o.csv")},
  };
  const std::set<std::string> before = Listing();
  for (const auto& [args, file] : cases) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("imufit: " + file + ":", 0), 0u) << r.err;
    EXPECT_EQ(Listing(), before);
  }
}

// ------------------------------------------------------------------------------------------ outputs

// A failing run never damages an existing output and leaves no temporary file: the error comes
// after more than two megabytes of output were written (so part of it reached the temporary file).
TEST_F(CliTest, AFailingRunLeavesAnExistingOutputUntouched) {
  const auto [samples, truth] = SimulateNoiseless(Fixture("plan_24pos.yaml"), Fixture("mems_truth.yaml"),
                                                  "run", {"--rate", "100", "--dwell", "2", "--temps=-40,85"});
  std::string text = ReadBytes(samples);
  ASSERT_GT(text.size(), 2u << 20);     // the output is about as long: beyond the 1 MiB write buffer
  text += "1e9,25,1,1,2,3,4,5,oops\n";  // the last row is bad
  const std::string bad_samples = Write("bad.csv", text);
  fs::remove(samples);
  fs::remove(truth);
  const std::string sentinel = "precious: an earlier result\n";
  for (const char* name : {"out.csv", "out.csv.gz"}) {
    SCOPED_TRACE(name);
    const std::string out = Write(name, sentinel);
    const std::set<std::string> before = Listing();
    const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", bad_samples, "-o", out});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("bad.csv:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"oops\""), std::string::npos) << r.err;
    EXPECT_EQ(ReadBytes(out), sentinel);
    EXPECT_EQ(Listing(), before) << "a temporary file was left behind";
  }
  // simulate onto existing outputs, failing on its calibration: both outputs stay.
  const std::string out = Write("sim.csv", sentinel);
  const std::string truth_out = Write("sim_truth.csv", sentinel);
  const std::string bad_calibration = Write("bad.yaml", "format: imufit-calibration\nversion: 1\ngyro: 3\n");
  const std::set<std::string> before = Listing();
  const RunResult r = Run(
      {"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", bad_calibration, "-o", out, "--truth", truth_out});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(ReadBytes(out), sentinel);
  EXPECT_EQ(ReadBytes(truth_out), sentinel);
  EXPECT_EQ(Listing(), before);
}

TEST_F(CliTest, AnOutputThatIsAlsoAnInputIsRefused) {
  const std::string plan = Write("plan.yaml", kGoodPlan);
  const std::string samples = Write("samples.csv", kGoodSamples);
  const std::string calibration = Write("cal.yaml", ReadBytes(Fixture("mems_truth.yaml")));
  fs::create_symlink(samples, Path("link.csv"));
  const std::string plan_text = ReadBytes(plan);
  const std::string samples_text = ReadBytes(samples);
  const std::string calibration_text = ReadBytes(calibration);
  const std::vector<std::vector<std::string>> cases = {
      {"apply", "-c", calibration, "-s", samples, "-o", samples},
      {"apply", "-c", calibration, "-s", samples, "-o", (dir_ / "." / "samples.csv").string()},
      {"apply", "-c", calibration, "-s", samples, "-o", Path("link.csv")},
      {"apply", "-c", calibration, "-s", samples, "-o", calibration},
      {"simulate", "-p", plan, "-c", calibration, "-o", plan},
      {"simulate", "-p", plan, "-c", calibration, "-o", calibration},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth", plan},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth", Path("new.csv")},
      {"simulate", "-p", plan, "-c", calibration, "-o", Path("new.csv"), "--truth",
       (dir_ / "." / "new.csv").string()},
  };
  const std::set<std::string> before = Listing();
  for (const auto& args : cases) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 2) << args.back() << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(ReadBytes(plan), plan_text);
    EXPECT_EQ(ReadBytes(samples), samples_text);
    EXPECT_EQ(ReadBytes(calibration), calibration_text);
    EXPECT_EQ(Listing(), before) << args.back();
  }
}

// ------------------------------------------------------------------------------------------
// Inputs as they really arrive: exit 2, one located line, nothing written, nothing damaged.

TEST_F(CliTest, ATruncatedGzipRunIsRefusedNotReadAsComplete) {
  const std::string whole = ReadBytes(Fixture("mems_6pos_noiseless.csv.gz"));
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::string>{"cut.csv.gz", whole.substr(0, whole.size() - 8)},
        {"garbage.csv.gz", whole + "junk"}}) {
    const std::string samples = Write(name, bytes);
    const RunResult r =
        Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
    EXPECT_EQ(r.status, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name + ": " + (name == "cut.csv.gz" ? "truncated gzip stream" : "trailing garbage")),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(Path("out.csv")));
  }
}

TEST_F(CliTest, MultiOutputCommandsWriteAllOrNothing) {
  const std::string calibration = Write("calibration.yaml", "precious\n");
  const RunResult fit = Run({"fit", "-p", Fixture("plan_6pos.yaml"), "-s", Fixture("mems_6pos_soak.csv.gz"),
                             "-o", calibration, "--report", Path("missing/report.html"), "-q"});
  EXPECT_EQ(fit.status, 2) << fit.err;
  EXPECT_NE(fit.err.find("missing/report.html: cannot create"), std::string::npos) << fit.err;
  EXPECT_EQ(ReadBytes(calibration), "precious\n")
      << "the calibration was replaced although the report failed";
  EXPECT_EQ(Listing(), (std::set<std::string>{"calibration.yaml"}));

  std::string rows = "time_s,gyro_x\n";
  for (int i = 0; i < 2000; ++i)
    rows += std::to_string(i * 0.01) + "," + std::to_string((i * 7919 % 101) * 1e-3) + "\n";
  const std::string samples = Write("rates.csv", rows);
  const RunResult allan =
      Run({"allan", "-s", samples, "-o", Path("adev.csv"), "--noise-yaml", Path("missing/noise.yaml"), "-q"});
  EXPECT_EQ(allan.status, 2) << allan.err;
  EXPECT_EQ(Listing(), (std::set<std::string>{"calibration.yaml", "rates.csv"})) << "adev.csv written alone";
}

TEST_F(CliTest, OutputsNeverReplaceALinkOrSpecialFile) {
  const std::string target = Write("target.csv", "the user's file\n");
  const std::string link = Path("link.csv");
  fs::create_symlink(target, link);
  const RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s",
                           Fixture("mems_6pos_noiseless.csv.gz"), "-o", link, "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("link.csv: is a symbolic link"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(ReadBytes(target), "the user's file\n");
  EXPECT_EQ(Listing(), (std::set<std::string>{"target.csv", "link.csv"}));
}

TEST_F(CliTest, NoCommandWritesANonFiniteNumber) {
  // apply: an absurd temperature, which would overflow the polynomials, is refused where it is read.
  const std::string header = "time_s,temp_c,gyro_x,gyro_y,gyro_z,accel_x,accel_y,accel_z\n";
  const std::string samples = Write("hot.csv", header + "0,25,1,2,3,4,5,6\n0.1,1e300,1,2,3,4,5,6\n");
  RunResult r = Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("hot.csv:3:2: temp_c: 1e+300 degC is outside -100..200 degC"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // apply: a calibration whose scale crosses zero inside its fit range is refused on read.
  YAML::Node calibration = YAML::LoadFile(Fixture("mems_truth.yaml"));
  calibration["gyro"]["scale"]["y"][1] =
      -calibration["gyro"]["scale"]["y"][0].as<double>() / 30.0;  // 0 at 55 degC
  YAML::Emitter emitter;
  emitter << calibration;
  r = Run({"apply", "-c", Write("bad.yaml", emitter.c_str()), "-s", Fixture("mems_6pos_noiseless.csv.gz"),
           "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("gyro.scale.y: the scale factor changes sign"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("out.csv")));
  // simulate: a temperature that is not a number.
  r = Run({"simulate", "-p", Fixture("plan_6pos.yaml"), "-c", Fixture("mems_truth.yaml"), "-o",
           Path("sim.csv"), "--temps", "25,nan", "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("temperatures must be numbers"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(Path("sim.csv")));
  // allan: a constant column gives zero deviations with zero-width intervals and says why there is
  // no noise fit.
  std::string rows = "time_s,gyro_x\n";
  for (int i = 0; i < 2000; ++i) rows += std::to_string(i * 0.01) + ",0.5\n";
  r = Run(
      {"allan", "-s", Write("stuck.csv", rows), "-o", Path("adev.csv"), "--noise-yaml", Path("noise.yaml")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("the column is constant"), std::string::npos) << r.out;
  for (const char* output : {"adev.csv", "noise.yaml"}) {
    const std::string text = ReadBytes(Path(output));
    EXPECT_FALSE(text.empty()) << output;
    EXPECT_EQ(text.find("nan"), std::string::npos) << output << ":\n" << text;
    EXPECT_EQ(text.find("inf"), std::string::npos) << output << ":\n" << text;
  }
}

TEST_F(CliTest, HostileInputGivesOneBoundedEscapedLine) {
  const std::string samples =
      Write("evil.csv", "time_s,temp_c,\x1b]0;owned\x07" + std::string(3000, 'x') + "\n1,2,3\n");
  const RunResult r =
      Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", samples, "-o", Path("out.csv"), "-q"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\x07'), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_LT(r.err.size(), 600u) << r.err;
  const RunResult zero =
      Run({"apply", "-c", Fixture("mems_truth.yaml"), "-s", "/dev/zero", "-o", Path("out.csv")});
  EXPECT_EQ(zero.status, 2) << zero.err;
  EXPECT_NE(zero.err.find("/dev/zero:1: line longer than"), std::string::npos) << zero.err;
}

}  // namespace
}  // namespace imufit::testing
