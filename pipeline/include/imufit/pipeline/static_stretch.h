// imufit — the longest static stretch of a run: the gyro outputs a certificate measures the unit's
// noise on (the Allan deviation, factory/certificate.h). It is gathered while the run is read into
// windows (run_windows.h), so that the samples file is not read again for it.
//
// A stretch is an unbroken sequence of samples labelled with one static plan segment (no rate, no
// turn): a sample of another segment, of a moving segment or of a transition ends it. The longest
// is the one with the most samples; of equal ones, the first.
#ifndef IMUFIT_PIPELINE_STATIC_STRETCH_H_
#define IMUFIT_PIPELINE_STATIC_STRETCH_H_

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "imufit/io/plan.h"
#include "imufit/model/sample.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/run/segmentation.h"

namespace imufit {

struct StaticStretch {
  int segment = kTransitionSegment;         // the plan segment; kTransitionSegment: no static sample
  double start_time_s = 0.0;                // of the first sample
  double end_time_s = 0.0;                  // of the last sample
  double temp_sum_c = 0.0;                  // the samples' temperatures summed in time order, degC
  std::array<std::vector<double>, 3> gyro;  // per axis, the raw outputs (B) in time order

  long long size() const { return static_cast<long long>(gyro[0].size()); }
  // Last minus first time stamp, s (0 with fewer than two samples).
  double duration_s() const { return size() > 1 ? end_time_s - start_time_s : 0.0; }
  double mean_temp_c() const { return temp_sum_c / static_cast<double>(size()); }
};

// Finds the longest static stretch of the samples given to it one by one, labelled, in time order.
class LongestStaticStretch {
 public:
  explicit LongestStaticStretch(const Plan& plan);

  void Add(const Sample& sample);
  // The longest stretch of all samples added (empty when none was static).
  StaticStretch Finish();

 private:
  void Close();  // the current stretch ends

  std::set<int> static_segments_;
  StaticStretch best_;
  StaticStretch current_;
};

// The longest static stretch of `samples_path`, read as a fit reads it: `input` for a file without
// temp_c, and a file without a segment column labelled by `segmentation` (found again when not
// given). Throws InputError for bad input. For callers that did not keep it while reading the run
// (RunReader does).
StaticStretch ReadStaticStretch(const Plan& plan, const std::string& samples_path, const SamplesInput& input,
                                const std::optional<Segmentation>& segmentation);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_STATIC_STRETCH_H_
