// The C runtime for firmware (model/c/imufit_runtime.h) against the shared C++ model: both builds
// on a grid of temperatures, rates and specific forces, the temperature clamp, the blob (CRC-32,
// every single flipped bit refused) and the exported header read back bit for bit.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/export/export.h"
#include "imufit/io/calibration.h"
#include "imufit/io/sha256.h"
#include "imufit_runtime.h"
#define IMUFIT_RUNTIME_FLOAT
#include "imufit_runtime.h"
#include "mems_truth.h"  // fixtures/golden/export: `imufit export --format c` of fixtures/mems_truth.yaml

namespace imufit {
namespace {

// The double build agrees with the C++ model within this, relative to the size of the sample's
// terms (the correction evaluated with every term's absolute value): rounding differences only.
constexpr double kDoubleBuildRelativeTolerance = 1e-12;
constexpr double kGravity = 9.80665;
constexpr double kRadPerDeg = M_PI / 180.0;

const char* const kUnits[] = {"mems_truth.yaml", "tactical_truth.yaml"};

const double* Cubic(const double* params, int index) { return params + index * kPolynomialTerms; }

Calibration Unit(const char* name) { return ReadCalibration(std::string(IMUFIT_FIXTURES_DIR) + "/" + name); }

// The runtime's calibration as it loads from the exported blob (double and float builds).
template <typename Runtime, typename Load>
Runtime RuntimeOf(const Calibration& calibration, Load load) {
  const std::string blob = CalibrationBlob(calibration, "");
  Runtime runtime{};
  EXPECT_EQ(load(reinterpret_cast<const unsigned char*>(blob.data()), blob.size(), &runtime), IMUFIT_OK);
  return runtime;
}
imufit_calibration DoubleBuild(const Calibration& c) {
  return RuntimeOf<imufit_calibration>(c, imufit_load_blob);
}
imufit_calibration_f FloatBuild(const Calibration& c) {
  return RuntimeOf<imufit_calibration_f>(c, imufit_load_blob_f);
}

// Every coefficient of `runtime` is the calibration's, converted to the build's type.
template <typename Runtime>
void ExpectCoefficientsOf(const Calibration& calibration, const Runtime& runtime) {
  using Real = decltype(runtime.reference_temp_c);
  for (int i = 0; i < kGyroParameters; ++i) {
    const Real expected = static_cast<Real>(calibration.model.gyro[i]), got = runtime.gyro[i / 4][i % 4];
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << "gyro parameter " << i;
  }
  for (int i = 0; i < kAccelParameters; ++i) {
    const Real expected = static_cast<Real>(calibration.model.accel[i]), got = runtime.accel[i / 4][i % 4];
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << "accel parameter " << i;
  }
  EXPECT_EQ(runtime.reference_temp_c, static_cast<Real>(calibration.model.basis.center_c));
  EXPECT_EQ(runtime.temp_min_c, static_cast<Real>(calibration.fit_temp_range_c[0]));
  EXPECT_EQ(runtime.temp_max_c, static_cast<Real>(calibration.fit_temp_range_c[1]));
  EXPECT_STREQ(runtime.serial, calibration.serial.c_str());
}

// A sample of the grid: temperature and raw outputs, all exact in float.
struct GridSample {
  double temp_c;
  Eigen::Vector3d gyro_raw, accel_raw;
};

// 11 temperatures across the fitted range x rates of -2000, 0, 2000 deg/s x specific forces of
// -2, 0, 2 g on each axis, made raw by the model's exact inverse and rounded to float (what a
// firmware has).
std::vector<GridSample> Grid(const Calibration& calibration) {
  std::vector<GridSample> grid;
  const double levels[] = {-1.0, 0.0, 1.0};
  for (int step = 0; step <= 10; ++step) {
    const double t = calibration.fit_temp_range_c[0] +
                     (calibration.fit_temp_range_c[1] - calibration.fit_temp_range_c[0]) * step / 10.0;
    const double temp_c = static_cast<float>(t);
    for (double wx : levels)
      for (double wy : levels)
        for (double wz : levels) {
          for (double ax : levels)
            for (double ay : levels)
              for (double az : levels) {
                const Eigen::Vector3d omega = 2000.0 * kRadPerDeg * Eigen::Vector3d(wx, wy, wz);
                const Eigen::Vector3d a = 2.0 * kGravity * Eigen::Vector3d(ax, ay, az);
                GridSample sample{temp_c, {}, {}};
                calibration.model.Forward(temp_c, omega, a, &sample.gyro_raw, &sample.accel_raw);
                sample.gyro_raw = sample.gyro_raw.cast<float>().cast<double>();
                sample.accel_raw = sample.accel_raw.cast<float>().cast<double>();
                grid.push_back(sample);
              }
        }
  }
  return grid;
}

// The size of a sample's terms: the correction with every sum made of absolute values (|raw| +
// |V| + |H| |a|, |M| |q|), to which rounding errors are relative.
void TermSizes(const SensorModel& model, const GridSample& s, Eigen::Vector3d* omega, Eigen::Vector3d* a) {
  const double x = std::abs(s.temp_c - model.basis.center_c);
  const auto size = [x](const double* c) {
    return std::abs(c[0]) + x * (std::abs(c[1]) + x * (std::abs(c[2]) + x * std::abs(c[3])));
  };
  const auto sensor = [&](const double* params, const Eigen::Vector3d& unbiased_size) {
    Eigen::Vector3d q, out;
    for (int m = 0; m < 3; ++m) {
      q(m) = unbiased_size(m) / std::abs(EvaluateTemperaturePolynomial(Cubic(params, kScaleCoefficient + m),
                                                                       s.temp_c - model.basis.center_c));
    }
    out = q;
    for (int m = 0; m < 6; ++m)
      out(kMisalignmentRow[m]) += size(Cubic(params, kMisalignmentCoefficient + m)) * q(kMisalignmentCol[m]);
    return out;
  };
  Eigen::Vector3d unbiased;
  for (int m = 0; m < 3; ++m)
    unbiased(m) = std::abs(s.accel_raw(m)) + size(Cubic(model.accel.data(), kBiasCoefficient + m));
  *a = sensor(model.accel.data(), unbiased);
  for (int m = 0; m < 3; ++m) {
    unbiased(m) = std::abs(s.gyro_raw(m)) + size(Cubic(model.gyro.data(), kBiasCoefficient + m));
    for (int n = 0; n < 3; ++n)
      unbiased(m) += size(Cubic(model.gyro.data(), kGSensitivityCoefficient + 3 * m + n)) * (*a)(n);
  }
  *omega = sensor(model.gyro.data(), unbiased);
}

TEST(CRuntimeTest, DoubleBuildMatchesTheModelOnTheGrid) {
  for (const char* name : kUnits) {
    const Calibration calibration = Unit(name);
    const imufit_calibration runtime = DoubleBuild(calibration);
    double worst = 0.0;
    for (const GridSample& s : Grid(calibration)) {
      Eigen::Vector3d omega_hat, a_hat, omega_size, a_size, omega_c, a_c;
      calibration.model.Correct(s.temp_c, s.gyro_raw, s.accel_raw, &omega_hat, &a_hat);
      TermSizes(calibration.model, s, &omega_size, &a_size);
      ASSERT_EQ(imufit_correct(&runtime, s.temp_c, s.gyro_raw.data(), s.accel_raw.data(), omega_c.data(),
                               a_c.data()),
                IMUFIT_OK);
      for (int axis = 0; axis < 3; ++axis) {
        worst = std::max(worst, std::abs(omega_c(axis) - omega_hat(axis)) / omega_size(axis));
        worst = std::max(worst, std::abs(a_c(axis) - a_hat(axis)) / a_size(axis));
      }
    }
    EXPECT_LE(worst, kDoubleBuildRelativeTolerance) << name;
  }
}

TEST(CRuntimeTest, FloatBuildStaysWithinItsDerivedBoundOnTheGrid) {
  for (const char* name : kUnits) {
    const Calibration calibration = Unit(name);
    const imufit_calibration_f runtime = FloatBuild(calibration);
    double worst_ratio = 0.0;
    for (const GridSample& s : Grid(calibration)) {
      Eigen::Vector3d omega_hat, a_hat;
      calibration.model.Correct(s.temp_c, s.gyro_raw, s.accel_raw, &omega_hat, &a_hat);
      const FloatRuntimeBound bound =
          FloatRuntimeErrorBound(calibration.model, s.temp_c, s.gyro_raw, s.accel_raw);
      const Eigen::Vector3f gyro = s.gyro_raw.cast<float>(), accel = s.accel_raw.cast<float>();
      Eigen::Vector3f omega_f, a_f;
      ASSERT_EQ(imufit_correct_f(&runtime, static_cast<float>(s.temp_c), gyro.data(), accel.data(),
                                 omega_f.data(), a_f.data()),
                IMUFIT_OK);
      for (int axis = 0; axis < 3; ++axis) {
        const double gyro_error = std::abs(omega_f(axis) - omega_hat(axis));
        const double accel_error = std::abs(a_f(axis) - a_hat(axis));
        ASSERT_LE(gyro_error, bound.omega_radps(axis))
            << name << " at " << s.temp_c << " degC, gyro axis " << axis;
        ASSERT_LE(accel_error, bound.a_mps2(axis))
            << name << " at " << s.temp_c << " degC, accel axis " << axis;
        worst_ratio =
            std::max({worst_ratio, gyro_error / bound.omega_radps(axis), accel_error / bound.a_mps2(axis)});
      }
    }
    // The bound is a bound, not a guess: report how much of it the worst sample uses.
    RecordProperty(std::string(name) + "_worst_error_over_bound", std::to_string(worst_ratio));
    EXPECT_GT(worst_ratio, 1e-3) << name << ": the bound is far looser than the errors it bounds";
  }
}

TEST(CRuntimeTest, ClampsTheTemperatureToTheFittedRange) {
  const Calibration calibration = Unit("mems_truth.yaml");
  const imufit_calibration runtime = DoubleBuild(calibration);
  const Eigen::Vector3d gyro_raw(120.0, -40.0, 900.0), accel_raw(30.0, -20.0, 2100.0);
  const struct { double temp_c, model_temp_c; } cases[] = {{-60.0, -40.0}, {120.0, 85.0}, {NAN, -40.0}};
  for (const auto& c : cases) {
    Eigen::Vector3d omega_hat, a_hat, omega_c, a_c;
    calibration.model.Correct(c.model_temp_c, gyro_raw, accel_raw, &omega_hat, &a_hat);
    EXPECT_EQ(
        imufit_correct(&runtime, c.temp_c, gyro_raw.data(), accel_raw.data(), omega_c.data(), a_c.data()),
        IMUFIT_TEMP_CLAMPED)
        << c.temp_c;
    EXPECT_LE((omega_c - omega_hat).norm(), 1e-12 * omega_hat.norm()) << c.temp_c;
    EXPECT_LE((a_c - a_hat).norm(), 1e-12 * a_hat.norm()) << c.temp_c;
  }
}

TEST(CRuntimeTest, BlobLoadsBitForBitAndEveryFlippedBitIsRefused) {
  const std::string path = std::string(IMUFIT_FIXTURES_DIR) + "/mems_truth.yaml";
  const Calibration calibration = ReadCalibration(path);
  std::string blob = CalibrationBlob(calibration, Sha256OfFile(path));
  ASSERT_EQ(blob.size(), size_t{IMUFIT_BLOB_BYTES});
  const auto* bytes = reinterpret_cast<const unsigned char*>(blob.data());

  imufit_calibration loaded{};
  ASSERT_EQ(imufit_load_blob(bytes, blob.size(), &loaded), IMUFIT_OK);
  ExpectCoefficientsOf(calibration, loaded);
  EXPECT_EQ(imufit_crc32(bytes, IMUFIT_BLOB_OFFSET_CRC), imufit_crc32_f(bytes, IMUFIT_BLOB_OFFSET_CRC));
  // The float build converts the binary64 numbers as a compiler does (round to nearest even).
  imufit_calibration_f loaded_f{};
  ASSERT_EQ(imufit_load_blob_f(bytes, blob.size(), &loaded_f), IMUFIT_OK);
  ExpectCoefficientsOf(calibration, loaded_f);

  const imufit_calibration untouched = loaded;
  for (size_t bit = 0; bit < 8 * blob.size(); ++bit) {
    blob[bit / 8] = static_cast<char>(blob[bit / 8] ^ (1 << (bit % 8)));
    ASSERT_LT(imufit_load_blob(bytes, blob.size(), &loaded), 0) << "bit " << bit;
    ASSERT_LT(imufit_load_blob_f(bytes, blob.size(), &loaded_f), 0) << "bit " << bit;
    blob[bit / 8] = static_cast<char>(blob[bit / 8] ^ (1 << (bit % 8)));
  }
  EXPECT_EQ(std::memcmp(&loaded, &untouched, sizeof loaded), 0) << "a refused blob changed the calibration";
  EXPECT_EQ(imufit_load_blob(bytes, blob.size() - 1, &loaded), IMUFIT_ERROR_SIZE);
}

// Values at the edges of float: subnormal, rounding ties, beyond float's range (refused).
TEST(CRuntimeTest, FloatBuildConvertsEveryBlobNumberAsACompilerDoes) {
  Calibration calibration = Unit("mems_truth.yaml");
  const double edges[] = {1e-40,
                          -1e-45,
                          7e-46,
                          1.5e-45,
                          3.4028234e38,
                          1.0000000596046448,
                          1.0000001788139343,
                          -2.5000001192092896,
                          1e-300,
                          5e-324,
                          0.1,
                          -0.0};
  for (size_t i = 0; i < std::size(edges); ++i) calibration.model.gyro[12 * 4 + i] = edges[i];
  const std::string blob = CalibrationBlob(calibration, "");
  imufit_calibration_f loaded{};
  ASSERT_EQ(imufit_load_blob_f(reinterpret_cast<const unsigned char*>(blob.data()), blob.size(), &loaded),
            IMUFIT_OK);
  for (size_t i = 0; i < std::size(edges); ++i) {
    const float expected = static_cast<float>(edges[i]);
    const float got = loaded.gyro[12 + i / 4][i % 4];
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << edges[i] << ": " << got << " vs " << expected;
  }
  calibration.model.gyro[12 * 4] = 3.5e38;  // rounds beyond the largest float
  const std::string too_large = CalibrationBlob(calibration, "");
  EXPECT_EQ(
      imufit_load_blob_f(reinterpret_cast<const unsigned char*>(too_large.data()), too_large.size(), &loaded),
      IMUFIT_ERROR_VALUE);
}

// The golden header (fixtures/golden/export/mems_truth.h) compiled into this test: its initializer
// gives the calibration's doubles bit for bit, and in the float build what the blob gives.
TEST(CRuntimeTest, ExportedHeaderReadsBackBitForBit) {
  const std::string path = std::string(IMUFIT_FIXTURES_DIR) + "/mems_truth.yaml";
  const Calibration calibration = ReadCalibration(path);
  const imufit_calibration header = IMUFIT_UNIT_INITIALIZER;
  ExpectCoefficientsOf(calibration, header);
  const std::string sha = Sha256OfFile(path);
  for (int i = 0; i < IMUFIT_SHA256_BYTES; ++i) {
    EXPECT_EQ(header.sha256[i], std::stoi(sha.substr(2 * i, 2), nullptr, 16)) << "byte " << i;
  }
  const imufit_calibration_f header_f = IMUFIT_UNIT_INITIALIZER_F;
  ExpectCoefficientsOf(calibration, header_f);
}

}  // namespace
}  // namespace imufit
