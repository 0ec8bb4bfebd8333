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
#include "imufit/io/log_samples.h"
#include "imufit/pipeline/segment_run.h"

namespace imufit {

// One session's file as read.
struct FieldSessionFile {
  std::string path;
  long long samples_read = 0;
  std::string samples_sha256;
};

struct FieldRunResult {
  FieldFitSummary fit;
  std::optional<Calibration> calibration;  // when fit.IsSolutionUsable()
  long long samples_read = 0;              // over every session
  std::string samples_sha256;              // the first session's
  std::vector<FieldSessionFile> sessions;  // in the order given
  std::string serial;                      // `serial` given, else the samples header's (unit_serial.h)
  std::vector<std::string> serial_warnings;
  LogFormat format = LogFormat::kSamplesCsv;  // the log's (io/log_samples.h)
  std::string topic, temp_topic;              // a bag's topics read ("" for a CSV)
  std::vector<std::string> read_notes;        // what reading the logs noted (a ULog's dropouts, ...)
};

// A bag's topics to read (--topic, --temp-topic; "" = the bag's only one).
struct LogTopics {
  std::string topic;
  std::string temp_topic;
};

// Reads `samples_path` as `input` says (its segment column, if any, is not used) and fits it. The
// file is a samples CSV, a ROS 1 bag or a PX4 ULog (told by its first bytes, io/log_samples.h; `topics`
// choose the bag's topics). `software` and the unit's serial go into the calibration: `serial` as stated
// (--serial), else the samples header's; a stated serial that contradicts the header is refused (InputError
// at the header) unless `allow_serial_mismatch`, as for a table fit. Throws InputError for bad input.
FieldRunResult FieldFitRun(const std::string& samples_path, const SamplesInput& input,
                           const FieldFitOptions& options, const std::string& software,
                           const std::string& serial, bool allow_serial_mismatch,
                           const LogTopics& topics = {});

// Whether the table fit's option `key` (FitRunOptionTable()) also means something to a session by
// hand: how the samples are read, the serial, the g-sensitivity, how rests are told from motion.
// `imufit fit --field` refuses the others; the Python fit_field() takes these as keywords.
bool AppliesToAFieldFit(const std::string& key);

// Several sessions of one unit (`imufit fit --field --samples A --samples B ...`, docs/field.md):
// each file read as its `inputs` entry says (one per path: a session's own --temp-c), fitted
// jointly (FitFieldSessions, the sessions named by their paths). The unit's serial as for one
// session, and the headers must agree with each other: two that name different serials are two
// units, refused (InputError at the later header) unless `allow_serial_mismatch`. The calibration's
// `fit: field:` block lists each session (session_samples, ..., io/fit_record.h); `fit: samples`
// and its SHA-256 are absent (they name one file), `samples_read` counts all. One path is
// FieldFitRun. Every session is a CSV or a bag, as FieldFitRun reads one (`topics` for each bag).
FieldRunResult FieldFitSessionsRun(const std::vector<std::string>& samples_paths,
                                   const std::vector<SamplesInput>& inputs, const FieldFitOptions& options,
                                   const std::string& software, const std::string& serial,
                                   bool allow_serial_mismatch, const LogTopics& topics = {});

// The calibration of a usable field fit (what FieldFitRun writes), without the record's file names.
Calibration FieldCalibration(const FieldFitSummary& fit, const FieldFitOptions& options);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_FIELD_RUN_H_
