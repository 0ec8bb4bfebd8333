// imufit — the key figures: every figure a unit is judged on, written once (kKeyFigures). The
// limits reader takes its quantities from it, acceptance its figures, titles and readings, the
// certificate its measured figures, the plan prediction its groups and the results store the
// names it keeps; docs/factory.md (key figures) and docs/spec.md (limits quantities) list it, and
// io_test checks those lists against it.
//
// A figure is named `quantity.axis` ("gyro_bias_dps.x", "gyro_g_sensitivity_dpsg.xy") or, without
// axes, `quantity` ("gyro_residual_rms_dps"); the unit is in the quantity's name. It is read from
//   kCoefficient   a coefficient group's 25 degC value in engineering units (the polynomial through
//                  the model's basis; conversions in report/engineering_units.h, g0 = 9.80665 m/s^2):
//                    gyro bias      deg/s        V_g / S_g * 180/pi
//                    accel bias     mg           V_a / S_a / g0 * 1e3
//                    gyro scale     raw/(deg/s)  S_g * pi/180
//                    accel scale    raw/g        S_a * g0
//                    misalignment   mrad         M_ij * 1e3
//                    g-sensitivity  deg/s/g      H_ij / S_g,i * 180/pi * g0
//                  with its 1-sigma from the calibration's `sigma` tree; `path` is the group,
//                  "gyro.bias" (coefficient path "gyro.bias.x"), axes in kCoefficientNames order;
//   kScaleError    the scale figure of group `path` relative to the limits file's nominal scale:
//                  (S / nominal - 1) x per_unit (1e6: ppm, 1e2: %); a limits quantity only;
//   kNoise         the gyro noise term `noise_term` (base/noise_terms.h) of each gyro axis: the ARW
//                  in deg/sqrt(h), the bias instability in deg/h, from the calibration's `noise:`
//                  block (key `path` of columns.gyro_AXIS) or what the certificate measured;
//   kFitRecord     the calibration's `fit:` record (`record`, in the figure's unit; "not run"
//                  values are negative and give no figure); `path` names the figure's source;
//   kCertificate   measured by the certificate on the run's windows (its per-segment table);
//   kFitRange      the calibration's fitted temperature range (a `covers:` criterion).
//
// io holds it, not factory: the limits reader (io) needs the quantities, and plan, factory and the
// store all link io; it needs the fit record's type (io) and the model's layout, which base may not.
#ifndef IMUFIT_IO_KEY_FIGURES_H_
#define IMUFIT_IO_KEY_FIGURES_H_

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "imufit/base/noise_terms.h"
#include "imufit/io/fit_record.h"
#include "imufit/io/units.h"

