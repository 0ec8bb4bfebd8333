// Helpers shared by the test programs (library imufit_test_util): a fresh folder per test, running
// a program with its output captured, reading files back, the fixtures folder.
#ifndef IMUFIT_TESTS_TEST_UTIL_H_
#define IMUFIT_TESTS_TEST_UTIL_H_

#include <sys/resource.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace imufit::testing {

// A file of fixtures/ (found through the IMUFIT_FIXTURES_DIR compile definition, never through the
// working directory).
std::string Fixture(const std::string& name);

// A file's bytes as they are on disk ("" when it cannot be read).
std::string ReadBytes(const std::string& path);

// A file's text, decompressed when it is gzip (other files pass through unchanged);
// "<cannot open PATH>" when it cannot be read.
std::string ReadFile(const std::string& path);

// Whether `got` is `expected` byte for byte; when not, the first line that differs, with its number,
// both versions and the lengths (EXPECT_EQ on two large texts builds an edit-distance diff that can
// exhaust memory).
::testing::AssertionResult SameText(const std::string& got, const std::string& expected);

struct RunResult {
  int status = -1;  // exit status, or 128 + signal
  std::string out;
  std::string err;
};

// Runs `program` with `args`, stdin from /dev/null, stdout and stderr captured through the files
// `out_path` and `err_path` (kept, so a failing test leaves them to look at).
RunResult RunProgram(const std::string& program, const std::vector<std::string>& args,
                     const std::string& out_path, const std::string& err_path);

// As RunProgram, but the program cannot write a file larger than `max_file_bytes` (RLIMIT_FSIZE,
// with SIGXFSZ ignored: a write past it fails with EFBIG, as on a disk that fills up).
RunResult RunProgramWithFileSizeLimit(const std::string& program, const std::vector<std::string>& args,
                                      const std::string& out_path, const std::string& err_path,
                                      rlim_t max_file_bytes);

// A test that works in a fresh, empty folder of its own, dir_, under the system's temporary
// folder, named after the test and the process. The folder is removed after a test that passed and
// kept after one that failed, to look at. Programs run through RunProgram() leave their captured
// stdout and stderr one level up, so that Listing() sees only what they wrote.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;

  // A path in dir_.
  std::string Path(const std::string& name) const;
  // Writes `text` byte for byte into dir_/name; returns its path.
  std::string Write(const std::string& name, const std::string& text) const;
  // The names in dir_.
  std::set<std::string> Listing() const;
  // Runs `program` with `args` (see ::imufit::testing::RunProgram).
  RunResult RunProgram(const std::string& program, const std::vector<std::string>& args) const;
  RunResult RunProgramWithFileSizeLimit(const std::string& program, const std::vector<std::string>& args,
                                        rlim_t max_file_bytes) const;

  std::filesystem::path dir_;

 private:
  std::filesystem::path root_;  // dir_ and the captured output
};

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_TEST_UTIL_H_
