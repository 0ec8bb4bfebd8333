#include "imufit/run/segmentation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "imufit/model/constants.h"

namespace imufit {
namespace {

// Pass 1 keeps this many samples before it fixes the block length from their mean interval.
constexpr size_t kHeadSamples = 32;
// A window holds at least this many samples (slow logs widen it).
constexpr double kMinWindowSamples = 16.0;
// A window is this many blocks, centred on the block it classifies.
constexpr int kWindowHalfBlocks = 2;
// The variance of a rounded reading (uniform over one count) summed over three axes, raw^2: the
// noise level of a quantised log cannot be lower.
constexpr double kQuantisationVar = 3.0 / 12.0;
// Noise level floor relative to the squared size of the readings (noise-free simulations).
constexpr double kRelativeVarFloor = 1e-18;
// Gyro offsets below this many per-sample noise sigmas are rest even in a plan with slow rates.
constexpr double kRestNoiseSigmas = 3.0;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm();
  const double nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 180.0;
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

std::string Vec(const Eigen::Vector3d& v, const char* format = "%+.2f") {
  std::string text = "(";
  for (int i = 0; i < 3; ++i) {
    char number[48];
    std::snprintf(number, sizeof number, format, v(i));
    text += number;
    if (i < 2) text += ", ";
  }
  return text + ")";
}

std::string Seconds(double t) {
  char text[48];
  std::snprintf(text, sizeof text, "%.2f", t);
  return text;
}

std::string Degrees(double deg) {
  char text[48];
  std::snprintf(text, sizeof text, "%.1f deg", deg);
  return text;
}

// Per axis, the median of `values` weighted by `weights`.
Eigen::Vector3d WeightedMedian(const std::vector<Eigen::Vector3d>& values,
                               const std::vector<double>& weights) {
  Eigen::Vector3d median = Eigen::Vector3d::Zero();
  if (values.empty()) return median;
  double total = 0.0;
  for (double w : weights) total += w;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<std::pair<double, double>> sorted;
    for (size_t i = 0; i < values.size(); ++i) sorted.emplace_back(values[i](axis), weights[i]);
    std::sort(sorted.begin(), sorted.end());
    double seen = 0.0;
    for (const auto& [value, weight] : sorted) {
      seen += weight;
      median(axis) = value;
      if (seen >= 0.5 * total) break;
    }
  }
  return median;
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const size_t index =
      std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(index), values.end());
  return values[index];
}

// The threshold of rests held by hand (SegmentationOptions::rests_held_by_hand): the log's windows
// split into a quiet and a moving class where the split of their log variances minimises the
// spread within the classes (Otsu); the quiet class's upper noise_quantile quantile, the level of
// its noisier rests, times threshold_factor, but never beyond the split itself. 0 when the log has
// too few windows to split.
double HandRestThreshold(const std::vector<double>& variances, const SegmentationOptions& options) {
  std::vector<double> logs;
  for (const double v : variances) {
    if (v > 0.0) logs.push_back(std::log(v));
  }
  if (logs.size() < 4) return 0.0;
  std::sort(logs.begin(), logs.end());
  // Prefix sums: the within-class spread of the split after element k in O(1).
  const size_t n = logs.size();
  std::vector<double> sum(n + 1, 0.0);
  std::vector<double> sum2(n + 1, 0.0);
  for (size_t k = 0; k < n; ++k) {
    sum[k + 1] = sum[k] + logs[k];
    sum2[k + 1] = sum2[k] + logs[k] * logs[k];
  }
  const auto spread = [&](size_t first, size_t end) {  // sum of squared deviations of [first, end)
    const double count = static_cast<double>(end - first);
    const double s = sum[end] - sum[first];
    return sum2[end] - sum2[first] - s * s / count;
  };
  size_t quiet = 1;  // elements [0, quiet) are the quiet class
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 1; k < n; ++k) {
    const double within = spread(0, k) + spread(k, n);
    if (within < best) best = within, quiet = k;
  }
  const double split = std::exp(0.5 * (logs[quiet - 1] + logs[quiet]));
  const size_t noisier = std::min(quiet - 1, static_cast<size_t>((1.0 - options.noise_quantile) * quiet));
  return std::min(split, options.threshold_factor * std::exp(logs[noisier]));
}

