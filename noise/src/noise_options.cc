// AllanOptions and NoiseFitOptions: their option tables (base/option_table.h) and their checks.
// `imufit allan` and the Python functions allan() and noise_terms() take their options, defaults,
// help and validation messages from here.
#include "imufit/noise/allan.h"
#include "imufit/noise/noise_model.h"

namespace imufit {
namespace {

// The message for a name that is not one of `names`.
std::string NotOneOf(const std::string& text, const std::string& names) {
  return "\"" + text + "\" is not one of: " + names;
}

OptionTable<AllanOptions> MakeAllanOptionTable() {
  using O = AllanOptions;
  OptionTable<O> t;
  t.Text(
      "estimator", "--estimator,-e", "the deviation: " + AllanEstimatorNames(),
      [](const O& o) { return std::string(ToString(o.estimator)); },
      [](const std::string& text, O* o) {
        return ParseAllanEstimator(text, &o->estimator) ? "" : NotOneOf(text, AllanEstimatorNames());
      });
  t.Number("confidence", "--confidence",
           "two-sided confidence of the intervals dev_lo..dev_hi (the default is one sigma)", "",
           &O::confidence, Between(0.0, 1.0, /*min_open=*/true, /*max_open=*/true));
  t.Text(
      "edf_noise", "--edf-noise",
      "noise type for the confidence intervals' degrees of freedom: " + EdfNoiseNames() +
          " (auto: identified per tau from the lag-1 autocorrelation)",
      [](const O& o) { return std::string(ToString(o.edf_noise)); },
      [](const std::string& text, O* o) {
        return ParseEdfNoise(text, &o->edf_noise) ? "" : NotOneOf(text, EdfNoiseNames());
      });
  t.Number("threads", "--threads", "worker threads (0: all cores)", "", &O::threads, NonNegative())
      .fingerprint = Fingerprint::kNone;
  return t;
}

OptionTable<NoiseFitOptions> MakeNoiseFitOptionTable() {
  using O = NoiseFitOptions;
  OptionTable<O> t;
  t.Number("min_clusters", "--min-clusters",
           "the noise fit leaves out taus with fewer than this many intervals in the record", "",
           &O::min_clusters, AtLeast(2.0));
  t.Number("iterations", "", "reweighting iterations of the noise fit (weights from the previous model)", "",
           &O::iterations, AtLeast(1));
  return t;
}

}  // namespace

const OptionTable<AllanOptions>& AllanOptionTable() {
  static const OptionTable<AllanOptions> table = MakeAllanOptionTable();
  return table;
}

const OptionTable<NoiseFitOptions>& NoiseFitOptionTable() {
  static const OptionTable<NoiseFitOptions> table = MakeNoiseFitOptionTable();
  return table;
}

}  // namespace imufit
