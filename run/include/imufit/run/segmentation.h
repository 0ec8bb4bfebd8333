// imufit — finding a plan's segments in an unlabelled run (`imufit segment`, and `imufit fit` /
// `imufit report` on a samples file without a `segment` column).
//
// A documented two-pass design; memory grows with the run's duration, not its sample count:
//
//  1. MotionDetector (pass 1, streaming) reduces the run to blocks of about window_s / 5 seconds:
//     per block the sample count, the mean and the sum of squared deviations of the gyro and the
//     accelerometer, and the gyro integrated over time (trapezoids on the actual time stamps, so
//     irregular sample intervals are exact). About 120 bytes per block: 19 MB for a 9-hour run at
//     the default 1 s window. Finish() then takes, for every block, the variance of the gyro and
//     of the accelerometer (sum over the three axes, raw^2) over a window of window_s centred on
//     it, estimates the noise level from the run itself (the noise_quantile quantile of those
//     variances: calibration runs rest or spin steadily much of the time; imu_tk estimates it from
//     an initial rest instead) and classifies each block: *steady* (both variances below
//     threshold_factor times their noise level), *steady gyro* (the gyro only: a constant rate about
//     a tilted axis turns gravity in the body frame) or *motion*. Runs of one class become pieces;
//     a steady piece shorter than min_steady_s counts as motion. The centred window makes every
//     steady piece start and end half a window inside the rest, away from the moves.
//
//  2. MatchPlan() walks the plan's segments in plan order, repeating the plan as often as the run
//     lasts (a soak passes through it once per temperature, a ramp many times), and finds each
//     segment among the pieces:
//       static: a steady piece with the gyro at rest whose gravity direction (the raw accelerometer
//               mean, normalised) lies within direction_tolerance_deg of the plan's `up`;
//       rate:   a steady(-gyro) piece whose gyro offset from rest points along the rotation axis with
//               the plan's sign, its size in proportion to the plan's rate as for the other rate
//               segments (within rate_tolerance);
//       turn:   a motion piece between two rests whose integrated gyro (less the bias of the rests)
//               points along the rotation axis with the sign of the angle; the rest before has
//               gravity along `up`, the rest after along `up` turned by -angle about the axis
//               (d(up)/dt = -omega x up), and successive turns agree in raw per radian. Its label
//               reaches turn_margin_s into the rests either side, so that it holds the whole motion.
//     Between segments it passes over motion (the table moving: label -1) and rests in the position
//     of the segment before or of the next one (settling, the pause before a turn). Raw axes may have
//     any scale and sign: every sign pattern of the accelerometer and of the gyro axes is tried
//     (axis permutations are not) and the one that matches the whole run is kept. Anything else is
//     a disagreement between log and plan, reported with its time: a rest in another position
//     (extra, missing or reordered segments), a rate or a turn that does not fit, the run ending
//     inside a pass.
//
//  3. Labeller (pass 2) gives each sample, by its time, the id of the segment matched there, or -1.
//
// Gyro rest is told from a rate by the gyro offset from the nearest rest before, against half the
// smallest plan rate in raw units (the raw scale estimated from the largest offset of the run and
// the largest plan rate); in a plan without rate segments every steady piece is a rest.
#ifndef IMUFIT_RUN_SEGMENTATION_H_
#define IMUFIT_RUN_SEGMENTATION_H_

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "imufit/base/option_table.h"
#include "imufit/model/rate_table.h"
#include "imufit/model/sample.h"

namespace imufit {

struct SegmentationOptions {
  // Length of the sliding window whose variance tells rest from motion, s (widened to 16 samples
  // on slow logs).
  double window_s = 1.0;
  // The noise level is this quantile of the windows' variances (the run must be steady at least
  // this fraction of the time).
  double noise_quantile = 0.1;
  // A window is steady when its variance is below this multiple of the noise level.
  double threshold_factor = 8.0;
  // Rests held by hand (the field fit, fit/field_fit.h): their tremor lies far above the log's
  // quietest windows (a rest on a table) yet far below its turns. When set, each sensor's threshold
  // is raised, where that is higher, to threshold_factor times the level of the noisier rests: the
  // (1 - noise_quantile) quantile of the quiet class of windows, the log's windows split in two
  // where the spread of their log variances within the two classes is least (Otsu), and never
  // beyond that split. Not an option of `imufit segment`: the field fit sets it.
  bool rests_held_by_hand = false;
  // Steady stretches shorter than this count as motion, s. The centred window already trims half a
  // window off each end, so a rest must last about min_steady_s + window_s to count.
  double min_steady_s = 0.5;
  // How far a measured gravity direction or rotation axis may be from the plan's, degrees (raw
  // biases, unequal axis scales and misalignment tilt the raw directions by a few degrees).
  double direction_tolerance_deg = 25.0;
  // How far the raw size of a rate (per rad/s) or of a turn (per rad) may be from the others',
  // relative.
  double rate_tolerance = 0.25;
  // A turn's label reaches this far into the rests either side (at most half of each), s: the slow
  // start and end of a turn lie below the detection threshold, and the turn's integral must be whole.
  double turn_margin_s = 2.0;

