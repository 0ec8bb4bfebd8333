// The options of a unit's fit and of how its run is read, shared by imufit fit, batch and report:
// one definition, so that a lot is fitted exactly as `imufit fit` would fit each unit.
#include "commands.h"
#include "imufit/io/calibration.h"
#include "imufit/io/error.h"
#include "imufit/io/units.h"

namespace imufit {

void AddRunReadingOptions(CLI::App* command, RunReadingArguments* args) {
  WindowOptions& w = args->windows;
  command->add_option("--trim", w.trim_s, "seconds dropped at the start of each segment occurrence")
      ->capture_default_str();
  command
      ->add_option("--window-temp-span", w.max_temp_span_c,
                   "a window closes when its temperature has moved this far, degC")
      ->capture_default_str();
  command
      ->add_option("--window-max-duration", w.max_duration_s,
                   "a window closes after this many seconds (0: never)")
      ->capture_default_str();
  command->add_option("--window-min-samples", w.min_samples, "windows with fewer samples are dropped")
      ->capture_default_str();
  command
      ->add_option("--max-turn-gap", w.max_turn_gap_s,
                   "a turn whose time stamps have a longer gap (lost samples in a row), s, is dropped: "
                   "integrating across it would bias the angle")
      ->capture_default_str();
  command
      ->add_option("--gyro-full-scale", w.gyro_full_scale_raw,
                   "the gyro's full scale, raw units (e.g. 32767 counts): windows with a sample at or beyond it "
                   "are left out (0: found only where an output sits at the run's extreme)")
      ->capture_default_str();
  command
      ->add_option("--accel-full-scale", w.accel_full_scale_raw,
                   "the accelerometer's full scale, raw units, as --gyro-full-scale")
      ->capture_default_str();
  AddTempOption(command, &args->input);
  AddSegmentationOptions(command, &args->input);
}

void AddFitRunOptions(CLI::App* command, FitRunArguments* args) {
  FitOptions& f = args->fit;
  args->gyro_order_option =
      command
          ->add_option("--gyro-temp-order", f.gyro_temp_order,
                       "order of the gyro temperature polynomials, 0..3 (0 with --temp-c)")
          ->capture_default_str()
          ->check(CLI::Range(0, 3));
  args->accel_order_option =
      command
          ->add_option("--accel-temp-order", f.accel_temp_order,
                       "order of the accel temperature polynomials, 0..3 (0 with --temp-c)")
          ->capture_default_str()
          ->check(CLI::Range(0, 3));
  command->add_flag("--no-g-sensitivity", args->no_g_sensitivity, "hold the gyro g-sensitivity at zero");
  command
      ->add_option("--fit", args->groups,
                   "what to fit, comma-separated: all, gyro, gyro-bias, accel, accel-bias; the rest is held "
                   "(--fit accel calibrates the accelerometer from a static-only run)")
      ->capture_default_str();
  command->add_option("--prior", args->prior,
                      "calibration YAML whose values the held groups keep (default: scale 1, the rest 0)");
  command->add_option("--loss", args->loss, "robust loss: none, huber, cauchy")->capture_default_str();
  command
      ->add_option("--loss-scale", f.loss_scale,
                   "where the robust loss acts, in robust spreads of the windows' normalised residuals")
      ->capture_default_str();
  command
      ->add_option("--gyro-bias-stability-dph", args->gyro_bias_stability_dph,
                   "the unit's in-run gyro bias stability, deg/h 1-sigma (bias instability and random walk "
                   "over --bias-correlation): added to the reported uncertainty")
      ->capture_default_str();
  command
      ->add_option(
          "--accel-bias-stability-ug", args->accel_bias_stability_ug,
          "the unit's in-run accel bias stability, micro-g 1-sigma: added to the reported uncertainty")
      ->capture_default_str();
  command
      ->add_option("--bias-correlation", f.bias_correlation_s,
                   "seconds over which the wandering bias is taken as constant")
      ->capture_default_str();
  command->add_option("--max-iterations", f.max_iterations, "solver iterations at most, per pass")
      ->capture_default_str();
  AddRunReadingOptions(command, &args->run);
}

FitRunOptions FitRunArguments::Resolve() const {
  FitRunOptions options;
  options.fit = fit;
  options.windows = run.windows;
  options.input = run.input.Get();
  std::string error;
  if (!ParseRobustLoss(loss, &options.fit.loss, &error)) throw InputError("--loss", error);
  options.fit.fit_g_sensitivity = !no_g_sensitivity;
  if (!ParseFitGroups(groups, &options.fit, &error)) throw InputError("--fit", error);
  if (!prior.empty()) options.fit.held = ReadCalibration(prior).model;
  options.fit.gyro_bias_stability_radps = RadpsFromDph(gyro_bias_stability_dph);
  options.fit.accel_bias_stability_mps2 = Mps2FromUg(accel_bias_stability_ug);
  if (run.input.HasTemp()) {
    // One temperature determines no temperature dependence: order 0, unless the user asked otherwise.
    const bool explicit_order = gyro_order_option->count() > 0 || accel_order_option->count() > 0;
    if (explicit_order && (fit.gyro_temp_order != 0 || fit.accel_temp_order != 0)) {
      throw InputError(
          "--temp-c",
          "one temperature for the whole run determines only order-0 temperature "
          "polynomials: use --gyro-temp-order 0 --accel-temp-order 0 (the default with --temp-c)");
    }
    options.fit.gyro_temp_order = 0;
    options.fit.accel_temp_order = 0;
  }
  return options;
}

}  // namespace imufit
