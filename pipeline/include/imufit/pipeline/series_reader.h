// imufit — reading columns of a samples file as uniformly sampled series (imufit allan).
//
// Streams the file (plain or .gz) through CsvReader and keeps only time_s and the requested
// columns, each as one std::vector<double>: no per-row allocation, so a 12-hour 1 kHz log
// (43 million rows) costs 8 bytes per value kept. For plain files the vectors are reserved from
// the file size after the first rows.
//
// The time column must be uniform: the first interval is the nominal one, and every later
// interval dt must satisfy |dt - dt_0| <= time_tolerance * dt_0. A longer interval is a gap: an
// InputError at the line and field of the sample after it, unless `bridge_gaps` joins the data on
// both sides as if contiguous (counted in the result). A shorter one is jitter: always an error.
// The sample interval reported is the mean of the accepted (not bridged) intervals, rounded to 12
// significant digits (decimal timestamps carry no more).
#ifndef IMUFIT_PIPELINE_SERIES_READER_H_
#define IMUFIT_PIPELINE_SERIES_READER_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "imufit/base/option_table.h"
#include "imufit/io/calibration.h"
#include "imufit/pipeline/correct_file.h"

namespace imufit {

// How the time column is read. UniformSeriesOptionTable() describes each option (`imufit allan`'s
// --time-tolerance and --gaps, the validation messages); the defaults are these.
struct UniformSeriesOptions {
  // Largest |dt - dt_0| accepted, as a fraction of the nominal interval dt_0 (0 < t < 0.5).
  double time_tolerance = 0.1;
  // Join the data across gaps instead of failing.
  bool bridge_gaps = false;

  // "" when valid, else a readable reason naming the option and its value.
  std::string Validate() const;
};
const OptionTable<UniformSeriesOptions>& UniformSeriesOptionTable();

struct UniformSeries {
  std::vector<std::string> names;            // the columns read, in the order asked
  std::vector<std::vector<double>> columns;  // one per name, all the same length
  double sample_interval_s = 0.0;            // mean accepted interval, 12 digits
  double start_time_s = 0.0;
  double end_time_s = 0.0;
  int64_t gaps_bridged = 0;
  double bridged_time_s = 0.0;  // time removed by bridging
  double max_jitter = 0.0;      // largest |dt - dt_0| / dt_0 accepted
};

// Reads `columns` (when empty: every column whose name starts with "gyro_" or "accel_") and
// time_s from `path`. Throws InputError located at file:line:field for a missing column, a bad
// number, a time that does not increase, a gap or jitter, or fewer than two samples.
UniformSeries ReadUniformSeries(const std::string& path, const std::vector<std::string>& columns,
                                const UniformSeriesOptions& options);

// The same series of a raw samples file corrected through `calibration` first, sample by sample
// with CorrectSamples (correct_file.h): the values are those `imufit apply` writes, bit for bit.
// `columns` are among gyro_x..z (rad/s), accel_x..z (m/s^2) and temp_c (when empty: the six
// rates); `format` says how the samples are read, as for SamplesReader (times in seconds).
// `report` receives the correction's counts (samples outside the fit temperature range).
// Throws InputError as ReadUniformSeries does, and for a column the calibration does not correct.
UniformSeries ReadCorrectedSeries(const std::string& path, const Calibration& calibration,
                                  const SamplesFormat& format, const std::vector<std::string>& columns,
                                  const UniformSeriesOptions& options, CorrectFileReport* report);

}  // namespace imufit

#endif  // IMUFIT_PIPELINE_SERIES_READER_H_
