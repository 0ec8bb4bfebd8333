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
  Channels value;
  value << sample.gyro, sample.accel;
  const long long lost = PlaceOnGrid(sample.time_s);
  CountSample(sample, value);
  if (sample.segment != occurrence_.segment) FollowOccurrence(sample.segment, sample.time_s);
  if (sample.segment == kTransitionSegment) {
    ++stats_.transition_samples;
    return;
  }
  if (!occurrence_.whole && sample.time_s - occurrence_.start_s < options_.trim_s) {
    ++stats_.trimmed_samples;
    return;
  }
  if (window_.open && WindowIsFull(sample)) Close();
  if (!window_.open) {
    Open(sample);
  } else if (lost > 0) {  // a gap inside the window
    window_.lost += lost;
    window_.longest_gap_s = std::max(window_.longest_gap_s, static_cast<double>(lost) * clock_.interval_s());
  }
  Accumulate(sample, value);
}

long long WindowBuilder::PlaceOnGrid(double time_s) {
  // The empty slots a stamp skips are lost samples (the first stamp's step is 1).
  const long long step = clock_.Place(time_s);
  slot_ += step;
  const long long lost = step - 1;
  if (!clock_.on_grid()) ++stats_.off_grid_samples;
  if (lost > 0) {
    stats_.lost_samples += lost;
    ++stats_.gaps;
    stats_.longest_gap_s = std::max(stats_.longest_gap_s, static_cast<double>(lost) * clock_.interval_s());
  }
  return lost;
}

void WindowBuilder::CountSample(const Sample& sample, const Channels& value) {
  if (stats_.samples == 0) {
    stats_.min_temp_c = stats_.max_temp_c = sample.temp_c;
    stats_.first_time_s = sample.time_s;
    stats_.raw_min = stats_.raw_max = value;
  }
  stats_.raw_min = stats_.raw_min.cwiseMin(value);
  stats_.raw_max = stats_.raw_max.cwiseMax(value);
  ++stats_.samples;
  stats_.last_time_s = sample.time_s;
  stats_.min_temp_c = std::min(stats_.min_temp_c, sample.temp_c);
  stats_.max_temp_c = std::max(stats_.max_temp_c, sample.temp_c);
}

void WindowBuilder::FollowOccurrence(int segment, double time_s) {
  Close();
  occurrence_ = {};
  occurrence_.segment = segment;
  if (segment == kTransitionSegment) return;
  auto it = std::find_if(occurrences_.begin(), occurrences_.end(),
                         [&](const auto& entry) { return entry.first == segment; });
  if (it == occurrences_.end()) {
    occurrences_.emplace_back(segment, 0);
    it = occurrences_.end() - 1;
  }
  occurrence_.index = it->second++;
  occurrence_.start_s = time_s;
  occurrence_.whole = std::find(turn_ids_.begin(), turn_ids_.end(), segment) != turn_ids_.end();
}

bool WindowBuilder::WindowIsFull(const Sample& sample) const {
  if (occurrence_.whole) return false;  // a turn's window closes with its occurrence
  // Closed sooner it would be dropped: on a fast ramp a window spans more instead.
  if (window_.n < options_.min_samples) return false;
  return std::abs(sample.temp_c - window_.first_temp_c) > options_.max_temp_span_c ||
         (options_.max_duration_s > 0.0 && sample.time_s - window_.start_s >= options_.max_duration_s);
}

void WindowBuilder::Open(const Sample& sample) {
  window_ = {};
  window_.open = true;
  window_.start_s = sample.time_s;
  window_.first_temp_c = sample.temp_c;
  window_.temp_min = window_.temp_max = sample.temp_c;
}

void WindowBuilder::Accumulate(const Sample& sample, const Channels& value) {
  OpenWindow& w = window_;
  w.off_grid = w.off_grid || !clock_.on_grid();
  ++w.n;
  w.end_s = sample.time_s;
  w.time_sum += sample.time_s - w.start_s;
  w.index_time_sum += static_cast<double>(w.n - 1) * (sample.time_s - w.start_s);
  const double inv_n = 1.0 / static_cast<double>(w.n);
  w.temp_mean += (sample.temp_c - w.temp_mean) * inv_n;
  w.temp_min = std::min(w.temp_min, sample.temp_c);
  w.temp_max = std::max(w.temp_max, sample.temp_c);
  for (int c = 0; c < 6 && w.clipped_channel < 0; ++c) {
    const double full_scale = c < 3 ? options_.gyro_full_scale_raw : options_.accel_full_scale_raw;
    if (full_scale > 0.0 && std::abs(value(c)) >= full_scale) {
      w.clipped_channel = c;
      w.clipped_value = value(c);
    }
  }
  const Channels delta = value - w.mean;
  w.mean += delta * inv_n;
  w.m2 += delta.cwiseProduct(value - w.mean);
  if (w.n >= 3) w.second_difference_sum += (value - 2.0 * w.previous[1] + w.previous[0]).cwiseAbs2();
  w.previous[0] = w.previous[1];
  w.previous[1] = value;
  if (occurrence_.whole) {
    w.turn_slots.push_back(slot_);
    w.turn_values.push_back(value);
  }
}

