// imufit history — what the results store knows, across stations: a serial's calibrations, the
// yield by lot, station or month, a key figure over time and a station's drift of it. Printed
// tables, CSV with --csv, or an HTML page with --html (factory/store_history.h; the lots with their
// key figures as on the lot page: --lot --html, factory/lot_history.h).
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "commands.h"
#include "imufit/base/text.h"
#include "imufit/factory/batch.h"
#include "imufit/factory/lot_history.h"
#include "imufit/factory/report.h"
#include "imufit/factory/store_history.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/store/store.h"

namespace imufit {
namespace {

struct HistoryArguments {
  std::string store;
  std::string serial;
  std::string lot;
  bool lot_given = false;
  std::string by;  // yield by lot, station or month
  std::string trend;
  std::string station;  // with --trend: one station's fits (its drift)
  bool csv = false;
  std::string html;    // --lot: the lots as a page of charts
  std::string limits;  // drawn on those charts
};

// The lots of the store as a page: every lot's yield and key figures, `lot` highlighted.
int WriteLotHistoryPage(const HistoryArguments& args, ResultsStore* store) {
  std::optional<Limits> limits;
  if (!args.limits.empty()) limits = ReadLimits(args.limits);
  const LotHistory history = MakeLotHistory(store, args.lot, limits ? &*limits : nullptr);
  if (!args.lot.empty() && history.current < 0)
    throw InputError(args.store, "no lot named " + QuoteForMessage(args.lot) + " to highlight");
  WriteFileAtomically(args.html, LotHistoryHtml(history));
  return 0;
}

// The first few of `names`, and how many more.
std::string JoinFirst(const std::vector<std::string>& names) {
  constexpr size_t kShown = 8;
  std::string text;
  for (size_t i = 0; i < names.size() && i < kShown; ++i) text += (i ? ", " : "") + names[i];
  if (names.size() > kShown) text += " and " + std::to_string(names.size() - kShown) + " more";
  return text;
}

// Yield of each group (the lots: `--lot [NAME]`, one lot or all; `--by GROUP`).
void PrintYields(const std::vector<GroupYield>& yields, const std::string& heading, bool csv) {
  if (csv) {
    std::printf("%s,units,passed,failed,not_fitted,yield\n", heading.c_str());
  } else {
    std::printf("%-24s %6s %6s %6s %10s %8s\n", heading.c_str(), "units", "passed", "failed", "not fitted",
                "yield");
  }
  for (const GroupYield& y : yields) {
    // A group without limits has no verdicts: its yield is not judged (empty in CSV), not 0 %.
    const double pct = YieldPct(y);
    char yield[32] = "not judged";
    if (!std::isnan(pct)) std::snprintf(yield, sizeof yield, csv ? "%.2f" : "%.1f", pct);
    if (csv) {
      std::printf("%s,%d,%d,%d,%d,%s\n", y.group.c_str(), y.units, y.passed, y.failed, y.not_fitted,
                  std::isnan(pct) ? "" : yield);
    } else {
      std::printf("%-24s %6d %6d %6d %10d %8s%s\n", y.group.c_str(), y.units, y.passed, y.failed,
                  y.not_fitted, yield, std::isnan(pct) ? "" : "%");
    }
  }
}

int Yields(const HistoryArguments& args, ResultsStore* store) {
  YieldGroup by = YieldGroup::kLot;
  if (!args.by.empty() && !ValueOf(kYieldGroupNames, args.by, &by))
    throw InputError("--by", QuoteForMessage(args.by) + " is not one of " + AllNames(kYieldGroupNames));
  std::vector<GroupYield> yields;
  std::vector<std::string> groups;
  for (const GroupYield& y : store->YieldBy(by)) {
    groups.push_back(y.group);
    if (args.lot.empty() || y.group == args.lot) yields.push_back(y);
  }
  // A lot the store does not hold is a mistake whatever is printed (as `imufit lot` and --html say).
  if (!args.lot.empty() && yields.empty()) {
    throw InputError(store->path(), "no lot named " + QuoteForMessage(args.lot) +
                                        (groups.empty() ? " (the store holds no lots)"
                                                        : " (it holds: " + JoinFirst(groups) + ")"));
  }
  if (!args.html.empty()) {
    WriteFileAtomically(args.html, YieldPageHtml(store->path(), by, yields));
    return 0;
  }
  PrintYields(yields, NameOf(kYieldGroupNames, by), args.csv);
  if (yields.empty() && !args.csv) std::printf("(no lots)\n");
  return 0;
}

int Trend(const HistoryArguments& args, ResultsStore* store) {
  const std::vector<TrendPoint> points = store->Trend(args.trend, args.serial, args.station);
  if (points.empty())
    throw InputError(args.store, "no figure " + QuoteForMessage(args.trend) + " recorded" +
                                     (args.serial.empty() ? "" : " for serial " + args.serial) +
                                     (args.station.empty() ? "" : " at station " + args.station) +
                                     " (names such as gyro_bias_dps.x or gyro.bias.x)");
  if (!args.html.empty()) {
    WriteFileAtomically(args.html, TrendPageHtml(store->path(), args.trend, points));
    return 0;
  }
  if (args.csv) {
    std::printf("time_utc,serial,lot,value,sigma,unit,station,U\n");
  } else {
    std::printf("%s over time:\n%-22s %-16s %-14s %-12s %14s %12s %12s\n", args.trend.c_str(), "time (UTC)",
                "serial", "lot", "station", "value", "1-sigma", "U (k = 2)");
  }
  for (const TrendPoint& p : points) {
    if (args.csv) {
      std::printf("%s,%s,%s,%s,%s,%s,%s,%s\n", p.time_utc.c_str(), p.serial.c_str(), p.lot.c_str(),
                  FormatDouble(p.value).c_str(), FormatDouble(p.sigma).c_str(), p.unit.c_str(),
                  p.station.c_str(), p.expanded_u >= 0 ? FormatDouble(p.expanded_u).c_str() : "");
    } else {
      std::printf("%-22s %-16s %-14s %-12s %14.6g %12.3g %12.3g %s\n", p.time_utc.c_str(), p.serial.c_str(),
                  p.lot.c_str(), p.station.c_str(), p.value, p.sigma, p.expanded_u, p.unit.c_str());
    }
  }
  if (args.csv) return 0;
  std::printf("\nmean per station and month (drift):\n%-12s %-8s %5s %14s %12s\n", "station", "month", "fits",
              "mean", "1-sigma");
  for (const MonthlyMean& m : MonthlyMeans(points)) {
    std::printf("%-12s %-8s %5d %14.6g %12.3g %s\n", m.station.empty() ? "-" : m.station.c_str(),
                m.month.c_str(), m.count, m.mean, m.sigma, m.unit.c_str());
  }
  return 0;
}

int Serial(const HistoryArguments& args, ResultsStore* store) {
  const std::vector<StoredFit> fits = store->BySerial(args.serial);
  if (fits.empty()) throw InputError(args.store, "no calibrations of serial " + QuoteForMessage(args.serial));
  if (!args.html.empty()) {
    WriteFileAtomically(args.html, SerialPageHtml(store->path(), args.serial, fits));
    return 0;
  }
  if (args.csv) {
    std::printf(
        "id,time_utc,serial,lot,unit,software,status,verdict,samples_sha256,message,station,acquired_utc,"
        "part_number");
    for (const std::string& name : kSummaryFigures) std::printf(",%s", name.c_str());
    std::printf("\n");
  } else {
    std::printf("calibrations of %s:\n%-5s %-22s %-14s %-12s %-12s %-8s %-18s %12s %12s  %s\n",
                args.serial.c_str(), "id", "time (UTC)", "lot", "station", "status", "verdict", "software",
                "gyro bias x", "samples", "message");
  }
  for (const StoredFit& f : fits) {
    if (args.csv) {
      std::string row = std::to_string(f.id);
      for (const std::string* text :
           {&f.time_utc, &f.serial, &f.lot, &f.unit, &f.software, &f.status, &f.verdict, &f.samples_sha256,
            &f.message, &f.station, &f.acquired_utc, &f.part_number}) {
        row += "," + CsvCell(*text);
      }
      std::printf("%s", row.c_str());
      for (const std::string& name : kSummaryFigures) {
        const StoredFigure* figure = FindFigure(f.figures, name);
        std::printf(",%s", figure ? FormatDouble(figure->value).c_str() : "");
      }
      std::printf("\n");
    } else {
      const StoredFigure* bias = FindFigure(f.figures, "gyro_bias_dps.x");
      std::printf("%-5lld %-22s %-14s %-12s %-12s %-8s %-18s %12s %12s  %s\n", static_cast<long long>(f.id),
                  f.time_utc.c_str(), f.lot.c_str(), f.station.empty() ? "-" : f.station.c_str(),
                  f.status.c_str(), f.verdict.empty() ? "-" : f.verdict.c_str(), f.software.c_str(),
                  bias ? (FormatDouble(bias->value).substr(0, 10) + " dps").c_str() : "-",
                  f.samples_sha256.substr(0, 12).c_str(), f.message.c_str());
    }
  }
  return 0;
}

int RunHistory(const HistoryArguments& args) {
  if (!args.limits.empty() && !(args.lot_given && !args.html.empty()))
    throw InputError("imufit history", "--limits draws the lots: give it with --lot [NAME] --html OUT");
  if (!args.station.empty() && args.trend.empty())
    throw InputError("imufit history", "--station gives a station's drift: give it with --trend FIGURE");
  if (args.lot_given && !args.by.empty())
    throw InputError("imufit history", "--lot is the yield by lot: leave out --by");
  const int queries = (args.lot_given ? 1 : 0) + (args.by.empty() ? 0 : 1) + (args.trend.empty() ? 0 : 1) +
                      (!args.serial.empty() && args.trend.empty() ? 1 : 0);
  if (queries != 1)
    throw InputError("imufit history",
                     "give one of --serial S, --lot [NAME], --by lot|station|month, --trend FIGURE [--serial "
                     "S] [--station S]");
  if (!args.html.empty()) RefuseToOverwriteInputs(args.html, {args.store, args.limits});
  ResultsStore store(args.store, StoreAccess::kRead);
  if (args.lot_given && !args.html.empty()) return WriteLotHistoryPage(args, &store);
  if (args.lot_given || !args.by.empty()) return Yields(args, &store);
  if (!args.trend.empty()) return Trend(args, &store);
  return Serial(args, &store);
}

}  // namespace

CommandRunner AddHistoryCommand(CliCommand command) {
  auto args = std::make_shared<HistoryArguments>();
  command
      .Option("store", &args->store,
              "results store written by imufit batch/fit --store: an SQLite file or a PostgreSQL URL")
      .Required();
  command.Option("--serial", &args->serial, "a unit's serial");
  CliOption lot =
      command.Option("--lot", &args->lot, "yield of this lot (no name: of every lot)").Expected(0, 1);
  command.Option("--by", &args->by, "yield by lot, station or month (YYYY-MM of the fit, UTC)");
  command.Option("--trend", &args->trend, "a key figure over time");
  command.Option("--station", &args->station, "with --trend: only this station's fits (its drift)");
  command.Flag("--csv", &args->csv, "print CSV instead of a table");
  command.Option("--html", &args->html,
                 "write the answer as an HTML page (with --lot: every lot's yield and key figures "
                 "as charts, NAME highlighted)");
  command.Option("--limits", &args->limits, "with --lot --html: draw these acceptance limits on the charts");
  return [args, lot] {
    args->lot_given = lot.Given();
    return RunHistory(*args);
  };
}

}  // namespace imufit
