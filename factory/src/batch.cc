#include "imufit/factory/batch.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "imufit/factory/certificate.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/factory/report.h"
#include "imufit/factory/store.h"
#include "imufit/io/error.h"
#include "imufit/io/limits.h"
#include "imufit/io/output_file.h"
#include "imufit/io/sha256.h"
#include "imufit/io/station.h"

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
    return m;
  } catch (const YAML::Exception&) {
    return std::nullopt;  // unreadable: the unit is done again
  }
}

void WriteManifest(const std::string& path, const Manifest& m) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "format" << YAML::Value << kManifestFormat << YAML::Key << "version"
      << YAML::Value << 1;
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
                                                               {"fit_options", &m.fit_options}};
  for (const auto& [key, value] : fields)
    out << YAML::Key << key << YAML::Value << YAML::DoubleQuoted << *value;
  out << YAML::EndMap;
  WriteFileAtomically(
      path, std::string("# imufit batch: this unit's inputs and outcome; delete to redo it\n") + out.c_str() +
                "\n");
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
  explicit FolderLock(const std::string& folder) {
    const std::string path = (fs::path(folder) / ".imufit-batch.lock").string();
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

std::string Join(const std::vector<std::string>& parts, const char* separator) {
  std::string text;
  for (const std::string& p : parts) text += (text.empty() ? "" : separator) + p;
  return text;
}

// Everything a worker needs that is shared by all units.
struct Shared {
  const BatchOptions* options;
  std::optional<Limits> limits;
  std::string limits_sha256;
  std::optional<Station> station;
  std::string station_sha256;
  std::string fit_options;  // options->fit.Describe()
  std::unique_ptr<ResultsStore> store;
  std::string lot;
  std::mutex store_mutex;
};

void Judge(const Shared& shared, const Calibration& calibration, UnitOutcome* outcome) {
  outcome->figures = KeyFigures(calibration);
  if (!shared.limits) return;
  outcome->verdict_detail = EvaluateLimits(*shared.limits, calibration);
  outcome->verdict = outcome->verdict_detail.pass ? "PASS" : "FAIL";
  outcome->message = outcome->verdict_detail.FailedSummary();
}

// The serial in UNIT/serial.txt (its first line, trimmed), or "" without that file.
std::string UnitSerial(const fs::path& unit_dir) {
  std::ifstream stream(unit_dir / "serial.txt");
  std::string line;
  if (!stream || !std::getline(stream, line)) return "";
  const size_t first = line.find_first_not_of(" \t\r");
  const size_t last = line.find_last_not_of(" \t\r");
  return first == std::string::npos ? "" : line.substr(first, last - first + 1);
}

UnitOutcome ProcessUnit(Shared& shared, const fs::path& unit_dir) {
  const BatchOptions& options = *shared.options;
  const auto start = std::chrono::steady_clock::now();
  UnitOutcome outcome;
  outcome.unit = unit_dir.filename().string();
  outcome.serial = outcome.unit;
  outcome.status = "error";
  const fs::path out_dir = fs::path(options.output_dir) / outcome.unit;
  const std::string calibration_path = (out_dir / "calibration.yaml").string();
  const std::string manifest_path = (out_dir / "manifest.yaml").string();
  const std::string report_path = (out_dir / "report.html").string();
  std::string calibration_yaml;
  Manifest manifest;
  try {
    std::string samples = (unit_dir / "samples.csv.gz").string();
    if (!fs::exists(samples)) samples = (unit_dir / "samples.csv").string();
    if (!fs::exists(samples)) throw InputError(unit_dir.string(), "no samples.csv or samples.csv.gz");
    std::string plan = (unit_dir / "plan.yaml").string();
    if (!fs::exists(plan)) {
      if (options.shared_plan.empty())
        throw InputError(unit_dir.string(), "no plan.yaml and no shared --plan");
      plan = options.shared_plan;
    }
    outcome.plan_path = plan;
    outcome.samples_path = samples;
    const std::string serial_file = UnitSerial(unit_dir);
    outcome.plan_sha256 = Sha256OfFile(plan);
    outcome.samples_sha256 = Sha256OfFile(samples);
    manifest = Manifest{};
    manifest.software = options.fit.software;
    manifest.plan_sha256 = outcome.plan_sha256;
    manifest.samples_sha256 = outcome.samples_sha256;
    manifest.limits_sha256 = shared.limits_sha256;
    manifest.station_sha256 = shared.station_sha256;
    manifest.fit_options = shared.fit_options;

    // Unchanged since a finished run (the same inputs, fit options and software, and its outputs
    // still there): take its outcome, redo nothing.
    if (const std::optional<Manifest> previous = ReadManifest(manifest_path);
        previous && previous->software == manifest.software &&
        previous->plan_sha256 == manifest.plan_sha256 &&
        previous->samples_sha256 == manifest.samples_sha256 &&
        previous->limits_sha256 == manifest.limits_sha256 &&
        previous->station_sha256 == manifest.station_sha256 &&
        previous->fit_options == manifest.fit_options &&
        (previous->status != "fitted" ||
         (fs::exists(calibration_path) && (!options.write_reports || fs::exists(report_path))))) {
      outcome.skipped = true;
      outcome.serial = previous->serial;
      outcome.status = previous->status;
      outcome.verdict = previous->verdict;
      outcome.message = previous->message;
      if (outcome.status == "fitted") Judge(shared, ReadCalibration(calibration_path), &outcome);
      return outcome;
    }

    fs::create_directories(out_dir);
    RemoveLeftovers(out_dir);
    FitRunOptions fit_options = options.fit;
    fit_options.serial = serial_file;
    fit_options.serial_source = (unit_dir / "serial.txt").string();
    fit_options.plan_sha256 = outcome.plan_sha256;
    fit_options.samples_sha256 = outcome.samples_sha256;
    FitRunResult result = FitRun(plan, samples, fit_options);
    if (!result.serial.empty()) outcome.serial = result.serial;  // serial.txt, the samples', the plan's
    outcome.warnings = result.serial_warnings;
    if (result.fit.status == FitStatus::kUndetermined) {
      outcome.status = "not-fitted";
      outcome.message = "the run does not determine the model: " + Join(result.fit.undetermined, "; ");
    } else if (!result.calibration) {
      outcome.status = "not-fitted";
      outcome.message = result.fit.BriefReport();
    } else {
      outcome.status = "fitted";
      Calibration& calibration = *result.calibration;
      if (calibration.serial.empty()) calibration.serial = outcome.serial;
      calibration_yaml = CalibrationToYaml(calibration);
      WriteFileAtomically(calibration_path, calibration_yaml);
      manifest.calibration_sha256 = Sha256Hex(calibration_yaml);
      Judge(shared, calibration, &outcome);
    }
    outcome.fit = std::move(result);
    if (outcome.status == "fitted" && options.write_reports) {
      const Certificate certificate = MakeCertificate(UnitCertificateSources(
          outcome, options.limits_path, shared.limits, calibration_path, options.fit, shared.station));
      // The certificate judges with the noise it measured itself: its verdict is the unit's.
      if (certificate.verdict) {
        outcome.verdict_detail = *certificate.verdict;
        outcome.verdict = certificate.verdict->pass ? "PASS" : "FAIL";
        outcome.message = certificate.verdict->FailedSummary();
      }
      WriteCertificate(report_path, certificate);
    }
  } catch (const InputError& e) {
    outcome.status = "error";
    outcome.message = e.what();
  } catch (const std::exception& e) {
    outcome.status = "error";
    outcome.message = std::string("error: ") + e.what();
  }
  outcome.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Record, then mark done: a crash between the two redoes the unit (a second row in the store),
  // never loses it.
  if (shared.store && !outcome.plan_sha256.empty()) {
    StoredFit row;
    row.serial = outcome.serial;
    row.unit = outcome.unit;
    row.lot = shared.lot;
    row.time_utc = UtcNow();
    row.software = options.fit.software;
    row.plan_sha256 = outcome.plan_sha256;
    row.samples_sha256 = outcome.samples_sha256;
    row.limits_sha256 = shared.limits_sha256;
    row.status = outcome.status;
    row.verdict = outcome.verdict;
    row.message = outcome.message;
    row.calibration_yaml = calibration_yaml;
    row.figures = outcome.figures;
    std::lock_guard<std::mutex> lock(shared.store_mutex);
    try {
      shared.store->Record(row);
    } catch (const std::exception& e) {
      // Not recorded: no manifest either, so that the next run does the unit again.
      outcome.status = "error";
      outcome.verdict.clear();
      outcome.message = std::string("not recorded in the results store: ") + e.what();
      return outcome;
    }
  }
  if (!outcome.plan_sha256.empty()) {
    manifest.serial = outcome.serial;
    manifest.status = outcome.status;
    manifest.verdict = outcome.verdict;
    manifest.message = outcome.message;
    try {
      fs::create_directories(out_dir);
      WriteManifest(manifest_path, manifest);
    } catch (const std::exception& e) {
      outcome.status = "error";
      outcome.message = std::string("cannot write the manifest: ") + e.what();
    }
  }
  return outcome;
}

std::string SummaryCell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return quoted + "\"";
}

