#include "imufit/factory/batch.h"

#include <fcntl.h>
#include <fnmatch.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "imufit/base/text.h"
#include "imufit/factory/certificate.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/factory/report.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/io/station.h"
#include "imufit/store/store.h"

namespace imufit {

const std::vector<std::string> kSummaryFigures = {"gyro_bias_dps.x",
                                                  "gyro_bias_dps.y",
                                                  "gyro_bias_dps.z",
                                                  "accel_bias_mg.x",
                                                  "accel_bias_mg.y",
                                                  "accel_bias_mg.z",
                                                  "gyro_scale_per_dps.x",
                                                  "gyro_scale_per_dps.y",
                                                  "gyro_scale_per_dps.z",
                                                  "gyro_g_sensitivity_dpsg.xx",
                                                  "gyro_g_sensitivity_dpsg.yy",
                                                  "gyro_g_sensitivity_dpsg.zz",
                                                  "gyro_residual_rms_dps",
                                                  "accel_residual_rms_mg"};

namespace {

namespace fs = std::filesystem;

constexpr const char* kManifestFormat = "imufit-unit-manifest";

// What a unit's manifest records: enough to know whether its inputs changed, and its outcome.
struct Manifest {
  std::string software, plan_sha256, samples_sha256, limits_sha256;
  std::string serial, status, verdict, message;
  std::string calibration_sha256;  // of the calibration written (fitted units)
  std::string station_sha256;      // "" without a station file
  std::string fit_options;         // FitRunOptions::Describe(): what the unit was fitted with
  std::string issued_to;           // --customer and --order, as the certificate prints them
  // The outcome as judged when the unit was fitted (its certificate's budget and measurements), so
  // that a unit skipped as unchanged states the same U and criteria: each key figure's U, and each
  // criterion's name, outcome and acceptance. `judged` is false in a manifest of an imufit that did
  // not record them: then the unit is done again.
  bool judged = false;
  std::vector<std::pair<std::string, double>> expanded_u;
  std::vector<CriterionResult> criteria;  // name, outcome and pass only
};

std::optional<Manifest> ReadManifest(const std::string& path) {
  if (!fs::exists(path)) return std::nullopt;
  try {
    const YAML::Node node = YAML::LoadFile(path);
    if (node["format"].as<std::string>() != kManifestFormat || node["version"].as<int>() != 1)
      return std::nullopt;
    Manifest m;
    std::string* fields[] = {&m.software, &m.plan_sha256, &m.samples_sha256, &m.limits_sha256,
                             &m.serial,   &m.status,      &m.verdict,        &m.message};
    const char* keys[] = {"software", "plan_sha256", "samples_sha256", "limits_sha256",
                          "serial",   "status",      "verdict",        "message"};
    for (int i = 0; i < 8; ++i) *fields[i] = node[keys[i]].as<std::string>();
    if (node["calibration_sha256"]) m.calibration_sha256 = node["calibration_sha256"].as<std::string>();
    if (node["station_sha256"]) m.station_sha256 = node["station_sha256"].as<std::string>();
    // Absent in a manifest of an imufit that did not record the options: they are unknown, so the
    // unit is done again.
    if (node["fit_options"]) m.fit_options = node["fit_options"].as<std::string>();
    if (node["issued_to"]) m.issued_to = node["issued_to"].as<std::string>();
    if (const YAML::Node judged = node["judged"]) {
      m.judged = true;
      for (const auto& entry : judged["expanded_u"])
        m.expanded_u.emplace_back(entry.first.as<std::string>(), entry.second.as<double>());
      for (const YAML::Node& item : judged["criteria"]) {
        CriterionResult c;
        c.name = item[0].as<std::string>();
        c.pass = item[2].as<bool>();
        if (!ValueOf(kOutcomeNames, item[1].as<std::string>(), &c.outcome)) return std::nullopt;
        m.criteria.push_back(c);
      }
    }
    return m;
  } catch (const YAML::Exception&) {
    return std::nullopt;  // unreadable: the unit is done again
  }
}

// Written by the one machine-text writer (io/machine_text.h): every value a string to every YAML
// reader (a serial "007" or a hash of digits is quoted, not read as a number).
void WriteManifest(const std::string& path, const Manifest& m, OutputTransaction* transaction) {
  MachineDoc doc = MachineDoc::Map();
  doc.CommentFirst({"imufit batch: this unit's inputs and outcome; delete to redo it"});
  doc.Add("format", MachineDoc::Text(kManifestFormat));
  doc.Add("version", MachineDoc::Integer(1));
  const std::pair<const char*, const std::string*> fields[] = {{"software", &m.software},
                                                               {"plan_sha256", &m.plan_sha256},
                                                               {"samples_sha256", &m.samples_sha256},
                                                               {"limits_sha256", &m.limits_sha256},
                                                               {"serial", &m.serial},
                                                               {"status", &m.status},
                                                               {"verdict", &m.verdict},
                                                               {"message", &m.message},
                                                               {"calibration_sha256", &m.calibration_sha256},
                                                               {"station_sha256", &m.station_sha256},
                                                               {"fit_options", &m.fit_options},
                                                               {"issued_to", &m.issued_to}};
  for (const auto& [key, value] : fields) doc.Add(key, MachineDoc::Text(*value));
  MachineDoc judged = MachineDoc::Map();
  MachineDoc expanded = MachineDoc::Map();
  for (const auto& [name, u] : m.expanded_u) expanded.Add(name, MachineDoc::Number(u));
  judged.Add("expanded_u", std::move(expanded));
  MachineDoc criteria = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const CriterionResult& c : m.criteria) {
    criteria.Push(std::move(MachineDoc::List()
                                .Push(MachineDoc::Text(c.name))
                                .Push(MachineDoc::Text(OutcomeName(c.outcome)))
                                .Push(MachineDoc::Bool(c.pass))));
  }
  judged.Add("criteria", std::move(criteria));
  doc.Add("judged", std::move(judged));
  WriteFileAtomically(path, YamlText(doc), transaction);
}

// Temporary files of outputs a killed run never committed (OutputFile's ".NAME.tmp-XXXXXX").
void RemoveLeftovers(const fs::path& folder) {
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 1 && name[0] == '.' && name.find(".tmp-") != std::string::npos)
      fs::remove(entry.path(), error);
  }
}

