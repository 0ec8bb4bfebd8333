#include "imufit/io/parallel_samples.h"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <mutex>
#include <string_view>
#include <utility>
#include <vector>

#include "imufit/io/error.h"
#include "imufit/model/check.h"

namespace imufit {

// A block of the file: its text, and what its parse gave: the samples with their lines (counted
// from the block's start: the lines before it are known only when it is handed on), the number of
// lines it holds, whether a row stopped it, and the read error after its rows, if one came.
// Blocks are reused, so that their memory is allocated (and paged in) once.
struct ParallelSamplesReader::Block {
  enum class State { kRead, kParsing, kParsed };
  std::string rows;
  bool first = false;  // the file's first block
  State state = State::kRead;
  std::vector<Sample> samples;
  std::vector<uint32_t> lines;
  long line_count = 0;
  bool row_error = false;  // the parse stopped at a row: parsed again, located, when handed on
  std::exception_ptr read_error;
  std::exception_ptr parse_error;  // anything but a row's error (out of memory), thrown when handed on
  std::string text;                // what the block work made of the samples
  bool text_taken = false;
};

namespace {

// The CSV text of a block: small enough to stay in cache with its samples, large enough that
// handing blocks between threads costs nothing.
constexpr size_t kBlockBytes = 1 << 20;
// Blocks read ahead of the one handed on, per parsing thread: while the caller's thread uses a
// block, the others have blocks to parse.
constexpr size_t kBlocksAheadPerThread = 3;

}  // namespace

SamplesReader::SamplesReader(const SamplesReader& header_of, std::string_view rows, long line_before,
                             std::optional<double> last_time_s, bool probe_interval)
    : format_(header_of.format_),
      csv_(header_of.csv_, rows, line_before),
      seconds_per_time_unit_(header_of.seconds_per_time_unit_),
      time_column_(header_of.time_column_),
      temp_column_(header_of.temp_column_),
      fixed_temp_c_(header_of.fixed_temp_c_),
      segment_column_(header_of.segment_column_),
      serial_(header_of.serial_),
      // Past the probe unless asked (the file's first block): a later block continues the file.
      rows_(probe_interval ? 0 : kIntervalProbeRows + 1),
      last_time_s_(last_time_s.value_or(0.0)) {
  std::copy(std::begin(header_of.gyro_columns_), std::end(header_of.gyro_columns_), gyro_columns_);
  std::copy(std::begin(header_of.accel_columns_), std::end(header_of.accel_columns_), accel_columns_);
}

ParallelSamplesReader::ParallelSamplesReader(SamplesReader* header, int threads, BlockWork block_work)
    : header_(header),
      threads_(std::max(threads, 1)),
      block_work_(std::move(block_work)),
      line_before_(header->line_number()) {
  for (int i = 1; i < threads_; ++i) workers_.emplace_back([this] { Work(); });
}

ParallelSamplesReader::~ParallelSamplesReader() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  work_.notify_all();
  for (std::thread& worker : workers_) worker.join();  // each finishes the block it parses
}

void ParallelSamplesReader::Parse(Block* block) const {
  block->samples.clear();
  block->lines.clear();
  block->text.clear();
  block->row_error = false;
  block->parse_error = nullptr;
  if (block->rows.empty()) return;  // a read error's
  try {
    SamplesReader reader(*header_, block->rows, 0, std::nullopt, block->first);
    Sample sample;
    while (reader.Next(&sample)) {
      block->samples.push_back(sample);
      block->lines.push_back(static_cast<uint32_t>(reader.line_number()));
    }
    block->line_count = reader.line_number();
  } catch (const InputError&) {
    block->row_error = true;
  } catch (...) {
    block->parse_error = std::current_exception();
    return;
  }
  try {
    if (block_work_) block_work_(&block->samples, &block->text);  // the samples before a row error too
  } catch (...) {
    block->parse_error = std::current_exception();
  }
}

ParallelSamplesReader::Block* ParallelSamplesReader::Unparsed() const {
  for (const std::unique_ptr<Block>& block : queue_) {
    if (block->state == Block::State::kRead) return block.get();
  }
  return nullptr;
}