std::string KindOf(const TableSegment& segment) {
  if (segment.IsTurn()) return "turn";
  return segment.IsStatic() ? "static" : "rate";
}

std::string DescribeSegment(const TableSegment& segment, int pass) {
  std::string text = "segment " + std::to_string(segment.id) + " (pass " + std::to_string(pass + 1) + ": " +
                     KindOf(segment) + ", up " + Vec(segment.up, "%+.2g");
  char number[64];
  if (segment.IsTurn()) {
    std::snprintf(number, sizeof number, ", %+.1f deg about ", *segment.angle_rad * kRadToDeg);
    text += number + Vec(segment.RotationAxis(), "%+.2g");
  } else if (!segment.IsStatic()) {
    std::snprintf(number, sizeof number, ", %+.4g deg/s about ", segment.rate_radps * kRadToDeg);
    text += number + Vec(segment.RotationAxis(), "%+.2g");
  }
  return text + ")";
}

// Where gravity points at the end of a segment, body frame (unknown after a rate about a tilted axis).
std::optional<Eigen::Vector3d> UpAfter(const TableSegment& segment) {
  if (segment.IsTurn()) return Eigen::AngleAxisd(-*segment.angle_rad, segment.RotationAxis()) * segment.up;
  if (segment.IsStatic() || AngleDeg(segment.RotationAxis(), segment.up) < 1.0 ||
      AngleDeg(segment.RotationAxis(), segment.up) > 179.0) {
    return segment.up;
  }
  return std::nullopt;
}

// What the whole run looks like, independent of the sign pattern tried.
struct RunFacts {
  bool plan_has_rates = false;
  bool plan_uses_gyro_signs = false;
  Eigen::Vector3d gyro_rest = Eigen::Vector3d::Zero();  // raw, the run's typical rest
  double rate_threshold = 0.0;                          // raw: gyro offsets above are rates
};

// One attempt at matching with one sign pattern of the raw axes.
class Matcher {
 public:
  Matcher(const DetectedRun& run, const std::vector<TableSegment>& segments,
          const SegmentationOptions& options, const RunFacts& facts, const Eigen::Vector3d& accel_signs,
          const Eigen::Vector3d& gyro_signs)
      : run_(run), segments_(segments), options_(options), facts_(facts) {
    result_.accel_signs = accel_signs;
    result_.gyro_signs = gyro_signs;
    gyro_rest_ = facts_.gyro_rest;
  }

  // True when the whole run matched; else problem() says where it did not.
  bool Run();
  const Segmentation& result() const { return result_; }
  const std::string& problem() const { return problem_; }
  double reached_s() const { return reached_s_; }
  double residual_deg() const { return residual_deg_; }

 private:
  Eigen::Vector3d Gravity(const MotionPiece& piece) const {
    return result_.accel_signs.cwiseProduct(piece.accel_mean).normalized();
  }
  Eigen::Vector3d GyroBody(const Eigen::Vector3d& raw) const { return result_.gyro_signs.cwiseProduct(raw); }
  bool IsRest(const MotionPiece& piece, const Eigen::Vector3d& gyro_rest) const {
    return piece.kind == PieceKind::kSteady &&
           (!facts_.plan_has_rates || (piece.gyro_mean - gyro_rest).norm() < facts_.rate_threshold);
  }
  bool ScaleFits(double scale) const {
    return !scale_ || std::abs(scale / *scale_ - 1.0) <= options_.rate_tolerance;
  }
  bool Fail(const MotionPiece* piece, const std::string& message) {
    reached_s_ = piece ? piece->start_s : (run_.pieces.empty() ? 0.0 : run_.pieces.back().end_s);
    problem_ = message;
    return false;
  }
  // Records a match over [start_s, end_s]; a match that reaches into the one before shortens it
  // (labels never overlap).
  void Add(const TableSegment& segment, int pass, double start_s, double end_s, double residual_deg,
           std::string evidence) {
    if (!result_.matches.empty() && result_.matches.back().end_s >= start_s) {
      result_.matches.back().end_s = std::nextafter(start_s, -INFINITY);
    }
    result_.matches.push_back({segment.id, pass, KindOf(segment), start_s, end_s, std::move(evidence)});
    residual_deg_ += residual_deg;
  }
  void Add(const TableSegment& segment, int pass, const MotionPiece& piece, double residual_deg,
           std::string evidence) {
    const double start_s =
        result_.matches.empty()
            ? piece.start_s
            : std::max(piece.start_s, std::nextafter(result_.matches.back().end_s, INFINITY));
    Add(segment, pass, start_s, piece.end_s, residual_deg, std::move(evidence));
  }
  // Is pieces[p] (motion) the turn `segment`? Sets *hint when it nearly is.
  bool TurnFits(size_t p, const TableSegment& segment, int pass, std::string* hint);

