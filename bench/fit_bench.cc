// imufit — benchmark of reading a factory-sized run and of `imufit fit` and `apply` on it:
//
//   7 soak temperatures x 18 segments x 30 s at 800 Hz, about 3.2 million samples, 128 MB of CSV.
//
// Every figure is a ratio of two things measured side by side in this one run (best of 3, warm
// cache), against yardsticks measured here too: a plain read(2) pass over the file and coreutils'
// sha256sum. Targets (printed beside each figure; measured, never asserted: this is not a test):
//   imufit fit (whole)            <= 1.2 x a single-core parse of the file
//   parse on 2 threads            >= 1.7 x as fast as on 1
//   apply -o .csv.gz              <= 2 x apply -o .csv
//   read + parse of the .csv.gz   >= 1 x the single-core parse of the plain .csv (MB/s of CSV)
//   imufit fit peak memory        < 100 MB, also on a run 4 x as long (it does not grow with it)
//
// It prints the 1-minute load average first and warns when it is above 1: on a shared machine the
// figures measure the sharing. There, as root, give the bench the CPU in a session of its own:
//   setsid -w sh -c 'echo -20 > /proc/$$/autogroup; exec build-release/bench/fit_bench'
// (nice alone does not: the scheduler shares the CPU between sessions first).
//
// Usage: fit_bench [--keep DIR] [--parse-only THREADS]
//   --keep DIR            the run is simulated into DIR (default a temp dir), kept for the next
//   --parse-only THREADS  only parses DIR's run once (0: one reader; N: blocks on N threads, the
//                         calling one included), for a profiler
//                         (perf record fit_bench --keep DIR --parse-only 1)
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/output_file.h"
#include "imufit/io/parallel_samples.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"

namespace fs = std::filesystem;

namespace {

// How much longer the run is whose fit's peak memory is measured too.
constexpr double kLongRun = 4.0;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Runs a command, returns wall seconds; *max_rss_kb gets the child's peak memory.
double RunChild(const std::vector<std::string>& argv, long* max_rss_kb) {
  std::fflush(stdout);  // or the child inherits (and prints again) what is buffered
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    if (std::freopen("/dev/null", "w", stdout) == nullptr) _exit(127);
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  const double seconds = Seconds(start);
  *max_rss_kb = usage.ru_maxrss;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "fit_bench: %s exited with status %d\n", argv[0].c_str(), WEXITSTATUS(status));
    std::exit(1);
  }
  return seconds;
}

// The best of 3 runs of `work` (warm cache), in seconds.
template <typename F>
double Best(F work) {
  double best = 1e300;
  for (int trial = 0; trial < 3; ++trial) {
    const auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(best, Seconds(start));
  }
  return best;
}

// Reads every sample of `path`, parsing on `threads` threads (0: one SamplesReader, no blocks);
// returns the CSV bytes parsed.
long long Parse(const std::string& path, int threads) {
  imufit::SamplesReader reader(path, true);
  imufit::Sample sample;
  double checksum = 0.0;
  if (threads == 0) {
    while (reader.Next(&sample)) checksum += sample.gyro.x();
  } else {
    imufit::ParallelSamplesReader parallel(&reader, threads);
    while (parallel.Next(&sample)) checksum += sample.gyro.x();
  }
  if (checksum == 0.12345) std::printf(" ");
  return reader.bytes_read();
}

// A plain read(2) pass over the file: the floor of any reading.
void ReadPass(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  std::vector<char> block(1 << 20);
  long long sum = 0;
  for (ssize_t n; (n = ::read(fd, block.data(), block.size())) > 0;) sum += block[n - 1];
  ::close(fd);
  if (sum == 12345) std::printf(" ");
}

// A copy of `from` at `to`, gzip-compressed by imufit's writer.
void Compress(const std::string& from, const std::string& to) {
  imufit::OutputFile out(to);
  std::ifstream in(from, std::ios::binary);
  std::vector<char> block(1 << 20);
  while (in.read(block.data(), block.size()) || in.gcount() > 0)
    out.Write(std::string_view(block.data(), in.gcount()));
  out.Commit();
}

// The factory run at `path` (simulated unless it is there), its dwells `length` times as long.
void SimulateOnce(const imufit::Plan& plan, const std::string& truth_path, double length,
                  const std::string& path) {
  if (fs::exists(path)) return;
  imufit::SimulationOptions options;
  options.soak_temps_c = {-40.0, -20.0, 0.0, 25.0, 45.0, 65.0, 85.0};
  options.dwell_s = 30.0 * length;
  options.transition_s = 2.0;
  options.rate_hz = 800.0;
  options.gyro_noise_density = 1e-4;
  options.accel_noise_density = 5e-4;
  options.quantize = true;
  options.seed = 1;
  const auto start = std::chrono::steady_clock::now();
  const imufit::Calibration truth = imufit::ReadCalibration(truth_path);
  imufit::SamplesWriter writer(path, true);
  imufit::SimulateRun(options, plan.site, plan.segments, truth.model,
                      [&](const imufit::Sample& raw, const imufit::SegmentTruth&) { writer.Write(raw); });
  writer.Commit();
  std::printf("simulated %s in %.2f s\n", path.c_str(), Seconds(start));
}

// The 1-minute load average: above 1 (on this 2-core machine, another process busy), the figures
// measure the sharing, not imufit.
double LoadAverage() {
  double load[1] = {0.0};
  return getloadavg(load, 1) == 1 ? load[0] : -1.0;
}

void Row(const char* what, double seconds, double ratio, const char* of, const char* target) {
  std::printf("%-34s %7.3f s  %6.2f x %-28s %s\n", what, seconds, ratio, of, target);
}

}  // namespace

