// imufit — the vocabulary of a noise analysis, shared by noise/ (which computes it) and io/ (which
// writes it): the kinds of column and the terms of the IEEE Std 952 model (noise/noise_model.h),
// in the order both use.
#ifndef IMUFIT_BASE_NOISE_TERMS_H_
#define IMUFIT_BASE_NOISE_TERMS_H_

#include <string>
#include <string_view>

#include "imufit/base/enum_names.h"

namespace imufit {

// What a column of rates is: it says which engineer units a writer uses (io/noise_file.h).
enum class ColumnKind { kGyro, kAccel, kOther };

// "gyro", "accel", "other".
inline const char* ToString(ColumnKind kind) {
  switch (kind) {
    case ColumnKind::kGyro:
      return "gyro";
    case ColumnKind::kAccel:
      return "accel";
    case ColumnKind::kOther:
      break;
  }
  return "other";
}

// The SI unit of a column of this kind: "rad/s", "m/s^2", "unit".
inline const char* SiUnit(ColumnKind kind) {
  switch (kind) {
    case ColumnKind::kGyro:
      return "rad/s";
    case ColumnKind::kAccel:
      return "m/s^2";
    case ColumnKind::kOther:
      break;
  }
  return "unit";
}

// The terms Q, N, B, K, R of the model (its equation and units: noise/noise_model.h).
enum NoiseTerm {
  kQuantization = 0,
  kRandomWalk = 1,
  kBiasInstability = 2,
  kRateRandomWalk = 3,
  kRateRamp = 4
};
inline constexpr int kNoiseTerms = 5;

inline constexpr EnumName<int> kNoiseTermNames[kNoiseTerms] = {{kQuantization, "quantization"},
                                                               {kRandomWalk, "random_walk"},
                                                               {kBiasInstability, "bias_instability"},
                                                               {kRateRandomWalk, "rate_random_walk"},
                                                               {kRateRamp, "rate_ramp"}};

// "quantization", "random_walk", "bias_instability", "rate_random_walk", "rate_ramp"; "?" else.
inline const char* NoiseTermName(int term) { return NameOf(kNoiseTermNames, term); }
// Parses a name; false (and `term` untouched) for anything else.
inline bool ParseNoiseTerm(std::string_view name, int* term) { return ValueOf(kNoiseTermNames, name, term); }
// Every name, comma-separated.
inline std::string NoiseTermNames() { return AllNames(kNoiseTermNames); }

}  // namespace imufit

#endif  // IMUFIT_BASE_NOISE_TERMS_H_