bool WindowBuilder::CloseTurn(Window* window) {
  if (window_.off_grid) {  // one slot a sample (Close()), as if nothing were lost
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
  const std::vector<long long>& slots = window_.turn_slots;
  const std::vector<Channels>& values = window_.turn_values;
  Channels slot_sum = Channels::Zero();
  Channels second_difference_sum = Channels::Zero();
  long long second_differences = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    slot_sum += values[i];
    if (i == 0) continue;
    const long long step = slots[i] - slots[i - 1];
    slot_sum += static_cast<double>(step - 1) * 0.5 * (values[i] + values[i - 1]);
    if (i >= 2 && step == 1 && slots[i - 1] - slots[i - 2] == 1) {
      second_difference_sum += (values[i] - 2.0 * values[i - 1] + values[i - 2]).cwiseAbs2();
      ++second_differences;
    }
  }
  const Channels mean = slot_sum / static_cast<double>(window->samples + window->lost_samples);
  window->gyro_mean = mean.head<3>();
  window->accel_mean = mean.tail<3>();
  if (second_differences > 0) {
    const Channels noise =
        (second_difference_sum / (6.0 * static_cast<double>(second_differences))).cwiseSqrt();
    window->gyro_noise = noise.head<3>();
    window->accel_noise = noise.tail<3>();
  }
  return true;
}

void WindowBuilder::Close() {
  if (!window_.open) return;
  window_.open = false;
  const OpenWindow& w = window_;
  Window window;
  window.segment = occurrence_.segment;
  window.occurrence = occurrence_.index;
  window.samples = w.n;
  window.start_s = w.start_s;
  window.end_s = w.end_s;
  // The run's grid interval: jitter of single time stamps averages out over the clock's memory,
  // where (end_s - start_s) / (n - 1) would carry the jitter of the two ends whole.
  window.interval_s = clock_.interval_s();
  window.lost_samples = w.lost;
  window.longest_gap_s = w.longest_gap_s;
  if (w.off_grid) {
    // The grid cannot be trusted here: one slot a sample, and the least-squares slope of the
    // window's stamps against their index.
    const double n = static_cast<double>(w.n);
    window.interval_s = (w.index_time_sum - 0.5 * (n - 1.0) * w.time_sum) / (n * (n * n - 1.0) / 12.0);
    window.lost_samples = 0;
    window.longest_gap_s = 0.0;
  }
  window.temp_c = w.temp_mean;
  window.min_temp_c = w.temp_min;
  window.max_temp_c = w.temp_max;
  const Channels std_dev = (w.m2 / static_cast<double>(std::max(w.n - 1, 1LL))).cwiseSqrt();
  window.gyro_mean = w.mean.head<3>();
  window.accel_mean = w.mean.tail<3>();
  window.gyro_std = std_dev.head<3>();
  window.accel_std = std_dev.tail<3>();
  if (w.n > 2) {
    const Channels noise = (w.second_difference_sum / (6.0 * static_cast<double>(w.n - 2))).cwiseSqrt();
    window.gyro_noise = noise.head<3>();
    window.accel_noise = noise.tail<3>();
  }
  window.whole_occurrence = occurrence_.whole;
  if (w.n < options_.min_samples) {
    if (w.clipped_channel < 0 && MergeRemainder(window)) return;
    ++stats_.short_windows;
    stats_.short_samples += w.n;
    return;
  }
  if (w.clipped_channel >= 0) {
    NoteSaturation(window, w.clipped_channel, w.clipped_value);
    return;
  }
  if (occurrence_.whole && !CloseTurn(&window)) {
    stats_.gap_turn_samples += w.n;
    return;
  }
  stats_.window_samples += w.n;
  windows_.push_back(window);
}

