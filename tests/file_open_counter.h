// Counting how often a test program's own code opens a file (library imufit_file_open_counter). A
// run's samples file can be large (an hour at 1 kHz), so commands read it as few times as their work
// needs (`imufit fit --report --store`: at most twice); tests hold them to it by counting.
//
// The library links its test program with `-Wl,--wrap=open`: every open(2) that the program's own
// objects and static libraries make (io's readers: ByteSource, Sha256OfFile) goes through a
// counting wrapper, which opens the file as open(2) does and counts the openings of the files
// counters watch. Nothing in io knows about it; shared libraries (libstdc++, libc) are not wrapped.
#ifndef IMUFIT_TESTS_FILE_OPEN_COUNTER_H_
#define IMUFIT_TESTS_FILE_OPEN_COUNTER_H_

#include <sys/types.h>

#include <string>

namespace imufit::testing {

// Counts, while it lives, the openings of the file `path` names (by its identity, device and inode:
// two spellings of a path are one file); safe while other threads open files. A file that does not
// exist fails the test.
class FileOpenCounter {
 public:
  explicit FileOpenCounter(const std::string& path);
  ~FileOpenCounter();
  FileOpenCounter(const FileOpenCounter&) = delete;
  FileOpenCounter& operator=(const FileOpenCounter&) = delete;

  // The openings since this counter was made.
  long long count() const;

  // Counts one opening of `fd` for the counters that watch its file (the wrapper calls it).
  static void Opened(int fd);

 private:
  dev_t device_ = 0;
  ino_t inode_ = 0;
  long long count_ = 0;  // under the watch list's lock
};

}  // namespace imufit::testing

#endif  // IMUFIT_TESTS_FILE_OPEN_COUNTER_H_
