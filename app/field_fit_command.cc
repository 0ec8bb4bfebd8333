// imufit fit --field (field_fit_command.h).
#include "field_fit_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>

#include "commands.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
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
    // Scales in significant digits: in counts (939.65 raw/(deg/s)) or in SI (0.017453 raw/(deg/s)
    // for a bag's or a ULog's rad/s), the sigma stays readable.
    std::printf("    gyro %c   bias %s deg/s   scale %s raw/(deg/s)\n", axes[i],
                text("%+.5f +- %.5f", Sensor::kGyro, kBiasCoefficient + i).c_str(),
                text("%.8g +- %.2g", Sensor::kGyro, kScaleCoefficient + i).c_str());
  }
  for (int i = 0; i < 3; ++i) {
    std::printf("    accel %c  bias %s mg      scale %s raw/g\n", axes[i],
                text("%+.4f +- %.4f", Sensor::kAccel, kBiasCoefficient + i).c_str(),
                text("%.8g +- %.2g", Sensor::kAccel, kScaleCoefficient + i).c_str());
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
      .Option("--topic", &args->topics.topic,
              "a ROS bag's sensor_msgs/Imu topic to read (default: the bag's only one; docs/field.md)")
      .Needs(field);
  command
      .Option("--temp-topic", &args->topics.temp_topic,
              "a ROS bag's sensor_msgs/Temperature topic, interpolated at the IMU stamps (default: the bag's "
              "only one, if it has one; without one, give --temp-c)")
      .Needs(field);
  command
      .Option("--session-temp-c", &args->session_temps_c,
              "several sessions without a temp_c column: each session's temperature, degC, in the order of "
              "--samples (given once per session, or as a list T1,T2,...)")
      .Delimiter(',')
      .Needs(field);
  command
      .Option("--instance", &args->instance,
              "a PX4 ULog's IMU instance: the multi_id of sensor_accel and sensor_gyro to read (default: the "
              "only one; docs/field.md)")
      .Needs(field);
  args->options.Add(command, FieldFitOptionTable());
  for (const auto& entry : FieldFitOptionTable().entries()) args->options.Find(entry.key).Needs(field);
}

void RefuseTableOptions(const FitRunArguments& run) {
  for (const auto& entry : FitRunOptionTable().entries()) {
    if (!entry.flag.empty() && run.options.Given(entry.key) && !AppliesToAFieldFit(entry.key)) {
      throw InputError(entry.flag.substr(0, entry.flag.find(',')),
                       "is an option of a table fit, not of --field");
    }
  }
}

// How each session is read: as `run` says, with its own --session-temp-c when given.
std::vector<SamplesInput> SessionInputs(const FieldFitArguments& args,
                                        const std::vector<std::string>& samples, const FitRunOptions& run) {
  std::vector<SamplesInput> inputs(samples.size(), WithUlogInstance(run.input, args.instance));
  if (args.session_temps_c.empty()) return inputs;
  if (run.input.temp_c) {
    throw InputError(
        "--session-temp-c",
        "and --temp-c both given: --temp-c is every session's temperature, --session-temp-c each one's");
  }
  if (args.session_temps_c.size() != samples.size()) {
    throw InputError("--session-temp-c", "gives " + std::to_string(args.session_temps_c.size()) +
                                             " temperatures for " + std::to_string(samples.size()) +
                                             " sessions (--samples): one per session, in order");
  }
  for (size_t s = 0; s < samples.size(); ++s) {
    const double temp_c = args.session_temps_c[s];
    if (!(temp_c >= kMinPlausibleTempC && temp_c <= kMaxPlausibleTempC)) {
      throw InputError("--session-temp-c", FormatDouble(temp_c) + " degC is not a plausible temperature");
    }
    inputs[s].temp_c = temp_c;
  }
  return inputs;
}

