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
// No sample is left out in silence. A window closes by span or duration only once it holds
// min_samples (on a ramp so fast that the span passes sooner it spans more, rather than being
// lost whole), and the remainder of an occurrence that ends with fewer than min_samples is merged
// into the window before it (its span grows by the remainder's: a fraction of max_temp_span_c).
// What is still left out (transitions, the trim, whole occurrences shorter than min_samples,
// windows at full scale, turns with a gap) is counted per reason in WindowStats, so that every
// sample of the run is either in a window or in one of those counts (LeftOutNote()).
//
// A turn through a known angle (TableSegment::IsTurn) is different: its truth is the integral of
// the rate over the whole occurrence, so each occurrence of a turn is exactly one window, neither
// trimmed nor split by temperature or duration.
//
// Lost samples. A serial link that drops frames leaves gaps in a log. A static or rate window's
// mean does not mind, but a turn's integral does: with each sample standing for one interval, a
// lost sample at the peak rate takes its share of the angle with it (1 % of samples lost biases
// the gyro scale by about 0.3 %, tens of sigmas). So every time stamp of the run is placed on a
// uniform grid t_k = a + b k as it comes (SampleClock): the line through the stamps placed so far
// (least squares, weighted towards the last SampleClock::kMemory samples so that a drifting clock
// is followed) says which slot a stamp is nearest to, and a jump of more than one slot is a gap.
// Jitter of less than half an interval moves no slot. A turn's samples are kept until it ends;
// its lost slots are filled by linear interpolation between their neighbours, its mean is over
// every slot and its duration is (samples + lost_samples) * b, with b from the whole stretch of
// run the clock remembers (a turn's own 4 s of stamps would leave b uncertain by tens of ppm under
// a few ms of jitter). Interpolation across a gap of length g errs by about
// g^3 |d^2 omega / dt^2| / 12, so a turn with a gap longer than WindowOptions::max_turn_gap_s is
// dropped. A turn with a stamp far off the grid (bunched by a host that stamps packets on arrival)
// keeps one slot a sample, as if nothing were lost, and is counted.
//
// Besides the sample standard deviation (which, in a window whose truth varies, measures the
// signal), every window carries a per-sample noise figure from second differences,
// sqrt(sum (x_i - 2 x_(i-1) + x_(i-2))^2 / (6 (n - 2))): for white noise its expectation is the
// noise's variance, and a smooth signal (a turn's rate profile) contributes only its second
// derivative times dt^2.
//
// Units: whatever the samples carry (raw for a fit, SI for a check of a corrected run).
#ifndef IMUFIT_RUN_WINDOWS_H_
#define IMUFIT_RUN_WINDOWS_H_

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/base/option_table.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"
#include "imufit/run/sample_clock.h"

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
  // A turn whose time stamps have a longer gap (lost samples in a row), s, is dropped: the
  // interpolation across the gap would bias its angle (see above; 0.05 s costs a 360 deg turn of
  // 4 s about 6 ppm of its angle).
  double max_turn_gap_s = 0.05;
  // The raw outputs' full scale, raw units (0: not given): a window with a sample at or beyond
  // +-full scale on an axis of that sensor is dropped, for a clipped sample biases its mean. Without
  // it, a window whose output on an axis is one constant value at the run's extreme while the
  // other windows show noise is taken for saturated and dropped (a partly clipped one is not seen).
  double gyro_full_scale_raw = 0.0;
  double accel_full_scale_raw = 0.0;

  // An empty string when usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
};

// Every option of WindowOptions, described once (model/option_table.h; window_options.cc).
const OptionTable<WindowOptions>& WindowOptionTable();

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

  // The sample interval, s: the slope b of the run's time grid when the window closed (see above),
  // so that jittered time stamps do not move it (the two end stamps alone would); in a window with
  // a stamp off the grid, the least-squares slope of its own stamps against their index.
  double interval_s = 0.0;
  // Slots of the time grid inside the window with no sample (lost), and the longest run of them, s.
  // A turn's mean counts them at interpolated values; other windows' means need not.
  long long lost_samples = 0;
  double longest_gap_s = 0.0;

  // The time the window stands for: its slots x the sample interval, s.
  double DurationS() const {
    return samples > 1 ? static_cast<double>(samples + lost_samples) * interval_s : 0.0;
  }

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
  long long short_samples = 0;       // the samples in them
  long long merged_remainders = 0;   // an occurrence's short last piece merged into its window before
  long long saturated_samples = 0;   // samples in windows left out as saturated (below)
  long long gap_turn_samples = 0;    // samples in turns dropped for a gap (below)
  long long window_samples = 0;      // samples in the windows kept
  long long lost_samples = 0;        // empty slots of the time grid over the whole run
  long long gaps = 0;                // runs of them
  double longest_gap_s = 0.0;        // the longest, s
  long long off_grid_samples = 0;    // stamps more than SampleClock::kTolerance from their slot
  int turns_dropped_for_gaps = 0;    // turns with a gap longer than max_turn_gap_s
  double max_turn_gap_s = 0.0;       // WindowOptions::max_turn_gap_s, the limit they were held to
  // Windows dropped as saturated (see WindowOptions::gyro_full_scale_raw), and what was seen in the
  // first few of them, e.g. "segment 7 at t = 36.5 s: gyro z at 32767".
  int saturated_windows = 0;
  std::vector<std::string> saturation;
  // Each raw channel's extremes over the run (gyro x, y, z, accel x, y, z).
  Eigen::Matrix<double, 6, 1> raw_min = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> raw_max = Eigen::Matrix<double, 6, 1>::Zero();
  int turns_off_grid = 0;  // turns with a stamp off the grid: one slot a sample

  // Whether the time stamps lie on a uniform grid (at most one in a thousand off it), so that the
  // lost samples counted are real: bunched stamps make gaps of their own.
  bool StampsOnGrid() const { return off_grid_samples * 1000 <= samples; }
  double min_temp_c = 0.0;  // over all samples
  double max_temp_c = 0.0;
  double first_time_s = 0.0;
  double last_time_s = 0.0;
};

