// imufit lot --store URL --lot NAME --html OUT — the lot page (and lot_summary.csv) of a lot from
// the results store: what a batch writes for itself, for a lot fitted in shards (imufit batch
// --shard), each of which leaves the lot page to the store (factory/store_history.h StoredLot).
#include <memory>
#include <optional>

#include "commands.h"
#include "imufit/factory/lot_page.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/factory/store_history.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/store/store.h"

namespace imufit {
namespace {

struct LotArguments {
  std::string store;
  std::string lot;
  std::string html;
  std::string csv;
  std::string limits;
};

int RunLot(const LotArguments& args) {
  if (args.html.empty() && args.csv.empty())
    throw InputError("imufit lot", "give --html OUT.html, --csv OUT.csv or both");
  for (const std::string* output : {&args.html, &args.csv}) {
    if (!output->empty()) RefuseToOverwriteInputs(*output, {args.store, args.limits});
  }
  std::optional<Limits> limits;
  if (!args.limits.empty()) limits = ReadLimits(args.limits);
  ResultsStore store(args.store, StoreAccess::kRead);
  const BatchResult lot = StoredLot(&store, args.lot);
  if (lot.units.empty()) throw InputError(store.path(), "no lot named " + QuoteForMessage(args.lot));
  OutputTransaction outputs;  // both files, or neither
  if (!args.csv.empty()) WriteFileAtomically(args.csv, LotSummaryCsv(lot), &outputs);
  if (!args.html.empty()) {
    LotSummary summary = MakeLotSummary(args.lot, lot, SoftwareVersion(), limits);
    summary.history = MakeLotHistory(&store, args.lot, limits ? &*limits : nullptr);
    WriteFileAtomically(args.html, LotPageHtml(summary), &outputs);
  }
  outputs.Commit();
  return 0;
}

}  // namespace

CommandRunner AddLotCommand(CliCommand command) {
  auto args = std::make_shared<LotArguments>();
  command.Option("--store", &args->store, "the results store: an SQLite file or a PostgreSQL URL").Required();
  command.Option("--lot", &args->lot, "the lot's name in the store").Required();
  command.Option("--html", &args->html, "write the lot page (as the batch's lot.html) here");
  command.Option("--csv", &args->csv, "write the lot summary (as the batch's lot_summary.csv) here");
  command.Option("--limits,-l", &args->limits, "the acceptance limits the lot was judged with (drawn)");
  return [args] { return RunLot(*args); };
}

}  // namespace imufit
