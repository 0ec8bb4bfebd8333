// The envelope, the loss measurement and the printed numbers shared by the exporters.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "export_internal.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"

namespace imufit::export_internal {
namespace {

constexpr int kTemperatureSteps = 25;  // 26 temperatures, ends included
constexpr double kLevels[] = {-1.0, -0.5, 0.0, 0.5, 1.0};

// Every combination of the levels on three axes, times `scale`.
std::vector<Eigen::Vector3d> Corners(double scale) {
  std::vector<Eigen::Vector3d> points;
  for (double x : kLevels) {
    for (double y : kLevels) {
      for (double z : kLevels) points.emplace_back(scale * x, scale * y, scale * z);
    }
  }
  return points;
}

}  // namespace

Envelope EnvelopeOf(const Calibration& calibration, const ExportOptions& options) {
  // ExportOptions::Validate() has checked the full scale and g (positive, finite).
  const ExportOptions defaults;
  const auto given = [](bool is_default, const char* flag) {
    return std::string(flag) + (is_default ? ", the default" : "");
  };
  Envelope envelope;
  envelope.temp_low_c = calibration.fit_temp_range_c[0];
  envelope.temp_high_c = calibration.fit_temp_range_c[1];
  envelope.temp_source = "the calibration's fitted range; --envelope-temp-c";
  if (!options.envelope_temp_c.empty()) {
    if (options.envelope_temp_c.size() != 2)
      throw InputError("--envelope-temp-c", "the envelope's temperatures are two numbers MIN,MAX");
    const double low = options.envelope_temp_c[0], high = options.envelope_temp_c[1];
    if (!(low <= high) || !(low >= envelope.temp_low_c) || !(high <= envelope.temp_high_c)) {
      throw InputError("--envelope-temp-c",
                       FormatDouble(low) + "," + FormatDouble(high) +
                           " degC is not a range MIN,MAX inside the calibration's fitted range [" +
                           FormatDouble(envelope.temp_low_c) + ", " + FormatDouble(envelope.temp_high_c) +
                           "] degC");
    }
    envelope.temp_low_c = low;
    envelope.temp_high_c = high;
    envelope.temp_source = "--envelope-temp-c";
  }
  envelope.full_scale_radps = options.full_scale_dps / kRadToDeg;
  envelope.rate_source = given(options.full_scale_dps == defaults.full_scale_dps, "--full-scale-dps");
  envelope.max_specific_force_mps2 = options.max_g * kStandardGravityMps2;
  envelope.force_source = given(options.max_g == defaults.max_g, "--max-g");
  return envelope;
}

std::string DescribeEnvelope(const Envelope& envelope) {
  char text[400];
  std::snprintf(
      text, sizeof text,
      "[%g, %g] degC (%s) x rate up to %g deg/s (%s) x specific force up to %g g (%s), on each axis",
      envelope.temp_low_c, envelope.temp_high_c, envelope.temp_source.c_str(),
      envelope.full_scale_radps * kRadToDeg, envelope.rate_source.c_str(),
      envelope.max_specific_force_mps2 / kStandardGravityMps2, envelope.force_source.c_str());
  return text;
}

ExportLoss MeasureLoss(const SensorModel& model, const Envelope& envelope,
                       const ConsumerCorrection& consumer) {
  const std::vector<Eigen::Vector3d> rates = Corners(envelope.full_scale_radps);
  const std::vector<Eigen::Vector3d> forces = Corners(envelope.max_specific_force_mps2);
  const int steps = envelope.temp_high_c > envelope.temp_low_c ? kTemperatureSteps : 0;
  ExportLoss loss;
  loss.measured = true;
  Eigen::Vector3d gyro_sum_sq = Eigen::Vector3d::Zero(), accel_sum_sq = Eigen::Vector3d::Zero();
  for (int step = 0; step <= steps; ++step) {
    const double temp_c = step == steps ? envelope.temp_high_c
                                        : envelope.temp_low_c + (envelope.temp_high_c - envelope.temp_low_c) *
                                                                    step / kTemperatureSteps;
    for (const Eigen::Vector3d& omega_true : rates) {
      for (const Eigen::Vector3d& a_true : forces) {
        Eigen::Vector3d gyro_raw, accel_raw, omega_hat, a_hat, omega_consumer, a_consumer;
        model.Forward(temp_c, omega_true, a_true, &gyro_raw, &accel_raw);
        model.Correct(temp_c, gyro_raw, accel_raw, &omega_hat, &a_hat);
        consumer(temp_c, gyro_raw, accel_raw, &omega_consumer, &a_consumer);
        const Eigen::Vector3d gyro_error_dps = (omega_consumer - omega_hat) * kRadToDeg;
        const Eigen::Vector3d accel_error_mg = (a_consumer - a_hat) / kStandardGravityMps2 * 1e3;
        loss.gyro_worst_dps = loss.gyro_worst_dps.cwiseMax(gyro_error_dps.cwiseAbs());
        loss.accel_worst_mg = loss.accel_worst_mg.cwiseMax(accel_error_mg.cwiseAbs());
        gyro_sum_sq += gyro_error_dps.cwiseAbs2();
        accel_sum_sq += accel_error_mg.cwiseAbs2();
        ++loss.points;
      }
    }
  }
  loss.gyro_rms_dps = (gyro_sum_sq / static_cast<double>(loss.points)).cwiseSqrt();
  loss.accel_rms_mg = (accel_sum_sq / static_cast<double>(loss.points)).cwiseSqrt();
  // A consumer whose correction is not finite somewhere in the envelope has an infinite loss.
  for (Eigen::Vector3d* v :
       {&loss.gyro_worst_dps, &loss.gyro_rms_dps, &loss.accel_worst_mg, &loss.accel_rms_mg}) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite((*v)(axis))) (*v)(axis) = HUGE_VAL;
    }
  }
  return loss;
}