  // Run()'s stages. What pieces[p] is against the segment `expected` next: passed over (the table
  // moving, settling or waiting), the segment found, or a disagreement (problem() says which).
  enum class Step { kPassOver, kFound, kFailed };
  Step MatchPiece(size_t p, const TableSegment& expected, int pass, std::string* hint);
  Step MatchRest(const MotionPiece& piece, const TableSegment& expected, int pass, const std::string& hint);
  Step MatchRate(const MotionPiece& piece, const Eigen::Vector3d& offset, const TableSegment& expected,
                 int pass);
  // After a whole pass: the rest of the run is the unit at rest where the last segment left it.
  bool EndsAtRest(size_t first_piece) const;
  // Why two segments in a row may not be told apart ("" when they can).
  std::string SamePositionHint(size_t j) const;

  const DetectedRun& run_;
  const std::vector<TableSegment>& segments_;
  const SegmentationOptions& options_;
  const RunFacts& facts_;
  Segmentation result_;
  std::string problem_;
  double reached_s_ = 0.0;
  double residual_deg_ = 0.0;
  std::optional<double> scale_;  // raw per rad/s (= raw * s per rad), from the rates and turns matched
  std::optional<Eigen::Vector3d> gravity_now_;  // where gravity points now (body), when known
  Eigen::Vector3d gyro_rest_;                   // raw, the rest before the piece at hand
};

bool Matcher::TurnFits(size_t p, const TableSegment& segment, int pass, std::string* hint) {
  const std::vector<MotionPiece>& pieces = run_.pieces;
  if (p == 0 || p + 1 >= pieces.size()) return false;
  const MotionPiece& before = pieces[p - 1];
  const MotionPiece& turn = pieces[p];
  const MotionPiece& after = pieces[p + 1];
  if (before.kind != PieceKind::kSteady || !IsRest(after, before.gyro_mean)) return false;
  const double tol = options_.direction_tolerance_deg;
  const double start_error = AngleDeg(Gravity(before), segment.up);
  const double end_error = AngleDeg(Gravity(after), *UpAfter(segment));
  if (start_error > tol || end_error > tol) return false;
  const Eigen::Vector3d bias = 0.5 * (before.gyro_mean + after.gyro_mean);
  const Eigen::Vector3d theta_raw = turn.gyro_integral - bias * turn.integral_s;
  const double angle = *segment.angle_rad;
  const Eigen::Vector3d expected = segment.RotationAxis() * (angle < 0.0 ? -1.0 : 1.0);
  const double axis_error = AngleDeg(GyroBody(theta_raw), expected);
  const double scale = theta_raw.norm() / std::abs(angle);
  if (axis_error > tol || !ScaleFits(scale)) {
    *hint = "; the motion at t = " + Seconds(turn.start_s) + " .. " + Seconds(turn.end_s) +
            " s between rests in the turn's positions turned about body " +
            Vec(GyroBody(theta_raw).normalized()) + " (" + Degrees(axis_error) + " from the plan's axis)" +
            (ScaleFits(scale) ? std::string()
                              : ", by an amount out of proportion with the other rates and turns");
    return false;
  }
  if (!scale_) scale_ = scale;
  // The slow start and end of a turn lie below the detection threshold: the label reaches into the
  // rests either side (which add nothing to the integral), up to turn_margin_s or half of each rest.
  const double margin_before = std::min(options_.turn_margin_s, 0.5 * (before.end_s - before.start_s));
  const double margin_after = std::min(options_.turn_margin_s, 0.5 * (after.end_s - after.start_s));
  Add(segment, pass, turn.start_s - margin_before, turn.end_s + margin_after,
      start_error + end_error + axis_error,
      "turn between rests: raw gyro integral " + Vec(theta_raw, "%+.4g") + " about body " +
          Vec(GyroBody(theta_raw).normalized()) + ", " + Degrees(axis_error) +
          " from the axis; gravity before " + Degrees(start_error) + " from up, after " + Degrees(end_error) +
          " from the turned up");
  return true;
}

