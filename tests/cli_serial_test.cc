// End-to-end tests of a unit's serial: from `imufit simulate --serial` through the samples'
// header to the calibration, the certificate (`fit --report`, `report`) and the batch's summary,
// and the sources that name different units (warned about, or refused unless --allow-mismatch).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "cli_util.h"

namespace imufit::testing {
namespace {

namespace fs = std::filesystem;

// The serial a file names in a certificate, as the page shows it (data-key="serial").
std::string CertificateSerial(const std::string& html) {
  const std::string key = "data-key=\"serial\">";
  const size_t at = html.find(key);
  if (at == std::string::npos) return "<no serial element>";
  const size_t start = at + key.size();
  return html.substr(start, html.find('<', start) - start);
}

// simulate --serial writes the serial into the samples' header, where fit, report
// and batch find it (after --serial and serial.txt, before the plan's); a certificate without a
// serial says so on stderr as well as on the page.
TEST_F(CliTest, SerialTravelsFromTheSamplesHeaderToCalibrationCertificateAndBatch) {
  const std::string plan = Fixture("plan_6pos.yaml");  // no serial of its own
  const auto simulate = [&](const std::string& out, const std::vector<std::string>& extra) {
    const RunResult r = Run(SmallRunArgs(out, extra));
    EXPECT_EQ(r.status, 0) << r.err;
  };
  fs::create_directories(dir_ / "lot" / "u1");
  fs::create_directories(dir_ / "lot" / "u2");
  const std::string named = Path("lot/u1/samples.csv");
  simulate(named, {"--serial", "SN-77", "--truth", Path("truth.csv"), "--seed", "1"});
  EXPECT_NE(ReadFile(named).find("\n# serial: SN-77\ntime_s,"), std::string::npos);
  EXPECT_NE(ReadFile(Path("truth.csv")).find("\n# serial: SN-77\ntime_s,"), std::string::npos);

  RunResult r =
      Run({"fit", "-p", plan, "-s", named, "-o", Path("cal.yaml"), "--report", Path("cal.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(YAML::LoadFile(Path("cal.yaml"))["serial"].as<std::string>(), "SN-77");
  EXPECT_EQ(CertificateSerial(ReadBytes(Path("cal.html"))), "SN-77");
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("cal_override.yaml"), "--serial", "SN-OTHER",
           "--allow-mismatch", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("cal_override.yaml"))["serial"].as<std::string>(), "SN-OTHER");

  // A calibration without a serial: report takes the samples' serial; without one anywhere the
  // certificate says "(no serial)" under a warning, and stderr says so too (report and fit --report).
  YAML::Node unnamed = YAML::LoadFile(Path("cal.yaml"));
  unnamed["serial"] = "";
  YAML::Emitter emitter;
  emitter << unnamed;
  const std::string unnamed_cal = Write("unnamed.yaml", emitter.c_str());
  r = Run({"report", "-c", unnamed_cal, "-p", plan, "-s", named, "-o", Path("report.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("no serial"), std::string::npos) << r.err;
  EXPECT_EQ(CertificateSerial(ReadBytes(Path("report.html"))), "SN-77");
  const std::string anonymous = Path("anonymous.csv");
  simulate(anonymous, {"--seed", "2"});
  r = Run({"fit", "-p", plan, "-s", anonymous, "-o", Path("anonymous.yaml"), "--report",
           Path("anonymous.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("anonymous.csv: no serial (give --serial"), std::string::npos) << r.err;
  std::string html = ReadBytes(Path("anonymous.html"));
  EXPECT_EQ(CertificateSerial(html), "(no serial)");
  EXPECT_NE(html.find("data-warning=\"no serial"), std::string::npos);
  r = Run(
      {"report", "-c", Path("anonymous.yaml"), "-p", plan, "-s", anonymous, "-o", Path("anonymous2.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("anonymous.yaml: no serial (give --serial"), std::string::npos) << r.err;
  html = ReadBytes(Path("anonymous2.html"));
  EXPECT_EQ(CertificateSerial(html), "(no serial)");
  EXPECT_NE(html.find("data-warning=\"no serial"), std::string::npos);

  // batch: u1 by its samples' header; u2's serial.txt wins over its header (when allowed: a
  // contradiction is refused otherwise, SerialsThatDisagreeAreWarnedAboutOrRefused).
  simulate(Path("lot/u2/samples.csv"), {"--serial", "SN-HEADER", "--seed", "3"});
  Write("lot/u2/serial.txt", "SN-FILE\n");
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--no-report", "--jobs", "1",
           "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const Table summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 2u);
  EXPECT_EQ(summary.rows[0][summary.Column("serial")], "SN-77");
  EXPECT_EQ(summary.rows[1][summary.Column("serial")], "SN-FILE");
  EXPECT_EQ(YAML::LoadFile(Path("out/u1/calibration.yaml"))["serial"].as<std::string>(), "SN-77");

  // Bad serials: exit 2 at their place, nothing written.
  r = Run(
      {"simulate", "-p", plan, "-c", Fixture("mems_truth.yaml"), "-o", Path("bad.csv"), "--serial", "SN\n1"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--serial: the serial \"SN\\x0a1\" holds a control character"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("bad.csv")));
  std::string two = ReadFile(named);
  two.insert(two.find("time_s,"), "#   serial: SN-78\n");
  r = Run({"fit", "-p", plan, "-s", Write("two.csv", two), "-o", Path("two.yaml")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("two.csv:3:13: a second serial \"SN-78\" after \"SN-77\""), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("two.yaml")));
  std::string bell = ReadFile(named);
  bell.replace(bell.find("SN-77"), 5, "SN\a77");
  r = Run({"apply", "-c", Path("cal.yaml"), "-s", Write("bell.csv", bell), "-o", Path("bell_out.csv")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bell.csv:2:11: the serial \"SN\\x0777\" holds a control character"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("bell_out.csv")));
}

// The warnings of a certificate (data-warning attributes), unescaped.
std::vector<std::string> CertificateWarnings(const std::string& html) {
  std::vector<std::string> warnings;
  const std::string key = "data-warning=\"";
  for (size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + 1)) {
    const size_t start = at + key.size();
    std::string text = html.substr(start, html.find('"', start) - start);
    for (const auto& [entity, character] :
         {std::pair<std::string, std::string>{"&quot;", "\""}, {"&amp;", "&"}}) {
      for (size_t e = text.find(entity); e != std::string::npos; e = text.find(entity, e + 1))
        text.replace(e, entity.size(), character);
    }
    warnings.push_back(text);
  }
  return warnings;
}

// Whether one of `lines` holds every one of `parts`.
bool AnyHoldsAll(const std::vector<std::string>& lines, const std::vector<std::string>& parts) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& line) {
    return std::all_of(parts.begin(), parts.end(),
                       [&](const std::string& part) { return line.find(part) != std::string::npos; });
  });
}

// --serial (a batch unit's serial.txt), the samples header's serial and the plan's may name
// different units. The first names the unit; each disagreement is a warning on stderr and on the
// certificate naming both sources and serials; a stated serial that contradicts the samples' own
// header (one unit's serial beside another unit's log) is refused at the header's line, exit 2,
// unless --allow-mismatch.
TEST_F(CliTest, SerialsThatDisagreeAreWarnedAboutOrRefused) {
  const std::string plan = Fixture("plan_6pos.yaml");  // no serial of its own
  std::string named_plan_text = ReadFile(plan);
  named_plan_text.insert(named_plan_text.find("version:"), "serial: SN-PLAN\n");
  const std::string named_plan = Write("named_plan.yaml", named_plan_text);
  fs::create_directories(dir_ / "lot" / "u1");
  const auto simulate = [&](const std::string& out, const std::vector<std::string>& extra) {
    const RunResult r = Run(SmallRunArgs(out, extra));
    ASSERT_EQ(r.status, 0) << r.err;
  };
  const std::string named = Path("lot/u1/samples.csv");  // its header: "# serial: SN-77" on line 2
  simulate(named, {"--serial", "SN-77", "--seed", "1"});
  const std::string anonymous = Path("anonymous.csv");
  simulate(anonymous, {"--seed", "2"});
  const std::string header = "the samples header of " + named;

  // The samples header and the plan: the header names the unit, a warning says what the plan said.
  RunResult r =
      Run({"fit", "-p", named_plan, "-s", named, "-o", Path("a.yaml"), "--report", Path("a.html"), "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string plan_vs_header = "the plan " + named_plan + " names the unit \"SN-PLAN\", " + header +
                                     " names it \"SN-77\": \"SN-77\" is used";
  EXPECT_NE(r.err.find("imufit: warning: " + plan_vs_header + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("a.yaml"))["serial"].as<std::string>(), "SN-77");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(ReadBytes(Path("a.html"))), {plan_vs_header}));

  // --serial over the plan (the unit's log names none): a warning.
  r = Run({"fit", "-p", named_plan, "-s", anonymous, "-o", Path("b.yaml"), "--serial", "SN-1", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the plan " + named_plan +
                       " names the unit \"SN-PLAN\", --serial names it \"SN-1\": "
                       "\"SN-1\" is used"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("b.yaml"))["serial"].as<std::string>(), "SN-1");

  // --serial against the samples' own header: refused at the header's line, nothing written.
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("c.yaml"), "--serial", "SN-OTHER", "--report",
           Path("c.html")});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(
      r.err.find(named + ":2:11: " + header +
                 " names the unit \"SN-77\", --serial names it "
                 "\"SN-OTHER\": are these that unit's samples? (--allow-mismatch uses \"SN-OTHER\" anyway)"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("c.yaml")));
  EXPECT_FALSE(fs::exists(Path("c.html")));
  // Allowed: --serial names the unit, with the warning on stderr and on the certificate.
  r = Run({"fit", "-p", plan, "-s", named, "-o", Path("c.yaml"), "--serial", "SN-OTHER", "--report",
           Path("c.html"), "--allow-mismatch", "-q"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string allowed = header +
                              " names the unit \"SN-77\", --serial names it \"SN-OTHER\": \"SN-OTHER\" "
                              "is used (allowed with --allow-mismatch)";
  EXPECT_NE(r.err.find("imufit: warning: " + allowed + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(YAML::LoadFile(Path("c.yaml"))["serial"].as<std::string>(), "SN-OTHER");
  std::string html = ReadBytes(Path("c.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-OTHER");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html), {allowed}));

  // report: the calibration's serial against the header is a warning; --serial against the header
  // is refused unless --allow-mismatch.
  r = Run({"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r.html")});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string calibration_vs_header =
      header + " names the unit \"SN-77\", the calibration " + Path("c.yaml") + " names it \"SN-OTHER\"";
  EXPECT_NE(r.err.find(calibration_vs_header), std::string::npos) << r.err;
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(ReadBytes(Path("r.html"))), {calibration_vs_header}));
  r = Run(
      {"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r2.html"), "--serial", "SN-3"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(named + ":2:11: " + header + " names the unit \"SN-77\", --serial names it \"SN-3\""),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(Path("r2.html")));
  r = Run({"report", "-c", Path("c.yaml"), "-p", plan, "-s", named, "-o", Path("r2.html"), "--serial", "SN-3",
           "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.err;
  html = ReadBytes(Path("r2.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-3");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html),
                          {"--serial names it \"SN-3\"", "(allowed with --allow-mismatch)"}));

  // batch: a unit whose serial.txt contradicts its samples header is an error (the lot exits 3);
  // allowed, it is fitted under serial.txt's serial with the warning on stderr and its certificate.
  Write("lot/u1/serial.txt", "SN-FILE\n");
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--jobs", "1", "-q"});
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  Table summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 1u);
  EXPECT_EQ(summary.rows[0][summary.Column("status")], "error");
  const std::string serial_txt = Path("lot/u1/serial.txt");
  EXPECT_NE(summary.rows[0][summary.Column("message")].find(named + ":2:11: " + header), std::string::npos);
  EXPECT_NE(ReadFile(Path("out/lot_summary.csv")).find(serial_txt + " names it \"\"SN-FILE\"\""),
            std::string::npos);
  EXPECT_FALSE(fs::exists(Path("out/u1/calibration.yaml")));
  r = Run({"batch", Path("lot"), "--plan", plan, "-o", Path("out"), "--jobs", "1", "-q", "--allow-mismatch"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string batch_allowed =
      header + " names the unit \"SN-77\", " + serial_txt +
      " names it \"SN-FILE\": \"SN-FILE\" is used (allowed with --allow-mismatch)";
  EXPECT_NE(r.err.find("imufit: warning: u1: " + batch_allowed + "\n"), std::string::npos) << r.err;
  summary = ReadTable(Path("out/lot_summary.csv"));
  ASSERT_EQ(summary.rows.size(), 1u);
  EXPECT_EQ(summary.rows[0][summary.Column("serial")], "SN-FILE");
  html = ReadBytes(Path("out/u1/report.html"));
  EXPECT_EQ(CertificateSerial(html), "SN-FILE");
  EXPECT_TRUE(AnyHoldsAll(CertificateWarnings(html), {batch_allowed}));
}

}  // namespace
}  // namespace imufit::testing