std::string FloatText(double value, const std::string& name) {
  const float single = static_cast<float>(value);
  if (!std::isfinite(single)) {
    throw ExportError(name + " = " + FormatDouble(value) + " is not a finite float32");
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", static_cast<double>(single));
  return text;
}

float ReadFloat(const std::string& text) { return std::strtof(text.c_str(), nullptr); }

std::string DoubleText(double value, const std::string& name) {
  if (!std::isfinite(value))
    throw ExportError(name + " = " + FormatDouble(value) + " is not a finite number");
  return FormatDouble(value);
}

double ReadDouble(const std::string& text) { return std::strtod(text.c_str(), nullptr); }

std::string VectorText(const Eigen::Vector3d& v, const std::string& name, Eigen::Vector3d* read_back) {
  std::string text = "[";
  for (int i = 0; i < 3; ++i) {
    const std::string number = DoubleText(v(i), name);
    (*read_back)(i) = ReadDouble(number);
    text += (i ? ", " : "") + number;
  }
  return text + "]";
}

std::string MatrixText(const Eigen::Matrix3d& m, const std::string& name, const std::string& indent,
                       Eigen::Matrix3d* read_back) {
  const std::string row_start = indent.empty() ? "" : "\n" + indent + "  ";
  std::string text = "[";
  for (int row = 0; row < 3; ++row) {
    Eigen::Vector3d values;
    text += (row ? "," : "") + (row_start.empty() && row ? std::string(" ") : row_start) +
            VectorText(m.row(row).transpose(), name, &values);
    read_back->row(row) = values.transpose();
  }
  return text + (indent.empty() ? "" : "\n" + indent) + "]";
}

MachineDoc NumberDoc(double value, const std::string& name) {
  DoubleText(value, name);  // refuses a value that is not finite
  return MachineDoc::Number(value);
}

MachineDoc VectorDoc(const Eigen::Vector3d& v, const std::string& name, Eigen::Vector3d* read_back) {
  MachineDoc list = MachineDoc::List();
  for (int i = 0; i < 3; ++i) {
    list.Push(NumberDoc(v(i), name));
    (*read_back)(i) = ReadDouble(YamlNumberText(v(i)));
  }
  return list;
}

MachineDoc MatrixDoc(const Eigen::Matrix3d& m, const std::string& name, MachineDoc::Style rows,
                     Eigen::Matrix3d* read_back) {
  MachineDoc list = MachineDoc::List(rows);
  for (int row = 0; row < 3; ++row) {
    Eigen::Vector3d values;
    list.Push(VectorDoc(m.row(row).transpose(), name, &values));
    read_back->row(row) = values.transpose();
  }
  return list;
}

std::string Commented(const std::vector<std::string>& lines, const std::string& marker) {
  std::string text;
  for (const std::string& line : lines) text += marker + line + "\n";
  return text;
}

ExportResult MeasuredResult(const char* consumer, const Calibration& calibration, const Envelope& envelope,
                            const ConsumerCorrection& correction) {
  ExportResult result;
  result.consumer = consumer;
  result.envelope = DescribeEnvelope(envelope);
  result.loss = MeasureLoss(calibration.model, envelope, correction);
  return result;
}

std::string CommentSafe(std::string_view text) {
  std::string safe;
  for (const char c : text) {
    const bool printable = c >= 0x20 && c < 0x7f;
    if (c == '/' && !safe.empty() && safe.back() == '*') safe += ' ';
    safe += printable ? c : '?';
  }
  return safe;
}

Eigen::Vector4d Rebased(const double* c, double from_reference_c, double to_reference_c) {
  const Eigen::Matrix4d rebase = RebaseTemperaturePolynomial(TemperatureBasis{from_reference_c, 1.0},
                                                             TemperatureBasis{to_reference_c, 1.0});
  return rebase * Eigen::Vector4d(c[0], c[1], c[2], c[3]);
}

SensorCoefficients<double> GyroAt(const SensorModel& model, double temp_c) {
  return CoefficientsAt(model.gyro.data(), kGyroCoefficients, model.basis.Argument(temp_c));
}

SensorCoefficients<double> AccelAt(const SensorModel& model, double temp_c) {
  return CoefficientsAt(model.accel.data(), kAccelCoefficients, model.basis.Argument(temp_c));
}

double ClampToRange(const Calibration& calibration, double temp_c) {
  return std::clamp(temp_c, calibration.fit_temp_range_c[0], calibration.fit_temp_range_c[1]);
}

}  // namespace imufit::export_internal
