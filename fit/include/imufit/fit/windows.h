// imufit — window statistics: a run reduced, in one streaming pass, to what the fit needs.
//
// Each occurrence of a segment (a contiguous stretch of samples with one id >= 0) is cut into
// windows. A window closes when its temperature has moved by more than max_temp_span_c since it
// opened (so on a ramp the temperature is effectively constant within each window and the fit
// stays exact: a cubic evaluated at the mean temperature differs from the mean of the cubic by
// at most c2 * span^2 / 4 plus smaller terms), when it reaches max_duration_s, or when the
// occurrence ends. The first trim_s seconds of every occurrence are dropped (the table settles
// after a move). Samples with segment -1 are skipped. Only running sums are kept: memory does
// not grow with the run.
//
// A turn through a known angle (TableSegment::IsTurn) is different: its truth is the integral of
// the rate over the whole occurrence, so each occurrence of a turn is exactly one window, neither
// trimmed nor split by temperature or duration.
//
// Besides the sample standard deviation (which, in a window whose truth varies, measures the
// signal), every window carries a per-sample noise figure from second differences,
// sqrt(sum (x_i - 2 x_(i-1) + x_(i-2))^2 / (6 (n - 2))): for white noise its expectation is the
// noise's variance, and a smooth signal (a turn's rate profile) contributes only its second
// derivative times dt^2.
//
// Units: whatever the samples carry (raw for a fit, SI for a check of a corrected run).
#ifndef IMUFIT_FIT_WINDOWS_H_
#define IMUFIT_FIT_WINDOWS_H_

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"

namespace imufit {

struct WindowOptions {
  // Seconds dropped at the start of every occurrence of a segment, while the table settles.
  double trim_s = 0.5;
  // A window closes once its temperature has moved this far from where it opened, degC.
  double max_temp_span_c = 0.5;
  // A window closes after this many seconds (0: only at the end of the occurrence).
  double max_duration_s = 0.0;
  // Windows with fewer samples are dropped (counted in WindowStats::short_windows).
  int min_samples = 20;

  // An empty string when usable, else what is wrong.
  std::string Validate() const;
};

// The statistics of one window.
struct Window {
  int segment = 0;
  int occurrence = 0;  // 0 for the first contiguous stretch of this segment id, 1 ...
  long long samples = 0;
  double start_s = 0.0;
  double end_s = 0.0;
  double temp_c = 0.0;      // mean temperature reading
  double min_temp_c = 0.0;  // extremes of the readings in the window
  double max_temp_c = 0.0;
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_std = Eigen::Vector3d::Zero();  // sample standard deviation
  Eigen::Vector3d accel_std = Eigen::Vector3d::Zero();
  // Per-sample noise from second differences (see above); zero with fewer than 3 samples.
  Eigen::Vector3d gyro_noise = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_noise = Eigen::Vector3d::Zero();
  bool whole_occurrence = false;  // a turn's occurrence: one window, untrimmed

  // Mean sample interval, s: the least-squares slope of the samples' times against their index, so
  // that jittered time stamps do not move it (the two end stamps alone would).
  double interval_s = 0.0;

  // The time the window's samples stand for: samples x their mean interval, s.
  double DurationS() const { return samples > 1 ? static_cast<double>(samples) * interval_s : 0.0; }

  // The noise of the window's mean per axis, in the samples' units: the per-sample spread over
  // sqrt(samples). Where the truth is constant over the window, the sample standard deviation (it
  // also holds the table's rate ripple and slow noise); in a turn's whole occurrence, whose rate
  // varies, the second-difference figure, which sees the noise and not the rate profile. The fit
  // weights its residuals by it; the certificate draws it as error bars.
  Eigen::Vector3d NoiseOfMean(bool gyro) const {
    const Eigen::Vector3d& spread =
        whole_occurrence ? (gyro ? gyro_noise : accel_noise) : (gyro ? gyro_std : accel_std);
    return spread / std::sqrt(static_cast<double>(samples > 0 ? samples : 1));
  }
};

// Counts of what went into the windows and what did not.
struct WindowStats {
  long long samples = 0;             // all samples seen
  long long transition_samples = 0;  // segment -1
  long long trimmed_samples = 0;     // dropped by trim_s
  long long short_windows = 0;       // windows dropped for having fewer than min_samples
  double min_temp_c = 0.0;           // over all samples
  double max_temp_c = 0.0;
  double first_time_s = 0.0;
  double last_time_s = 0.0;
};

class WindowBuilder {
 public:
  explicit WindowBuilder(const WindowOptions& options = WindowOptions());
  // As above; the occurrences of the turns among `segments` become one window each.
  WindowBuilder(const WindowOptions& options, const std::vector<TableSegment>& segments);

  // Adds the next sample of the run (in time order).
  void Add(const Sample& sample);
  // Closes the open window and returns all windows, in time order.
  std::vector<Window> Finish();
  const WindowStats& stats() const { return stats_; }

 private:
  void Close();

  WindowOptions options_;
  WindowStats stats_;
  std::vector<Window> windows_;
  std::vector<std::pair<int, int>> occurrences_;  // segment id -> occurrences so far
  std::vector<int> turn_ids_;                     // segments whose occurrence is one window
  bool whole_occurrence_ = false;                 // the current segment is a turn
  // The open window: running mean and sum of squared deviations (Welford), per channel.
  bool open_ = false;
  int current_segment_ = kTransitionSegment;
  int current_occurrence_ = 0;
  double occurrence_start_s_ = 0.0;
  double window_first_temp_c_ = 0.0;
  long long n_ = 0;
  double start_s_ = 0.0;
  double end_s_ = 0.0;
  double temp_mean_ = 0.0;
  double temp_min_ = 0.0;
  double temp_max_ = 0.0;
  Eigen::Matrix<double, 6, 1> mean_ = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> m2_ = Eigen::Matrix<double, 6, 1>::Zero();
  // The last two samples and the sum of squared second differences.
  Eigen::Matrix<double, 6, 1> previous_[2];
  Eigen::Matrix<double, 6, 1> second_difference_sum_ = Eigen::Matrix<double, 6, 1>::Zero();
  // Sums of (t - start_s) and of k (t - start_s) over the window's samples k = 0, 1, ...
  double time_sum_ = 0.0;
  double index_time_sum_ = 0.0;
};

}  // namespace imufit

#endif  // IMUFIT_FIT_WINDOWS_H_
