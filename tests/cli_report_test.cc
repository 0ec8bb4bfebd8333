// `imufit report` and the certificate end to end on the lot of cli_factory_util.h: the noise of a static
// stretch, the station file, the run, item and laboratory named, printing to PDF (headless Chromium, checked
// with poppler-utils; skipped without them).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_factory_util.h"
#include "imufit/io/calibration.h"
#include "imufit/io/sha256.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;
using testing::RunResult;

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
  // The store names each printed certificate among the fit's attachments, with the PDF's SHA-256,
  // also for a unit skipped as unchanged and recorded in another store.
  const std::string pdf = Path("out/unit-04/report.pdf");
  const std::string attachment = "certificate_pdf|" + pdf + "|" + Sha256OfFile(pdf) + "\n";
  const std::string sql =
      "SELECT a.kind, a.path, a.sha256 FROM attachments a JOIN fits f ON f.id = a.fit_id JOIN runs r ON "
      "r.run_key = f.run_key WHERE r.serial = 'SN-04' AND a.kind = 'certificate_pdf'";
  EXPECT_EQ(Query(Path("store.db"), sql), attachment);
  args = BatchArgs("out");
  *(std::find(args.begin(), args.end(), "--store") + 1) = Path("again.db");
  args.push_back("--pdf");
  r = Run(args);
  ASSERT_EQ(r.status, kExitFailedLimits) << r.out << r.err;
  EXPECT_NE(r.out.find("unchanged and skipped"), std::string::npos) << r.out;
  EXPECT_EQ(Query(Path("again.db"), sql), attachment);
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
  // --station without --report: its Type B sources are in U whether a page is written or not
  // (issue 29 item 4), so the fit takes it.
  r = Run({"fit", "-p", plan, "-s", samples, "-o", Path("cal_no_report.yaml"), "--station", station});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(Path("cal_no_report.yaml")));

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

// Issue 29 item 4, end to end: `fit --limits` and `fit --limits --report` judge the same unit the
// same (the noise terms and the worst window error the certificate measures, the station's U): the
// same acceptance table on stdout, exit status and store row. Under guard_band: 2 no row of a
// failed criterion reads PASS.
TEST_F(FactoryCliTest, FitJudgesTheSameWithAndWithoutACertificate) {
  const std::string plan = Path("units/unit-01/plan.yaml"), samples = Path("units/unit-01/samples.csv.gz");
  const std::string limits =
      Write("one_verdict_limits.yaml",
            "format: imufit-limits\nversion: 1\nname: one verdict\n"
            "nominal: {gyro_scale: 939.65, accel_scale: 208.838}\n"
            "decision_rule: guarded\nguard_band: 2\ncriteria:\n"
            "  - {quantity: gyro_bias_dps, max_abs: 5}\n"
            "  - {quantity: gyro_bias_dps, axes: [x], max_abs: 1.421}\n"
            "  - {quantity: gyro_scale_error_ppm, max_abs: 20000}\n"
            "  - {quantity: gyro_scale_error_ppm, statistic: largest, max_abs: 20000}\n"
            "  - {quantity: gyro_residual_max_dps, max_abs: 1}\n"
            "  - {quantity: accel_residual_max_mg, max_abs: 50}\n"
            "  - {quantity: gyro_arw_deg_per_sqrt_hr, max_abs: 10}\n");
  const std::string station = Write("one_verdict_station.yaml",
                                    "format: imufit-station\nversion: 1\nstation: bench\nuncertainty:\n"
                                    "  rate_accuracy: {u: 10, unit: ppm, source: table cert}\n"
                                    "  table_axis_tilt: {half_width: 20, unit: arcsec, source: levelled}\n");
  const auto fit = [&](const std::string& name, bool report) {
    std::vector<std::string> args = {
        "fit",  "-p",        plan,    "-s",      samples,           "-o", Path(name + ".yaml"), "--limits",
        limits, "--station", station, "--store", Path(name + ".db")};
    if (report) args.insert(args.end(), {"--report", Path(name + ".html")});
    return Run(args);
  };
  const RunResult plain = fit("plain", false), certified = fit("certified", true);
  EXPECT_EQ(plain.status, certified.status) << plain.out << certified.out;
  // The acceptance table: from its first line to the line before "wrote".
  const auto table = [](const std::string& out) {
    const size_t from = out.find("  acceptance");
    const size_t to = out.find("  wrote", from);
    return from == std::string::npos ? std::string() : out.substr(from, to - from);
  };
  ASSERT_FALSE(table(plain.out).empty()) << plain.out;
  EXPECT_EQ(table(plain.out), table(certified.out));
  EXPECT_EQ(table(plain.out).find("not in calibration"), std::string::npos) << table(plain.out);
  // No failed row reads PASS: the rows that read PASS are the criteria that passed.
  const std::string rows = table(certified.out);
  std::smatch counts;
  ASSERT_TRUE(std::regex_search(rows, counts, std::regex("\\((\\d+) of (\\d+) criteria failed\\)"))) << rows;
  const int failed = std::stoi(counts[1]), criteria = std::stoi(counts[2]);
  int pass_rows = 0;
  for (size_t at = rows.find("  PASS"); at != std::string::npos; at = rows.find("  PASS", at + 1))
    ++pass_rows;
  EXPECT_EQ(pass_rows, criteria - failed) << rows;
  // Gyro bias x (+1.41445 deg/s, U about 0.0043 deg/s) against 1.421: clear of the limit by about
  // 1.5 U, inside the guard band of 2 U: not accepted, and its row says FAIL.
  std::smatch guarded;
  ASSERT_TRUE(std::regex_search(rows, guarded, std::regex("\\|gyro_bias_dps\\.x\\|[^\\n]*< 1\\.421[^\\n]*")))
      << rows;
  EXPECT_NE(guarded.str().find("FAIL: inside the guard band w = 2 x U"), std::string::npos) << rows;
  // The store's rows: the same verdict and message.
  for (const char* column : {"verdict", "message"}) {
    const std::string sql = std::string("SELECT ") + column + " FROM fits";
    const auto query = [&](const std::string& db) {
      return RunProgram("/usr/bin/python3",
                        {"-c",
                         "import sqlite3, sys\n"
                         "print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchall())\n",
                         db, sql})
          .out;
    };
    EXPECT_EQ(query(Path("plain.db")), query(Path("certified.db"))) << column;
  }
}

}  // namespace
}  // namespace imufit