std::string Where(const MotionPiece& piece) {
  return "at t = " + Seconds(piece.start_s) + " .. " + Seconds(piece.end_s) + " s: ";
}

bool Matcher::EndsAtRest(size_t first_piece) const {
  if (!gravity_now_) return false;
  const std::vector<MotionPiece>& pieces = run_.pieces;
  for (size_t p = first_piece; p < pieces.size(); ++p) {
    if (!IsRest(pieces[p], gyro_rest_) ||
        !(AngleDeg(Gravity(pieces[p]), *gravity_now_) <= options_.direction_tolerance_deg)) {
      return false;
    }
  }
  return true;
}

std::string Matcher::SamePositionHint(size_t j) const {
  const TableSegment& expected = segments_[j];
  const TableSegment& before = segments_[(j + segments_.size() - 1) % segments_.size()];
  if (segments_.size() < 2 || !expected.IsStatic() || !before.IsStatic() ||
      !(AngleDeg(before.up, expected.up) <= options_.direction_tolerance_deg)) {
    return "";
  }
  return "; segment " + std::to_string(expected.id) + " follows segment " + std::to_string(before.id) +
         " in the same position: without labels they are told apart only by a move between them (the table "
         "turning about the vertical), and the log shows none";
}

Matcher::Step Matcher::MatchPiece(size_t p, const TableSegment& expected, int pass, std::string* hint) {
  const MotionPiece& piece = run_.pieces[p];
  const Eigen::Vector3d offset = piece.gyro_mean - gyro_rest_;
  const bool turning = facts_.plan_has_rates && offset.norm() >= facts_.rate_threshold;
  if (piece.kind == PieceKind::kMotion || (piece.kind == PieceKind::kSteadyGyro && !turning)) {
    if (!expected.IsTurn() || !TurnFits(p, expected, pass, hint)) return Step::kPassOver;  // moving
    gravity_now_ = UpAfter(expected);
    return Step::kFound;
  }
  if (!turning) return MatchRest(piece, expected, pass, *hint);
  return MatchRate(piece, offset, expected, pass);
}

Matcher::Step Matcher::MatchRest(const MotionPiece& piece, const TableSegment& expected, int pass,
                                 const std::string& hint) {
  const double tol = options_.direction_tolerance_deg;
  const Eigen::Vector3d gravity = Gravity(piece);
  const double error = AngleDeg(gravity, expected.up);
  if (expected.IsStatic() && error <= tol) {
    Add(expected, pass, piece, error,
        "rest, gravity along body " + Vec(gravity) + ", " + Degrees(error) + " from up; raw accel " +
            Vec(piece.accel_mean, "%.6g"));
    gravity_now_ = expected.up;
    gyro_rest_ = piece.gyro_mean;
    return Step::kFound;
  }
  if (gravity_now_ && AngleDeg(gravity, *gravity_now_) <= tol) {
    gyro_rest_ = piece.gyro_mean;  // settling after a move
    return Step::kPassOver;
  }
  if (!expected.IsStatic() && error <= tol) {
    gyro_rest_ = piece.gyro_mean;  // waiting in position for the next rate or turn
    gravity_now_ = expected.up;
    return Step::kPassOver;
  }
  Fail(&piece, Where(piece) + "a rest with gravity along body " + Vec(gravity) + " (raw accel " +
                   Vec(piece.accel_mean, "%.6g") + ") where " + DescribeSegment(expected, pass) +
                   " is expected; it is neither that position nor the one before" +
                   (gravity_now_ ? " (up " + Vec(*gravity_now_, "%+.2g") + ")" : std::string()) +
                   ": a segment is missing, extra or out of order" + hint);
  return Step::kFailed;
}

