// imufit store merge SRC... --into DEST — uploads station stores (SQLite files) into the factory's
// store (PostgreSQL, or another SQLite file); run again, it changes nothing (factory/store.h).
#include <cstdio>
#include <memory>

#include "commands.h"
#include "imufit/store/store.h"

namespace imufit {
namespace {

struct MergeArguments {
  std::vector<std::string> sources;
  std::string into;
};

int RunMerge(const MergeArguments& args) {
  for (const MergeResult& r : MergeStores(args.sources, args.into)) {
    std::printf("%s: %lld fits, %lld new\n", r.source.c_str(), static_cast<long long>(r.fits),
                static_cast<long long>(r.added));
  }
  return 0;
}

}  // namespace

CommandRunner AddStoreCommand(CliCommand command) {
  auto args = std::make_shared<MergeArguments>();
  command.RequireSubcommand();
  CliCommand merge = command.Subcommand(
      "merge",
      "Copy every fit of the SRC stores into DEST (a PostgreSQL URL or connection string, or an SQLite "
      "file); a fit DEST holds already is left as it is, so merging again changes nothing.");
  merge.Option("sources", &args->sources, "station stores (SQLite files, or PostgreSQL URLs)").Required();
  merge.Option("--into", &args->into, "the store to merge into (created when a missing SQLite file)")
      .Required();
  return [args] { return RunMerge(*args); };
}

}  // namespace imufit