// Holds an exclusive lock on OUT_DIR/.imufit-batch.lock: two batches never write one folder.
class FolderLock {
 public:
  FolderLock(const std::string& folder, const Shard& shard) {
    const std::string name = shard.count > 1 ? ".imufit-batch-shard-" + std::to_string(shard.index) + "-of-" +
                                                   std::to_string(shard.count) + ".lock"
                                             : ".imufit-batch.lock";
    const std::string path = (fs::path(folder) / name).string();
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw InputError(path, "cannot create the lock file");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw InputError(folder, "another imufit batch is writing to this folder");
    }
  }
  ~FolderLock() { ::close(fd_); }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

// Everything a worker needs that is shared by all units.
struct Shared {
  const BatchOptions* options = nullptr;
  CertifySettings certify;  // the software, limits, station, store and lot
  std::string fit_options;  // options->fit.Describe()
  std::unique_ptr<ResultsStore> store;
};

// Where a unit's outputs go: OUT_DIR/<unit>/.
struct UnitPaths {
  fs::path folder;
  std::string calibration, report, pdf, manifest;
};

UnitPaths PathsOf(const BatchOptions& options, const std::string& unit) {
  UnitPaths paths;
  paths.folder = fs::path(options.output_dir) / unit;
  paths.calibration = (paths.folder / "calibration.yaml").string();
  paths.report = (paths.folder / "report.html").string();
  if (options.write_pdf) paths.pdf = (paths.folder / "report.pdf").string();
  paths.manifest = (paths.folder / "manifest.yaml").string();
  return paths;
}

// One unit to fit: a folder of UNITS_DIR, or a line of --units-list.
struct UnitInput {
  std::string name;  // OUT_DIR/<name>/: the folder's name, or the list's serial
  fs::path dir;      // the unit folder (a folder unit)
  bool listed = false;
  // A listed unit: its serial, where the list states it ("units.csv line 3"), its samples and plan
  // (empty: the shared --plan).
  std::string serial, serial_source, samples, plan;
};

// The serial in UNIT/serial.txt (its first line, trimmed), or "" without that file.
std::string SerialFile(const fs::path& unit_dir) {
  std::ifstream stream(unit_dir / "serial.txt");
  std::string line;
  if (!stream || !std::getline(stream, line)) return "";
  const size_t first = line.find_first_not_of(" \t\r");
  const size_t last = line.find_last_not_of(" \t\r");
  return first == std::string::npos ? "" : line.substr(first, last - first + 1);
}

