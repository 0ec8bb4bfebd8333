#include "imufit/pipeline/correct_file.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "imufit/io/output_file.h"
#include "imufit/io/parallel_samples.h"

namespace imufit {

namespace {

// Corrects samples in the order they come with one calibration's model, evaluating the coefficients
// again only when the temperature changes (a thermometer repeats its reading over many samples): the
// same numbers as SensorModel::Correct(), bit for bit.
class Corrector {
 public:
  explicit Corrector(const SensorModel& model) : model_(model) {}

  // `raw` corrected into `corrected` (time_s, temp_c and segment as read).
  void Correct(const Sample& raw, Sample* corrected) {
    if (!(raw.temp_c == temp_c_)) {  // also the first sample (NaN)
      coefficients_ = model_.CoefficientsAtTemperature(raw.temp_c);
      temp_c_ = raw.temp_c;
    }
    corrected->time_s = raw.time_s;
    corrected->temp_c = raw.temp_c;
    corrected->segment = raw.segment;
    CorrectWith(coefficients_, raw.gyro, raw.accel, &corrected->gyro, &corrected->accel);
  }

 private:
  const SensorModel& model_;
  double temp_c_ = std::numeric_limits<double>::quiet_NaN();
  UnitCoefficients<double> coefficients_;
};

bool Finite(const Sample& corrected) { return corrected.gyro.allFinite() && corrected.accel.allFinite(); }

// Counts `corrected` in `report`, refusing a correction that is not finite at its row of `reader` (a
// SamplesReader or a ParallelSamplesReader).
template <typename Reader>
void Count(const Calibration& calibration, const Reader& reader, const Sample& corrected,
           CorrectFileReport* report) {
  const double temp_c = corrected.temp_c;
  if (!Finite(corrected)) {
    // Never a non-finite number in the output: at an absurd temperature the polynomials overflow.
    reader.Fail("temp_c", "the correction at " + FormatDouble(temp_c) +
                              " degC is not a finite number (the calibration's fit range is [" +
                              FormatDouble(calibration.fit_temp_range_c[0]) + ", " +
                              FormatDouble(calibration.fit_temp_range_c[1]) + "] degC)");
  }
  if (report->samples == 0) report->min_temp_c = report->max_temp_c = temp_c;
  report->min_temp_c = std::min(report->min_temp_c, temp_c);
  report->max_temp_c = std::max(report->max_temp_c, temp_c);
  if (temp_c < calibration.fit_temp_range_c[0] - kFitRangeToleranceC ||
      temp_c > calibration.fit_temp_range_c[1] + kFitRangeToleranceC) {
    ++report->outside_temp_range;
  }
  ++report->samples;
}

}  // namespace

CorrectFileReport CorrectSamples(const Calibration& calibration, SamplesReader* reader,
                                 const std::function<void(const Sample& corrected)>& sink) {
  RefuseCorrectedSamples(*reader);
  CorrectFileReport report;
  Corrector corrector(calibration.model);
  Sample raw;
  Sample corrected;
  while (reader->Next(&raw)) {
    corrector.Correct(raw, &corrected);
    Count(calibration, *reader, corrected, &report);
    sink(corrected);
  }
  return report;
}

std::string CorrectedByComment(const Calibration& calibration, const std::string& calibration_sha256,
                               const std::string& software) {
  const std::string serial = calibration.serial.empty() ? "(none)" : calibration.serial;
  std::string line = std::string(kCorrectedByKey) + " serial " + serial + ", calibration sha256 " +
                     calibration_sha256 + ", software " + software;
  for (char& c : line) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';  // one header line
  }
  return line;
}

void RefuseCorrectedSamples(const SamplesReader& reader) {
  for (const CsvReader::Comment& comment : reader.header_comments()) {
    if (comment.text.compare(0, kCorrectedByKey.size(), kCorrectedByKey) != 0) continue;
    throw std::runtime_error(reader.path() + ":" + std::to_string(comment.line) + ": is corrected already (" +
                             comment.text +
                             "): a calibration corrects the unit's raw log, not its corrected samples");
  }
}

CorrectFileReport CorrectSamplesFile(const Calibration& calibration, const std::string& samples_path,
                                     const std::string& output_path, const SamplesFormat& format,
                                     const std::string& corrected_by) {
  SamplesReader reader(samples_path, /*require_segment=*/false, format);
  std::string comment = SerialComment(reader.serial(), samples_path);
  if (!corrected_by.empty()) comment += (comment.empty() ? "" : "\n") + corrected_by;
  SamplesWriter writer(output_path, reader.has_segment(), comment);
  RefuseCorrectedSamples(reader);
  // Each block of the file is corrected and its rows formatted on the thread that parsed it (both
  // cores); this one checks the samples and writes the rows in the file's order. The rows stop
  // before a correction that is not finite, which is refused at its row.
  const SampleColumns columns = writer.columns();
  ParallelSamplesReader parallel(&reader, 2,
                                 [&calibration, columns](std::vector<Sample>* samples, std::string* rows) {
                                   Corrector corrector(calibration.model);
                                   for (Sample& sample : *samples) {
                                     corrector.Correct(Sample(sample), &sample);
                                     if (!Finite(sample)) break;
                                     SamplesWriter::AppendRow(sample, columns, rows);
                                   }
                                 });
  CorrectFileReport report;
  Sample corrected;
  while (parallel.Next(&corrected)) {
    writer.WriteRows(parallel.TakeText());
    Count(calibration, parallel, corrected, &report);
  }
  writer.Commit();
  return report;
}

}  // namespace imufit
