#include "imufit/run/windows.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace imufit {

std::string TimeStampNote(const WindowStats& stats) {
  std::string note;
  const auto add = [&note](const char* format, auto... values) {
    char line[320];
    std::snprintf(line, sizeof line, format, values...);
    note += (note.empty() ? "" : "; ") + std::string(line);
  };
  if (!stats.StampsOnGrid()) {
    add("%lld of %lld time stamps lie off a uniform grid (bunched or irregular): lost samples cannot be told "
        "from "
        "jitter%s",
        stats.off_grid_samples, stats.samples,
        stats.turns_off_grid > 0 ? ", so in the turns each sample is taken as one interval" : "");
    return note;
  }
  if (stats.lost_samples > 0) {
    add("%lld sample%s lost in %lld gap%s (longest %.3g s): turns are integrated across them",
        stats.lost_samples, stats.lost_samples == 1 ? "" : "s", stats.gaps, stats.gaps == 1 ? "" : "s",
        stats.longest_gap_s);
  }
  if (stats.turns_dropped_for_gaps > 0) {
    add("%d turn%s dropped for a gap longer than %.3g s, which would bias the angle",
        stats.turns_dropped_for_gaps, stats.turns_dropped_for_gaps == 1 ? "" : "s", stats.max_turn_gap_s);
  }
  if (stats.turns_off_grid > 0) {
    add("%d turn%s with a time stamp off the grid: each of its samples taken as one interval",
        stats.turns_off_grid, stats.turns_off_grid == 1 ? "" : "s");
  }
  return note;
}

WindowBuilder::WindowBuilder(const WindowOptions& options) : options_(options) {
  stats_.max_turn_gap_s = options.max_turn_gap_s;
}

WindowBuilder::WindowBuilder(const WindowOptions& options, const std::vector<TableSegment>& segments)
    : options_(options) {
  stats_.max_turn_gap_s = options.max_turn_gap_s;
  for (const TableSegment& segment : segments) {
    if (segment.IsTurn()) turn_ids_.push_back(segment.id);
  }
}

void WindowBuilder::Add(const Sample& sample) {
  if (stats_.samples == 0) {
    stats_.min_temp_c = stats_.max_temp_c = sample.temp_c;
    stats_.first_time_s = sample.time_s;
  }
  // The sample's slot on the run's time grid; the empty slots it skips are lost samples (the first
  // stamp's step is 1).
  const long long step = clock_.Place(sample.time_s);
  slot_ += step;
  const long long lost = step - 1;
  const double gap_s = static_cast<double>(lost) * clock_.interval_s();
  if (!clock_.on_grid()) ++stats_.off_grid_samples;
  if (lost > 0) {
    stats_.lost_samples += lost;
    ++stats_.gaps;
    stats_.longest_gap_s = std::max(stats_.longest_gap_s, gap_s);
  }
  Eigen::Matrix<double, 6, 1> value;
  value << sample.gyro, sample.accel;
  if (stats_.samples == 0) stats_.raw_min = stats_.raw_max = value;
  stats_.raw_min = stats_.raw_min.cwiseMin(value);
  stats_.raw_max = stats_.raw_max.cwiseMax(value);
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
    lost_ = 0;
    longest_gap_s_ = 0.0;
    off_grid_ = false;
    clipped_channel_ = -1;
    time_sum_ = 0.0;
    index_time_sum_ = 0.0;
    turn_slots_.clear();
    turn_values_.clear();
  } else if (lost > 0) {  // a gap inside the window
    lost_ += lost;
    longest_gap_s_ = std::max(longest_gap_s_, gap_s);
  }
  off_grid_ = off_grid_ || !clock_.on_grid();
  ++n_;
  end_s_ = sample.time_s;
  time_sum_ += sample.time_s - start_s_;
  index_time_sum_ += static_cast<double>(n_ - 1) * (sample.time_s - start_s_);
  const double inv_n = 1.0 / static_cast<double>(n_);
  temp_mean_ += (sample.temp_c - temp_mean_) * inv_n;
  temp_min_ = std::min(temp_min_, sample.temp_c);
  temp_max_ = std::max(temp_max_, sample.temp_c);
  for (int c = 0; c < 6 && clipped_channel_ < 0; ++c) {
    const double full_scale = c < 3 ? options_.gyro_full_scale_raw : options_.accel_full_scale_raw;
    if (full_scale > 0.0 && std::abs(value(c)) >= full_scale) {
      clipped_channel_ = c;
      clipped_value_ = value(c);
    }
  }
  const Eigen::Matrix<double, 6, 1> delta = value - mean_;
  mean_ += delta * inv_n;
  m2_ += delta.cwiseProduct(value - mean_);
  if (n_ >= 3) second_difference_sum_ += (value - 2.0 * previous_[1] + previous_[0]).cwiseAbs2();
  previous_[0] = previous_[1];
  previous_[1] = value;
  if (whole_occurrence_) {
    turn_slots_.push_back(slot_);
    turn_values_.push_back(value);
  }
}