// What a unit folder holds, for a message: "it has: a.csv, plan.yaml" or "it is empty".
std::string FolderContents(const fs::path& dir) {
  constexpr size_t kMostNamesShown = 8;
  std::set<std::string> names;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error))
    names.insert(entry.path().filename().string() + (entry.is_directory() ? "/" : ""));
  if (names.empty()) return "it is empty";
  std::vector<std::string> shown(names.begin(), names.end());
  const size_t more = shown.size() > kMostNamesShown ? shown.size() - kMostNamesShown : 0;
  shown.resize(shown.size() - more);
  return "it has: " + Join(shown, ", ") + (more > 0 ? " and " + std::to_string(more) + " more" : "");
}

// The unit folder's samples file: the one file matching --samples-glob, else samples.csv.gz or
// samples.csv. A folder with both (today's run beside yesterday's) is refused: which one is this
// unit's run is not imufit's to guess.
std::string FindSamples(const BatchOptions& options, const fs::path& unit_dir) {
  if (options.samples_glob.empty()) {
    const bool gz = fs::exists(unit_dir / "samples.csv.gz"), plain = fs::exists(unit_dir / "samples.csv");
    if (gz && plain) {
      throw InputError(unit_dir.string(),
                       "holds both samples.csv and samples.csv.gz: which is this unit's run? (move the other "
                       "away, or name one with --samples-glob)");
    }
    if (gz || plain) return (unit_dir / (gz ? "samples.csv.gz" : "samples.csv")).string();
    throw InputError(unit_dir.string(), "no samples.csv or samples.csv.gz (" + FolderContents(unit_dir) +
                                            "; --samples-glob names the logger's samples file)");
  }
  std::vector<std::string> matches;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(unit_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_directory() && fnmatch(options.samples_glob.c_str(), name.c_str(), FNM_PERIOD) == 0)
      matches.push_back(name);
  }
  std::sort(matches.begin(), matches.end());
  if (matches.size() == 1) return (unit_dir / matches[0]).string();
  const std::string glob = "--samples-glob \"" + options.samples_glob + "\"";
  if (matches.empty())
    throw InputError(unit_dir.string(), glob + " matches no file (" + FolderContents(unit_dir) + ")");
  throw InputError(unit_dir.string(), glob + " matches " + std::to_string(matches.size()) +
                                          " files, one unit's samples are one file: " + Join(matches, ", "));
}

// The unit's plan (the list's, its plan.yaml, else the shared plan) and samples (the list's, or
// FindSamples'), and their hashes.
void FindInputs(const BatchOptions& options, const UnitInput& input, UnitOutcome* unit) {
  std::string samples = input.samples, plan = input.plan;
  if (input.listed) {
    if (!fs::exists(samples)) throw InputError(samples, "no such file (" + input.serial_source + ")");
    if (!plan.empty() && !fs::exists(plan))
      throw InputError(plan, "no such file (" + input.serial_source + ")");
  } else {
    samples = FindSamples(options, input.dir);
    plan = (input.dir / "plan.yaml").string();
    if (!fs::exists(plan)) plan.clear();
  }
  if (plan.empty()) {
    if (options.shared_plan.empty())
      throw InputError(
          input.listed ? input.serial_source : input.dir.string(),
          input.listed ? "no plan in the list and no shared --plan" : "no plan.yaml and no shared --plan");
    plan = options.shared_plan;
  }
  unit->plan_path = plan;
  unit->samples_path = samples;
  unit->plan_sha256 = Sha256OfFile(plan);
  unit->samples_sha256 = Sha256OfFile(samples);
}

// What the unit's manifest says of its inputs (the outcome is added when the unit is done).
Manifest InputsManifest(const Shared& shared, const UnitOutcome& unit) {
  Manifest manifest;
  manifest.software = shared.options->fit.software;
  manifest.plan_sha256 = unit.plan_sha256;
  manifest.samples_sha256 = unit.samples_sha256;
  manifest.limits_sha256 = shared.certify.limits_sha256;
  manifest.station_sha256 = shared.certify.station_sha256;
  manifest.fit_options = shared.fit_options;
  if (!shared.certify.customer.empty() || !shared.certify.order.empty())
    manifest.issued_to = "customer: " + shared.certify.customer + "; order: " + shared.certify.order;
  return manifest;
}

