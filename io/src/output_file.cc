#include "imufit/io/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <limits.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "gzip_writer.h"
#include "imufit/io/error.h"
#include "imufit/io/path.h"

namespace imufit {
namespace {

constexpr size_t kFlushBytes = 1 << 20;

// The temporary files that exist right now, for the signal handler to remove. A fixed table of
// fixed-size slots: the handler may only read memory and call async-signal-safe functions
// (unlink, signal, raise). Registration (any thread) takes a mutex; the handler does not.
struct TempSlot {
  volatile std::sig_atomic_t used = 0;
  char path[PATH_MAX] = {};
};
constexpr int kTempSlots = 128;
TempSlot g_temp_slots[kTempSlots];
std::mutex g_temp_mutex;

int RegisterTempFile(const std::string& path) {
  if (path.size() >= PATH_MAX) return -1;
  const std::lock_guard<std::mutex> lock(g_temp_mutex);
  for (int i = 0; i < kTempSlots; ++i) {
    if (g_temp_slots[i].used) continue;
    std::memcpy(g_temp_slots[i].path, path.c_str(), path.size() + 1);
    std::atomic_signal_fence(std::memory_order_seq_cst);  // the path before the flag
    g_temp_slots[i].used = 1;
    return i;
  }
  return -1;  // more than kTempSlots outputs at once: this one is not removed on a signal
}

void UnregisterTempFile(int slot) {
  if (slot < 0) return;
  const std::lock_guard<std::mutex> lock(g_temp_mutex);
  g_temp_slots[slot].used = 0;
}

// A signal that arrives while outputs are being committed (SignalsDeferred) waits until they are:
// the handler notes it and returns, and the last section to end stops the program. Lock-free
// atomics, so the handler (on any thread) may use them.
std::atomic<int> g_commit_sections{0};
std::atomic<int> g_pending_signal{0};
std::atomic<void (*)()> g_interrupt_note{nullptr};

[[noreturn]] void StopOnSignal(int signal_number) {
  if (void (*note)() = g_interrupt_note.load(); note != nullptr && signal_number != SIGPIPE) note();
  for (TempSlot& slot : g_temp_slots) {
    if (slot.used) ::unlink(slot.path);
  }
  std::signal(signal_number, SIG_DFL);
  sigset_t blocked;  // in the handler, the signal itself is blocked
  sigemptyset(&blocked);
  sigaddset(&blocked, signal_number);
  ::pthread_sigmask(SIG_UNBLOCK, &blocked, nullptr);
  std::raise(signal_number);
  ::_exit(128 + signal_number);  // not reached
}

extern "C" void RemoveTempFilesAndReraise(int signal_number) {
  g_pending_signal.store(signal_number);  // first: a section starting now sees it
  if (g_commit_sections.load() > 0) return;
  StopOnSignal(signal_number);
}

// Refuses a destination that exists but is not an ordinary, writable file: rename() would
// replace a symbolic link (not its target), a FIFO or a device node, or a read-only file.
void CheckDestination(const std::string& path) {
  struct stat status;
  if (::lstat(path.c_str(), &status) != 0) return;  // does not exist (yet): fine
  if (S_ISLNK(status.st_mode)) {
    throw InputError(path,
                     "is a symbolic link: imufit neither writes through a link nor replaces it (give the "
                     "link's target as the output, or remove the link)");
  }
  if (S_ISDIR(status.st_mode)) throw InputError(path, "is a directory");
  if (!S_ISREG(status.st_mode)) {
    const char* kind = S_ISFIFO(status.st_mode)                             ? "a FIFO"
                       : S_ISCHR(status.st_mode) || S_ISBLK(status.st_mode) ? "a device"
                       : S_ISSOCK(status.st_mode)                           ? "a socket"
                                                                            : "a special file";
    throw InputError(path, std::string("is ") + kind +
                               ", not a regular file: imufit writes outputs only to "
                               "regular files, which it replaces whole");
  }
  if ((status.st_mode & 0222) == 0 || ::access(path.c_str(), W_OK) != 0) {
    throw InputError(path, "is read-only: imufit does not replace a file it may not write");
  }
}

}  // namespace

SignalsDeferred::SignalsDeferred() {
  g_commit_sections.fetch_add(1);
  if (g_pending_signal.load() != 0) {
    // The program is being stopped: a commit that has not started does not start.
    g_commit_sections.fetch_sub(1);
    for (;;) ::pause();
  }
}

SignalsDeferred::~SignalsDeferred() {
  if (g_commit_sections.fetch_sub(1) == 1 && g_pending_signal.load() != 0) {
    StopOnSignal(g_pending_signal.load());
  }
}

void SetInterruptNote(void (*note)()) { g_interrupt_note.store(note); }

void InstallOutputCleanupOnSignals() {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) {
    struct sigaction previous;
    if (::sigaction(signal_number, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN)
      continue;  // nohup
    struct sigaction action {};
    action.sa_handler = RemoveTempFilesAndReraise;
    sigfillset(&action.sa_mask);  // one signal handled at a time
    ::sigaction(signal_number, &action, nullptr);
  }
}

OutputTransaction::~OutputTransaction() {
  for (const Pending& pending : pending_) {
    ::unlink(pending.temp_path.c_str());
    UnregisterTempFile(pending.slot);
  }
}

void OutputTransaction::Add(std::string temp_path, std::string path, int slot) {
  pending_.push_back({std::move(temp_path), std::move(path), slot});
}

void OutputTransaction::Commit() {
  const SignalsDeferred deferred;  // the renames all happen, or none
  // Every output is complete and synced on disk; only the renames are left, in one folder each,
  // so the last thing that can fail has been done for all of them before any is renamed.
  for (const Pending& pending : pending_) CheckDestination(pending.path);
  while (!pending_.empty()) {
    const Pending& pending = pending_.front();
    if (std::rename(pending.temp_path.c_str(), pending.path.c_str()) != 0) {
      throw InputError(pending.path, std::string("cannot replace the file: ") + std::strerror(errno));
    }
    UnregisterTempFile(pending.slot);
    pending_.erase(pending_.begin());
  }
}

OutputFile::OutputFile(std::string path, OutputTransaction* transaction)
    : path_(std::move(path)), transaction_(transaction) {
  namespace fs = std::filesystem;
  const fs::path destination(path_);
  if (!destination.has_filename()) throw InputError(path_, "not a file name");
  CheckDestination(path_);
  const fs::path folder = destination.parent_path().empty() ? fs::path(".") : destination.parent_path();
  std::string pattern = (folder / ("." + destination.filename().string() + ".tmp-XXXXXX")).string();
  fd_ = ::mkstemp(pattern.data());
  if (fd_ < 0) {
    throw InputError(path_,
                     std::string("cannot create a file in ") + folder.string() + ": " + std::strerror(errno));
  }
  temp_path_ = pattern;
  temp_slot_ = RegisterTempFile(temp_path_);
  // mkstemp creates mode 0600; give the result the permissions an ordinary new file would get.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::fchmod(fd_, 0666 & ~mask);
  if (IsGzipPath(path_)) gz_ = std::make_unique<GzipWriter>(fd_, path_);
  buffer_.reserve(kFlushBytes + 4096);
}

OutputFile::~OutputFile() {
  if (committed_) return;
  if (fd_ >= 0) ::close(fd_);
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
  UnregisterTempFile(temp_slot_);
}

void OutputFile::Write(std::string_view text) {
  buffer_.append(text);
  if (buffer_.size() >= kFlushBytes) Flush();
}

void OutputFile::WriteNumber(double value) {
  char digits[32];
  if (!std::isfinite(value)) {
    Write(FormatDouble(value));
    return;
  }
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  Write(std::string_view(digits, result.ptr - digits));
}

void OutputFile::Flush() {
  if (buffer_.empty()) return;
  if (gz_ != nullptr) {
    gz_->Write(&buffer_);  // compressed on its thread; buffer_ is one it has compressed, or new
    buffer_.reserve(kFlushBytes + 4096);
  } else {
    WriteAll(fd_, buffer_, path_);
  }
  buffer_.clear();
}

void OutputFile::Commit() {
  Flush();
  if (gz_ != nullptr) gz_->Finish();
  if (::fsync(fd_) != 0 && errno != EINVAL) {
    throw InputError(path_, std::string("sync failed: ") + std::strerror(errno));
  }
  ::close(fd_);
  fd_ = -1;
  if (transaction_ != nullptr) {
    transaction_->Add(temp_path_, path_, temp_slot_);  // renamed with the others, or removed
    committed_ = true;
    return;
  }
  CheckDestination(path_);  // again: a link or FIFO may have appeared while we wrote
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    throw InputError(path_, std::string("cannot replace the file: ") + std::strerror(errno));
  }
  UnregisterTempFile(temp_slot_);
  committed_ = true;
}

void WriteFileAtomically(const std::string& path, std::string_view text, OutputTransaction* transaction) {
  OutputFile file(path, transaction);
  file.Write(text);
  file.Commit();
}

void RefuseToOverwriteInputs(const std::string& output, const std::vector<std::string>& inputs) {
  std::error_code ec;
  if (!std::filesystem::exists(output, ec)) return;
  for (const std::string& input : inputs) {
    if (std::filesystem::equivalent(output, input, ec)) {
      throw InputError(output, "is also an input (" + input +
                                   "); choose another output file, imufit never replaces its input");
    }
  }
}

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  return std::string(digits, result.ptr - digits);
}

}  // namespace imufit
