// imufit history — what the results store knows: a serial's calibrations, lots' yield, a
// coefficient's trend over time. Printed tables, or CSV with --csv; the lots as an HTML page of
// charts with --lot --html (factory/lot_history.h, report.h).
#include <cstdio>
#include <memory>
#include <optional>

#include "commands.h"
#include "imufit/factory/batch.h"
#include "imufit/factory/lot_history.h"
#include "imufit/factory/report.h"
#include "imufit/factory/store.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"

namespace imufit {
namespace {

struct HistoryArguments {
  std::string store;
  std::string serial;
  std::string lot;
  bool lot_given = false;
  std::string trend;
  bool csv = false;
  std::string html;    // --lot: the lots as a page of charts
  std::string limits;  // drawn on those charts
};

// The lots of the store as a page: every lot's yield and key figures, `lot` highlighted.
int WriteLotHistoryPage(const HistoryArguments& args, ResultsStore* store) {
  RefuseToOverwriteInputs(args.html, {args.store, args.limits});
  std::optional<Limits> limits;
  if (!args.limits.empty()) limits = ReadLimits(args.limits);
  const LotHistory history = MakeLotHistory(store, args.lot, limits ? &*limits : nullptr);
  if (!args.lot.empty() && history.current < 0)
    throw InputError(args.store, "no lot named " + QuoteForMessage(args.lot) + " to highlight");
  WriteFileAtomically(args.html, LotHistoryHtml(history));
  return 0;
}

int RunHistory(const HistoryArguments& args) {
  if ((!args.html.empty() || !args.limits.empty()) && !args.lot_given)
    throw InputError("imufit history", "--html and --limits draw the lots: give them with --lot [NAME]");
  const int queries = (args.lot_given ? 1 : 0) + (args.trend.empty() ? 0 : 1) +
                      (!args.serial.empty() && args.trend.empty() ? 1 : 0);
  if (queries != 1)
    throw InputError("imufit history", "give one of --serial S, --lot [NAME], --trend FIGURE [--serial S]");
  ResultsStore store(args.store, StoreAccess::kRead);
  if (args.lot_given && !args.html.empty()) return WriteLotHistoryPage(args, &store);
  if (args.lot_given) {
    const std::vector<LotYield> yields = store.Yield(args.lot);
    if (args.csv) {
      std::printf("lot,units,passed,failed,not_fitted,yield\n");
    } else {
      std::printf("%-24s %6s %6s %6s %10s %8s\n", "lot", "units", "passed", "failed", "not fitted", "yield");
    }
    for (const LotYield& y : yields) {
      // A lot without limits has no verdicts: its yield is not judged (empty in CSV), not 0 %.
      char yield[32] = "not judged";
      if (y.passed + y.failed > 0)
        std::snprintf(yield, sizeof yield, args.csv ? "%.2f" : "%.1f", 100.0 * y.passed / y.units);
      if (args.csv) {
        std::printf("%s,%d,%d,%d,%d,%s\n", y.lot.c_str(), y.units, y.passed, y.failed, y.not_fitted,
                    y.passed + y.failed > 0 ? yield : "");
      } else {
        std::printf("%-24s %6d %6d %6d %10d %8s%s\n", y.lot.c_str(), y.units, y.passed, y.failed,
                    y.not_fitted, yield, y.passed + y.failed > 0 ? "%" : "");
      }
    }
    if (yields.empty() && !args.csv)
      std::printf("(no lots%s)\n", args.lot.empty() ? "" : (" named " + args.lot).c_str());
    return 0;
  }
  if (!args.trend.empty()) {
    const std::vector<TrendPoint> points = store.Trend(args.trend, args.serial);
    if (points.empty())
      throw InputError(args.store, "no figure " + QuoteForMessage(args.trend) + " recorded" +
                                       (args.serial.empty() ? "" : " for serial " + args.serial) +
                                       " (names such as gyro_bias_dps.x or gyro.bias.x)");
    if (args.csv) {
      std::printf("time_utc,serial,lot,value,sigma,unit\n");
    } else {
      std::printf("%s over time:\n%-22s %-16s %-14s %14s %12s\n", args.trend.c_str(), "time (UTC)", "serial",
                  "lot", "value", "1-sigma");
    }
    for (const TrendPoint& p : points) {
      if (args.csv) {
        std::printf("%s,%s,%s,%s,%s,%s\n", p.time_utc.c_str(), p.serial.c_str(), p.lot.c_str(),
                    FormatDouble(p.value).c_str(), FormatDouble(p.sigma).c_str(), p.unit.c_str());
      } else {
        std::printf("%-22s %-16s %-14s %14.6g %12.3g %s\n", p.time_utc.c_str(), p.serial.c_str(),
                    p.lot.c_str(), p.value, p.sigma, p.unit.c_str());
      }
    }
    return 0;
  }
  const std::vector<StoredFit> fits = store.BySerial(args.serial);
  if (fits.empty()) throw InputError(args.store, "no calibrations of serial " + QuoteForMessage(args.serial));
  if (args.csv) {
    std::printf("id,time_utc,serial,lot,unit,software,status,verdict,samples_sha256,message");
    for (const std::string& name : kSummaryFigures) std::printf(",%s", name.c_str());
    std::printf("\n");
  } else {
    std::printf("calibrations of %s:\n%-5s %-22s %-14s %-12s %-8s %-18s %12s %12s  %s\n", args.serial.c_str(),
                "id", "time (UTC)", "lot", "status", "verdict", "software", "gyro bias x", "samples",
                "message");
  }
  for (const StoredFit& f : fits) {
    if (args.csv) {
      std::printf("%lld,%s,%s,%s,%s,%s,%s,%s,%s,\"%s\"", static_cast<long long>(f.id), f.time_utc.c_str(),
                  f.serial.c_str(), f.lot.c_str(), f.unit.c_str(), f.software.c_str(), f.status.c_str(),
                  f.verdict.c_str(), f.samples_sha256.c_str(), f.message.c_str());
      for (const std::string& name : kSummaryFigures) {
        const Figure* figure = FindFigure(f.figures, name);
        std::printf(",%s", figure ? FormatDouble(figure->value).c_str() : "");
      }
      std::printf("\n");
    } else {
      const Figure* bias = FindFigure(f.figures, "gyro_bias_dps.x");
      std::printf("%-5lld %-22s %-14s %-12s %-8s %-18s %12s %12s  %s\n", static_cast<long long>(f.id),
                  f.time_utc.c_str(), f.lot.c_str(), f.status.c_str(),
                  f.verdict.empty() ? "-" : f.verdict.c_str(), f.software.c_str(),
                  bias ? (FormatDouble(bias->value).substr(0, 10) + " dps").c_str() : "-",
                  f.samples_sha256.substr(0, 12).c_str(), f.message.c_str());
    }
  }
  return 0;
}

}  // namespace

CommandRunner AddHistoryCommand(CLI::App* root) {
  auto args = std::make_shared<HistoryArguments>();
  CLI::App* command = root->add_subcommand("history",
                                           "Query the results store: every calibration of a serial "
                                           "(--serial), the yield of lots (--lot [NAME]), or a "
                                           "key figure over time (--trend gyro.bias.x, or a figure name such "
                                           "as gyro_bias_dps.x; with --serial, one unit's).");
  command
      ->add_option("store", args->store,
                   "results store written by imufit batch/fit --store: an SQLite file or a PostgreSQL URL")
      ->required();
  command->add_option("--serial", args->serial, "a unit's serial");
  CLI::Option* lot =
      command->add_option("--lot", args->lot, "yield of this lot (no name: of every lot)")->expected(0, 1);
  command->add_option("--trend", args->trend, "a key figure over time");
  command->add_flag("--csv", args->csv, "print CSV instead of a table");
  command->add_option("--html", args->html,
                      "with --lot: write every lot's yield and key figures as charts to this HTML page "
                      "(NAME highlighted)");
  command->add_option("--limits", args->limits, "with --html: draw these acceptance limits on the charts");
  return [args, lot] {
    args->lot_given = lot->count() > 0;
    return RunHistory(*args);
  };
}

}  // namespace imufit