Matcher::Step Matcher::MatchRate(const MotionPiece& piece, const Eigen::Vector3d& offset,
                                 const TableSegment& expected, int pass) {
  const double tol = options_.direction_tolerance_deg;
  const Eigen::Vector3d offset_body = GyroBody(offset);
  if (expected.IsStatic() || expected.IsTurn()) {
    Fail(&piece, Where(piece) + "a constant rate about body " + Vec(offset_body.normalized()) +
                     " (raw gyro offset " + Vec(offset, "%+.5g") + ") where " +
                     DescribeSegment(expected, pass) +
                     " is expected: a segment is missing, extra or out of order");
    return Step::kFailed;
  }
  const Eigen::Vector3d axis = expected.RotationAxis() * (expected.rate_radps < 0.0 ? -1.0 : 1.0);
  const double axis_error = AngleDeg(offset_body, axis);
  const double scale = offset.norm() / std::abs(expected.rate_radps);
  const std::optional<Eigen::Vector3d> up_after = UpAfter(expected);
  const bool check_gravity = piece.kind == PieceKind::kSteady && up_after;
  const double gravity_error = check_gravity ? AngleDeg(Gravity(piece), expected.up) : 0.0;
  if (axis_error <= tol && ScaleFits(scale) && gravity_error <= tol) {
    if (!scale_) scale_ = scale;
    Add(expected, pass, piece, axis_error + gravity_error,
        "constant rate: raw gyro offset " + Vec(offset, "%+.5g") + " about body " +
            Vec(offset_body.normalized()) + ", " + Degrees(axis_error) + " from the axis" +
            (check_gravity ? "; gravity " + Degrees(gravity_error) + " from up" : std::string()));
    gravity_now_ = up_after;
    return Step::kFound;
  }
  Fail(&piece,
       Where(piece) + "a constant rate about body " + Vec(offset_body.normalized()) + " (raw gyro offset " +
           Vec(offset, "%+.5g") + ", " + Degrees(axis_error) + " from the expected axis" +
           (ScaleFits(scale) ? "" : ", its size out of proportion with the other rates") +
           (gravity_error > tol ? ", gravity " + Degrees(gravity_error) + " from up" : "") + ") where " +
           DescribeSegment(expected, pass) + " is expected: a segment is missing, extra or out of order");
  return Step::kFailed;
}

bool Matcher::Run() {
  const std::vector<MotionPiece>& pieces = run_.pieces;
  size_t k = 0;  // the first piece not yet matched
  size_t j = 0;  // the segment expected next
  int pass = 0;
  while (true) {
    // A whole pass is done: a log that ends at rest where the last segment left the unit (the
    // rest after a final turn) has no further pass in it.
    if (j == 0 && pass > 0 && segments_.size() > 1 && EndsAtRest(k)) break;
    const TableSegment& expected = segments_[j];
    std::string hint = SamePositionHint(j);
    Step step = Step::kPassOver;
    size_t p = k;
    for (; p < pieces.size() && step == Step::kPassOver; ++p) step = MatchPiece(p, expected, pass, &hint);
    if (step == Step::kFailed) return false;
    if (step == Step::kPassOver) {
      if (j == 0 && pass > 0) break;  // the run ended after a whole pass
      const double end_s = pieces.empty() ? 0.0 : pieces.back().end_s;
      return Fail(nullptr,
                  "the run ends (t = " + Seconds(end_s) + " s) before " + DescribeSegment(expected, pass) +
                      " was found: a segment is missing" + hint +
                      (pass > 0 || j > 0 ? " (or the last pass through the plan is incomplete)" : ""));
    }
    k = p;
    if (++j == segments_.size()) {
      j = 0;
      ++pass;
    }
  }
  result_.passes = pass;
  return true;
}

