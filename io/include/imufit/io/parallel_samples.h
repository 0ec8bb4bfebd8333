// imufit — a samples file parsed on several cores, its samples handed on in the file's order.
//
// The file is read in blocks of whole lines (1 MiB each, CsvReader::NextBlock) by the calling
// thread, which also decompresses and hashes; each block is parsed on a thread of its own by a
// SamplesReader over the block's text, counting its lines from the block's start. At most `threads`
// blocks are in flight ahead of the reader's user, and their memory is reused, so memory stays
// bounded whatever the file's length. Every error is the one a single SamplesReader gives, at the
// same line and column, and comes after the samples before it: a block that stops at a row error is
// parsed again when its samples have been handed on, knowing its first line, to throw that error
// at its place; a read error comes after the block before it; and the first row of each block is
// checked against the last row of the one before (a time that does not increase).
#ifndef IMUFIT_IO_PARALLEL_SAMPLES_H_
#define IMUFIT_IO_PARALLEL_SAMPLES_H_

#include <deque>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "imufit/io/samples.h"

namespace imufit {

class ParallelSamplesReader {
 public:
  // Reads the samples of `header`, a SamplesReader that has read its header and no row (it must
  // outlive this reader; what it hashes, it still hashes). `threads` is the number of blocks
  // parsed at once; 1 parses each block in the calling thread.
  explicit ParallelSamplesReader(SamplesReader* header, int threads = 2);
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

 private:
  struct Block;
  // Parses `block` (on a thread of its own): its samples, until a row error.
  static void Parse(const SamplesReader& header, Block* block);
  // Reads the next block and starts its parse; false at the end of the file.
  bool Launch();
  // Takes the oldest block in flight as the current one; false when there is none.
  bool Advance();
  // At the end of the current block's samples: throws its error (a row's, located, or a read's).
  void EndOfBlock() const;

  SamplesReader* header_;
  int threads_;
  std::deque<std::future<std::unique_ptr<Block>>> in_flight_;
  std::vector<std::unique_ptr<Block>> free_;  // blocks handed on, to read the next into
  std::unique_ptr<Block> current_;
  long line_before_;  // the line before the current block's first
  size_t next_ = 0;   // the next sample of current_
  bool end_of_file_ = false;
  bool launched_ = false;  // a block was launched: the next is not the file's first
  std::optional<double> last_time_s_;
  long line_ = 0;
};

}  // namespace imufit

#endif  // IMUFIT_IO_PARALLEL_SAMPLES_H_
