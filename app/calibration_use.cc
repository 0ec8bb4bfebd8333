// imufit — a calibration read for use: the one place where apply, allan --calibration, export and
// report learn which sensors a calibration does not calibrate (io's UncalibratedSensors), so that
// none of them uses a sensor held at nominal values as if it had been fitted.
#include <cstdio>

#include "commands.h"
#include "imufit/base/text.h"
#include "imufit/io/calibration.h"
#include "imufit/run/segmentation.h"

namespace imufit {
namespace {

// What a command would do with an uncalibrated sensor, and what --allow-uncalibrated does instead.
const char* Doing(CalibrationUse use) {
  switch (use) {
    case CalibrationUse::kCorrect:
      return "correcting would write its raw output as if it were in SI units; calibrate it (imufit fit "
             "--fit all, or --prior), or give --allow-uncalibrated to pass it through as logged, marked in "
             "the output's header";
    case CalibrationUse::kExport:
      return "an export would hand its nominal values on as a calibration; calibrate it (imufit fit --fit "
             "all, or --prior), or give --allow-uncalibrated to export them anyway";
    case CalibrationUse::kCertify:
      break;
  }
  return "";
}

}  // namespace

std::vector<std::string> UncalibratedNotes(const Calibration& calibration, const std::string& path) {
  std::vector<std::string> notes;
  for (const std::string& sensor : UncalibratedSensors(calibration)) {
    notes.push_back(path + ": the " + sensor + " is not calibrated (held at scale 1 raw per " +
                    (sensor == "gyro" ? "rad/s" : "m/s^2") + " and 0 by a fit of the " +
                    (sensor == "gyro" ? "accelerometer" : "gyro") + " alone, without --prior)");
  }
  return notes;
}

std::vector<std::string> CheckCalibratedSensors(const Calibration& calibration, const std::string& path,
                                                CalibrationUse use, bool allow_uncalibrated) {
  const std::vector<std::string> notes = UncalibratedNotes(calibration, path);
  if (notes.empty()) return notes;
  if (use != CalibrationUse::kCertify && !allow_uncalibrated) {
    throw PlanMismatchError(Join(notes, "; ") + ": " + Doing(use));
  }
  for (const std::string& note : notes) {
    std::fprintf(
        stderr, "imufit: warning: %s%s\n", note.c_str(),
        use == CalibrationUse::kCertify ? " (marked on the certificate)" : " (--allow-uncalibrated)");
  }
  return notes;
}

void AddAllowUncalibratedFlag(CliCommand command, bool* allow_uncalibrated) {
  command.Flag("--allow-uncalibrated", allow_uncalibrated,
               "use a calibration that leaves a sensor uncalibrated (fitted with --fit accel or --fit gyro "
               "without --prior): that sensor passes through as logged, with a warning; without it such a "
               "calibration is refused");
}

}  // namespace imufit