// Takes a finished run's outcome when the unit is unchanged since (the same inputs, fit options
// and software, and its outputs still there): then nothing is redone.
bool TakeUnchanged(const Shared& shared, const Manifest& manifest, const UnitPaths& paths,
                   UnitOutcome* unit) {
  const std::optional<Manifest> previous = ReadManifest(paths.manifest);
  if (!previous || previous->software != manifest.software || previous->plan_sha256 != manifest.plan_sha256 ||
      previous->samples_sha256 != manifest.samples_sha256 ||
      previous->limits_sha256 != manifest.limits_sha256 ||
      previous->station_sha256 != manifest.station_sha256 || previous->fit_options != manifest.fit_options ||
      previous->issued_to != manifest.issued_to || !previous->judged) {
    return false;
  }
  UnitStatus status = UnitStatus::kError;
  if (!ValueOf(kUnitStatusNames, previous->status, &status)) return false;  // not ours: done again
  if (status == UnitStatus::kFitted &&
      !(fs::exists(paths.calibration) && (!shared.options->write_reports || fs::exists(paths.report)) &&
        (paths.pdf.empty() || fs::exists(paths.pdf)))) {
    return false;
  }
  unit->skipped = true;
  unit->serial = previous->serial;
  unit->status = status;
  if (unit->status == UnitStatus::kFitted) {
    const Calibration calibration = ReadCalibration(paths.calibration);
    JudgeUnit(shared.certify, calibration, nullptr, unit);
    // The outcome is the one judged when the unit was fitted (with its certificate's noise, window
    // errors and uncertainty budget), as its manifest and the store hold it: not judged again from
    // less. The figures' values and sigmas are the calibration's; their U and the criteria the
    // manifest's.
    for (Figure& f : unit->figures) {
      for (const auto& [name, u] : previous->expanded_u) {
        if (name == f.name) f.expanded = u;
      }
    }
    if (unit->verdict) {
      bool pass = false;
      if (!ValueOf(kVerdictNames, previous->verdict, &pass)) return false;  // not ours: done again
      unit->verdict->pass = pass;
      unit->verdict->criteria = previous->criteria;
    }
    unit->attachments = {{"calibration", paths.calibration, previous->calibration_sha256}};
    if (shared.options->write_reports)
      unit->attachments.push_back({"certificate", paths.report, Sha256OfFile(paths.report)});
    if (shared.options->write_reports && !paths.pdf.empty())
      unit->attachments.push_back({"certificate_pdf", paths.pdf, Sha256OfFile(paths.pdf)});
  }
  unit->message = previous->message;
  return true;
}

// Refuses a unit whose run (serial, plan and samples) the store holds under another lot than this
// batch's: a run keeps the lot it was first recorded in, so recording it would put it there, and
// `imufit lot --lot` of this batch's lot would not find it. The unit is an error saying so, neither
// recorded nor marked done (throws InputError).
void RefuseAnotherLotsRun(const Shared& shared, const UnitOutcome& unit) {
  if (shared.store == nullptr) return;
  StoredFit run;
  run.serial = unit.serial.empty() ? unit.unit : unit.serial;
  run.plan_sha256 = unit.plan_sha256;
  run.samples_sha256 = unit.samples_sha256;
  const std::optional<std::string> lot = shared.store->LotOfRun(run);
  if (!lot || *lot == shared.certify.lot) return;
  throw InputError(unit.samples_path, "this run of " + run.serial + " is recorded in lot " +
                                          QuoteForMessage(*lot) + " of " + shared.store->path() + ", not " +
                                          QuoteForMessage(shared.certify.lot) +
                                          ": a run belongs to the lot it was first recorded in (give --lot " +
                                          *lot + ", or another --store)");
}

