#include "imufit/io/correct_file.h"

#include <algorithm>

#include "imufit/io/output_file.h"

namespace imufit {

CorrectFileReport CorrectSamples(const Calibration& calibration, SamplesReader* reader,
                                 const std::function<void(const Sample& corrected)>& sink) {
  CorrectFileReport report;
  Sample raw;
  Sample corrected;
  while (reader->Next(&raw)) {
    corrected.time_s = raw.time_s;
    corrected.temp_c = raw.temp_c;
    corrected.segment = raw.segment;
    calibration.model.Correct(raw.temp_c, raw.gyro, raw.accel, &corrected.gyro, &corrected.accel);
    if (!corrected.gyro.allFinite() || !corrected.accel.allFinite()) {
      // Never a non-finite number in the output: at an absurd temperature the polynomials overflow.
      reader->Fail("temp_c", "the correction at " + FormatDouble(raw.temp_c) +
                                 " degC is not a finite number (the calibration's fit range is [" +
                                 FormatDouble(calibration.fit_temp_range_c[0]) + ", " +
                                 FormatDouble(calibration.fit_temp_range_c[1]) + "] degC)");
    }
    sink(corrected);
    if (report.samples == 0) report.min_temp_c = report.max_temp_c = raw.temp_c;
    report.min_temp_c = std::min(report.min_temp_c, raw.temp_c);
    report.max_temp_c = std::max(report.max_temp_c, raw.temp_c);
    if (raw.temp_c < calibration.fit_temp_range_c[0] - kFitRangeToleranceC ||
        raw.temp_c > calibration.fit_temp_range_c[1] + kFitRangeToleranceC) {
      ++report.outside_temp_range;
    }
    ++report.samples;
  }
  return report;
}

CorrectFileReport CorrectSamplesFile(const Calibration& calibration, const std::string& samples_path,
                                     const std::string& output_path, std::optional<double> temp_c) {
  SamplesReader reader(samples_path, /*require_segment=*/false, temp_c);
  SamplesWriter writer(output_path, reader.has_segment(), SerialComment(reader.serial(), samples_path));
  const CorrectFileReport report =
      CorrectSamples(calibration, &reader, [&writer](const Sample& corrected) { writer.Write(corrected); });
  writer.Commit();
  return report;
}

}  // namespace imufit
