// imufit — the static stretch of a run a certificate measures the unit's gyro noise on (the Allan
// deviation, factory/gyro_noise.h). It is gathered while the run is read into windows
// (run_windows.h), so that the samples file is not read again for it.
//
// A stretch is an unbroken sequence of samples labelled with one static plan segment (no rate, no
// turn): a sample of another segment, of a moving segment or of a transition ends it. Data sheets
// quote noise at 25 degC, so the stretch measured is, of those at least kMinAllanStretchS long,
// the one whose mean temperature is nearest kNoiseReferenceTempC (of equally near ones, the longer;
// of equally long ones, the first); with none that long, the longest. A user may name the plan
// segment instead (NoiseStretchOptions::segment): then its longest stretch. Streaming: at most two
// stretches are held, the one being read and the best so far.
#ifndef IMUFIT_PIPELINE_STATIC_STRETCH_H_
#define IMUFIT_PIPELINE_STATIC_STRETCH_H_

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/io/plan.h"
#include "imufit/model/sample.h"
#include "imufit/model/temperature_polynomial.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/run/segmentation.h"

namespace imufit {

// The Allan deviation needs a static stretch at least this long, s.
inline constexpr double kMinAllanStretchS = 60.0;
// A bias instability is read at the floor of the Allan deviation, which a MEMS gyro reaches at tens
// to hundreds of seconds: a stretch shorter than this rarely shows it, s.
inline constexpr double kBiasInstabilityStretchS = 1800.0;
// The temperature data sheets quote noise at, degC.
inline constexpr double kNoiseReferenceTempC = kReferenceTempC;

struct StaticStretch {
  int segment = kTransitionSegment;         // the plan segment; kTransitionSegment: no static sample
  double start_time_s = 0.0;                // of the first sample
  double end_time_s = 0.0;                  // of the last sample
  double temp_sum_c = 0.0;                  // the samples' temperatures summed in time order, degC
  std::array<std::vector<double>, 3> gyro;  // per axis, the raw outputs (B) in time order
  // Why this stretch was chosen, for the certificate ("the nearest 25 degC of 4 static stretches at
  // least 60 s long"); empty for an empty stretch.
  std::string chosen;
  bool named = false;  // of the segment NoiseStretchOptions::segment names

  long long size() const { return static_cast<long long>(gyro[0].size()); }
  // Last minus first time stamp, s (0 with fewer than two samples).
  double duration_s() const { return size() > 1 ? end_time_s - start_time_s : 0.0; }
  double mean_temp_c() const { return temp_sum_c / static_cast<double>(size()); }
};

// How the noise stretch is chosen (NoiseStretchOptionTable(): --noise-segment, the Python keyword
// noise_segment).
struct NoiseStretchOptions {
  // The plan segment (its id, which must be static) whose longest stretch is measured; absent: the
  // stretch nearest kNoiseReferenceTempC.
  std::optional<int> segment;
};
const OptionTable<NoiseStretchOptions>& NoiseStretchOptionTable();

// Chooses the noise stretch of the samples given to it one by one, labelled, in time order.
class NoiseStretchFinder {
 public:
  // Throws InputError (naming the plan) when `options` names a segment the plan does not have or
  // that is not static.
  explicit NoiseStretchFinder(const Plan& plan, const NoiseStretchOptions& options = NoiseStretchOptions());

  void Add(const Sample& sample);
  // The chosen stretch of all samples added (empty when none was static, or none of the named
  // segment), with why it was chosen.
  StaticStretch Finish();

 private:
  void Close();  // the current stretch ends
  // Whether stretch `a` is to be measured rather than `b` (which may be empty).
  bool Better(const StaticStretch& a, const StaticStretch& b) const;

  std::set<int> static_segments_;
  std::optional<int> named_;
  int stretches_ = 0;  // closed so far
  int long_ones_ = 0;  // of them, at least kMinAllanStretchS long
  StaticStretch best_;
  StaticStretch current_;
};

// The noise stretch of `samples_path`, read as a fit reads it: `input` for a file without temp_c,
// and a file without a segment column labelled by `segmentation` (found again when not given).
// Throws InputError for bad input. For callers that did not keep it while reading the run
// (RunReader does).
StaticStretch ReadStaticStretch(const Plan& plan, const std::string& samples_path, const SamplesInput& input,
                                const std::optional<Segmentation>& segmentation,
                                const NoiseStretchOptions& options = NoiseStretchOptions());

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_STATIC_STRETCH_H_
