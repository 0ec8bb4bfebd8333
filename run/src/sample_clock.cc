#include "imufit/run/sample_clock.h"

#include <algorithm>
#include <cmath>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

// Acquisition: intervals searched around the median one, and the least resultant (a fraction of
// the stamps) that is taken for a grid. Uniform jitter of +-0.4 intervals leaves sinc(0.8) = 0.23.
constexpr double kAcquireSpan = 0.15;        // +- this fraction of the median interval
constexpr double kAcquireResolution = 0.05;  // cycles of phase drift across the stamps per step
constexpr double kMinResultant = 0.15;

double Resultant(const std::vector<double>& time_s, double interval_s, double* phase) {
  double re = 0.0, im = 0.0;
  for (double t : time_s) {
    const double angle = 2.0 * kPi * (t - time_s.front()) / interval_s;
    re += std::cos(angle);
    im += std::sin(angle);
  }
  if (phase != nullptr) *phase = std::atan2(im, re);
  return std::hypot(re, im) / static_cast<double>(time_s.size());
}

}  // namespace

void SampleClock::ResetLine() { weight_ = mean_slot_ = mean_time_s_ = slot_variance_ = covariance_ = 0.0; }

void SampleClock::Update(double slot, double time_s) {
  // Exponentially weighted Welford update: W = l W + 1, mean += d / W, C = l C + d_k (t - mean_t).
  constexpr double kDecay = 1.0 - 1.0 / kMemory;
  weight_ = kDecay * weight_ + 1.0;
  const double d_slot = slot - mean_slot_;
  mean_slot_ += d_slot / weight_;
  mean_time_s_ += (time_s - mean_time_s_) / weight_;
  slot_variance_ = kDecay * slot_variance_ + d_slot * (slot - mean_slot_);
  covariance_ = kDecay * covariance_ + d_slot * (time_s - mean_time_s_);
  slot_ = slot;
}

void SampleClock::Acquire() {
  const std::vector<double>& t = acquiring_;
  std::vector<double> intervals(t.size() - 1);
  for (size_t i = 1; i < t.size(); ++i) intervals[i - 1] = t[i] - t[i - 1];
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  const double median_s = intervals[intervals.size() / 2];
  acquired_ = true;
  locked_ = false;
  double best_s = 0.0, best = 0.0;
  // The grid's slots spanned by the stamps: more than twice as many as stamps would be a grid
  // that lost most of its samples (the spacing inside a host's bunches, say): none.
  const double cycles = median_s > 0.0 ? (t.back() - t.front()) / median_s : 0.0;
  if (cycles > 0.0 && cycles <= 2.0 * static_cast<double>(t.size())) {
    // A step that drifts the last stamp's phase by kAcquireResolution cycles.
    const double step_s = median_s * kAcquireResolution / std::max(cycles, 1.0);
    for (double b = median_s * (1.0 - kAcquireSpan); b <= median_s * (1.0 + kAcquireSpan); b += step_s) {
      const double r = Resultant(t, b, nullptr);
      if (r > best) {
        best = r;
        best_s = b;
      }
    }
  }
  if (best >= kMinResultant) {
    double phase = 0.0;
    Resultant(t, best_s, &phase);
    // Slots from the grid, then the line through them; the first stamp's slot is 0.
    const double start_s = t.front() + best_s * phase / (2.0 * kPi);
    const double first = std::round((t.front() - start_s) / best_s);
    ResetLine();
    double previous = -1.0;
    locked_ = true;
    for (double time_s : t) {
      const double slot = std::round((time_s - start_s) / best_s) - first;
      if (slot <= previous) locked_ = false;  // two stamps in one slot: no grid after all
      previous = slot;
      Update(slot, time_s);
    }
  }
  if (!locked_) {  // one slot a stamp, as placed provisionally
    ResetLine();
    for (size_t i = 0; i < t.size(); ++i) Update(static_cast<double>(i), t[i]);
  }
  acquiring_.clear();
  acquiring_.shrink_to_fit();
}

long long SampleClock::Place(double time_s) {
  if (!acquired_) {
    // Provisionally one slot after the last; the line through them for interval_s() meanwhile.
    if (acquiring_.empty()) ResetLine();
    acquiring_.push_back(time_s);
    Update(static_cast<double>(acquiring_.size() - 1), time_s);
    on_grid_ = true;
    if (static_cast<int>(acquiring_.size()) == kAcquire) Acquire();
    return 1;
  }
  const double b = interval_s();
  // The line's time for a slot, before this stamp moves it.
  const auto line_s = [&](double k) { return mean_time_s_ + b * (k - mean_slot_); };
  long long step = 1;
  if (locked_ && b > 0.0) step = std::max(1LL, 1 + std::llround((time_s - line_s(slot_ + 1.0)) / b));
  const double slot = slot_ + static_cast<double>(step);
  on_grid_ = locked_ && b > 0.0 && std::abs(time_s - line_s(slot)) <= kTolerance * b;
  Update(slot, time_s);
  off_grid_run_ = on_grid_ ? 0 : off_grid_run_ + 1;
  // Lost lock (the clock jumped), or none found for a long while: find the grid again.
  if (off_grid_run_ >= (locked_ ? kRelock : 4 * kAcquire)) {
    acquired_ = false;
    off_grid_run_ = 0;
  }
  return step;
}

}  // namespace imufit