  // An empty string when usable, else what is wrong (naming the option and its value).
  std::string Validate() const;
};

// Every option of SegmentationOptions, described once (model/option_table.h; segmentation_options.cc).
const OptionTable<SegmentationOptions>& SegmentationOptionTable();

enum class PieceKind {
  kSteady,      // gyro and accelerometer steady: a rest, or a constant rate about the vertical
  kSteadyGyro,  // gyro steady, accelerometer not: a constant rate about a tilted axis
  kMotion,      // neither
};

// A stretch of the run of one kind, raw units.
struct MotionPiece {
  PieceKind kind = PieceKind::kMotion;
  double start_s = 0.0;  // time of the first and the last sample
  double end_s = 0.0;
  long long samples = 0;
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
  // Integral of the raw gyro over time from the last sample before the piece to its last
  // sample (raw * s), over integral_s seconds.
  Eigen::Vector3d gyro_integral = Eigen::Vector3d::Zero();
  double integral_s = 0.0;
};

// What pass 1 found.
struct DetectedRun {
  std::vector<MotionPiece> pieces;  // in time order, covering every sample
  long long samples = 0;
  double sample_interval_s = 0.0;  // mean
  double window_s = 0.0;           // the window used
  // Noise level and threshold of the windows' variances (sum over the axes), raw^2.
  double gyro_noise_var = 0.0;
  double accel_noise_var = 0.0;
  double gyro_threshold_var = 0.0;
  double accel_threshold_var = 0.0;
};

class MotionDetector {
 public:
  explicit MotionDetector(const SegmentationOptions& options = SegmentationOptions());

  // Adds the next sample (times strictly increasing; intervals may vary).
  void Add(const Sample& sample);
  DetectedRun Finish();

 private:
  struct Block {
    double first_s = 0.0;
    double last_s = 0.0;
    long long n = 0;
    Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();  // relative to reference_
    Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
    double gyro_m2 = 0.0;  // sum of squared deviations from the block mean, all axes
    double accel_m2 = 0.0;
    Eigen::Vector3d gyro_integral = Eigen::Vector3d::Zero();  // raw * s (not relative)
    double integral_s = 0.0;
  };
  void Start();
  void Accumulate(const Sample& sample);
  // Finish()'s stages: each block's variance (sum over the axes, raw^2) over the window centred
  // on it; the noise levels and thresholds from them; the blocks classified as `kinds`, joined
  // into pieces.
  void WindowVariances(std::vector<double>* gyro_var, std::vector<double>* accel_var) const;
  void SetNoiseLevels(const std::vector<double>& gyro_var, const std::vector<double>& accel_var,
                      DetectedRun* run) const;
  std::vector<MotionPiece> Pieces(const std::vector<PieceKind>& kinds) const;

  SegmentationOptions options_;
  std::vector<Sample> head_;  // the first samples, until the sample interval is known
  bool started_ = false;
  double block_s_ = 0.0;
  double window_s_ = 0.0;
  std::vector<Block> blocks_;
  Sample reference_;  // the first sample: accumulated values are relative to it (no cancellation)
  Sample previous_;
  long long samples_ = 0;
  bool integer_gyro_ = true;  // every raw value an integer (quantised counts): noise floor 1/12
  bool integer_accel_ = true;
};

// One segment found in the run.
struct SegmentMatch {
  int segment = 0;       // plan id
  int pass = 0;          // 0 for the first pass through the plan, 1 ...
  std::string kind;      // "static", "rate" or "turn"
  double start_s = 0.0;  // first and last sample labelled with it
  double end_s = 0.0;
  std::string evidence;  // what was measured, for the report
};

struct Segmentation {
  std::vector<SegmentMatch> matches;                      // in time order
  int passes = 0;                                         // complete passes through the plan
  Eigen::Vector3d accel_signs = Eigen::Vector3d::Ones();  // the raw axis signs that matched
  Eigen::Vector3d gyro_signs = Eigen::Vector3d::Ones();
};

// The log and the plan disagree (imufit exits 1): what() names the time and what was found.
class PlanMismatchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Finds `segments` (plan order, repeated) in `run`. Throws PlanMismatchError.
Segmentation MatchPlan(const DetectedRun& run, const std::vector<TableSegment>& segments,
                       const SegmentationOptions& options = SegmentationOptions());

// Labels samples by time (pass 2). Times must not decrease between calls.
class Labeller {
 public:
  explicit Labeller(const Segmentation& segmentation) : matches_(segmentation.matches) {}
  int Label(double time_s);

 private:
  std::vector<SegmentMatch> matches_;
  size_t next_ = 0;
};

// The match as a table for people: segment, pass, kind, start_s, end_s, evidence.
std::string SegmentationReport(const Segmentation& segmentation);

}  // namespace imufit

#endif  // IMUFIT_RUN_SEGMENTATION_H_
