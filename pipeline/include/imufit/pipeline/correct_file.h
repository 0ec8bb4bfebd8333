// imufit — correcting a whole samples file with a calibration (`imufit apply`, `imufit allan
// --calibration`).
//
// Streams the samples row by row through the shared model (SensorModel::Correct: the
// accelerometer first, then the gyro with the corrected specific force of the same row).
// CorrectSamplesFile writes the corrected layout of docs/spec.md (time_s, temp_c, segment if the
// input had it, gyro in rad/s, accel in m/s^2) to `output_path`, atomically; CorrectSamples hands
// each corrected sample to a caller, so that what `imufit allan --calibration` analyses is, bit
// for bit, what `imufit apply` writes.
//
// Temperatures are not clamped: a sample beyond the fitted range is corrected by extrapolating the
// cubics (counted in the report, warned about by the command) and a correction that is not finite
// is refused. The C runtime for firmware (model/c/imufit_runtime.h) clamps to the fitted range
// instead (docs/export.md).
#ifndef IMUFIT_PIPELINE_CORRECT_FILE_H_
#define IMUFIT_PIPELINE_CORRECT_FILE_H_

#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "imufit/io/calibration.h"
#include "imufit/io/samples.h"

namespace imufit {

// A temperature reading this close outside the calibration's fit_temp_range_c is no
// extrapolation, degC: the range is the extremes of the fit's window readings, so the noise of the
// thermometer alone puts a few samples of the same run just beyond it (a few hundredths of a
// degree), where a cubic has not moved.
inline constexpr double kFitRangeToleranceC = 0.5;

struct CorrectFileReport {
  long long samples = 0;
  // Samples whose temperature lies more than kFitRangeToleranceC outside the calibration's
  // fit_temp_range_c.
  long long outside_temp_range = 0;
  double min_temp_c = 0.0;
  double max_temp_c = 0.0;
};

// A corrected file says what corrected it, in a header line (without the '#'):
//   corrected by: serial SN0001, calibration sha256 3f2a...e1, software imufit 0.1.0 (git abc123)
// and such a file is never corrected again (its numbers are rad/s and m/s^2, not raw).
inline constexpr std::string_view kCorrectedByKey = "corrected by:";
// That line for `calibration` (whose file has the SHA-256 `calibration_sha256`), corrected by
// `software`.
std::string CorrectedByComment(const Calibration& calibration, const std::string& calibration_sha256,
                               const std::string& software);
// Throws std::runtime_error (exit status 1) naming the file, its line and what corrected it when
// the header of `reader` has a `corrected by:` line.
void RefuseCorrectedSamples(const SamplesReader& reader);

// Reads every sample of `reader` (refused by RefuseCorrectedSamples first), corrects it and calls `sink` with
// the corrected sample (time_s, temp_c and segment as read). Throws InputError, located at the row, when a
// correction is not a finite number (a temperature far outside the fit range overflows the polynomials).
CorrectFileReport CorrectSamples(const Calibration& calibration, SamplesReader* reader,
                                 const std::function<void(const Sample& corrected)>& sink);

// `format`: how the samples are read (a fixed temperature is written to the output; times are
// written in seconds). `corrected_by` (CorrectedByComment), when not empty, is written into the
// output's header.
CorrectFileReport CorrectSamplesFile(const Calibration& calibration, const std::string& samples_path,
                                     const std::string& output_path, const SamplesFormat& format = {},
                                     const std::string& corrected_by = "");

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_CORRECT_FILE_H_
