// The options of a unit's fit and of how its run is read, shared by imufit fit, batch and report:
// one definition, so that a lot is fitted exactly as `imufit fit` would fit each unit. The options
// themselves are the tables' (FitRunOptionTable(), pipeline/fit_run.h).
#include "commands.h"
#include "imufit/io/error.h"

namespace imufit {

void AddRunReadingOptions(CliCommand command, RunReadingArguments* args) {
  args->windows.Add(command, WindowOptionTable());
  AddTempOption(command, &args->input);
  AddSegmentationOptions(command, &args->input);
  args->noise_stretch.Add(command, NoiseStretchOptionTable());
}

void AddFitRunOptions(CliCommand command, FitRunArguments* args, const std::set<std::string>& except) {
  args->options.Add(command, FitRunOptionTable(), except);
}

FitRunOptions FitRunArguments::Resolve() const {
  FitRunOptions options;
  this->options.Apply(&options);
  if (this->options.Given("temp_c")) {
    // One temperature determines no temperature dependence: order 0, unless the user asked otherwise.
    const bool explicit_order =
        this->options.Given("gyro_temp_order") || this->options.Given("accel_temp_order");
    if (explicit_order && (options.fit.gyro_temp_order != 0 || options.fit.accel_temp_order != 0)) {
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
