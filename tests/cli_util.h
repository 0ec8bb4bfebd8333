// The fixture of the end-to-end tests of the `imufit` command (library imufit_cli_util): the built
// program (IMUFIT_EXE) is run on fixtures and on files written into a fresh folder per test, never
// the working directory; its CSV outputs are read back as tables.
//
// The tests are split by command: cli_test.cc (the program as a whole: help, bad invocations, bad
// input, how outputs are written), cli_simulate_test.cc, cli_apply_test.cc, cli_fit_test.cc,
// cli_segment_test.cc (logs without labels or a thermometer), cli_serial_test.cc (a unit's serial
// from the samples to the certificate and the batch) and cli_allan_test.cc. Every test is
// CliTest.NAME, whichever program holds it (ctest -R CliTest.Fit).
#ifndef IMUFIT_TESTS_CLI_UTIL_H_
#define IMUFIT_TESTS_CLI_UTIL_H_

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "test_util.h"

namespace imufit::testing {

// Worst-case absolute error of a recovered rate (rad/s) or specific force (m/s^2).
constexpr double kRecoveryToleranceSi = 1e-9;
constexpr double kDegToRad = M_PI / 180.0;
// The white noise of CliTest::StaticRun(): rad/s/sqrt(Hz) and m/s^2/sqrt(Hz).
constexpr double kStaticGyroNoiseDensity = 8.7e-5;
constexpr double kStaticAccelNoiseDensity = 1.5e-3;

// A CSV file (gzip or not) split into its header and rows ('#' lines skipped), for checking outputs.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  // The index of the column `name` (a test failure, and 0, when there is none).
  int Column(const std::string& name) const;
  double Number(size_t row, const std::string& name) const;
  // The columns PREFIX_x, PREFIX_y, PREFIX_z of `row`.
  Eigen::Vector3d Vector(size_t row, const std::string& prefix) const;
};

Table ReadTable(const std::string& path);

class CliTest : public TempDirTest {
 protected:
  // Runs imufit with `args`, stdin from /dev/null, and captures its output.
  RunResult Run(const std::vector<std::string>& args) const;
  // As Run, with a file size limit (see RunProgramWithFileSizeLimit).
  RunResult RunWithFileSizeLimit(const std::vector<std::string>& args, rlim_t max_file_bytes) const;

  // The arguments of `imufit simulate` for a small noisy run of the 6-position plan (10 Hz, 3 s
  // dwells, four soaks: enough for a fit, quick to make) into `out`; `extra` adds options.
  static std::vector<std::string> SmallRunArgs(const std::string& out, const std::vector<std::string>& extra);
  // The arguments of `imufit simulate` for a hand session (fixtures/plan_hand_6faces_3turns.yaml:
  // six faces and a 360 deg turn about each axis) of the MEMS unit at 25 degC, 100 Hz, 10 s dwells,
  // in raw counts with white noise, without a segment column, 3 ms of time-stamp jitter, seed 4,
  // into `out`; `extra` adds options.
  static std::vector<std::string> HandSessionArgs(const std::string& out,
                                                  const std::vector<std::string>& extra);

  // A one-segment static plan (the unit at rest, z up), written as static.yaml; returns its path.
  std::string StaticPlan() const;
  // Simulates the MEMS unit (fixtures/mems_truth.yaml, raw counts) on StaticPlan() for `dwell_s`
  // at `temp_c`, 100 Hz, white noise kStaticGyroNoiseDensity and kStaticAccelNoiseDensity, seed
  // `seed`, into `out` (in the test's folder); returns its path.
  std::string StaticRun(const std::string& out, int dwell_s, int temp_c, int seed) const;

  // Runs a noiseless simulation at 20 Hz with 1 s dwells and 0.75 s transitions (`extra` adds
  // options or overrides these) and returns the paths of {samples, truth}.
  std::pair<std::string, std::string> SimulateNoiseless(const std::string& plan,
                                                        const std::string& calibration,
                                                        const std::string& stem,
                                                        const std::vector<std::string>& extra = {}) const;

  // Expects `corrected` (imufit apply's output) to hold the truth of `truth_path` in every row, to
  // kRecoveryToleranceSi.
  static void ExpectRecovered(const std::string& corrected, const std::string& truth_path);
};

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_CLI_UTIL_H_