bool WindowBuilder::MergeRemainder(const Window& remainder) {
  if (remainder.whole_occurrence || windows_.empty()) return false;
  Window& before = windows_.back();
  if (before.whole_occurrence || before.segment != remainder.segment ||
      before.occurrence != remainder.occurrence) {
    return false;
  }
  // Pooled mean and sum of squared deviations (Chan et al.); the second differences of both
  // pieces (none across the seam), each recovered from its per-sample figure.
  const double n1 = static_cast<double>(before.samples);
  const double n2 = static_cast<double>(remainder.samples);
  const double n = n1 + n2;
  const double d1 = std::max(n1 - 2.0, 0.0), d2 = std::max(n2 - 2.0, 0.0);
  const auto pool = [&](Eigen::Vector3d* mean, Eigen::Vector3d* std_dev, Eigen::Vector3d* noise,
                        const Eigen::Vector3d& mean2, const Eigen::Vector3d& std2,
                        const Eigen::Vector3d& noise2) {
    const Eigen::Vector3d delta = mean2 - *mean;
    const Eigen::Vector3d m2 = std_dev->cwiseAbs2() * (n1 - 1.0) +
                               std2.cwiseAbs2() * std::max(n2 - 1.0, 0.0) + delta.cwiseAbs2() * (n1 * n2 / n);
    const Eigen::Vector3d second = noise->cwiseAbs2() * (6.0 * d1) + noise2.cwiseAbs2() * (6.0 * d2);
    *mean += delta * (n2 / n);
    *std_dev = (m2 / (n - 1.0)).cwiseSqrt();
    if (d1 + d2 > 0.0) *noise = (second / (6.0 * (d1 + d2))).cwiseSqrt();
  };
  pool(&before.gyro_mean, &before.gyro_std, &before.gyro_noise, remainder.gyro_mean, remainder.gyro_std,
       remainder.gyro_noise);
  pool(&before.accel_mean, &before.accel_std, &before.accel_noise, remainder.accel_mean, remainder.accel_std,
       remainder.accel_noise);
  before.temp_c += (remainder.temp_c - before.temp_c) * (n2 / n);
  before.min_temp_c = std::min(before.min_temp_c, remainder.min_temp_c);
  before.max_temp_c = std::max(before.max_temp_c, remainder.max_temp_c);
  before.samples += remainder.samples;
  before.end_s = remainder.end_s;
  // The slots between the two pieces (none on a gap-free grid) and the remainder's own.
  before.lost_samples += remainder.lost_samples;
  before.longest_gap_s = std::max(before.longest_gap_s, remainder.longest_gap_s);
  ++stats_.merged_remainders;
  stats_.window_samples += remainder.samples;
  return true;
}

void WindowBuilder::NoteSaturation(const Window& window, int channel, double value) {
  constexpr int kSaturationExamples = 4;
  ++stats_.saturated_windows;
  stats_.saturated_samples += window.samples;
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
    if (!pinned[i]) {
      kept.push_back(windows_[i]);
    } else {
      stats_.window_samples -= windows_[i].samples;  // counted saturated by NoteSaturation
    }
  }
  windows_ = std::move(kept);
}

std::vector<Window> WindowBuilder::Finish() {
  Close();
  DropPinnedWindows();
  return std::move(windows_);
}

long long AccountedSamples(const WindowStats& stats) {
  return stats.transition_samples + stats.trimmed_samples + stats.short_samples + stats.saturated_samples +
         stats.gap_turn_samples + stats.window_samples;
}

std::string LeftOutNote(const WindowStats& stats, const WindowOptions& options) {
  std::string note;
  const auto add = [&note](long long count, const std::string& what) {
    if (count > 0) note += (note.empty() ? "" : ", ") + std::to_string(count) + " " + what;
  };
  add(stats.transition_samples, "in transitions (segment -1)");
  add(stats.trimmed_samples, "trimmed after moves (--trim " + OptionNumberText(options.trim_s) + " s)");
  add(stats.short_samples, "in " + std::to_string(stats.short_windows) + " segment occurrence" +
                               (stats.short_windows == 1 ? "" : "s") + " shorter than " +
                               std::to_string(options.min_samples) + " samples (--window-min-samples)");
  add(stats.saturated_samples, "in " + std::to_string(stats.saturated_windows) + " saturated window" +
                                   (stats.saturated_windows == 1 ? "" : "s"));
  add(stats.gap_turn_samples, "in " + std::to_string(stats.turns_dropped_for_gaps) + " turn" +
                                  (stats.turns_dropped_for_gaps == 1 ? "" : "s") +
                                  " with a gap (--max-turn-gap)");
  return note;
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