// A unit skipped as unchanged that the store does not know (a new store, or another one): recorded
// from its manifest and calibration, so that the store holds every unit of the lot.
void RecordSkippedUnit(const Shared& shared, const UnitPaths& paths, UnitOutcome* unit) {
  if (shared.store == nullptr || shared.store->HasUnit(shared.certify.lot, unit->unit)) return;
  RefuseAnotherLotsRun(shared, *unit);
  if (unit->status == UnitStatus::kFitted) {
    std::ifstream stream(paths.calibration, std::ios::binary);
    unit->calibration_yaml.assign(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
  }
  RecordUnit(shared.certify, unit);
  unit->calibration_yaml.clear();
}

// The warning, on stderr and the certificate, for a unit that nothing names.
constexpr const char* kSerialNotStated =
    "serial not stated: the unit folder's name is used (no serial.txt, no \"# serial:\" line in the samples "
    "header, no serial in the plan)";

// Fits the unit, whose serial.txt (or list line) states its serial. A unit not fitted says why; a fitted
// one's calibration carries the unit's serial (the folder name when nothing else names the unit).
void FitUnit(const Shared& shared, const UnitInput& input, const UnitPaths& paths, UnitOutcome* unit) {
  fs::create_directories(paths.folder);
  RemoveLeftovers(paths.folder);
  FitRunOptions options = shared.options->fit;
  options.serial = input.listed ? input.serial : SerialFile(input.dir);
  options.serial_source = input.listed ? input.serial_source : (input.dir / "serial.txt").string();
  options.plan_sha256 = unit->plan_sha256;
  // The certificate's noise section: measured whenever the unit is judged, printed or not.
  options.keep_static_stretch =
      shared.options->write_reports || shared.certify.limits || shared.certify.store != nullptr;
  unit->fit = FitRun(unit->plan_path, unit->samples_path, options);
  FitRunResult& result = *unit->fit;
  if (!result.serial.empty()) unit->serial = result.serial;  // serial.txt, the samples', the plan's
  unit->warnings = result.serial_warnings;
  unit->warnings.insert(unit->warnings.end(), result.run_warnings.begin(), result.run_warnings.end());
  if (result.serial.empty()) unit->warnings.push_back(kSerialNotStated);
  if (result.fit.status == FitStatus::kUndetermined) {
    unit->status = UnitStatus::kNotFitted;
    unit->message = "the run does not determine the model: " + Join(result.fit.undetermined, "; ");
  } else if (!result.calibration) {
    unit->status = UnitStatus::kNotFitted;
    unit->message = result.fit.BriefReport();
  } else if (result.calibration->serial.empty()) {
    result.calibration->serial = unit->serial;
  }
}

// Marks the unit done: its manifest, in the transaction of the unit's other outputs.
void WriteUnitManifest(const UnitPaths& paths, const UnitOutcome& unit, Manifest manifest,
                       OutputTransaction* transaction) {
  manifest.serial = unit.serial;
  manifest.status = unit.StatusText();
  manifest.verdict = unit.VerdictText();
  manifest.message = unit.message;
  for (const Figure& f : unit.figures) {
    if (f.sigma >= 0.0 && f.expanded >= 0.0) manifest.expanded_u.emplace_back(f.name, f.expanded);
  }
  if (unit.verdict) manifest.criteria = unit.verdict->criteria;
  if (!unit.calibration_yaml.empty()) manifest.calibration_sha256 = Sha256Hex(unit.calibration_yaml);
  fs::create_directories(paths.folder);
  WriteManifest(paths.manifest, manifest, transaction);
}

// A failure that is not the unit's (the output folder or the disk, a read error, memory): the unit
// is neither recorded nor marked done, so the next run does it again.
bool OutsideTheUnit(const InputError& e) {
  const std::string& m = e.message();
  return m.rfind("cannot read", 0) == 0 || m.rfind("cannot open", 0) == 0 || m.rfind("cannot stat", 0) == 0;
}

// The batch's progress for the interrupt note (a signal handler reads them).
std::atomic<int> g_units_done{0};
std::atomic<int> g_units_total{0};

// Appends the decimal digits of `value` (async-signal-safe).
char* AppendNumber(char* out, int value) {
  char digits[16];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value > 0 && n < 16);
  while (n > 0) *out++ = digits[--n];
  return out;
}

// "imufit: interrupted: 3 of 8 units done; run the same command again to finish", from a signal handler.
void InterruptNote() {
  char line[160];
  char* out = line;
  const auto append = [&out](const char* text) {
    while (*text) *out++ = *text++;
  };
  append("\nimufit: interrupted: ");
  out = AppendNumber(out, g_units_done.load());
  append(" of ");
  out = AppendNumber(out, g_units_total.load());
  append(" units done; run the same command again to finish\n");
  [[maybe_unused]] const ssize_t written = ::write(2, line, static_cast<size_t>(out - line));
}

