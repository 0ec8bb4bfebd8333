// imufit — the certificate's gyro noise: the overlapping Allan deviation of the longest static
// stretch of a run and its IEEE 952 fit (ARW, bias instability), the analysis `imufit allan` runs
// on a long static log (noise/column_analysis.h).
//
// The run streams past: StaticStretchCollector takes its samples one at a time, labelled with
// their segment, and keeps of the longest static stretch so far, and of the one being read, only
// what the analysis needs: the three raw gyro outputs (24 bytes a sample, where a Sample is 72) and
// running sums of the time and temperature. The outputs themselves must be held: the overlapping
// estimator reads the integrated rates at every offset up to half the record (about 86 MB for an
// hour at 1 kHz). The pass that reads the windows can feed the collector as well as a pass of its
// own (MeasureGyroNoise); the calibration is needed only at the end, to turn the raw outputs into
// rates (over the scale factors at the stretch's mean temperature).
#ifndef IMUFIT_FACTORY_GYRO_NOISE_H_
#define IMUFIT_FACTORY_GYRO_NOISE_H_

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "imufit/fit/segmentation.h"
#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/model/sample.h"
#include "imufit/noise/column_analysis.h"
#include "imufit/pipeline/segment_run.h"

namespace imufit {

// The Allan section needs a static stretch at least this long, s.
inline constexpr double kMinAllanStretchS = 60.0;

struct NoiseAxis {
  std::string axis;
  bool fitted = false;
  std::string why_not;
  double arw_deg_per_sqrt_hr = 0.0, arw_sigma = 0.0;
  bool arw_resolved = false;
  double bias_instability_dph = 0.0, bias_instability_sigma = 0.0;
  bool bias_instability_resolved = false;
  int points = 0;
};

struct NoiseSection {
  bool computed = false;
  std::string why_not;
  int segment = -1;
  double duration_s = 0.0;
  double temp_c = 0.0;
  std::vector<NoiseAxis> axes;
  // Per gyro axis ("gyro_x", ...), in rad/s: the overlapping Allan deviation and its IEEE 952 fit
  // as `imufit allan` computes them, drawn by the same plot (allan_plot.h) in deg/h.
  std::vector<ColumnAnalysis> columns;
};

// The longest static stretch of a run, collected as its samples stream past. A stretch is a run of
// consecutive samples of one static segment of the plan; the first of equally long ones is kept.
class StaticStretchCollector {
 public:
  explicit StaticStretchCollector(const Plan& plan);

  // The next sample of the run, labelled with its segment.
  void Add(const Sample& sample);
  // The section of the longest stretch (or why there is none): the raw outputs over the
  // calibration's scale factors at the stretch's mean temperature, in rad/s. Ends the collection.
  NoiseSection Finish(const Calibration& calibration);

 private:
  struct Stretch {
    int segment = -1;
    double first_time_s = 0.0, last_time_s = 0.0;
    double temp_sum_c = 0.0;
    std::array<std::vector<double>, 3> gyro_raw;  // per axis

    size_t size() const { return gyro_raw[0].size(); }
  };
  void Close();  // the current stretch ends: kept when it is the longest so far

  std::set<int> static_segments_;
  Stretch current_, longest_;
};

// Reads `samples_path` as the fit read it (labelled from `segmentation`, or segmented again, when
// the file has no segment column) through a StaticStretchCollector. A file that cannot be read or
// does not match the plan gives a section that says why, not an exception.
NoiseSection MeasureGyroNoise(const Calibration& calibration, const Plan& plan,
                              const std::string& samples_path, const SamplesInput& input,
                              const std::optional<Segmentation>& segmentation);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_GYRO_NOISE_H_
