// imufit — output files that are written whole or not at all (docs/spec.md section 4).
//
// An OutputFile writes into a temporary file in the destination's folder and renames it over the
// destination only in Commit(), after a flush and an fsync. If Commit() is never reached (an
// error, an exception, a crash) the temporary file is removed and an existing destination is
// left exactly as it was; on SIGINT, SIGTERM, SIGHUP or SIGPIPE too (InstallOutputCleanupOnSignals).
// Paths ending in ".gz" are written gzip-compressed (ISA-L's igzip; standard gzip).
//
// An existing destination must be a regular file that may be written: a symbolic link, FIFO,
// device node, directory or read-only file is refused (InputError) rather than replaced.
//
// Several outputs that belong together (a calibration and its certificate) are written in one
// OutputTransaction, given explicitly to each writer: all of them appear, or none.
#ifndef IMUFIT_IO_OUTPUT_FILE_H_
#define IMUFIT_IO_OUTPUT_FILE_H_

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace imufit {

class GzipWriter;
class OutputTransaction;

class OutputFile {
 public:
  // Creates the temporary file; throws InputError naming `path` when its folder is not writable.
  // With a `transaction` (may be null), Commit() leaves the finished file to the transaction.
  explicit OutputFile(std::string path, OutputTransaction* transaction = nullptr);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void Write(std::string_view text);
  // Appends the shortest decimal text that reads back as exactly `value`.
  void WriteNumber(double value);
  // Flushes, syncs and renames the temporary file over the destination; in a transaction, the
  // rename is the transaction's (with the other outputs). Throws InputError.
  void Commit();

  const std::string& path() const { return path_; }
  // The temporary file, for a program that writes the output itself (gnuplot): whatever is at
  // this path when Commit() runs becomes the destination.
  const std::string& temp_path() const { return temp_path_; }

 private:
  void Flush();

  std::string path_;
  OutputTransaction* transaction_;
  std::string temp_path_;
  std::string buffer_;
  int fd_ = -1;
  std::unique_ptr<GzipWriter> gz_;  // when compressing (ISA-L)
  bool committed_ = false;
  int temp_slot_ = -1;  // in the table of temporaries removed on a signal
};

// Several outputs written all or nothing (`fit -o .. --report ..`). An OutputFile made with a
// transaction completes its temporary file in Commit() (flushed, synced, closed) but leaves it in
// place; the transaction's Commit() renames them all over their destinations. A transaction
// destroyed without Commit() (an error in any output) removes every temporary, so no destination
// changes. The renames themselves are the only step after which a failure (of the file system)
// can leave some outputs replaced and others not.
class OutputTransaction {
 public:
  OutputTransaction() = default;
  ~OutputTransaction();
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;

  void Commit();

 private:
  friend class OutputFile;
  // A finished temporary file (OutputFile::Commit()), renamed over `path` by Commit().
  void Add(std::string temp_path, std::string path, int slot);

  struct Pending {
    std::string temp_path, path;
    int slot;
  };
  std::vector<Pending> pending_;
};

// Removes the temporary files of uncommitted outputs when the program is stopped by SIGINT,
// SIGTERM, SIGHUP or SIGPIPE (`imufit fit ... | head`), then dies of that signal as it would have,
// silently. Signals that are ignored (nohup) stay ignored. Called once by main().
void InstallOutputCleanupOnSignals();

// While one of these lives (on any thread), those signals wait: the outputs being committed (a
// transaction's renames, and the results store's commit that goes with them) all appear before
// the program stops. A section that would start after a signal arrived never starts.
class SignalsDeferred {
 public:
  SignalsDeferred();
  ~SignalsDeferred();
  SignalsDeferred(const SignalsDeferred&) = delete;
  SignalsDeferred& operator=(const SignalsDeferred&) = delete;
};

// `note` (async-signal-safe: write(2) only) runs when SIGINT, SIGTERM or SIGHUP stops the program,
// before the temporary files are removed: a batch says how far it got. nullptr: none.
void SetInterruptNote(void (*note)());

// Writes `text` to `path` atomically (OutputFile in one call), in `transaction` when not null.
void WriteFileAtomically(const std::string& path, std::string_view text,
                         OutputTransaction* transaction = nullptr);

// Throws InputError when `output` names the same file as one of `inputs`: imufit never replaces
// a file it is reading.
void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs);

// The shortest decimal representation that reads back as exactly `value` ("nan", "inf" and
// "-inf" for non-finite values).
std::string FormatDouble(double value);

}  // namespace imufit

#endif  // IMUFIT_IO_OUTPUT_FILE_H_
