// imufit — how many times io opens a file to read it. A run's samples file can be large (an hour
// at 1 kHz), so commands read it as few times as their work needs (`imufit fit --report --store`:
// at most twice); tests hold them to it by counting.
//
// A FileReadCounter counts, while it lives, the openings of one file (by its identity, device and
// inode: two spellings of a path are one file) by every io reader that opens a file itself:
// CsvReader (samples, series) and Sha256OfFile. Nothing is counted, or kept, for files nobody
// watches.
#ifndef IMUFIT_IO_FILE_READS_H_
#define IMUFIT_IO_FILE_READS_H_

#include <sys/types.h>

#include <string>

namespace imufit {

class FileReadCounter {
 public:
  // Starts counting the openings of the file `path` names (which must exist: else InputError).
  explicit FileReadCounter(const std::string& path);
  ~FileReadCounter();
  FileReadCounter(const FileReadCounter&) = delete;
  FileReadCounter& operator=(const FileReadCounter&) = delete;

  // The openings since this counter was made (safe while readers on other threads open files).
  long long count() const;

 private:
  friend void CountOpenedForReading(const std::string& path);
  dev_t device_;
  ino_t inode_;
  long long count_ = 0;  // under the watch list's lock
};

// Counts one opening of the file `path` names for the counters that watch it (io's readers call it
// once they have opened a file).
void CountOpenedForReading(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_FILE_READS_H_