RunFacts Facts(const DetectedRun& run, const std::vector<TableSegment>& segments) {
  RunFacts facts;
  double min_rate = 0.0;
  double max_rate = 0.0;
  for (const TableSegment& segment : segments) {
    if (!segment.IsStatic()) facts.plan_uses_gyro_signs = true;
    if (segment.IsStatic() || segment.IsTurn()) continue;
    const double rate = std::abs(segment.rate_radps);
    min_rate = facts.plan_has_rates ? std::min(min_rate, rate) : rate;
    max_rate = std::max(max_rate, rate);
    facts.plan_has_rates = true;
  }
  std::vector<Eigen::Vector3d> means;
  std::vector<double> durations;
  for (const MotionPiece& piece : run.pieces) {
    if (piece.kind != PieceKind::kSteady) continue;
    means.push_back(piece.gyro_mean);
    durations.push_back(piece.end_s - piece.start_s + run.sample_interval_s);
  }
  facts.gyro_rest = WeightedMedian(means, durations);
  if (facts.plan_has_rates) {
    // The raw scale from the largest steady offset, which the fastest plan rate should make.
    double largest = 0.0;
    for (const MotionPiece& piece : run.pieces) {
      if (piece.kind != PieceKind::kMotion)
        largest = std::max(largest, (piece.gyro_mean - facts.gyro_rest).norm());
    }
    const double scale = largest / max_rate;
    facts.rate_threshold =
        std::max(0.5 * scale * min_rate, kRestNoiseSigmas * std::sqrt(run.gyro_noise_var / 3.0));
  }
  return facts;
}

std::vector<Eigen::Vector3d> SignPatterns(bool all) {
  std::vector<Eigen::Vector3d> patterns;
  for (int bits = 0; bits < (all ? 8 : 1); ++bits) {
    patterns.emplace_back(bits & 1 ? -1.0 : 1.0, bits & 2 ? -1.0 : 1.0, bits & 4 ? -1.0 : 1.0);
  }
  return patterns;
}

}  // namespace

MotionDetector::MotionDetector(const SegmentationOptions& options) : options_(options) {}

void MotionDetector::Add(const Sample& sample) {
  if (!started_) {
    head_.push_back(sample);
    if (head_.size() >= kHeadSamples) Start();
    return;
  }
  Accumulate(sample);
}

void MotionDetector::Start() {
  started_ = true;
  if (head_.empty()) return;
  const double interval_s =
      head_.size() > 1 ? (head_.back().time_s - head_.front().time_s) / static_cast<double>(head_.size() - 1)
                       : 1.0;
  window_s_ = std::max(options_.window_s, kMinWindowSamples * interval_s);
  block_s_ = window_s_ / (2 * kWindowHalfBlocks + 1);
  reference_ = head_.front();
  std::vector<Sample> head;
  head.swap(head_);
  for (const Sample& sample : head) Accumulate(sample);
}

void MotionDetector::Accumulate(const Sample& sample) {
  for (int axis = 0; axis < 3; ++axis) {
    integer_gyro_ = integer_gyro_ && sample.gyro(axis) == std::round(sample.gyro(axis));
    integer_accel_ = integer_accel_ && sample.accel(axis) == std::round(sample.accel(axis));
  }
  if (blocks_.empty() || sample.time_s - blocks_.back().first_s >= block_s_) {
    blocks_.emplace_back();
    blocks_.back().first_s = sample.time_s;
  }
  Block& block = blocks_.back();
  ++block.n;
  block.last_s = sample.time_s;
  const double inv_n = 1.0 / static_cast<double>(block.n);
  const Eigen::Vector3d gyro = sample.gyro - reference_.gyro;
  const Eigen::Vector3d accel = sample.accel - reference_.accel;
  const Eigen::Vector3d gyro_delta = gyro - block.gyro_mean;
  block.gyro_mean += gyro_delta * inv_n;
  block.gyro_m2 += gyro_delta.dot(gyro - block.gyro_mean);
  const Eigen::Vector3d accel_delta = accel - block.accel_mean;
  block.accel_mean += accel_delta * inv_n;
  block.accel_m2 += accel_delta.dot(accel - block.accel_mean);
  if (samples_ > 0) {
    // Trapezoids on the actual time stamps: exact for any spacing of the samples.
    const double dt = sample.time_s - previous_.time_s;
    block.gyro_integral += 0.5 * (sample.gyro + previous_.gyro) * dt;
    block.integral_s += dt;
  }
  previous_ = sample;
  ++samples_;
}

