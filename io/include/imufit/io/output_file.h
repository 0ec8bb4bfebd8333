// imufit — output files that are written whole or not at all (docs/spec.md section 4).
//
// An OutputFile writes into a temporary file in the destination's folder and renames it over the
// destination only in Commit(), after a flush and an fsync. If Commit() is never reached (an
// error, an exception, a crash) the temporary file is removed and an existing destination is
// left exactly as it was. Paths ending in ".gz" are written gzip-compressed.
#ifndef IMUFIT_IO_OUTPUT_FILE_H_
#define IMUFIT_IO_OUTPUT_FILE_H_

#include <string>
#include <string_view>
#include <vector>

namespace imufit {

class OutputFile {
 public:
  // Creates the temporary file; throws InputError naming `path` when its folder is not writable.
  explicit OutputFile(std::string path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void Write(std::string_view text);
  // Appends the shortest decimal text that reads back as exactly `value`.
  void WriteNumber(double value);
  // Flushes, syncs and renames the temporary file over the destination. Throws InputError.
  void Commit();

  const std::string& path() const { return path_; }

 private:
  void Flush();

  std::string path_;
  std::string temp_path_;
  std::string buffer_;
  int fd_ = -1;
  void* gz_ = nullptr;  // gzFile when compressing
  bool committed_ = false;
};

// Writes `text` to `path` atomically (OutputFile in one call).
void WriteFileAtomically(const std::string& path, std::string_view text);

// Throws InputError when `output` names the same file as one of `inputs`: imufit never replaces
// a file it is reading.
void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs);

// The shortest decimal representation that reads back as exactly `value` ("nan", "inf" and
// "-inf" for non-finite values).
std::string FormatDouble(double value);

}  // namespace imufit

#endif  // IMUFIT_IO_OUTPUT_FILE_H_
