// AllanOptions and NoiseFitOptions: their option tables (base/option_table.h) and their checks.
// `imufit allan` and the Python functions allan() and noise_terms() take their options, defaults,
// help and validation messages from here.
#include <cmath>
#include <cstdlib>
#include <limits>

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

// "all", or "LO:HI" with either side empty when open.
std::string FitTausText(const NoiseFitOptions& o) {
  if (!(o.fit_tau_min_s > 0.0) && !std::isfinite(o.fit_tau_max_s)) return "all";
  return (o.fit_tau_min_s > 0.0 ? OptionNumberText(o.fit_tau_min_s) : "") + ":" +
         (std::isfinite(o.fit_tau_max_s) ? OptionNumberText(o.fit_tau_max_s) : "");
}

std::string ParseFitTaus(const std::string& text, NoiseFitOptions* o) {
  if (text == "all") {
    o->fit_tau_min_s = 0.0;
    o->fit_tau_max_s = std::numeric_limits<double>::infinity();
    return "";
  }
  const size_t colon = text.find(':');
  const auto number = [](const std::string& part, double empty, double* value) {
    if (part.empty()) {
      *value = empty;
      return true;
    }
    char* end = nullptr;
    *value = std::strtod(part.c_str(), &end);
    return end == part.c_str() + part.size() && std::isfinite(*value) && *value > 0.0;
  };
  double lo = 0.0, hi = 0.0;
  if (colon == std::string::npos || !number(text.substr(0, colon), 0.0, &lo) ||
      !number(text.substr(colon + 1), std::numeric_limits<double>::infinity(), &hi) || !(lo < hi)) {
    return "\"" + text + "\" is not LO:HI (taus in seconds, LO < HI, either may be empty) or all";
  }
  o->fit_tau_min_s = lo;
  o->fit_tau_max_s = hi;
  return "";
}

OptionTable<NoiseFitOptions> MakeNoiseFitOptionTable() {
  using O = NoiseFitOptions;
  OptionTable<O> t;
  t.Number("min_clusters", "--min-clusters",
           "the noise fit leaves out taus with fewer than this many intervals in the record", "",
           &O::min_clusters, AtLeast(2.0));
  t.Number("model_error", "--model-error",
           "relative model-error floor on each Allan variance point of the noise fit (no point counts for "
           "more than 2 / model_error^2 degrees of freedom; 0: off)",
           "", &O::model_error, Between(0.0, 1.0));
  t.Text(
      "fit_taus", "--fit-taus",
      "taus the noise fit uses, LO:HI in seconds (either may be empty; default all: the taus an output "
      "filter bends are detected and left out)",
      [](const O& o) { return FitTausText(o); },
      [](const std::string& text, O* o) { return ParseFitTaus(text, o); });
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