DetectedRun MotionDetector::Finish() {
  if (!started_) Start();
  DetectedRun run;
  run.samples = samples_;
  run.window_s = window_s_;
  if (blocks_.empty()) return run;
  run.sample_interval_s =
      samples_ > 1 ? (blocks_.back().last_s - blocks_.front().first_s) / static_cast<double>(samples_ - 1)
                   : 0.0;
  std::vector<double> gyro_var;
  std::vector<double> accel_var;
  WindowVariances(&gyro_var, &accel_var);
  SetNoiseLevels(gyro_var, accel_var, &run);
  std::vector<PieceKind> kinds(blocks_.size());
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const bool gyro_steady = gyro_var[b] <= run.gyro_threshold_var;
    const bool accel_steady = accel_var[b] <= run.accel_threshold_var;
    kinds[b] = !gyro_steady ? PieceKind::kMotion : accel_steady ? PieceKind::kSteady : PieceKind::kSteadyGyro;
  }
  run.pieces = Pieces(kinds);
  return run;
}

void MotionDetector::WindowVariances(std::vector<double>* gyro_var, std::vector<double>* accel_var) const {
  // Pooled from the means and deviations of the blocks of the window centred on each block.
  const int count = static_cast<int>(blocks_.size());
  gyro_var->assign(blocks_.size(), 0.0);
  accel_var->assign(blocks_.size(), 0.0);
  for (int b = 0; b < count; ++b) {
    const int lo = std::max(0, b - kWindowHalfBlocks);
    const int hi = std::min(count - 1, b + kWindowHalfBlocks);
    double n = 0.0;
    Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
    Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
    for (int i = lo; i <= hi; ++i) {
      n += static_cast<double>(blocks_[i].n);
      gyro_mean += static_cast<double>(blocks_[i].n) * blocks_[i].gyro_mean;
      accel_mean += static_cast<double>(blocks_[i].n) * blocks_[i].accel_mean;
    }
    if (n < 2.0) continue;
    gyro_mean /= n;
    accel_mean /= n;
    double gyro_m2 = 0.0;
    double accel_m2 = 0.0;
    for (int i = lo; i <= hi; ++i) {
      const double ni = static_cast<double>(blocks_[i].n);
      gyro_m2 += blocks_[i].gyro_m2 + ni * (blocks_[i].gyro_mean - gyro_mean).squaredNorm();
      accel_m2 += blocks_[i].accel_m2 + ni * (blocks_[i].accel_mean - accel_mean).squaredNorm();
    }
    (*gyro_var)[b] = gyro_m2 / (n - 1.0);
    (*accel_var)[b] = accel_m2 / (n - 1.0);
  }
}

void MotionDetector::SetNoiseLevels(const std::vector<double>& gyro_var, const std::vector<double>& accel_var,
                                    DetectedRun* run) const {
  const double gyro_floor = std::max(integer_gyro_ ? kQuantisationVar : 0.0,
                                     kRelativeVarFloor * (1.0 + reference_.gyro.squaredNorm()));
  const double accel_floor = std::max(integer_accel_ ? kQuantisationVar : 0.0,
                                      kRelativeVarFloor * (1.0 + reference_.accel.squaredNorm()));
  run->gyro_noise_var = std::max(Quantile(gyro_var, options_.noise_quantile), gyro_floor);
  run->accel_noise_var = std::max(Quantile(accel_var, options_.noise_quantile), accel_floor);
  run->gyro_threshold_var = options_.threshold_factor * run->gyro_noise_var;
  run->accel_threshold_var = options_.threshold_factor * run->accel_noise_var;
  if (!options_.rests_held_by_hand) return;
  run->gyro_threshold_var = std::max(run->gyro_threshold_var, HandRestThreshold(gyro_var, options_));
  run->accel_threshold_var = std::max(run->accel_threshold_var, HandRestThreshold(accel_var, options_));
}