void WriteLotSummary(const std::string& path, const BatchResult& result) {
  OutputFile out(path);
  out.Write("unit,serial,status,verdict,message");
  for (const std::string& name : kSummaryFigures) out.Write("," + name);
  out.Write("\n");
  for (const UnitOutcome& u : result.units) {
    out.Write(SummaryCell(u.unit) + "," + SummaryCell(u.serial) + "," + u.status + "," + u.verdict + "," +
              SummaryCell(u.message));
    for (const std::string& name : kSummaryFigures) {
      out.Write(",");
      if (const Figure* f = FindFigure(u.figures, name)) out.WriteNumber(f->value);
    }
    out.Write("\n");
  }
  out.Commit();
}

}  // namespace

std::string BatchOptions::Validate() const {
  if (units_dir.empty()) return "no units folder";
  if (output_dir.empty()) return "no output folder";
  if (jobs < 0) return "jobs must be >= 0";
  if (max_units < 0) return "max_units must be >= 0";
  return fit.Validate();
}

BatchResult RunBatch(const BatchOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit batch", problem);
  if (!fs::is_directory(options.units_dir)) throw InputError(options.units_dir, "not a folder");
  Shared shared;
  shared.options = &options;
  shared.fit_options = options.fit.Describe();
  if (!options.limits_path.empty()) {
    shared.limits = ReadLimits(options.limits_path);
    shared.limits_sha256 = Sha256OfFile(options.limits_path);
  }
  if (!options.station_path.empty()) {
    shared.station = ReadStation(options.station_path);
    shared.station_sha256 = Sha256OfFile(options.station_path);
  }
  if (!options.shared_plan.empty()) ReadPlan(options.shared_plan);  // a bad shared plan is the lot's error
  std::error_code error;
  fs::create_directories(options.output_dir, error);
  if (!fs::is_directory(options.output_dir)) {
    throw InputError(options.output_dir, "cannot create the output folder");
  }
  const FolderLock lock(options.output_dir);
  shared.lot =
      options.lot.empty() ? fs::path(options.units_dir).lexically_normal().filename().string() : options.lot;
  if (shared.lot.empty())
    shared.lot = fs::path(options.units_dir).lexically_normal().parent_path().filename().string();
  if (!options.store_path.empty()) shared.store = std::make_unique<ResultsStore>(options.store_path);

  std::vector<fs::path> units;
  for (const fs::directory_entry& entry : fs::directory_iterator(options.units_dir)) {
    if (entry.is_directory() && entry.path().filename().string()[0] != '.')
      units.push_back(entry.path());  // not .git and the like
  }
  std::sort(units.begin(), units.end());

  BatchResult result;
  result.units.resize(units.size());
  std::vector<bool> finished(units.size(), false);
  std::atomic<size_t> next{0};
  std::atomic<int> fitted{0};
  std::mutex progress_mutex;
  BatchProgress progress;
  progress.total = static_cast<int>(units.size());
  const auto start = std::chrono::steady_clock::now();
  const auto worker = [&] {
    for (;;) {
      if (options.max_units > 0 && fitted.load() >= options.max_units) return;
      const size_t i = next.fetch_add(1);
      if (i >= units.size()) return;
      UnitOutcome outcome = ProcessUnit(shared, units[i]);
      if (!outcome.skipped) ++fitted;
      std::lock_guard<std::mutex> lock(progress_mutex);
      result.units[i] = std::move(outcome);
      finished[i] = true;
      ++progress.done;
      progress.skipped += result.units[i].skipped ? 1 : 0;
      progress.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress.last = &result.units[i];
      if (options.progress) options.progress(progress);
    }
  };
  int jobs =
      options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = std::min<int>(jobs, std::max<size_t>(units.size(), 1));
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();

  std::vector<UnitOutcome> done;
  for (size_t i = 0; i < units.size(); ++i) {
    if (!finished[i]) {
      result.complete = false;
      continue;
    }
    UnitOutcome& u = result.units[i];
    result.skipped += u.skipped ? 1 : 0;
    if (u.status == "error") ++result.errors;
    if (u.status == "not-fitted") ++result.not_fitted;
    if (u.verdict == "PASS") ++result.passed;
    if (u.verdict == "FAIL") ++result.failed;
    done.push_back(std::move(u));
  }
  result.units = std::move(done);
  if (result.complete) {
    WriteLotSummary((fs::path(options.output_dir) / "lot_summary.csv").string(), result);
    if (options.write_reports) {
      std::optional<Limits> limits;
      if (!options.limits_path.empty()) limits = ReadLimits(options.limits_path);
      LotSummary summary = MakeLotSummary(shared.lot, result, options.fit.software, limits);
      // With a results store, the page compares this lot with every lot recorded there.
      if (shared.store)
        summary.history = MakeLotHistory(shared.store.get(), shared.lot, limits ? &*limits : nullptr);
      WriteFileAtomically((fs::path(options.output_dir) / "lot.html").string(), LotPageHtml(summary));
    }
  }
  return result;
}

}  // namespace imufit
