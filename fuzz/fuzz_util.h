// imufit fuzzing: what every libFuzzer target shares. The readers take paths, so each input is
// written to a file in a folder of this process (named by the reader's suffix, ".csv.gz" when
// the bytes start with the gzip magic) and read back from there.
#ifndef IMUFIT_FUZZ_FUZZ_UTIL_H_
#define IMUFIT_FUZZ_FUZZ_UTIL_H_

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace imufit::fuzz {

// The folder of this process's inputs and outputs, created once.
inline const std::string& Folder() {
  static const std::string folder = [] {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("imufit-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    return path.string();
  }();
  return folder;
}

// Writes the input to Folder()/input<suffix> and returns the path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path = Folder() + "/input" + suffix;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), size);
  return path;
}

// ".csv.gz" for bytes that start like gzip, ".csv" otherwise: both readers are reached.
inline std::string CsvSuffix(const uint8_t* data, size_t size) {
  return size >= 2 && data[0] == 0x1f && data[1] == 0x8b ? ".csv.gz" : ".csv";
}

// An oracle: a property every accepted input must have. Aborts (a libFuzzer crash) when not.
#define IMUFIT_FUZZ_CHECK(condition, what)                                                           \
  do {                                                                                               \
    if (!(condition)) {                                                                              \
      std::fprintf(stderr, "%s:%d: oracle failed: %s (%s)\n", __FILE__, __LINE__, #condition, what); \
      std::abort();                                                                                  \
    }                                                                                                \
  } while (0)

}  // namespace imufit::fuzz

#endif  // IMUFIT_FUZZ_FUZZ_UTIL_H_