std::vector<MotionPiece> MotionDetector::Pieces(const std::vector<PieceKind>& kinds) const {
  // Runs of one kind as [first, last] block ranges; a steady run shorter than min_steady_s counts
  // as motion, and joins the motion around it.
  struct Range {
    PieceKind kind;
    int first;
    int last;
  };
  std::vector<Range> ranges;
  for (int b = 0; b < static_cast<int>(kinds.size()); ++b) {
    if (ranges.empty() || ranges.back().kind != kinds[b]) {
      ranges.push_back({kinds[b], b, b});
    } else {
      ranges.back().last = b;
    }
  }
  std::vector<Range> merged;
  for (Range range : ranges) {
    if (range.kind != PieceKind::kMotion &&
        blocks_[range.last].last_s - blocks_[range.first].first_s < options_.min_steady_s) {
      range.kind = PieceKind::kMotion;
    }
    if (!merged.empty() && merged.back().kind == PieceKind::kMotion && range.kind == PieceKind::kMotion) {
      merged.back().last = range.last;
    } else {
      merged.push_back(range);
    }
  }
  std::vector<MotionPiece> pieces;
  for (const Range& range : merged) {
    MotionPiece piece;
    piece.kind = range.kind;
    piece.start_s = blocks_[range.first].first_s;
    piece.end_s = blocks_[range.last].last_s;
    for (int i = range.first; i <= range.last; ++i) {
      const Block& block = blocks_[i];
      piece.samples += block.n;
      piece.gyro_mean += static_cast<double>(block.n) * block.gyro_mean;
      piece.accel_mean += static_cast<double>(block.n) * block.accel_mean;
      piece.gyro_integral += block.gyro_integral;
      piece.integral_s += block.integral_s;
    }
    piece.gyro_mean = piece.gyro_mean / static_cast<double>(piece.samples) + reference_.gyro;
    piece.accel_mean = piece.accel_mean / static_cast<double>(piece.samples) + reference_.accel;
    pieces.push_back(piece);
  }
  return pieces;
}

Segmentation MatchPlan(const DetectedRun& run, const std::vector<TableSegment>& segments,
                       const SegmentationOptions& options) {
  if (segments.empty()) throw PlanMismatchError("the plan has no segments");
  if (run.samples == 0) throw PlanMismatchError("the run has no samples");
  const RunFacts facts = Facts(run, segments);
  std::optional<Matcher> best_match;
  std::optional<Matcher> furthest;
  std::optional<Matcher> as_read;  // the raw axes unflipped
  for (const Eigen::Vector3d& accel_signs : SignPatterns(true)) {
    for (const Eigen::Vector3d& gyro_signs : SignPatterns(facts.plan_uses_gyro_signs)) {
      Matcher matcher(run, segments, options, facts, accel_signs, gyro_signs);
      if (matcher.Run()) {
        if (!best_match || matcher.residual_deg() < best_match->residual_deg()) best_match.emplace(matcher);
        continue;
      }
      if (!furthest || matcher.reached_s() > furthest->reached_s()) furthest.emplace(matcher);
      if (accel_signs == Eigen::Vector3d::Ones() && gyro_signs == Eigen::Vector3d::Ones())
        as_read.emplace(matcher);
    }
  }
  if (best_match) return best_match->result();
  // The furthest a sign pattern got is the likeliest place; a flipped axis can also hide a missing
  // segment for a while, so the first disagreement with the axes as read is named too.
  std::string message = furthest->problem() + " (raw axis signs: accel " +
                        Vec(furthest->result().accel_signs, "%+.0f") + ", gyro " +
                        Vec(furthest->result().gyro_signs, "%+.0f") + ")";
  if (as_read && as_read->reached_s() != furthest->reached_s()) {
    message += "; with the raw axes as they are: " + as_read->problem();
  }
  throw PlanMismatchError(message);
}

int Labeller::Label(double time_s) {
  while (next_ < matches_.size() && matches_[next_].end_s < time_s) ++next_;
  if (next_ < matches_.size() && time_s >= matches_[next_].start_s) return matches_[next_].segment;
  return kTransitionSegment;
}

std::string SegmentationReport(const Segmentation& segmentation) {
  std::ostringstream out;
  char line[160];
  std::snprintf(line, sizeof line, "  %7s  %4s  %-6s  %12s  %12s  %s\n", "segment", "pass", "kind", "start_s",
                "end_s", "evidence");
  out << line;
  for (const SegmentMatch& match : segmentation.matches) {
    std::snprintf(line, sizeof line, "  %7d  %4d  %-6s  %12.3f  %12.3f  ", match.segment, match.pass + 1,
                  match.kind.c_str(), match.start_s, match.end_s);
    out << line << match.evidence << "\n";
  }
  return out.str();
}

}  // namespace imufit
