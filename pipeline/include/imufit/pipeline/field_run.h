// imufit — a session by hand fitted as one call (`imufit fit --field`, docs/field.md): the samples
// file read whole (the turns are integrated sample by sample), the field fit (fit/field_fit.h), and
// the calibration it gives, in the body frame of kBodyFrameAccelerometerXy (docs/spec.md section 1).
//
// The calibration holds the coefficients at order 0 in temperature (the fit's), their sigmas (0 for
// the accelerometer misalignments the body frame holds), `fit_temp_range_c` the readings' range, a
// `fit:` record (what was read, the solver, the residuals; the session's own figures under
// `fit: field:`) and the top-level key `body_frame: accelerometer_xy`.
#ifndef IMUFIT_PIPELINE_FIELD_RUN_H_
#define IMUFIT_PIPELINE_FIELD_RUN_H_

#include <optional>
#include <string>
#include <vector>

#include "imufit/fit/field_fit.h"
#include "imufit/io/calibration.h"
#include "imufit/pipeline/segment_run.h"

namespace imufit {

struct FieldRunResult {
  FieldFitSummary fit;
  std::optional<Calibration> calibration;  // when fit.IsSolutionUsable()
  long long samples_read = 0;
  std::string samples_sha256;
  std::string serial;  // `serial` given, else the samples header's (unit_serial.h)
  std::vector<std::string> serial_warnings;
  std::vector<std::string> read_notes;  // what reading the log noted (a ULog's dropouts, ...)
};

// Reads `samples_path` (a samples CSV or a PX4 ULog, io/log_samples.h) as `input` says (its segment column,
// if any, is not used) and fits it. `software` and the unit's serial go into the calibration: `serial` as
// stated (--serial), else the samples header's; a stated serial that contradicts the header is refused
// (InputError at the header) unless `allow_serial_mismatch`, as for a table fit. Throws InputError for bad
// input.
FieldRunResult FieldFitRun(const std::string& samples_path, const SamplesInput& input,
                           const FieldFitOptions& options, const std::string& software,
                           const std::string& serial, bool allow_serial_mismatch);

// The calibration of a usable field fit (what FieldFitRun writes), without the record's file names.
Calibration FieldCalibration(const FieldFitSummary& fit, const FieldFitOptions& options);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_FIELD_RUN_H_
