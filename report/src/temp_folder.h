// A private temporary folder for a program imufit runs (gnuplot, Chromium), removed with its
// contents when the object goes.
#ifndef IMUFIT_FACTORY_REPORT_SRC_TEMP_FOLDER_H_
#define IMUFIT_FACTORY_REPORT_SRC_TEMP_FOLDER_H_

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace imufit::internal {

struct TempFolder {
  std::string path;
  // `prefix`: the folder's name before its random part ("imufit-plot").
  explicit TempFolder(const std::string& prefix) {
    path = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
    if (::mkdtemp(path.data()) == nullptr)
      throw std::runtime_error("cannot create a temporary folder " + path);
  }
  ~TempFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
};

}  // namespace imufit::internal

#endif  // IMUFIT_FACTORY_REPORT_SRC_TEMP_FOLDER_H_