// Every sample of the run is in a window or in one of the counts of what was left out:
// transition_samples + trimmed_samples + short_samples + saturated_samples + gap_turn_samples +
// window_samples == samples.
long long AccountedSamples(const WindowStats& stats);

// What was left out of the windows, each reason with its count, for a person ("31000 in transitions,
// 1600 trimmed after moves, 45 in 3 windows shorter than 20 samples, ..."): every count that is not
// zero, the options named where one changes it.
std::string LeftOutNote(const WindowStats& stats, const WindowOptions& options);

// What saturation was found, for a person; empty when none.
std::string SaturationNote(const WindowStats& stats);

// What the time stamps showed, for a person: samples lost (and filled in within the turns),
// turns dropped for a long gap, stamps off a uniform grid. Empty when there is nothing to say.
std::string TimeStampNote(const WindowStats& stats);

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
  using Channels = Eigen::Matrix<double, 6, 1>;  // gyro x, y, z, accel x, y, z

  // The occurrence the last sample belongs to (reset as a whole when the segment id changes).
  struct Occurrence {
    int segment = kTransitionSegment;
    int index = 0;         // Window::occurrence
    double start_s = 0.0;  // time of its first sample
    bool whole = false;    // a turn: the whole occurrence is one window
  };

  // The window being filled: running sums from which Close() makes a Window. Reset as a whole
  // when a window opens (window_ = {}).
  struct OpenWindow {
    bool open = false;
    long long n = 0;
    double start_s = 0.0;
    double end_s = 0.0;
    double first_temp_c = 0.0;  // the temperature span is measured from here
    double temp_mean = 0.0;
    double temp_min = 0.0;
    double temp_max = 0.0;
    // Running mean and sum of squared deviations (Welford), per channel.
    Channels mean = Channels::Zero();
    Channels m2 = Channels::Zero();
    // The last two samples and the sum of squared second differences.
    Channels previous[2] = {Channels::Zero(), Channels::Zero()};
    Channels second_difference_sum = Channels::Zero();
    long long lost = 0;  // empty slots of the grid inside the window
    double longest_gap_s = 0.0;
    bool off_grid = false;     // a stamp of the window was off the grid
    int clipped_channel = -1;  // a channel at or beyond its full scale
    double clipped_value = 0.0;
    // Sums of (t - start_s) and of k (t - start_s) over the window's samples k = 0, 1, ...: the
    // interval of a window off the grid.
    double time_sum = 0.0;
    double index_time_sum = 0.0;
    // A turn's samples (slot, gyro and accel), kept until it ends (CloseTurn()).
    std::vector<long long> turn_slots;
    std::vector<Channels> turn_values;
  };

  // Add()'s stages: the sample placed on the run's time grid (returns the slots lost before it),
  // counted in the run's statistics, its occurrence followed, and added to the open window.
  long long PlaceOnGrid(double time_s);
  void CountSample(const Sample& sample, const Channels& value);
  void FollowOccurrence(int segment, double time_s);
  bool WindowIsFull(const Sample& sample) const;
  void Open(const Sample& sample);
  void Accumulate(const Sample& sample, const Channels& value);

  void Close();
  // Merges the open window (an occurrence's last piece, shorter than min_samples) into the window
  // before it when that is of the same occurrence; false when there is none.
  bool MergeRemainder(const Window& remainder);
  // Fills a turn's mean and noise from its kept samples; false when it is dropped for a gap.
  bool CloseTurn(Window* window);
  // Drops the windows whose output is pinned at the run's extreme (Finish()).
  void DropPinnedWindows();
  void NoteSaturation(const Window& window, int channel, double value);

  WindowOptions options_;
  WindowStats stats_;
  std::vector<Window> windows_;
  std::vector<std::pair<int, int>> occurrences_;  // segment id -> occurrences so far
  std::vector<int> turn_ids_;                     // segments whose occurrence is one window
  SampleClock clock_;
  long long slot_ = -1;  // the last sample's slot: its clock's steps summed
  Occurrence occurrence_;
  OpenWindow window_;
};

}  // namespace imufit

#endif  // IMUFIT_RUN_WINDOWS_H_
