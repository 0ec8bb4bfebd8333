#include "imufit/io/parallel_samples.h"

#include <algorithm>
#include <exception>
#include <string_view>
#include <utility>
#include <vector>

#include "imufit/io/error.h"

namespace imufit {

// A block of the file: its text, where it starts, and what its parse gave (the samples with their
// lines, then the error that stopped it, if one did).
struct ParallelSamplesReader::Block {
  std::string rows;
  long line_before = 0;
  std::vector<Sample> samples;
  std::vector<long> lines;
  std::exception_ptr error;
};

namespace {

// The bytes of a CSV row of samples, at least: to reserve for a block's samples.
constexpr size_t kMinRowBytes = 24;

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

ParallelSamplesReader::ParallelSamplesReader(SamplesReader* header, int threads)
    : header_(header), threads_(std::max(threads, 1)) {}

ParallelSamplesReader::~ParallelSamplesReader() = default;  // waits for the blocks in flight

bool ParallelSamplesReader::Launch() {
  if (end_of_file_) return false;
  auto block = std::make_unique<Block>();
  try {
    std::string_view rows;
    if (!header_->csv_.NextBlock(&rows, &block->line_before)) {
      end_of_file_ = true;
      return false;
    }
    block->rows.assign(rows);
  } catch (...) {
    // A read error comes after the rows before it: it waits in line with their blocks.
    block->error = std::current_exception();
    end_of_file_ = true;
  }
  const SamplesReader* header = header_;
  const bool first_block = !launched_;
  launched_ = true;
  auto parse = [header, first_block, block = std::move(block)]() mutable {
    if (block->error) return std::move(block);
    try {
      SamplesReader reader(*header, block->rows, block->line_before, std::nullopt, first_block);
      block->samples.reserve(block->rows.size() / kMinRowBytes);
      block->lines.reserve(block->rows.size() / kMinRowBytes);
      Sample sample;
      while (reader.Next(&sample)) {
        block->samples.push_back(sample);
        block->lines.push_back(reader.line_number());
      }
    } catch (...) {
      block->error = std::current_exception();
    }
    return std::move(block);
  };
  in_flight_.push_back(
      std::async(threads_ > 1 ? std::launch::async : std::launch::deferred, std::move(parse)));
  return true;
}

bool ParallelSamplesReader::Advance() {
  while (static_cast<int>(in_flight_.size()) < threads_ && Launch()) {
  }
  if (in_flight_.empty()) return false;
  current_ = in_flight_.front().get();
  in_flight_.pop_front();
  next_ = 0;
  Launch();  // the next block parses while this one is handed on
  // The block's first row against the last row before it: when its time does not increase (or
  // the row has an error of its own), parse it again after that row, as one reader would have.
  if (last_time_s_ && (current_->samples.empty() || !(current_->samples.front().time_s > *last_time_s_))) {
    SamplesReader first_row(*header_, current_->rows, current_->line_before, last_time_s_);
    Sample sample;
    first_row.Next(&sample);
  }
  return true;
}

bool ParallelSamplesReader::Next(Sample* sample) {
  while (current_ == nullptr || next_ == current_->samples.size()) {
    if (current_ != nullptr && current_->error) std::rethrow_exception(current_->error);
    if (!Advance()) return false;
  }
  *sample = current_->samples[next_];
  line_ = current_->lines[next_];
  ++next_;
  last_time_s_ = sample->time_s;
  return true;
}

void ParallelSamplesReader::Fail(const std::string& column, const std::string& message) const {
  const CsvReader& csv = header_->csv_;
  const std::optional<int> index = header_->FindColumn(column);
  if (!index) throw InputError(csv.path(), line_, 0, message);
  csv.FailAt(line_, *index, message);
}

}  // namespace imufit