UnitOutcome ProcessUnit(const Shared& shared, const UnitInput& input) {
  const auto start = std::chrono::steady_clock::now();
  UnitOutcome unit;
  unit.unit = input.name;
  unit.serial = unit.unit;
  unit.status = UnitStatus::kError;
  const UnitPaths paths = PathsOf(*shared.options, unit.unit);
  Manifest manifest;
  bool done = false;     // certified: outputs, manifest and store row committed together
  bool outside = false;  // failed for a reason outside the unit: not marked done
  try {
    FindInputs(*shared.options, input, &unit);
    manifest = InputsManifest(shared, unit);
    if (TakeUnchanged(shared, manifest, paths, &unit)) {
      try {
        RecordSkippedUnit(shared, paths, &unit);
      } catch (const InputError& e) {  // recorded under another lot: said, not recorded
        unit.status = UnitStatus::kError;
        unit.verdict.reset();
        unit.message = e.what();
      }
      return unit;
    }
    FitUnit(shared, input, paths, &unit);
  } catch (const InputError& e) {
    unit.status = UnitStatus::kError;
    unit.message = e.what();
    outside = OutsideTheUnit(e);
  } catch (const std::exception& e) {
    unit.status = UnitStatus::kError;
    unit.message = std::string("error: ") + e.what();
    outside = true;
  }
  if (!outside && !unit.plan_sha256.empty()) {
    try {
      RefuseAnotherLotsRun(shared, unit);
    } catch (const InputError& e) {  // a run of another lot: said, neither recorded nor marked done
      unit.status = UnitStatus::kError;
      unit.verdict.reset();
      unit.message = e.what();
      outside = true;
    }
  }
  try {
    if (!outside && unit.fit && unit.fit->calibration) {
      const bool reports = shared.options->write_reports;
      UnitFiles files;
      files.calibration = paths.calibration;
      files.report = reports ? paths.report : "";
      files.pdf = reports ? paths.pdf : "";
      files.paper = shared.options->paper;
      files.more = [&](const UnitOutcome& judged, OutputTransaction* outputs) {
        WriteUnitManifest(paths, judged, manifest, outputs);
      };
      CertifyUnit(shared.certify, files, &unit);
      unit.fit->run.static_stretch.reset();  // measured: not kept for the rest of the lot
      done = true;
    }
    // Not fitted, or the unit's own bad input: recorded and marked done together.
    if (!outside && !done && !unit.plan_sha256.empty()) {
      OutputTransaction outputs;
      WriteUnitManifest(paths, unit, manifest, &outputs);
      RecordUnit(shared.certify, &unit, &outputs);
    }
  } catch (const std::exception& e) {  // an output could not be written: nothing was
    unit.status = UnitStatus::kError;
    unit.verdict.reset();
    unit.message = std::string("not written (the unit is done again on the next run): ") + e.what();
  }
  unit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return unit;
}

void WriteLotSummary(const std::string& path, const BatchResult& result) {
  OutputFile out(path);
  out.Write(LotSummaryCsv(result));
  out.Commit();
}

// The lot's name in the store: --lot, else the units folder's name (the list's, without its
// extension).
std::string LotName(const BatchOptions& options) {
  if (!options.lot.empty()) return options.lot;
  if (!options.units_list.empty()) return fs::path(options.units_list).stem().string();
  const fs::path units = fs::path(options.units_dir).lexically_normal();
  const std::string name = units.filename().string();
  return name.empty() ? units.parent_path().filename().string() : name;  // "units/" ends in ""
}

// The unit folders of `shard`, in name order (not .git and the like, nor the batch's own output
// folder when it lies among them: a re-run does not take its outputs for a unit).
std::vector<UnitInput> ListUnits(const std::string& units_dir, const std::string& output_dir,
                                 const Shard& shard) {
  std::vector<UnitInput> units;
  for (const fs::directory_entry& entry : fs::directory_iterator(units_dir)) {
    const std::string name = entry.path().filename().string();
    std::error_code error;
    if (fs::equivalent(entry.path(), output_dir, error)) continue;
    if (entry.is_directory() && name[0] != '.' && ShardOf(name, shard.count) == shard.index) {
      UnitInput unit;
      unit.name = name;
      unit.dir = entry.path();
      units.push_back(unit);
    }
  }
  std::sort(units.begin(), units.end(),
            [](const UnitInput& a, const UnitInput& b) { return a.name < b.name; });
  return units;
}

