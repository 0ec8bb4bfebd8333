// imufit batch — fits every unit of a lot, judges it against acceptance limits, writes each unit's
// calibration (and report) and the lot summary, records every fit in the results store.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "commands.h"
#include "imufit/factory/batch.h"
#include "imufit/io/error.h"

namespace imufit {
namespace {

struct BatchArguments {
  CliOptions<BatchOptions> batch;  // BatchOptionTable(): the folders, --jobs, --max-units, --no-report
  FitRunArguments run;             // every unit is fitted with these, as imufit fit would fit it
  PdfArguments pdf;
  CustomerArguments customer;
  bool quiet = false;
  std::string shard;  // --shard I/N, auto, auto/N
};

// Units done, rate and time left: one updating line on a terminal, plain lines otherwise.
void ShowProgress(const BatchProgress& p, bool terminal) {
  const int fitted = p.done - p.skipped;
  const double rate = p.elapsed_s > 0.0 && fitted > 0 ? fitted / p.elapsed_s : 0.0;
  const double left_s = rate > 0.0 ? (p.total - p.done) / rate : 0.0;
  const UnitOutcome& u = *p.last;
  const std::string outcome =
      u.skipped ? "unchanged, skipped"
                : std::string(u.StatusText()) + (u.verdict ? std::string(" ") + u.VerdictText() : "");
  if (terminal) {
    std::fprintf(stderr, "\r\033[K[%d/%d] %.2f units/s, %.0f s left; %s: %s", p.done, p.total, rate, left_s,
                 u.unit.c_str(), outcome.c_str());
    if (p.done == p.total) std::fprintf(stderr, "\n");
  } else {
    std::fprintf(stderr, "imufit batch: [%d/%d] %s: %s%s%s (%.1f s; %.2f units/s, %.0f s left)\n", p.done,
                 p.total, u.unit.c_str(), outcome.c_str(), u.message.empty() ? "" : ": ", u.message.c_str(),
                 u.seconds, rate, left_s);
  }
  std::fflush(stderr);
}

int RunBatchCommand(const BatchArguments& args) {
  BatchOptions options;
  args.batch.Apply(&options);
  options.fit = args.run.Resolve();
  options.fit.software = SoftwareVersion();
  options.fit.fit.num_threads = 1;  // parallel over units instead
  const bool terminal = isatty(STDERR_FILENO) != 0;
  if (!args.quiet) options.progress = [terminal](const BatchProgress& p) { ShowProgress(p, terminal); };
  if (args.pdf.pdf && !options.write_reports)
    throw InputError("--pdf", "prints the certificates: leave out --no-report");
  options.paper = args.pdf.Resolve();
  args.customer.Check();
  options.customer = args.customer.customer;
  options.order = args.customer.order;
  options.write_pdf = args.pdf.pdf;
  if (!args.shard.empty())
    options.shard = ParseShard(args.shard, [](const char* name) { return std::getenv(name); });
  const BatchResult result = RunBatch(options);
  // Warnings even with --quiet, as imufit fit gives them (a unit skipped as unchanged gave its own
  // when it was fitted; its certificate keeps them).
  for (const UnitOutcome& u : result.units) {
    for (const std::string& warning : u.warnings) {
      std::fprintf(stderr, "imufit: warning: %s: %s\n", u.unit.c_str(), warning.c_str());
    }
  }
  if (!args.quiet) {
    std::printf(
        "imufit batch: %zu units: %d passed, %d failed limits, %d not fitted, %d errors; %d unchanged and "
        "skipped\n",
        result.units.size(), result.passed, result.failed, result.not_fitted, result.errors, result.skipped);
    for (const UnitOutcome& u : result.units) {
      if (u.verdict ? u.verdict->pass : u.status == UnitStatus::kFitted) continue;
      std::printf("  %s (%s): %s%s%s\n", u.unit.c_str(), u.serial.c_str(),
                  u.verdict ? u.VerdictText() : u.StatusText(), u.message.empty() ? "" : ": ",
                  u.message.c_str());
    }
    // A shard writes no lot summary (the store holds the lot: imufit lot, imufit history --lot).
    if (result.complete && options.shard.count == 1)
      std::printf("  wrote %s/lot_summary.csv\n", options.output_dir.c_str());
  }
  if (!result.complete) {
    std::fprintf(stderr, "imufit batch: stopped after --max-units %d; run again to finish the lot\n",
                 options.max_units);
    return 1;
  }
  return result.failed + result.not_fitted + result.errors > 0 ? kExitFailedLimits : 0;
}

}  // namespace

CommandRunner AddBatchCommand(CliCommand command) {
  auto args = std::make_shared<BatchArguments>();
  args->batch.Add(command, BatchOptionTable());
  args->batch.Find("output_dir").Required();
  command.Option("--shard", &args->shard,
                 "fit only this shard of the lot: I/N (units whose folder name hashes to I of N), auto "
                 "(Slurm array), auto/N (Kubernetes JOB_COMPLETION_INDEX or GNU parallel's PARALLEL_SEQ); "
                 "with shards, the lot page comes from the store (imufit history --lot)");
  AddPdfOptions(command, &args->pdf);
  AddCustomerOptions(command, &args->customer);
  // Not --threads (units run in parallel instead) nor a check run (a lot has no held-out runs).
  AddFitRunOptions(command, &args->run, {"threads", "check_samples", "check_plan"});
  command.Flag("--quiet,-q", &args->quiet, "print nothing but errors");
  return [args] { return RunBatchCommand(*args); };
}

}  // namespace imufit
