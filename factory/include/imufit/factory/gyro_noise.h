// imufit — the certificate's gyro noise: the overlapping Allan deviation of a static stretch of a
// run (by default the one nearest 25 degC, pipeline/static_stretch.h) and its IEEE 952 fit (ARW, bias
// instability), the analysis `imufit allan` runs on a long static log (noise/column_analysis.h).
//
// The stretch itself (pipeline/static_stretch.h) is gathered while the run is read into windows, so
// the samples file is not read again for it; only the three raw gyro outputs of each of its samples
// are held (the overlapping estimator reads the integrated rates at every offset up to half the
// record). The calibration turns them into rates, over the scale factors at the stretch's mean
// temperature.
#ifndef IMUFIT_FACTORY_GYRO_NOISE_H_
#define IMUFIT_FACTORY_GYRO_NOISE_H_

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "imufit/io/calibration.h"
#include "imufit/io/plan.h"
#include "imufit/model/sample.h"
#include "imufit/noise/column_analysis.h"
#include "imufit/pipeline/segment_run.h"
#include "imufit/pipeline/static_stretch.h"
#include "imufit/run/segmentation.h"

namespace imufit {

// kBiasInstabilityStretchS: pipeline/static_stretch.h (plan check judges plans by it too).

struct NoiseAxis {
  std::string axis;
  bool fitted = false;
  std::string why_not;
  // The fit's estimates with their intervals, resolved or not (column_analysis.h): ARW in
  // deg/sqrt(h), bias instability in deg/h.
  NoiseTermFigure arw_deg_per_sqrt_hr;
  NoiseTermFigure bias_instability_dph;
  int points = 0;
};

struct NoiseSection {
  bool computed = false;
  std::string why_not;
  int segment = -1;
  double duration_s = 0.0;
  double temp_c = 0.0;  // the stretch's mean temperature
  std::string chosen;   // why this stretch (StaticStretch::chosen)
  std::vector<NoiseAxis> axes;
  // Per gyro axis ("gyro_x", ...), in rad/s: the overlapping Allan deviation and its IEEE 952 fit
  // as `imufit allan` computes them, drawn by the same plot (allan_plot.h) in deg/h.
  std::vector<ColumnAnalysis> columns;
};

// The section of `stretch` (or why there is none): the raw outputs over the calibration's scale
// factors at the stretch's mean temperature, in rad/s. Consumes the stretch's outputs.
NoiseSection GyroNoise(const Calibration& calibration, StaticStretch stretch);

// Reads `samples_path` as the fit read it (labelled from `segmentation`, or segmented again, when
// the file has no segment column) for its noise stretch (ReadStaticStretch). A file that cannot be
// read or does not match the plan (or the options) gives a section that says why, not an exception.
NoiseSection MeasureGyroNoise(const Calibration& calibration, const Plan& plan,
                              const std::string& samples_path, const SamplesInput& input,
                              const std::optional<Segmentation>& segmentation,
                              const NoiseStretchOptions& options = NoiseStretchOptions());

}  // namespace imufit

#endif  // IMUFIT_FACTORY_GYRO_NOISE_H_
