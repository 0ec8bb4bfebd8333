// imufit — what a file's name says about it.
#ifndef IMUFIT_IO_PATH_H_
#define IMUFIT_IO_PATH_H_

#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace imufit {

// True when `path` ends with `suffix` (".gz", ".png"); case-sensitive, as file systems are.
inline bool HasSuffix(std::string_view path, std::string_view suffix) {
  return path.size() >= suffix.size() && path.substr(path.size() - suffix.size()) == suffix;
}

// Files whose name ends in ".gz" are read and written gzip-compressed.
inline bool IsGzipPath(std::string_view path) { return HasSuffix(path, ".gz"); }

// Whether `path` can be opened again from its start: a regular file (also through /dev/stdin
// redirected from one), not a pipe or a process substitution, which can be read once.
inline bool IsRereadable(const std::string& path) {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error);
}

}  // namespace imufit

#endif  // IMUFIT_IO_PATH_H_
