// Fuzzes the calibration reader. Oracle: an accepted calibration, written and read again, gives
// back the same doubles bit for bit and the same text (write -> read -> write is a fixed point),
// and corrects a sample at the ends of its fit range to finite values.
#include <cstring>

#include "fuzz_util.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace imufit;
  Calibration calibration;
  try {
    calibration = ReadCalibration(fuzz::WriteInput(data, size, ".yaml"));
  } catch (const InputError&) {
    return 0;
  }
  calibration.model.basis.half_range_c = 1.0;
  const std::string text = CalibrationToYaml(calibration);
  const std::string copy = fuzz::Folder() + "/copy.yaml";
  WriteCalibration(copy, calibration);
  Calibration again;
  try {
    again = ReadCalibration(copy);
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    IMUFIT_FUZZ_CHECK(false, "a calibration imufit wrote reads back");
  }
  IMUFIT_FUZZ_CHECK(std::memcmp(again.model.gyro.data(), calibration.model.gyro.data(),
                                sizeof(double) * calibration.model.gyro.size()) == 0,
                    "gyro coefficients round-trip bit-exactly");
  IMUFIT_FUZZ_CHECK(std::memcmp(again.model.accel.data(), calibration.model.accel.data(),
                                sizeof(double) * calibration.model.accel.size()) == 0,
                    "accel coefficients round-trip bit-exactly");
  IMUFIT_FUZZ_CHECK(again.fit_temp_range_c == calibration.fit_temp_range_c, "the range round-trips");
  IMUFIT_FUZZ_CHECK(CalibrationToYaml(again) == text, "write -> read -> write gives the same text");
  for (const double temp_c : calibration.fit_temp_range_c) {
    Eigen::Vector3d omega, a;
    calibration.model.Correct(temp_c, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6), &omega, &a);
    IMUFIT_FUZZ_CHECK(omega.allFinite() && a.allFinite(), "a correction inside the fit range is finite");
  }
  return 0;
}
