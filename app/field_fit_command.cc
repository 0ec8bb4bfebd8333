// imufit fit --field (field_fit_command.h).
#include "field_fit_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>

#include "commands.h"
#include "imufit/io/error.h"
#include "imufit/io/units.h"
#include "imufit/pipeline/field_run.h"
#include "imufit/report/engineering_units.h"

namespace imufit {
namespace {

// The coefficients in familiar units with their 1-sigma (engineering_units.h).
void PrintFieldCoefficients(const FieldFitSummary& fit) {
  const auto text = [&](const char* format, Sensor sensor, int coefficient) {
    const EngineeringValue v =
        EngineeringCoefficient(fit.model, &fit.sigma, sensor, coefficient, kFigureTempC);
    char out[96];
    std::snprintf(out, sizeof out, format, v.value, std::abs(v.sigma));
    return std::string(out);
  };
  const char* axes = "xyz";
  std::printf("  coefficients (+- 1 sigma):\n");
  for (int i = 0; i < 3; ++i) {
    std::printf("    gyro %c   bias %s deg/s   scale %s raw/(deg/s)\n", axes[i],
                text("%+.5f +- %.5f", Sensor::kGyro, kBiasCoefficient + i).c_str(),
                text("%.5f +- %.5f", Sensor::kGyro, kScaleCoefficient + i).c_str());
  }
  for (int i = 0; i < 3; ++i) {
    std::printf("    accel %c  bias %s mg      scale %s raw/g\n", axes[i],
                text("%+.4f +- %.4f", Sensor::kAccel, kBiasCoefficient + i).c_str(),
                text("%.4f +- %.4f", Sensor::kAccel, kScaleCoefficient + i).c_str());
  }
  std::printf(
      "    misalignment, mrad:          gyro                      accel (xy, xz, yz: the body frame)\n");
  for (int m = 0; m < 6; ++m) {
    const int c = kMisalignmentCoefficient + m;
    std::printf("      %-2s  %s   %s\n", kCoefficientNames[c].axis,
                text("%+9.4f +- %.4f", Sensor::kGyro, c).c_str(),
                text("%+9.4f +- %.4f", Sensor::kAccel, c).c_str());
  }
  std::printf("    gyro g-sensitivity, deg/s/g:\n");
  for (int h = 0; h < 9; ++h) {
    const int c = kGSensitivityCoefficient + h;
    std::printf("      %-2s  %s%s", kCoefficientNames[c].axis,
                text("%+.5f +- %.5f", Sensor::kGyro, c).c_str(), h % 3 == 2 ? "\n" : "   ");
  }
}

// The second session against the first: each coefficient's difference in its familiar unit and in
// combined sigmas, those beyond FieldRepeatability::kFieldRepeatZ named, and the verdict.
void PrintRepeatability(const std::string& repeat, const FieldFitSummary& first,
                        const FieldFitSummary& second) {
  const FieldRepeatability r = CompareFieldFits(first, second);
  std::printf(
      "  repeatability against %s (%zu poses): %zu coefficients, difference / combined sigma RMS %.3g\n",
      repeat.c_str(), second.poses.size(), r.differences.size(), r.z_rms);
  for (const FieldCoefficientDifference& d : r.beyond) {
    const Sensor sensor = d.gyro ? Sensor::kGyro : Sensor::kAccel;
    const double factor = EngineeringFactor(first.model, sensor, d.coefficient, kReferenceTempC);
    std::printf("    differs: %s %s %s by %+.4g +- %.3g %s (%.1f sigma)\n", d.gyro ? "gyro" : "accel",
                kCoefficientNames[d.coefficient].group, kCoefficientNames[d.coefficient].axis,
                factor * d.difference, std::abs(factor) * d.combined_sigma,
                EngineeringUnit(sensor, d.coefficient), d.z);
  }
  std::printf("  %s\n", r.beyond.empty() && r.z_rms < 1.5
                            ? "the sessions agree within their sigmas: the procedure is repeatable"
                            : "the sessions differ beyond their sigmas: the procedure does not reproduce "
                              "the coefficients named (rests not still, turns too fast, the unit moved in "
                              "the hand)");
}

// `input` with the ULog instance `instance` (--instance, "" for none); throws InputError unless 0..255.
SamplesInput WithUlogInstance(SamplesInput input, const std::string& instance) {
  if (instance.empty()) return input;
  char* end = nullptr;
  const long id = std::strtol(instance.c_str(), &end, 10);
  if (*end != '\0' || id < 0 || id > 255)
    throw InputError("--instance", QuoteForMessage(instance) + " is not a ULog multi_id (0..255)");
  input.ulog_instance = static_cast<int>(id);
  return input;
}

}  // namespace

void AddFieldFitOptions(CliCommand command, FieldFitArguments* args) {
  const CliOption field = command.Flag(
      "--field", &args->field,
      "a session by hand, without a plan or a table: the unit rested in at least 9 arbitrary poses and "
      "was turned by hand between them (docs/field.md)");
  command
      .Option(
          "--repeat", &args->repeat,
          "a second session of the same unit by hand: fitted alike and compared, coefficient by coefficient, "
          "against the two sessions' combined sigma (is the procedure repeatable?); the file is the first's")
      .Needs(field);
  command
      .Option("--instance", &args->instance,
              "a PX4 ULog's IMU instance: the multi_id of sensor_accel and sensor_gyro to read (default: the "
              "only one; docs/field.md)")
      .Needs(field);
  args->options.Add(command, FieldFitOptionTable());
  for (const auto& entry : FieldFitOptionTable().entries()) args->options.Find(entry.key).Needs(field);
}

// The options of a table fit that also mean something to a session by hand: how the samples are
// read, the serial, the g-sensitivity, and how rests are told from motion.
bool AppliesToAFieldFit(const std::string& key) {
  static const char* const kKeys[] = {"temp_c",
                                      "time_unit",
                                      "delimiter",
                                      "decimal_comma",
                                      "column",
                                      "allow_serial_mismatch",
                                      "fit_g_sensitivity",
                                      "segment_window_s",
                                      "segment_noise_quantile",
                                      "segment_threshold_factor",
                                      "min_steady_s"};
  return std::find(std::begin(kKeys), std::end(kKeys), key) != std::end(kKeys);
}

void RefuseTableOptions(const FitRunArguments& run) {
  for (const auto& entry : FitRunOptionTable().entries()) {
    if (!entry.flag.empty() && run.options.Given(entry.key) && !AppliesToAFieldFit(entry.key)) {
      throw InputError(entry.flag.substr(0, entry.flag.find(',')),
                       "is an option of a table fit, not of --field");
    }
  }
}

int RunFieldFit(const FieldFitArguments& args, const std::string& samples, const std::string& output,
                const std::string& serial, bool quiet, const FitRunOptions& run) {
  RefuseToOverwriteInputs(output, {samples});
  FieldFitOptions options;
  args.options.Apply(&options);
  options.detection = run.input.segmentation;
  options.fit_g_sensitivity = run.fit.Fits(true, kGSensitivityCoefficient);
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit fit --field", problem);
  const SamplesInput input = WithUlogInstance(run.input, args.instance);
  const FieldRunResult result =
      FieldFitRun(samples, input, options, SoftwareVersion(), serial, run.allow_serial_mismatch);
  const FieldFitSummary& fit = result.fit;
  // At order 0 the coefficients are constant in temperature: a unit that warmed during the
  // session is fitted at its mean, its drift taken for noise.
  constexpr double kConstantTempSpanC = 1.0;
  if (options.bias_temp_order == 0 && options.scale_temp_order == 0 &&
      fit.temp_range_c[1] - fit.temp_range_c[0] > kConstantTempSpanC) {
    std::fprintf(stderr,
                 "imufit: warning: the session spans %.3g .. %.3g degC; at --bias-temp-order 0 a field "
                 "calibration is constant in temperature: let the unit warm up before the session, or fit "
                 "the warm-up (--bias-temp-order, docs/field.md)\n",
                 fit.temp_range_c[0], fit.temp_range_c[1]);
  }
  for (const std::string& warning : result.serial_warnings)
    std::fprintf(stderr, "imufit: warning: %s\n", warning.c_str());
  for (const std::string& note : result.read_notes) std::fprintf(stderr, "imufit: note: %s\n", note.c_str());
  if (!fit.IsSolutionUsable()) {
    std::fprintf(stderr, "imufit: %s: %s, nothing written\n", samples.c_str(), fit.BriefReport().c_str());
    return 1;
  }
  if (!quiet) {
    if (run.input.temp_c) {
      std::printf("imufit fit --field: note: no temp_c column, every sample at %g degC (--temp-c)\n",
                  *run.input.temp_c);
    }
    std::printf("imufit fit --field: %s\n", fit.BriefReport().c_str());
    std::printf("  session: %lld samples, %.1f .. %.1f degC; body frame: %s (docs/spec.md section 1)\n",
                result.samples_read, fit.temp_range_c[0], fit.temp_range_c[1], kBodyFrameAccelerometerXy);
    std::printf("  static gyro RMS %.5f deg/s over the poses\n", DpsFromRadps(fit.gyro_static_rms_radps));
    PrintFieldCoefficients(fit);
    const bool scaled = fit.noise_scale[0] > 1.0 || fit.noise_scale[1] > 1.0 || fit.noise_scale[2] > 1.0;
    std::printf("  note: the sigmas reflect %s; Earth's rotation (up to 0.004 deg/s) is not modelled\n",
                scaled ? "the session's scatter, beyond its white noise (tremor, drift)"
                       : "the session's white noise");
  }
  if (!args.repeat.empty()) {
    RefuseToOverwriteInputs(output, {args.repeat});
    const FieldRunResult second =
        FieldFitRun(args.repeat, input, options, SoftwareVersion(), result.serial, run.allow_serial_mismatch);
    if (!second.fit.IsSolutionUsable()) {
      std::fprintf(stderr, "imufit: %s (--repeat): %s, nothing written\n", args.repeat.c_str(),
                   second.fit.BriefReport().c_str());
      return 1;
    }
    if (!quiet) PrintRepeatability(args.repeat, fit, second.fit);
  }
  WriteCalibration(output, *result.calibration);
  if (!quiet) std::printf("  wrote %s\n", output.c_str());
  return 0;
}

}  // namespace imufit
