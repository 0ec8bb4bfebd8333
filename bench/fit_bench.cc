// imufit — benchmark of `imufit fit` on a factory-sized run:
//
//   7 soak temperatures x 18 segments x 30 s at 800 Hz, about 3 million samples.
//
// Prints: the ingest rate of reading + parsing the samples file (MB/s, one core), the time of
// the whole `imufit fit` run (a child process, as a user runs it) and its ratio to the read
// alone, and the peak memory (max RSS) of that run. Targets: >= 200 MB/s, ratio <= 1.5,
// peak < 100 MB. Figures are measured, never asserted: this is not a test.
//
// Usage: fit_bench [--keep DIR] [--gzip]   (the run is simulated into DIR, default a temp dir)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/io/samples.h"
#include "imufit/pipeline/run_windows.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"

namespace fs = std::filesystem;

namespace {

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

}  // namespace

int main(int argc, char** argv) {
  fs::path dir;
  bool gzip = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--keep") == 0 && i + 1 < argc) dir = argv[++i];
    if (std::strcmp(argv[i], "--gzip") == 0) gzip = true;
  }
  const bool temporary = dir.empty();
  if (temporary) dir = fs::temp_directory_path() / ("imufit_fit_bench_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string plan_path = IMUFIT_FIXTURES_DIR "/plan_6pos.yaml";
  const std::string truth_path = IMUFIT_FIXTURES_DIR "/mems_truth.yaml";
  const std::string samples_path = (dir / (gzip ? "factory_run.csv.gz" : "factory_run.csv")).string();

  const imufit::Plan plan = imufit::ReadPlan(plan_path);
  imufit::SimulationOptions options;
  options.soak_temps_c = {-40.0, -20.0, 0.0, 25.0, 45.0, 65.0, 85.0};
  options.dwell_s = 30.0;
  options.transition_s = 2.0;
  options.rate_hz = 800.0;
  options.gyro_noise_density = 1e-4;
  options.accel_noise_density = 5e-4;
  options.quantize = true;
  options.seed = 1;
  if (!fs::exists(samples_path)) {
    const auto start = std::chrono::steady_clock::now();
    const imufit::Calibration truth = imufit::ReadCalibration(truth_path);
    imufit::SamplesWriter writer(samples_path, true);
    imufit::SimulateRun(options, plan.site, plan.segments, truth.model,
                        [&](const imufit::Sample& raw, const imufit::SegmentTruth&) { writer.Write(raw); });
    writer.Commit();
    std::printf("simulated %s in %.2f s\n", samples_path.c_str(), Seconds(start));
  }
  const double megabytes = static_cast<double>(fs::file_size(samples_path)) / 1e6;

  // 1. Read and parse only (best of 3, warm cache): the floor any fit is measured against.
  double read_s = 1e300;
  long long samples = 0;
  long long bytes = 0;
  for (int trial = 0; trial < 3; ++trial) {
    const auto start = std::chrono::steady_clock::now();
    imufit::SamplesReader reader(samples_path, true);
    imufit::Sample sample;
    samples = 0;
    double checksum = 0.0;
    while (reader.Next(&sample)) {
      checksum += sample.gyro.x();
      ++samples;
    }
    bytes = reader.bytes_read();
    read_s = std::min(read_s, Seconds(start));
    if (checksum == 0.12345) std::printf(" ");
  }
  // 2. Read + windows (the fit's streaming pass), in process.
  double window_s = 1e300;
  for (int trial = 0; trial < 3; ++trial) {
    const auto start = std::chrono::steady_clock::now();
    imufit::ReadRunWindows(plan, samples_path, imufit::WindowOptions());
    window_s = std::min(window_s, Seconds(start));
  }
  // 3. The whole command, as a user runs it.
  const std::string output = (dir / "calibration.yaml").string();
  double fit_s = 1e300;
  long max_rss_kb = 0;
  for (int trial = 0; trial < 3; ++trial) {
    long rss = 0;
    fit_s = std::min(
        fit_s,
        RunChild({IMUFIT_BINARY, "fit", "--plan", plan_path, "--samples", samples_path, "-o", output}, &rss));
    max_rss_kb = std::max(max_rss_kb, rss);
  }

  const double uncompressed_mb = static_cast<double>(bytes) / 1e6;
  std::printf("factory run: %lld samples, %.1f MB on disk (%.1f MB of CSV)%s\n", samples, megabytes,
              uncompressed_mb, gzip ? ", gzip" : "");
  std::printf("read + parse:          %7.3f s   %7.1f MB/s of CSV   (target >= 200 MB/s per core)\n", read_s,
              uncompressed_mb / read_s);
  std::printf("read + windows:        %7.3f s   %7.2f x read\n", window_s, window_s / read_s);
  std::printf("imufit fit (whole):    %7.3f s   %7.2f x read          (target <= 1.5 x)\n", fit_s,
              fit_s / read_s);
  std::printf("imufit fit peak memory: %6.1f MB                       (target < 100 MB)\n",
              max_rss_kb / 1024.0);
  if (temporary) fs::remove_all(dir);
  return 0;
}
