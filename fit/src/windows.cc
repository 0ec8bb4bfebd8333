#include "imufit/fit/windows.h"

#include <algorithm>
#include <cmath>

namespace imufit {

std::string WindowOptions::Validate() const {
  if (!(trim_s >= 0.0)) return "the trim time cannot be negative";
  if (!(max_temp_span_c > 0.0)) return "the window temperature span must be positive";
  if (!(max_duration_s >= 0.0)) return "the window duration cannot be negative";
  if (min_samples < 2) return "a window needs at least 2 samples";
  return "";
}

WindowBuilder::WindowBuilder(const WindowOptions& options) : options_(options) {}

WindowBuilder::WindowBuilder(const WindowOptions& options, const std::vector<TableSegment>& segments)
    : options_(options) {
  for (const TableSegment& segment : segments) {
    if (segment.IsTurn()) turn_ids_.push_back(segment.id);
  }
}

void WindowBuilder::Add(const Sample& sample) {
  if (stats_.samples == 0) {
    stats_.min_temp_c = stats_.max_temp_c = sample.temp_c;
    stats_.first_time_s = sample.time_s;
  }
  ++stats_.samples;
  stats_.last_time_s = sample.time_s;
  stats_.min_temp_c = std::min(stats_.min_temp_c, sample.temp_c);
  stats_.max_temp_c = std::max(stats_.max_temp_c, sample.temp_c);

  if (sample.segment != current_segment_) {
    // A new occurrence starts (or a transition).
    Close();
    current_segment_ = sample.segment;
    if (sample.segment != kTransitionSegment) {
      auto it = std::find_if(occurrences_.begin(), occurrences_.end(),
                             [&](const auto& entry) { return entry.first == sample.segment; });
      if (it == occurrences_.end()) {
        occurrences_.emplace_back(sample.segment, 0);
        it = occurrences_.end() - 1;
      }
      current_occurrence_ = it->second++;
      occurrence_start_s_ = sample.time_s;
      whole_occurrence_ = std::find(turn_ids_.begin(), turn_ids_.end(), sample.segment) != turn_ids_.end();
    }
  }
  if (sample.segment == kTransitionSegment) {
    ++stats_.transition_samples;
    return;
  }
  if (!whole_occurrence_ && sample.time_s - occurrence_start_s_ < options_.trim_s) {
    ++stats_.trimmed_samples;
    return;
  }
  if (open_ && !whole_occurrence_ &&
      (std::abs(sample.temp_c - window_first_temp_c_) > options_.max_temp_span_c ||
       (options_.max_duration_s > 0.0 && sample.time_s - start_s_ >= options_.max_duration_s))) {
    Close();
  }
  if (!open_) {
    open_ = true;
    n_ = 0;
    start_s_ = sample.time_s;
    window_first_temp_c_ = sample.temp_c;
    temp_mean_ = 0.0;
    temp_min_ = temp_max_ = sample.temp_c;
    mean_.setZero();
    m2_.setZero();
    second_difference_sum_.setZero();
    time_sum_ = 0.0;
    index_time_sum_ = 0.0;
  }
  ++n_;
  end_s_ = sample.time_s;
  // For the mean sample interval: time against sample index, k = n - 1 (see Close()).
  time_sum_ += sample.time_s - start_s_;
  index_time_sum_ += static_cast<double>(n_ - 1) * (sample.time_s - start_s_);
  const double inv_n = 1.0 / static_cast<double>(n_);
  temp_mean_ += (sample.temp_c - temp_mean_) * inv_n;
  temp_min_ = std::min(temp_min_, sample.temp_c);
  temp_max_ = std::max(temp_max_, sample.temp_c);
  Eigen::Matrix<double, 6, 1> value;
  value << sample.gyro, sample.accel;
  const Eigen::Matrix<double, 6, 1> delta = value - mean_;
  mean_ += delta * inv_n;
  m2_ += delta.cwiseProduct(value - mean_);
  if (n_ >= 3) second_difference_sum_ += (value - 2.0 * previous_[1] + previous_[0]).cwiseAbs2();
  previous_[0] = previous_[1];
  previous_[1] = value;
}

void WindowBuilder::Close() {
  if (!open_) return;
  open_ = false;
  if (n_ < options_.min_samples) {
    ++stats_.short_windows;
    return;
  }
  Window window;
  window.segment = current_segment_;
  window.occurrence = current_occurrence_;
  window.samples = n_;
  window.start_s = start_s_;
  window.end_s = end_s_;
  // The least-squares slope of time against index: jitter of single time stamps averages out,
  // where (end_s - start_s) / (n - 1) would carry the jitter of the two ends whole.
  const double n = static_cast<double>(n_);
  window.interval_s = (index_time_sum_ - 0.5 * (n - 1.0) * time_sum_) / (n * (n * n - 1.0) / 12.0);
  window.temp_c = temp_mean_;
  window.min_temp_c = temp_min_;
  window.max_temp_c = temp_max_;
  const Eigen::Matrix<double, 6, 1> std_dev = (m2_ / static_cast<double>(n_ - 1)).cwiseSqrt();
  window.gyro_mean = mean_.head<3>();
  window.accel_mean = mean_.tail<3>();
  window.gyro_std = std_dev.head<3>();
  window.accel_std = std_dev.tail<3>();
  if (n_ > 2) {
    const Eigen::Matrix<double, 6, 1> noise =
        (second_difference_sum_ / (6.0 * static_cast<double>(n_ - 2))).cwiseSqrt();
    window.gyro_noise = noise.head<3>();
    window.accel_noise = noise.tail<3>();
  }
  window.whole_occurrence = whole_occurrence_;
  windows_.push_back(window);
}

std::vector<Window> WindowBuilder::Finish() {
  Close();
  return std::move(windows_);
}

}  // namespace imufit