int main(int argc, char** argv) {
  fs::path dir;
  int parse_only = -1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--keep") == 0 && i + 1 < argc) dir = argv[++i];
    if (std::strcmp(argv[i], "--parse-only") == 0 && i + 1 < argc) parse_only = std::atoi(argv[++i]);
  }
  const double load = LoadAverage();
  std::printf("1-minute load average at the start: %.2f%s\n", load,
              load > 1.0
                  ? "  WARNING: the machine is busy; these figures are not the targets' (a quiet machine's;"
                    " see this bench's header for running it in a session of its own at nice -20)"
                  : "");
  const bool temporary = dir.empty();
  if (temporary) dir = fs::temp_directory_path() / ("imufit_fit_bench_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string plan_path = IMUFIT_FIXTURES_DIR "/plan_6pos.yaml";
  const std::string truth_path = IMUFIT_FIXTURES_DIR "/mems_truth.yaml";
  const std::string samples_path = (dir / "factory_run.csv").string();
  const std::string gzip_path = (dir / "factory_run.csv.gz").string();

  const imufit::Plan plan = imufit::ReadPlan(plan_path);
  SimulateOnce(plan, truth_path, 1.0, samples_path);
  if (!fs::exists(gzip_path)) Compress(samples_path, gzip_path);
  if (parse_only >= 0) {
    const auto start = std::chrono::steady_clock::now();
    Parse(samples_path, parse_only);
    std::printf("parsed on %d threads in %.3f s\n", parse_only, Seconds(start));
    return 0;
  }
  long rss = 0;

  // Yardsticks: a plain read pass, coreutils' sha256sum.
  const double read_pass_s = Best([&] { ReadPass(samples_path); });
  const double sha256sum_s = Best([&] { RunChild({"/usr/bin/sha256sum", samples_path}, &rss); });
  // Parsing: one reader; blocks on 1 and on 2 threads; the .csv.gz as the fit reads it.
  long long csv_bytes = 0;
  const double parse_s = Best([&] { csv_bytes = Parse(samples_path, 0); });
  const double blocks1_s = Best([&] { Parse(samples_path, 1); });
  const double blocks2_s = Best([&] { Parse(samples_path, 2); });
  const double gzip_parse_s = Best([&] { Parse(gzip_path, 2); });
  // The whole commands, as a user runs them.
  const std::string output = (dir / "calibration.yaml").string();
  long fit_rss_kb = 0;
  const double fit_s = Best([&] {
    RunChild({IMUFIT_BINARY, "fit", "--plan", plan_path, "--samples", samples_path, "-o", output}, &rss);
    fit_rss_kb = std::max(fit_rss_kb, rss);
  });
  const auto apply = [&](const std::string& out) {
    return Best([&] {
      RunChild(
          {IMUFIT_BINARY, "apply", "-c", truth_path, "-s", samples_path, "-o", (dir / out).string(), "-q"},
          &rss);
    });
  };
  const double apply_csv_s = apply("corrected.csv");
  const double apply_gz_s = apply("corrected.csv.gz");
  // Peak memory does not grow with the run: the same fit on a run kLongRun times as long (once).
  const std::string long_path = (dir / "factory_run_long.csv").string();
  SimulateOnce(plan, truth_path, kLongRun, long_path);
  long long_rss_kb = 0;
  const double long_fit_s = RunChild(
      {IMUFIT_BINARY, "fit", "--plan", plan_path, "--samples", long_path, "-o", output}, &long_rss_kb);

  const double mb = static_cast<double>(csv_bytes) / 1e6;
  std::printf("factory run: %.1f MB of CSV (%.1f MB as .csv.gz), ratios of runs side by side, best of 3\n",
              mb, static_cast<double>(fs::file_size(gzip_path)) / 1e6);
  Row("plain read(2) pass (yardstick)", read_pass_s, mb / read_pass_s, "MB/s", "");
  Row("sha256sum (yardstick)", sha256sum_s, sha256sum_s / read_pass_s, "read pass", "");
  Row("parse, one reader", parse_s, mb / parse_s, "MB/s of CSV", "");
  Row("parse in blocks, 1 thread", blocks1_s, blocks1_s / parse_s, "one reader", "");
  Row("parse in blocks, 2 threads", blocks2_s, blocks1_s / blocks2_s, "faster than 1 thread",
      "(target >= 1.7 x)");
  Row("read + parse of the .csv.gz", gzip_parse_s, parse_s / gzip_parse_s, "as fast as one reader, plain",
      "(target >= 1 x)");
  Row("imufit fit (whole)", fit_s, fit_s / parse_s, "one reader's parse", "(target <= 1.2 x)");
  Row("imufit fit, against sha256sum", fit_s, fit_s / sha256sum_s, "sha256sum", "");
  Row("imufit apply -o .csv", apply_csv_s, apply_csv_s / parse_s, "one reader's parse", "");
  Row("imufit apply -o .csv.gz", apply_gz_s, apply_gz_s / apply_csv_s, "apply -o .csv", "(target <= 2 x)");
  std::printf("%-34s %7.1f MB%46s\n", "imufit fit peak memory", fit_rss_kb / 1024.0, "(target < 100 MB)");
  std::printf("  on a run %.0f x as long (%6.1f MB) %7.1f MB%46s\n", kLongRun,
              static_cast<double>(fs::file_size(long_path)) / 1e6, long_rss_kb / 1024.0, "(target < 100 MB)");
  std::printf("  (its fit took %.2f s, once)\n", long_fit_s);
  const double load_after = LoadAverage();
  if (load_after > 1.0)
    std::printf("1-minute load average at the end: %.2f: the machine was busy\n", load_after);
  if (temporary) fs::remove_all(dir);
  return 0;
}