// Several sessions: what each contributed and how its biases compare with the joint fit; a warning
// when the curve in temperature absorbs a session's offset (nothing could be tested).
void PrintSessions(const FieldRunResult& result, bool quiet) {
  const FieldFitSummary& fit = result.fit;
  std::string untested;
  for (const FieldSessionShare& share : fit.sessions) {
    if (!share.gyro_bias.tested || !share.accel_bias.tested)
      untested += (untested.empty() ? "" : ", ") + share.name;
  }
  if (!untested.empty() && fit.status != FieldFitStatus::kInconsistent) {
    std::fprintf(
        stderr,
        "imufit: warning: the sessions' biases cannot be tested against each other (%s): the joint fit "
        "follows such a session's bias wholly (a curve in temperature with as many terms as sessions, "
        "each at one temperature, or a session of too few rests), so a bias that changed from one "
        "power-on to the next (turn-on repeatability) is taken for temperature unseen: record a further "
        "session, or the warm-up in one power-on (docs/field.md)\n",
        untested.c_str());
  }
  if (quiet && fit.status != FieldFitStatus::kInconsistent) return;
  FILE* out = fit.status == FieldFitStatus::kInconsistent ? stderr : stdout;
  std::fprintf(out,
               "  sessions (%zu): what each contributed, and its biases' offset from the joint fit (+- 1 "
               "sigma; chi-square for 3):\n",
               fit.sessions.size());
  const auto offset_text = [&](const FieldSessionOffset& o, Sensor sensor, double temp_c) {
    if (!o.tested) return std::string("untested (the curve absorbs it)");
    char text[160];
    double v[3];
    double e[3];
    for (int axis = 0; axis < 3; ++axis) {
      const double factor = EngineeringFactor(fit.model, sensor, kBiasCoefficient + axis, temp_c);
      v[axis] = factor * o.offset(axis);
      e[axis] = std::abs(factor) * o.sigma(axis);
    }
    std::snprintf(text, sizeof text, "%+.4g %+.4g %+.4g +- %.2g %.2g %.2g %s, chi-square %.3g%s", v[0], v[1],
                  v[2], e[0], e[1], e[2], EngineeringUnit(sensor, kBiasCoefficient), o.chi2,
                  o.beyond ? " (beyond chance)" : "");
    return std::string(text);
  };
  for (size_t s = 0; s < fit.sessions.size(); ++s) {
    const FieldSessionShare& share = fit.sessions[s];
    const double temp_c = 0.5 * (share.temp_range_c[0] + share.temp_range_c[1]);
    std::fprintf(out, "    %zu %s: %lld samples, %.1f .. %.1f degC, %d poses, %d turns\n", s + 1,
                 share.name.c_str(), share.samples, share.temp_range_c[0], share.temp_range_c[1], share.poses,
                 share.turns);
    std::fprintf(out, "        gyro  %s\n", offset_text(share.gyro_bias, Sensor::kGyro, temp_c).c_str());
    std::fprintf(out, "        accel %s\n", offset_text(share.accel_bias, Sensor::kAccel, temp_c).c_str());
  }
}