// The fields of a unit list's line: comma-separated (trimmed) when it has a comma, read as CSV
// (RFC 4180: a field in double quotes may hold commas, "" is a quote, as a spreadsheet writes it),
// else separated by blanks.
std::vector<std::string> ListFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  if (line.find(',') != std::string::npos) {
    const auto trimmed = [](const std::string& text) {
      const size_t first = text.find_first_not_of(" \t"), last = text.find_last_not_of(" \t");
      return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
    };
    bool quoted = false, was_quoted = false;
    for (size_t i = 0; i <= line.size(); ++i) {
      const char c = i < line.size() ? line[i] : ',';
      if (quoted) {
        if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
          field += '"';
          ++i;
        } else if (c == '"') {
          quoted = false;
        } else {
          field += c;
        }
      } else if (c == '"' && trimmed(field).empty()) {
        quoted = was_quoted = true;
        field.clear();
      } else if (c == ',') {
        fields.push_back(was_quoted ? field : trimmed(field));
        field.clear();
        was_quoted = false;
      } else if (!was_quoted || (c != ' ' && c != '\t')) {
        field += c;
      }
    }
  } else {
    std::istringstream words(line);
    while (words >> field) fields.push_back(field);
  }
  return fields;
}

// The units of --units-list in `shard`: one a line, "serial, samples[, plan]" (paths relative to
// the list's folder), an optional header line starting "serial", blank lines and # comments.
std::vector<UnitInput> ReadUnitsList(const std::string& list, const Shard& shard) {
  std::ifstream stream(list);
  if (!stream) throw InputError(list, "cannot open the unit list");
  const fs::path base = fs::path(list).parent_path();
  std::vector<UnitInput> units;
  std::map<std::string, long> lines_of;
  std::string line;
  for (long number = 1; std::getline(stream, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte order mark
    const std::vector<std::string> f = ListFields(line);
    if (f.empty() || f[0].empty() || f[0][0] == '#' ||
        (units.empty() && lines_of.empty() && f[0] == "serial"))
      continue;
    if (f.size() < 2 || f.size() > 3 || f[1].empty())
      throw InputError(list, number, 1,
                       "a unit is \"serial, samples file[, plan]\"; this line has " +
                           std::to_string(f.size()) + (f.size() == 1 ? " field" : " fields"));
    if (f[0] == "." || f[0] == ".." || f[0][0] == '.' || f[0].find('/') != std::string::npos)
      throw InputError(list, number, 1,
                       "serial " + QuoteForMessage(f[0]) + " cannot name the unit's output folder");
    if (const auto [at, added] = lines_of.emplace(f[0], number); !added)
      throw InputError(list, number, 1,
                       "serial " + QuoteForMessage(f[0]) + " is listed twice (lines " +
                           std::to_string(at->second) + " and " + std::to_string(number) + ")");
    if (ShardOf(f[0], shard.count) != shard.index) continue;
    UnitInput unit;
    unit.name = unit.serial = f[0];
    unit.listed = true;
    unit.serial_source = list + " line " + std::to_string(number);
    unit.samples = (base / f[1]).string();
    if (f.size() == 3 && !f[2].empty()) unit.plan = (base / f[2]).string();
    units.push_back(unit);
  }
  std::sort(units.begin(), units.end(),
            [](const UnitInput& a, const UnitInput& b) { return a.name < b.name; });
  return units;
}

// Everything shared by the units, each input checked: a bad one is the lot's error, before any unit.
void Prepare(const BatchOptions& options, Shared* shared, std::vector<UnitInput>* units) {
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit batch", problem);
  if (options.units_list.empty() && !fs::is_directory(options.units_dir))
    throw InputError(options.units_dir, "not a folder");
  *units = options.units_list.empty() ? ListUnits(options.units_dir, options.output_dir, options.shard)
                                      : ReadUnitsList(options.units_list, options.shard);
  shared->options = &options;
  shared->fit_options = options.fit.Describe();
  shared->certify.fit_options = shared->fit_options;
  shared->certify.software = options.fit.software;
  shared->certify.windows = options.fit.windows;
  shared->certify.samples_input = options.fit.input;
  ReadLimitsAndStation(options.limits_path, options.station_path, &shared->certify);
  shared->certify.customer = options.customer;
  shared->certify.order = options.order;
  if (!options.shared_plan.empty()) ReadPlan(options.shared_plan);
  std::error_code error;
  fs::create_directories(options.output_dir, error);
  if (!fs::is_directory(options.output_dir))
    throw InputError(options.output_dir, "cannot create the output folder");
}

// The units processed by a pool of threads; a unit is nullopt when max_units stopped the batch
// before it.
std::vector<std::optional<UnitOutcome>> ProcessUnits(const Shared& shared,
                                                     const std::vector<UnitInput>& units) {
  const BatchOptions& options = *shared.options;
  std::vector<std::optional<UnitOutcome>> outcomes(units.size());
  std::atomic<size_t> next{0};
  std::atomic<int> fitted{0};
  std::mutex progress_mutex;
  BatchProgress progress;
  progress.total = static_cast<int>(units.size());
  g_units_done.store(0);
  g_units_total.store(progress.total);
  const auto start = std::chrono::steady_clock::now();
  const auto worker = [&] {
    for (;;) {
      if (options.max_units > 0 && fitted.load() >= options.max_units) return;
      const size_t i = next.fetch_add(1);
      if (i >= units.size()) return;
      UnitOutcome outcome = ProcessUnit(shared, units[i]);
      if (!outcome.skipped) ++fitted;
      std::lock_guard<std::mutex> lock(progress_mutex);
      outcomes[i] = std::move(outcome);
      ++progress.done;
      progress.skipped += outcomes[i]->skipped ? 1 : 0;
      progress.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress.last = &*outcomes[i];
      g_units_done.store(progress.done);
      if (options.progress) options.progress(progress);
    }
  };
  int jobs =
      options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = std::min<int>(jobs, std::max<size_t>(units.size(), 1));
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  return outcomes;
}

// The finished units and their counts.
BatchResult Tally(std::vector<std::optional<UnitOutcome>> outcomes) {
  BatchResult result;
  for (std::optional<UnitOutcome>& outcome : outcomes) {
    if (!outcome) {
      result.complete = false;
      continue;
    }
    result.Add(std::move(*outcome));
  }
  return result;
}

// OUT_DIR/lot_summary.csv, and with reports OUT_DIR/lot.html (with a results store, the page
// compares this lot with every lot recorded there).
void WriteLotOutputs(const Shared& shared, const BatchResult& result) {
  const BatchOptions& options = *shared.options;
  WriteLotSummary((fs::path(options.output_dir) / "lot_summary.csv").string(), result);
  if (!options.write_reports) return;
  const std::optional<Limits>& limits = shared.certify.limits;
  LotSummary summary = MakeLotSummary(shared.certify.lot, result, options.fit.software, limits);
  if (shared.store) {
    summary.history = MakeLotHistory(shared.store.get(), shared.certify.lot, limits ? &*limits : nullptr);
  }
  const std::string page = LotPageHtml(summary);
  OutputTransaction outputs;
  WriteFileAtomically((fs::path(options.output_dir) / "lot.html").string(), page, &outputs);
  if (options.write_pdf)
    WritePdf(page, (fs::path(options.output_dir) / "lot.pdf").string(), options.paper, &outputs);
  outputs.Commit();
}

}  // namespace

