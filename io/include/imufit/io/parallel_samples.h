// imufit — a samples file parsed on several cores, its samples handed on in the file's order.
//
// The file is read in blocks of whole lines (1 MiB each, CsvReader::NextBlock) by the calling
// thread, which also decompresses and hashes; each block is parsed by a SamplesReader over the
// block's text, counting its lines from the block's start, on whichever of `threads` threads is free:
// `threads - 1` parsing threads and the calling thread itself, which, when the block it is to hand
// on is still being parsed, parses the next one instead of waiting. At most 3 x `threads` blocks are
// read ahead of the reader's user, and their memory is reused, so memory stays bounded whatever the
// file's length. Every error is the one a single SamplesReader gives, at the
// same line and column, and comes after the samples before it: a block that stops at a row error is
// parsed again when its samples have been handed on, knowing its first line, to throw that error
// at its place; a read error comes after the block before it; and the first row of each block is
// checked against the last row of the one before (a time that does not increase).
#ifndef IMUFIT_IO_PARALLEL_SAMPLES_H_
#define IMUFIT_IO_PARALLEL_SAMPLES_H_

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "imufit/io/samples.h"

namespace imufit {

class ParallelSamplesReader {
 public:
  // Work on the samples of one block, done on the thread that parsed them, before they are handed
  // on: it may change them (not their number, time or order) and write what it makes of them to
  // `text` (empty at the start). A correction, and the formatting of its rows, so that they run on
  // every core.
  using BlockWork = std::function<void(std::vector<Sample>* samples, std::string* text)>;

  // Reads the samples of `header`, a SamplesReader that has read its header and no row (it must
  // outlive this reader; what it hashes, it still hashes). `threads` is the number of threads that
  // parse, the calling one included; 1 parses each block in the calling thread. `block_work`, when
  // not null, is done on every block (it is called on several threads at once).
  explicit ParallelSamplesReader(SamplesReader* header, int threads = 2, BlockWork block_work = nullptr);
  ~ParallelSamplesReader();
  ParallelSamplesReader(const ParallelSamplesReader&) = delete;
  ParallelSamplesReader& operator=(const ParallelSamplesReader&) = delete;

  // As SamplesReader::Next.
  bool Next(Sample* sample);
  // Throws an InputError located at the row of the last sample and the column called `column`.
  [[noreturn]] void Fail(const std::string& column, const std::string& message) const;
  const std::string& path() const { return header_->path(); }
  // The line of the last sample.
  long line_number() const { return line_; }
  // The text the block work made of the block of the last sample, the first time it is asked for
  // after Next() entered that block; empty otherwise. Valid until the next Next().
  std::string_view TakeText();

 private:
  struct Block;
  // Parses `block`: its samples, until a row error; then does the block work on them.
  void Parse(Block* block) const;
  // The oldest block read and not yet parsed, or null (under mutex_).
  Block* Unparsed() const;
  // Parses `block`, with `lock` (on mutex_) released meanwhile.
  void ParseLocked(Block* block, std::unique_lock<std::mutex>* lock);
  // A parsing thread's loop: parses the oldest unparsed block until stop_.
  void Work();
  // Reads the next block into the queue, unless it is full; false at the end of the file or full.
  bool ReadBlock();
  // Takes the oldest block, parsed, as the current one; false when there is none.
  bool Advance();
  // At the end of the current block's samples: throws its error (a row's, located, or a read's).
  void EndOfBlock() const;

  SamplesReader* header_;
  int threads_;
  BlockWork block_work_;
  // Blocks in the file's order, read, being parsed or parsed. Only the caller's thread adds and
  // removes them; the parsing threads change their state (under mutex_).
  std::deque<std::unique_ptr<Block>> queue_;
  std::mutex mutex_;
  std::condition_variable work_;    // a block to parse, or stop_
  std::condition_variable parsed_;  // a block parsed
  bool stop_ = false;
  std::vector<std::thread> workers_;
  std::vector<std::unique_ptr<Block>> free_;  // blocks handed on, to read the next into
  std::unique_ptr<Block> current_;
  long line_before_;  // the line before the current block's first
  size_t next_ = 0;   // the next sample of current_
  bool end_of_file_ = false;
  bool launched_ = false;  // a block was read: the next is not the file's first
  std::optional<double> last_time_s_;
  long line_ = 0;
};

}  // namespace imufit

#endif  // IMUFIT_IO_PARALLEL_SAMPLES_H_