namespace imufit {

enum class FigureSource { kCoefficient, kScaleError, kNoise, kFitRecord, kCertificate, kFitRange };

// How a limits criterion on a quantity is judged (io/limits.h).
enum class LimitKind {
  kCoefficient,  // a 25 degC coefficient value per axis: |value| (or its 1-sigma) < max_abs
  kFigure,       // one number without axes (residual RMS): value < max_abs
  kCoverage,     // fit_temp_range_c must cover [lo, hi]
};

struct KeyFigure {
  const char* name;   // the quantity, its unit in the name
  const char* title;  // in words, for a reader: "Gyro bias"
  const char* unit;   // for tables: "deg/s", "ppm", ...
  const char* axes;   // space-separated axis names, "" for a figure without axes
  bool pair_axes;     // two-letter axes read "X from Y" (FigureTitle)
  FigureSource source;
  // kCoefficient, kScaleError: the coefficient group ("gyro.bias"); kNoise: the noise block's key;
  // kFitRecord, kCertificate: the figure's coefficient path ("fit.gyro_residual_rms"); kFitRange:
  // the calibration's key.
  const char* path;
  double per_unit = 1.0;  // kScaleError: 1e6 (ppm) or 1e2 (%) per unit of relative error
  int noise_term = -1;    // kNoise: kRandomWalk (ARW) or kBiasInstability
  std::optional<double> (*record)(const FitRecord&) = nullptr;  // kFitRecord: the value, in `unit`
  bool in_limits = true;  // a limits file may name it (a scale factor is judged by its scale error)
};

namespace key_figures_internal {

constexpr KeyFigure Coefficient(const char* name, const char* title, const char* unit, const char* axes,
                                bool pair_axes, const char* group, bool in_limits = true) {
  KeyFigure figure{name, title, unit, axes, pair_axes, FigureSource::kCoefficient, group};
  figure.in_limits = in_limits;
  return figure;
}
constexpr KeyFigure ScaleError(const char* name, const char* title, const char* unit, const char* group,
                               double per_unit) {
  KeyFigure figure{name, title, unit, "x y z", false, FigureSource::kScaleError, group};
  figure.per_unit = per_unit;
  return figure;
}
constexpr KeyFigure Noise(const char* name, const char* title, const char* unit, const char* key, int term) {
  KeyFigure figure{name, title, unit, "x y z", false, FigureSource::kNoise, key};
  figure.noise_term = term;
  return figure;
}
constexpr KeyFigure Record(const char* name, const char* title, const char* unit, const char* path,
                           std::optional<double> (*record)(const FitRecord&)) {
  KeyFigure figure{name, title, unit, "", false, FigureSource::kFitRecord, path};
  figure.record = record;
  return figure;
}
constexpr KeyFigure Other(const char* name, const char* title, const char* unit, FigureSource source,
                          const char* path) {
  return KeyFigure{name, title, unit, "", false, source, path};
}
// A record's optional value through `convert`.
template <typename Value>
std::optional<double> Converted(const std::optional<Value>& value, double (*convert)(double)) {
  if (!value) return std::nullopt;
  return convert(static_cast<double>(*value));
}
inline double Unchanged(double value) { return value; }

}  // namespace key_figures_internal

// In the order KeyFigures() lists a calibration's figures (lot_summary.csv's columns follow it);
// the quantities a limits file may name are those with `in_limits`.
inline constexpr KeyFigure kKeyFigures[] = {
    key_figures_internal::Coefficient("gyro_bias_dps", "Gyro bias", "deg/s", "x y z", false, "gyro.bias"),
    key_figures_internal::Coefficient("accel_bias_mg", "Accel bias", "mg", "x y z", false, "accel.bias"),
    key_figures_internal::Coefficient("gyro_scale_per_dps", "Gyro scale factor", "raw/(deg/s)", "x y z",
                                      false, "gyro.scale", false),
    key_figures_internal::Coefficient("accel_scale_per_g", "Accel scale factor", "raw/g", "x y z", false,
                                      "accel.scale", false),
    key_figures_internal::ScaleError("gyro_scale_error_ppm", "Gyro scale-factor error", "ppm", "gyro.scale",
                                     1e6),
    key_figures_internal::ScaleError("gyro_scale_error_pct", "Gyro scale-factor error", "%", "gyro.scale",
                                     1e2),
    key_figures_internal::ScaleError("accel_scale_error_ppm", "Accel scale-factor error", "ppm",
                                     "accel.scale", 1e6),
    key_figures_internal::ScaleError("accel_scale_error_pct", "Accel scale-factor error", "%", "accel.scale",
                                     1e2),
    key_figures_internal::Coefficient("gyro_misalignment_mrad", "Gyro misalignment", "mrad",
                                      "xy xz yx yz zx zy", true, "gyro.misalignment"),
    key_figures_internal::Coefficient("accel_misalignment_mrad", "Accel misalignment", "mrad",
                                      "xy xz yx yz zx zy", true, "accel.misalignment"),
    key_figures_internal::Coefficient("gyro_g_sensitivity_dpsg", "Gyro g-sensitivity", "deg/s/g",
                                      "xx xy xz yx yy yz zx zy zz", true, "gyro.g_sensitivity"),
    key_figures_internal::Noise("gyro_arw_deg_per_sqrt_hr", "Gyro angle random walk", "deg/sqrt(h)",
                                "arw_deg_per_sqrt_hr", kRandomWalk),
    key_figures_internal::Noise("gyro_bias_instability_dph", "Gyro bias instability", "deg/h",
                                "bias_instability_deg_per_hr", kBiasInstability),
    key_figures_internal::Record(
        "gyro_residual_rms_dps", "Gyro residual RMS", "deg/s", "fit.gyro_residual_rms",
        [](const FitRecord& r) {
          return key_figures_internal::Converted(r.gyro_residual_rms_radps, DpsFromRadps);
        }),
    // Plan segments without a usable window in the run: {quantity: coverage, max_abs: 1} passes when
    // every segment of the plan was measured.
    key_figures_internal::Record(
        "coverage", "Plan segments without a window", "segments missing", "fit.missing_segments",
        [](const FitRecord& r) {
          return key_figures_internal::Converted(r.missing_segments, key_figures_internal::Unchanged);
        }),
    key_figures_internal::Record(
        "accel_residual_rms_mg", "Accel residual RMS", "mg", "fit.accel_residual_rms",
        [](const FitRecord& r) {
          return key_figures_internal::Converted(r.accel_residual_rms_mps2, MgFromMps2);
        }),
    // The largest error of any window after correction, at any temperature of the run: measured by
    // the certificate (its per-segment table), not in the calibration.
    key_figures_internal::Other("gyro_residual_max_dps", "Gyro largest window error", "deg/s",
                                FigureSource::kCertificate, "certificate.gyro_residual_max"),
    key_figures_internal::Other("accel_residual_max_mg", "Accel largest window error", "mg",
                                FigureSource::kCertificate, "certificate.accel_residual_max"),
    key_figures_internal::Other("fit_temp_range_c", "Fitted temperature range", "degC",
                                FigureSource::kFitRange, "fit_temp_range_c"),
};

// The entry of quantity `quantity` ("gyro_bias_dps"), or of the figure `name` with its axis
// ("gyro_bias_dps.x"); nullptr for a name the table does not know.
inline const KeyFigure* FindKeyFigure(std::string_view name) {
  const std::string_view quantity = name.substr(0, name.find('.'));
  for (const KeyFigure& figure : kKeyFigures) {
    if (quantity == figure.name) return &figure;
  }
  return nullptr;
}

// How a limits criterion on `figure` is judged.
inline LimitKind LimitKindOf(const KeyFigure& figure) {
  switch (figure.source) {
    case FigureSource::kCoefficient:
    case FigureSource::kScaleError:
    case FigureSource::kNoise:
      return LimitKind::kCoefficient;
    case FigureSource::kFitRecord:
    case FigureSource::kCertificate:
      return LimitKind::kFigure;
    case FigureSource::kFitRange:
      break;
  }
  return LimitKind::kCoverage;
}

// Whether `figure` is the gyro's (its name starts "gyro_").
inline bool IsGyroFigure(const KeyFigure& figure) {
  return std::string_view(figure.name).rfind("gyro_", 0) == 0;
}

// Whether the figure is a coefficient's value that varies with temperature in the model (a
// statistic over a temperature range can be taken of it).
inline bool HasTemperatureCurve(const KeyFigure& figure) {
  return figure.source == FigureSource::kCoefficient || figure.source == FigureSource::kScaleError;
}

// The entry's axes, in order ({} for a figure without axes).
inline std::vector<std::string> KeyFigureAxes(const KeyFigure& figure) {
  std::vector<std::string> axes;
  for (std::string_view rest = figure.axes; !rest.empty();) {
    const size_t end = rest.find(' ');
    if (end != 0) axes.emplace_back(rest.substr(0, end));
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
  }
  return axes;
}

}  // namespace imufit

#endif  // IMUFIT_IO_KEY_FIGURES_H_
