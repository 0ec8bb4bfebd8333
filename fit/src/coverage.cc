#include "coverage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

namespace imufit::internal {

std::string FormatTemperatures(const std::vector<double>& temps_c) {
  std::string text;
  char value[32];
  for (size_t i = 0; i < temps_c.size() && i < 8; ++i) {
    std::snprintf(value, sizeof value, "%.1f", temps_c[i]);
    text += (i ? ", " : "") + std::string(value);
  }
  if (temps_c.size() > 8) text += ", ...";
  return text + " degC";
}

namespace {

constexpr char kAxis[] = "xyz";
// Gravity counts as "along" an axis when its component there is at least half of g.
constexpr double kAlongFraction = 0.5;

const char* Plural(size_t n, const char* one, const char* many) { return n == 1 ? one : many; }

// Distinct temperatures of the windows that satisfy `pick`.
std::vector<double> TempsWhere(const std::vector<FitWindow>& windows, const FitOptions& options,
                               const std::function<bool(const FitWindow&)>& pick) {
  std::vector<double> temps;
  for (const FitWindow& w : windows) {
    if (pick(w)) temps.push_back(w.window->temp_c);
  }
  return DistinctTemperatures(temps, options.distinct_temp_c);
}

// "no positions with gravity along -y" or "gravity along -y at only 2 distinct temperatures
// (25.0, 55.0 degC), the gyro temperature order 3 needs 4"; empty when enough.
std::string Shortfall(const std::vector<double>& temps, size_t needed, const std::string& what,
                      const std::string& none, const char* sensor, int order) {
  if (temps.empty()) return none;
  if (temps.size() >= needed) return "";
  char text[256];
  std::snprintf(text, sizeof text, "%s at only %zu distinct %s (%s), the %s temperature order %d needs %zu",
                what.c_str(), temps.size(), Plural(temps.size(), "temperature", "temperatures"),
                FormatTemperatures(temps).c_str(), sensor, order, needed);
  return text;
}

std::string OffDiagonalColumn(int column) {
  std::string names;
  for (int row = 0; row < 3; ++row) {
    if (row == column) continue;
    names += (names.empty() ? "" : ", ") + std::string(1, kAxis[row]) + kAxis[column];
  }
  return names;
}

// The finding when the run has fewer distinct temperatures than the highest order fitted needs
// (empty when enough).
std::string TemperatureShortfall(const std::vector<double>& all_temps, size_t most_needed) {
  if (all_temps.size() >= most_needed) return "";
  const char* model = most_needed == 4 ? "a cubic" : most_needed == 3 ? "a quadratic" : "a linear";
  char text[320];
  std::snprintf(text, sizeof text,
                "too few temperatures for %s temperature model: %zu distinct %s (%s), at least %zu needed "
                "(add soaks at other temperatures, or fit a lower order with --gyro-temp-order / "
                "--accel-temp-order)",
                model, all_temps.size(), Plural(all_temps.size(), "temperature", "temperatures"),
                FormatTemperatures(all_temps).c_str(), most_needed);
  return text;
}

// Gyro column j of K = diag(S) inv(M): scale j and the misalignments of column j. A rate segment or
// a turn (whose truth is its mean rate) about any axis with a component along j determines it.
// The finding when the run does not (empty when it does, or when they are not fitted).
std::string GyroRotationShortfall(const std::vector<FitWindow>& windows, const FitOptions& options, int j,
                                  size_t needed) {
  const std::string axis(1, kAxis[j]);
  const auto spinning = TempsWhere(windows, options, [&](const FitWindow& w) {
    return std::abs(w.truth.omega_radps(j)) >= options.min_excitation_rate_radps;
  });
  const std::string rate =
      Shortfall(spinning, needed, "rate segments or turns about " + axis,
                "no rate segments or turns about the " + axis + " axis (the table must spin with " + axis +
                    " up or down, or a rate or turn segment must give an axis along " + axis + ")",
                "gyro", options.gyro_temp_order);
  if (rate.empty() || !options.Fits(true, kScaleCoefficient + j)) return "";
  return "gyro scale " + axis + " and misalignment " + OffDiagonalColumn(j) + " are undetermined: " + rate;
}

// Gravity along +j and -j separates H's column j (gyro) and K's column j (accel) from the bias.
// Only windows whose specific force is known count (not turns or rates about a tilted axis). Adds
// the findings of column j to `findings`; true when the accelerometer's is among them.
bool GravityShortfalls(const std::vector<FitWindow>& windows, double gravity_mps2, const FitOptions& options,
                       int j, size_t gyro_needed, size_t accel_needed, std::vector<std::string>* findings) {
  const std::string axis(1, kAxis[j]);
  const double along = kAlongFraction * gravity_mps2;
  const auto up = TempsWhere(windows, options,
                             [&](const FitWindow& w) { return w.accel_known && w.truth.a_mps2(j) >= along; });
  const auto down = TempsWhere(
      windows, options, [&](const FitWindow& w) { return w.accel_known && w.truth.a_mps2(j) <= -along; });
  bool accel_missing = false;
  for (const auto& [sensor, order, needed] :
       {std::tuple<const char*, int, size_t>{"gyro", options.gyro_temp_order, gyro_needed},
        std::tuple<const char*, int, size_t>{"accel", options.accel_temp_order, accel_needed}}) {
    const bool gyro = std::string(sensor) == "gyro";
    if (!options.Fits(gyro, gyro ? kGSensitivityCoefficient : kScaleCoefficient)) continue;
    std::string missing = Shortfall(up, needed, "gravity along +" + axis,
                                    "no positions with gravity along +" + axis, sensor, order);
    const std::string missing_down = Shortfall(down, needed, "gravity along -" + axis,
                                               "no positions with gravity along -" + axis, sensor, order);
    if (!missing_down.empty()) missing += (missing.empty() ? "" : "; ") + missing_down;
    if (missing.empty()) continue;
    if (gyro) {
      findings->push_back("gyro g_sensitivity column " + axis + " (x" + axis + ", y" + axis + ", z" + axis +
                          ") is undetermined: " + missing +
                          " (or leave g-sensitivity out with --no-g-sensitivity)");
    } else {
      accel_missing = true;
      findings->push_back("accel scale " + axis + " and misalignment " + OffDiagonalColumn(j) +
                          " are undetermined: " + missing);
    }
  }
  return accel_missing;
}

}  // namespace

std::vector<std::string> CheckCoverage(const std::vector<FitWindow>& windows, double gravity_mps2,
                                       const FitOptions& options) {
  std::vector<std::string> findings;
  if (windows.empty()) {
    findings.push_back(
        "the run has no usable windows: no samples with a segment id of the plan that last longer "
        "than the trim time");
    return findings;
  }
  const std::vector<double> all_temps = TempsWhere(windows, options, [](const FitWindow&) { return true; });
  // A held sensor (SensorFit::kNone) needs no temperatures; its groups are not checked.
  const bool gyro_held = options.gyro_fit == SensorFit::kNone;
  const bool accel_held = options.accel_fit == SensorFit::kNone;
  const size_t most_needed = static_cast<size_t>(std::max(gyro_held ? 0 : options.gyro_temp_order,
                                                          accel_held ? 0 : options.accel_temp_order)) +
                             1;
  const std::string temps = TemperatureShortfall(all_temps, most_needed);
  if (!temps.empty()) findings.push_back(temps);
  // With too few temperatures overall, ask each group only to be present at all.
  const size_t gyro_needed = !temps.empty() ? 1 : static_cast<size_t>(options.gyro_temp_order) + 1;
  const size_t accel_needed = !temps.empty() ? 1 : static_cast<size_t>(options.accel_temp_order) + 1;
  bool gyro_rotation_missing = false;
  bool accel_missing = false;
  for (int j = 0; j < 3; ++j) {
    const std::string rotation = GyroRotationShortfall(windows, options, j, gyro_needed);
    if (!rotation.empty()) {
      gyro_rotation_missing = true;
      findings.push_back(rotation);
    }
    if (GravityShortfalls(windows, gravity_mps2, options, j, gyro_needed, accel_needed, &findings)) {
      accel_missing = true;
    }
  }
  // A run without rotation (a static-only run) still determines the accelerometer and the gyro
  // bias: say how to fit just those when the whole model was asked for.
  const bool whole_model = options.gyro_fit == SensorFit::kAll && options.accel_fit == SensorFit::kAll;
  if (whole_model && gyro_rotation_missing && !accel_missing) {
    findings.push_back(
        "to calibrate only what this run determines, fit a subset: --fit accel (the gyro held), or --fit "
        "gyro-bias,accel (the gyro scale and misalignment held; give their values with --prior CAL.yaml)");
  }
  return findings;
}

}  // namespace imufit::internal