bool WindowBuilder::CloseTurn(Window* window) {
  if (off_grid_) {  // one slot a sample (Close()), as if nothing were lost
    ++stats_.turns_off_grid;
    return true;
  }
  if (window->longest_gap_s > options_.max_turn_gap_s) {
    ++stats_.turns_dropped_for_gaps;
    return false;
  }
  if (window->lost_samples == 0) return true;  // the running sums hold every slot
  // The mean over every slot, a lost one counted at the value interpolated linearly between its
  // neighbours: a gap of g slots adds (g - 1) (x_before + x_after) / 2. Noise from second
  // differences of three consecutive slots only: across a gap the signal's change would count.
  Eigen::Matrix<double, 6, 1> slot_sum = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> second_difference_sum = Eigen::Matrix<double, 6, 1>::Zero();
  long long second_differences = 0;
  for (size_t i = 0; i < turn_values_.size(); ++i) {
    slot_sum += turn_values_[i];
    if (i == 0) continue;
    const long long step = turn_slots_[i] - turn_slots_[i - 1];
    slot_sum += static_cast<double>(step - 1) * 0.5 * (turn_values_[i] + turn_values_[i - 1]);
    if (i >= 2 && step == 1 && turn_slots_[i - 1] - turn_slots_[i - 2] == 1) {
      second_difference_sum +=
          (turn_values_[i] - 2.0 * turn_values_[i - 1] + turn_values_[i - 2]).cwiseAbs2();
      ++second_differences;
    }
  }
  const Eigen::Matrix<double, 6, 1> mean =
      slot_sum / static_cast<double>(window->samples + window->lost_samples);
  window->gyro_mean = mean.head<3>();
  window->accel_mean = mean.tail<3>();
  if (second_differences > 0) {
    const Eigen::Matrix<double, 6, 1> noise =
        (second_difference_sum / (6.0 * static_cast<double>(second_differences))).cwiseSqrt();
    window->gyro_noise = noise.head<3>();
    window->accel_noise = noise.tail<3>();
  }
  return true;
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
  // The run's grid interval: jitter of single time stamps averages out over the clock's memory,
  // where (end_s - start_s) / (n - 1) would carry the jitter of the two ends whole.
  window.interval_s = clock_.interval_s();
  window.lost_samples = lost_;
  window.longest_gap_s = longest_gap_s_;
  if (off_grid_) {
    // The grid cannot be trusted here: one slot a sample, and the least-squares slope of the
    // window's stamps against their index.
    const double n = static_cast<double>(n_);
    window.interval_s = (index_time_sum_ - 0.5 * (n - 1.0) * time_sum_) / (n * (n * n - 1.0) / 12.0);
    window.lost_samples = 0;
    window.longest_gap_s = 0.0;
  }
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
  if (clipped_channel_ >= 0) {
    NoteSaturation(window, clipped_channel_, clipped_value_);
    return;
  }
  if (whole_occurrence_ && !CloseTurn(&window)) return;
  windows_.push_back(window);
}

void WindowBuilder::NoteSaturation(const Window& window, int channel, double value) {
  constexpr int kSaturationExamples = 4;
  ++stats_.saturated_windows;
  if (static_cast<int>(stats_.saturation.size()) >= kSaturationExamples) return;
  char line[160];
  std::snprintf(line, sizeof line, "segment %d at t = %.1f s: %s %c at %.9g", window.segment, window.start_s,
                channel < 3 ? "gyro" : "accel", "xyz"[channel % 3], value);
  stats_.saturation.push_back(line);
}

void WindowBuilder::DropPinnedWindows() {
  // A window whose output on a channel is one constant value (a zero spread), at the run's largest or
  // smallest value of that channel, while the windows' median spread on it is not zero (the unit is
  // not noise-free): the output was pinned at a rail.
  std::vector<bool> pinned(windows_.size(), false);
  for (int c = 0; c < 6; ++c) {
    std::vector<double> spreads;
    for (const Window& w : windows_) spreads.push_back(c < 3 ? w.gyro_std(c) : w.accel_std(c - 3));
    if (spreads.empty()) continue;
    std::nth_element(spreads.begin(), spreads.begin() + spreads.size() / 2, spreads.end());
    if (!(spreads[spreads.size() / 2] > 0.0)) continue;
    for (size_t i = 0; i < windows_.size(); ++i) {
      const Window& w = windows_[i];
      const double spread = c < 3 ? w.gyro_std(c) : w.accel_std(c - 3);
      const double mean = c < 3 ? w.gyro_mean(c) : w.accel_mean(c - 3);
      if (pinned[i] || spread != 0.0 || (mean != stats_.raw_max(c) && mean != stats_.raw_min(c))) continue;
      pinned[i] = true;
      NoteSaturation(w, c, mean);
    }
  }
  std::vector<Window> kept;
  for (size_t i = 0; i < windows_.size(); ++i) {
    if (!pinned[i]) kept.push_back(windows_[i]);
  }
  windows_ = std::move(kept);
}

std::vector<Window> WindowBuilder::Finish() {
  Close();
  DropPinnedWindows();
  return std::move(windows_);
}

std::string SaturationNote(const WindowStats& stats) {
  if (stats.saturated_windows == 0) return "";
  std::string note =
      std::to_string(stats.saturated_windows) + " window" + (stats.saturated_windows == 1 ? "" : "s") +
      " left out with an output at full scale (saturated: the plan's rate or the part's range?): ";
  for (size_t i = 0; i < stats.saturation.size(); ++i) note += (i > 0 ? "; " : "") + stats.saturation[i];
  if (stats.saturated_windows > static_cast<int>(stats.saturation.size())) note += "; ...";
  return note;
}

}  // namespace imufit