int RunFieldFit(const FieldFitArguments& args, const std::vector<std::string>& samples,
                const std::string& output, const std::string& serial, bool quiet, const FitRunOptions& run,
                const std::function<int(const FieldRunResult&)>& certify) {
  RefuseToOverwriteInputs(output, samples);
  const bool several = samples.size() > 1;
  if (several && !args.repeat.empty()) {
    throw InputError("--repeat",
                     "compares one session with another; several --samples are fitted jointly and each "
                     "session's biases checked against the joint fit (fit the sessions one by one to compare "
                     "two)");
  }
  FieldFitOptions options;
  args.options.Apply(&options);
  options.detection = run.input.segmentation;
  options.fit_g_sensitivity = run.fit.Fits(true, kGSensitivityCoefficient);
  if (const std::string problem = options.Validate(); !problem.empty())
    throw InputError("imufit fit --field", problem);
  const SamplesInput input = WithUlogInstance(run.input, args.instance);
  const FieldRunResult result =
      FieldFitSessionsRun(samples, SessionInputs(args, samples, run), options, SoftwareVersion(), serial,
                          run.allow_serial_mismatch, args.topics);
  const FieldFitSummary& fit = result.fit;
  // At order 0 the coefficients are constant in temperature: a unit that warmed during the
  // session is fitted at its mean, its drift taken for noise.
  constexpr double kConstantTempSpanC = 1.0;
  if (options.bias_temp_order == 0 && options.scale_temp_order == 0 &&
      fit.temp_range_c[1] - fit.temp_range_c[0] > kConstantTempSpanC) {
    std::fprintf(stderr,
                 "imufit: warning: the %s %.3g .. %.3g degC; at --bias-temp-order 0 a field "
                 "calibration is constant in temperature: let the unit warm up before the session, or fit "
                 "the warm-up (--bias-temp-order, docs/field.md)\n",
                 several ? "sessions span" : "session spans", fit.temp_range_c[0], fit.temp_range_c[1]);
  }
  for (const std::string& warning : result.serial_warnings)
    std::fprintf(stderr, "imufit: warning: %s\n", warning.c_str());
  const std::string name = several ? std::to_string(samples.size()) + " sessions" : samples.front();
  if (several && fit.status == FieldFitStatus::kInconsistent) PrintSessions(result, quiet);
  for (const std::string& note : result.read_notes) std::fprintf(stderr, "imufit: note: %s\n", note.c_str());
  if (!fit.IsSolutionUsable()) {
    std::fprintf(stderr, "imufit: %s: %s, nothing written\n", name.c_str(), fit.BriefReport().c_str());
    return 1;
  }
  if (!quiet) {
    if (result.format == LogFormat::kRosbag) {
      std::printf(
          "imufit fit --field: read the ROS bag's topic %s (sensor_msgs/Imu, SI units: raw units rad/s "
          "and m/s^2)%s%s\n",
          result.topic.c_str(), result.temp_topic.empty() ? "" : ", temperature from ",
          result.temp_topic.c_str());
    }
    if (run.input.temp_c) {
      std::printf("imufit fit --field: note: no %s, every sample at %g degC (--temp-c)\n",
                  result.format == LogFormat::kRosbag ? "temperature topic" : "temp_c column",
                  *run.input.temp_c);
    }
    std::printf("imufit fit --field: %s\n", fit.BriefReport().c_str());
    std::printf("  %s: %lld samples, %.1f .. %.1f degC; body frame: %s (docs/spec.md section 1)\n",
                several ? "sessions" : "session", result.samples_read, fit.temp_range_c[0],
                fit.temp_range_c[1], kBodyFrameAccelerometerXy);
    std::printf("  static gyro RMS %.5f deg/s over the poses\n", DpsFromRadps(fit.gyro_static_rms_radps));
    PrintFieldCoefficients(fit);
    const bool scaled = fit.noise_scale[0] > 1.0 || fit.noise_scale[1] > 1.0 || fit.noise_scale[2] > 1.0;
    std::printf("  note: the sigmas reflect %s; Earth's rotation (up to 0.004 deg/s) is not modelled\n",
                scaled ? "the session's scatter, beyond its white noise (tremor, drift)"
                       : "the session's white noise");
  }
  if (several) PrintSessions(result, quiet);
  if (!args.repeat.empty()) {
    RefuseToOverwriteInputs(output, {args.repeat});
    const FieldRunResult second = FieldFitRun(args.repeat, input, options, SoftwareVersion(), result.serial,
                                              run.allow_serial_mismatch, args.topics);
    if (!second.fit.IsSolutionUsable()) {
      std::fprintf(stderr, "imufit: %s (--repeat): %s, nothing written\n", args.repeat.c_str(),
                   second.fit.BriefReport().c_str());
      return 1;
    }
    if (!quiet) PrintRepeatability(args.repeat, fit, second.fit);
  }
  if (certify) return certify(result);
  WriteCalibration(output, *result.calibration);
  if (!quiet) std::printf("  wrote %s\n", output.c_str());
  return 0;
}

}  // namespace imufit