void ParallelSamplesReader::ParseLocked(Block* block, std::unique_lock<std::mutex>* lock) {
  block->state = Block::State::kParsing;
  lock->unlock();
  Parse(block);
  lock->lock();
  block->state = Block::State::kParsed;
}

void ParallelSamplesReader::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    Block* block = nullptr;
    work_.wait(lock, [&] { return stop_ || (block = Unparsed()) != nullptr; });
    if (stop_) return;
    ParseLocked(block, &lock);
    parsed_.notify_one();  // the caller's thread may wait for it
  }
}

bool ParallelSamplesReader::ReadBlock() {
  if (end_of_file_ || queue_.size() >= kBlocksAheadPerThread * static_cast<size_t>(threads_)) return false;
  std::unique_ptr<Block> block;
  if (free_.empty()) {
    block = std::make_unique<Block>();
  } else {
    block = std::move(free_.back());
    free_.pop_back();
  }
  block->read_error = nullptr;
  try {
    if (!header_->csv_.NextBlock(&block->rows, kBlockBytes)) {
      end_of_file_ = true;
      free_.push_back(std::move(block));
      return false;
    }
  } catch (...) {
    // A read error comes after the rows before it: it waits in line with their blocks.
    block->read_error = std::current_exception();
    block->rows.clear();
    end_of_file_ = true;
  }
  block->first = !launched_;
  launched_ = true;
  block->state = Block::State::kRead;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(block));
  }
  work_.notify_one();
  return true;
}

bool ParallelSamplesReader::Advance() {
  if (current_ != nullptr) {
    line_before_ += current_->line_count;
    free_.push_back(std::move(current_));
  }
  // Only this thread reads blocks and takes them out of the queue; every thread parses them. While
  // the block to hand on is parsed elsewhere, this thread reads and parses the ones after it.
  for (;;) {
    while (ReadBlock()) {
    }
    std::unique_lock<std::mutex> lock(mutex_);
    if (queue_.empty()) return false;
    if (queue_.front()->state == Block::State::kParsed) {
      current_ = std::move(queue_.front());
      queue_.pop_front();
      break;
    }
    if (Block* block = Unparsed()) {
      ParseLocked(block, &lock);
    } else {
      parsed_.wait(lock, [&] { return queue_.front()->state == Block::State::kParsed; });
    }
  }
  next_ = 0;
  current_->text_taken = false;
  if (current_->parse_error) std::rethrow_exception(current_->parse_error);
  if (current_->rows.empty()) std::rethrow_exception(current_->read_error);
  // The block's first row against the last row before it: when its time does not increase (or
  // the row has an error of its own), parse it again after that row, as one reader would have.
  if (last_time_s_ && (current_->samples.empty() || !(current_->samples.front().time_s > *last_time_s_))) {
    SamplesReader first_row(*header_, current_->rows, line_before_, last_time_s_);
    Sample sample;
    first_row.Next(&sample);
  }
  return true;
}

void ParallelSamplesReader::EndOfBlock() const {
  if (current_->row_error) {
    // Parsed again where its lines are known, it throws its error at its place.
    SamplesReader reader(*header_, current_->rows, line_before_, std::nullopt, current_->first);
    Sample sample;
    while (reader.Next(&sample)) {
    }
    IMUFIT_CHECK(false, "a block's row error is not found again");
  }
  if (current_->read_error) std::rethrow_exception(current_->read_error);
}

bool ParallelSamplesReader::Next(Sample* sample) {
  while (current_ == nullptr || next_ == current_->samples.size()) {
    if (current_ != nullptr) EndOfBlock();
    if (!Advance()) return false;
  }
  *sample = current_->samples[next_];
  line_ = line_before_ + current_->lines[next_];
  ++next_;
  last_time_s_ = sample->time_s;
  return true;
}

std::string_view ParallelSamplesReader::TakeText() {
  if (current_ == nullptr || current_->text_taken) return {};
  current_->text_taken = true;
  return current_->text;
}

void ParallelSamplesReader::Fail(const std::string& column, const std::string& message) const {
  const CsvReader& csv = header_->csv_;
  const std::optional<int> index = header_->FindColumn(column);
  if (!index) throw InputError(csv.path(), line_, 0, message);
  csv.FailAt(line_, *index, message);
}

}  // namespace imufit