std::string BatchOptions::Validate() const {
  if (units_dir.empty() && units_list.empty()) return "no units folder and no --units-list";
  if (!units_dir.empty() && !units_list.empty()) return "give a units folder or --units-list, not both";
  if (!units_list.empty() && !samples_glob.empty())
    return "--samples-glob names the samples file in unit folders; a --units-list names each itself";
  if (output_dir.empty()) return "no output folder";
  if (std::string problem = ValidateOptions(BatchOptionTable(), *this); !problem.empty()) return problem;
  if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count)
    return "shard index must be below the count";
  return fit.Validate();
}

BatchResult RunBatch(const BatchOptions& options) {
  Shared shared;
  std::vector<UnitInput> units;
  Prepare(options, &shared, &units);
  const FolderLock lock(options.output_dir, options.shard);
  shared.certify.lot = LotName(options);
  if (!options.store_path.empty()) {
    shared.store = std::make_unique<ResultsStore>(options.store_path);
    shared.certify.store = shared.store.get();
  }
  SetInterruptNote(InterruptNote);
  BatchResult result = Tally(ProcessUnits(shared, units));
  SetInterruptNote(nullptr);
  if (result.complete && options.shard.count == 1) WriteLotOutputs(shared, result);
  return result;
}

}  // namespace imufit
