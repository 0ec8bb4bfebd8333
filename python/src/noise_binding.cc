// imufit Python module: Allan deviation and the IEEE 952 noise terms (noise/), on numpy arrays,
// the same steps as `imufit allan` takes for one column: RatesToPhase, AveragingFactors,
// ComputeAllan, and FitNoiseModel on the overlapping Allan deviation.
#include <cmath>
#include <string>
#include <type_traits>

#include "binding.h"
#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/noise/allan.h"
#include "imufit/noise/column_analysis.h"
#include "imufit/noise/noise_model.h"
#include "keyword_options.h"

namespace imufit::python {
namespace {

// The rates of `y`, shape (N,), as a vector with room for the phase's extra point.
std::vector<double> Rates(const std::string& where, const py::object& y) {
  const DoubleArray array = DoubleArray::ensure(y);
  if (!array) throw py::error_already_set();
  if (array.ndim() != 1) ThrowBadArgument(where, "y must have shape (N,)");
  std::vector<double> rates;
  rates.reserve(array.shape(0) + 1);
  rates.assign(array.data(), array.data() + array.shape(0));
  for (size_t i = 0; i < rates.size(); ++i) {
    if (!std::isfinite(rates[i])) ThrowBadArgument(where, "y[" + std::to_string(i) + "] is not finite");
  }
  return rates;
}

// "octave", "decade", "all", "per-decade:K", "1,10,100" or a sequence of taus in seconds.
TauSpec Taus(const std::string& where, const py::object& taus) {
  TauSpec spec;
  if (py::isinstance<py::str>(taus)) {
    if (const std::string problem = ParseTauSpec(taus.cast<std::string>(), &spec); !problem.empty()) {
      ThrowBadArgument(where, "taus: " + problem);
    }
    return spec;
  }
  spec.kind = TauSpec::Kind::kList;
  try {
    spec.taus_s = taus.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    ThrowBadArgument(where,
                     "taus must be 'octave', 'decade', 'all', 'per-decade:K' or a sequence of taus in s");
  }
  return spec;
}

// The Allan computation of `imufit allan` for one column.
AllanResult Allan(const std::string& where, std::vector<double> rates, double tau0_s, const TauSpec& spec,
                  const AllanOptions& options) {
  if (const std::string problem = options.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  if (!(tau0_s > 0.0) || !std::isfinite(tau0_s)) ThrowBadArgument(where, "tau0_s must be a positive number");
  const int64_t n = static_cast<int64_t>(rates.size());
  if (n < 2) ThrowBadArgument(where, "y needs at least two samples");
  std::vector<int64_t> factors;
  if (const std::string problem = AveragingFactors(spec, options.estimator, n, tau0_s, &factors);
      !problem.empty()) {
    ThrowBadArgument(where, problem);
  }
  py::gil_scoped_release release;
  const double mean = RatesToPhase(&rates, options.threads);
  AllanResult result = ComputeAllan(rates, tau0_s, factors, options);
  result.mean = mean;
  return result;
}

// The getter of one field of every AllanPoint as an array (int64 for whole numbers, else float64).
template <typename T>
auto PointArray(T AllanPoint::*field) {
  using Element = std::conditional_t<std::is_integral_v<T>, int64_t, double>;
  return [field](const AllanResult& result) {
    py::array_t<Element> array(static_cast<py::ssize_t>(result.points.size()));
    for (size_t i = 0; i < result.points.size(); ++i) array.mutable_data()[i] = result.points[i].*field;
    return array;
  };
}

py::dict PerTerm(const std::array<double, kNoiseTerms>& values) {
  py::dict d;
  for (int k = 0; k < kNoiseTerms; ++k) d[NoiseTermName(k)] = values[k];
  return d;
}

NoiseFitSummary NoiseTerms(const py::object& data, const py::object& tau0_s, const py::object& taus,
                           double min_clusters, const py::object& terms) {
  const std::string where = "imufit.noise_terms";
  NoiseFitOptions options;
  options.min_clusters = min_clusters;
  if (!terms.is_none()) {
    options.enabled.fill(false);
    for (const py::handle& term : terms) {
      const std::string name = py::str(term);
      int k = 0;
      if (!ParseNoiseTerm(name, &k)) {
        ThrowBadArgument(where, "term \"" + name + "\" is not one of: " + NoiseTermNames());
      }
      options.enabled[k] = true;
    }
  }
  if (const std::string problem = options.Validate(); !problem.empty()) ThrowBadArgument(where, problem);
  if (py::isinstance<AllanResult>(data)) {
    const AllanResult& allan = data.cast<const AllanResult&>();
    if (allan.estimator != AllanEstimator::kAdev && allan.estimator != AllanEstimator::kOadev &&
        allan.estimator != AllanEstimator::kTotdev) {
      ThrowBadArgument(where,
                       std::string("the noise model is the Allan variance's: give an adev, oadev or totdev "
                                   "result, not ") +
                           ToString(allan.estimator));
    }
    py::gil_scoped_release release;
    return FitNoiseModel(allan.points, allan.n_samples, options);
  }
  if (tau0_s.is_none()) ThrowBadArgument(where, "tau0_s is needed with an array of rates");
  AllanOptions allan_options;  // oadev, as `imufit allan` fits it
  const AllanResult allan =
      Allan(where, Rates(where, data), tau0_s.cast<double>(), Taus(where, taus), allan_options);
  py::gil_scoped_release release;
  return FitNoiseModel(allan.points, allan.n_samples, options);
}

// imufit.allan(): the Allan computation of `imufit allan` for one column, options by name.
AllanResult AllanOfRates(const py::object& y, double tau0_s, const std::string& estimator,
                         const py::object& taus, double confidence, const std::string& edf_noise,
                         int threads) {
  const std::string where = "imufit.allan";
  AllanOptions options;
  py::dict keywords;  // read, and refused, as AllanOptionTable() says
  keywords["estimator"] = estimator;
  keywords["confidence"] = confidence;
  keywords["edf_noise"] = edf_noise;
  keywords["threads"] = threads;
  ApplyKeywords(AllanOptionTable(), where, keywords, &options);
  return Allan(where, Rates(where, y), tau0_s, Taus(where, taus), options);
}

// The points of an AllanResult as arrays, one property per field of AllanPoint.
void BindAllanResult(py::module_& m) {
  py::class_<AllanResult>(
      m, "AllanResult",
      "An Allan-family deviation at several taus, with confidence intervals (NIST SP 1065).")
      .def_property_readonly("estimator",
                             [](const AllanResult& r) { return std::string(ToString(r.estimator)); })
      .def_readonly("tau0_s", &AllanResult::tau0_s, "sample interval, s")
      .def_readonly("n_samples", &AllanResult::n_samples)
      .def_readonly("mean", &AllanResult::mean, "the mean of y that was removed, units of y")
      .def_property_readonly("m", PointArray(&AllanPoint::m), "averaging factors, tau / tau0")
      .def_property_readonly("tau_s", PointArray(&AllanPoint::tau_s), "averaging times, s")
      .def_property_readonly("terms", PointArray(&AllanPoint::terms),
                             "number of terms of the estimator at each tau")
      .def_property_readonly("dev", PointArray(&AllanPoint::dev),
                             "the deviation, units of y (tdev: units of y times s)")
      .def_property_readonly("dev_lo", PointArray(&AllanPoint::dev_lo),
                             "lower bound of the confidence interval (nan when no edf)")
      .def_property_readonly("dev_hi", PointArray(&AllanPoint::dev_hi),
                             "upper bound of the confidence interval (nan when no edf)")
      .def_property_readonly("edf", PointArray(&AllanPoint::edf), "equivalent degrees of freedom")
      .def_property_readonly("alpha", PointArray(&AllanPoint::alpha), "noise exponent used for the edf")
      .def("__len__", [](const AllanResult& r) { return r.points.size(); })
      .def("__repr__", [](const AllanResult& r) {
        return "<imufit.AllanResult " + std::string(ToString(r.estimator)) + ", " +
               std::to_string(r.points.size()) + " taus, " + std::to_string(r.n_samples) + " samples at " +
               FormatDouble(r.tau0_s) + " s>";
      });
}

// The IEEE 952 terms of a fit, read-only, SI.
void BindNoiseTerms(py::module_& m) {
  py::class_<NoiseFitSummary>(
      m, "NoiseTerms",
      "The IEEE Std 952 noise model fitted to an Allan variance: sigma^2(tau) = 3 Q^2/tau^2 "
      "+ N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2, SI units of the rate y.")
      .def_readonly("fitted", &NoiseFitSummary::fitted, "False: too few usable points (see message)")
      .def_readonly("message", &NoiseFitSummary::message)
      .def_readonly("points_used", &NoiseFitSummary::points_used)
      .def_readonly("reduced_chi_square", &NoiseFitSummary::reduced_chi_square)
      .def_property_readonly(
          "value", [](const NoiseFitSummary& s) { return PerTerm(s.value); },
          "{quantization, random_walk, bias_instability, rate_random_walk, rate_ramp}: Q, N, B, K, R")
      .def_property_readonly(
          "sigma", [](const NoiseFitSummary& s) { return PerTerm(s.sigma); }, "1-sigma of each value")
      .def_property_readonly("variance", [](const NoiseFitSummary& s) { return PerTerm(s.variance); })
      .def_property_readonly("variance_sigma",
                             [](const NoiseFitSummary& s) { return PerTerm(s.variance_sigma); })
      .def_property_readonly("free",
                             [](const NoiseFitSummary& s) {
                               py::dict d;
                               for (int k = 0; k < kNoiseTerms; ++k)
                                 d[NoiseTermName(k)] = static_cast<bool>(s.free[k]);
                               return d;
                             })
      .def_property_readonly(
          "arw", [](const NoiseFitSummary& s) { return s.value[kRandomWalk]; },
          "angle (velocity) random walk N: rad/sqrt(s) for a gyro in rad/s (x 180/pi x 60 = deg/sqrt(h))")
      .def_property_readonly("arw_sigma", [](const NoiseFitSummary& s) { return s.sigma[kRandomWalk]; })
      .def_property_readonly(
          "bias_instability", [](const NoiseFitSummary& s) { return s.value[kBiasInstability]; },
          "bias instability B: rad/s for a gyro (x 180/pi x 3600 = deg/h)")
      .def_property_readonly("bias_instability_sigma",
                             [](const NoiseFitSummary& s) { return s.sigma[kBiasInstability]; })
      .def_property_readonly(
          "rrw", [](const NoiseFitSummary& s) { return s.value[kRateRandomWalk]; },
          "rate random walk K: rad/s/sqrt(s) for a gyro (x 180/pi x 3600 x 60 = deg/h/sqrt(h))")
      .def_property_readonly("rrw_sigma", [](const NoiseFitSummary& s) { return s.sigma[kRateRandomWalk]; })
      .def_property_readonly(
          "readouts",
          [](const NoiseFitSummary& s) {
            py::dict d;
            d["random_walk"] = s.readout_random_walk;
            d["bias_instability"] = s.readout_bias_instability;
            d["bias_tau_s"] = s.readout_bias_tau_s;
            d["rate_random_walk"] = s.readout_rate_random_walk;
            d["random_walk_sigma"] = s.readout_random_walk_sigma;
            d["random_walk_taus_s"] =
                py::make_tuple(s.readout_random_walk_tau_min_s, s.readout_random_walk_tau_max_s);
            d["bias_interval"] = py::make_tuple(s.readout_bias_lower, s.readout_bias_upper);
            d["bias_resolved"] = s.readout_bias_resolved;
            d["rate_random_walk_sigma"] = s.readout_rate_random_walk_sigma;
            d["rate_random_walk_taus_s"] =
                py::make_tuple(s.readout_rate_random_walk_tau_min_s, s.readout_rate_random_walk_tau_max_s);
            d["skipped_tau_s"] = s.skipped_tau_s;
            return d;
          },
          "IEEE 952's classic read-outs from the curve: N along the -1/2 segment and K along the +1/2 "
          "segment (with their taus), B = min / 0.664 with its 95 % interval and whether the minimum is "
          "resolved (nan: no such region); the tau left out for too few intervals")
      .def_readonly("describes_curve", &NoiseFitSummary::describes_curve,
                    "False when the reduced chi-square exceeds the misfit threshold: quote the read-outs")
      .def_readonly("filter_detected", &NoiseFitSummary::filter_detected,
                    "an output filter bends the short taus (left out of the fit)")
      .def_readonly("filtered_points", &NoiseFitSummary::filtered_points)
      .def_readonly("sample_lag1", &NoiseFitSummary::sample_lag1)
      .def_property_readonly(
          "fit_taus_s",
          [](const NoiseFitSummary& s) { return py::make_tuple(s.fit_tau_min_s, s.fit_tau_max_s); },
          "the taus the fit used (s)")
      .def_property_readonly(
          "term_taus_s",
          [](const NoiseFitSummary& s) {
            py::dict d;
            for (int k = 0; k < kNoiseTerms; ++k)
              d[NoiseTermName(k)] = py::make_tuple(s.term_tau_min_s[k], s.term_tau_max_s[k]);
            return d;
          },
          "per term, the used taus where it carries a quarter of the model or more (nan: nowhere)")
      .def(
          "quote",
          [](const NoiseFitSummary& s, const std::string& term) {
            int k = 0;
            if (!ParseNoiseTerm(term, &k))
              ThrowBadArgument("imufit.NoiseTerms.quote", "no term \"" + term + "\"");
            const QuotedFigure q = QuoteTerm(s, k);
            py::dict d;
            d["value"] = q.value;
            d["sigma"] = q.sigma;
            d["interval"] = py::make_tuple(q.lower, q.upper);
            d["at_most"] = q.bound();
            d["from"] = QuoteSourceText(q);
            return d;
          },
          py::arg("term"), "The figure to quote for a term and where it comes from (docs/allan.md).")
      .def(
          "model_deviation",
          [](const NoiseFitSummary& s, const py::object& tau_s) {
            return py::vectorize([&s](double tau) { return s.ModelDeviation(tau); })(tau_s);
          },
          py::arg("tau_s"), "The fitted Allan deviation at tau_s (s; a number or an array).")
      .def(
          "term_deviation",
          [](const NoiseFitSummary& s, const std::string& term, const py::object& tau_s) {
            int k = 0;
            if (!ParseNoiseTerm(term, &k)) {
              ThrowBadArgument("imufit.NoiseTerms.term_deviation", "no term \"" + term + "\"");
            }
            return py::vectorize([&s, k](double tau) { return s.TermDeviation(k, tau); })(tau_s);
          },
          py::arg("term"), py::arg("tau_s"), "One term's share of the fitted Allan deviation at tau_s.")
      .def("__repr__", [](const NoiseFitSummary& s) {
        if (!s.fitted) return "<imufit.NoiseTerms not fitted: " + s.message + ">";
        return "<imufit.NoiseTerms N=" + FormatDouble(s.value[kRandomWalk]) +
               " B=" + FormatDouble(s.value[kBiasInstability]) +
               " K=" + FormatDouble(s.value[kRateRandomWalk]) + ">";
      });
}

}  // namespace

void BindNoise(py::module_& m) {
  BindAllanResult(m);
  // The defaults are AllanOptions' and NoiseFitOptions' (their option tables).
  const AllanOptions allan_defaults;
  m.def(
      "allan", &AllanOfRates, py::arg("y"), py::arg("tau0_s"),
      py::arg("estimator") = std::string(ToString(allan_defaults.estimator)), py::arg("taus") = "octave",
      py::arg("confidence") = allan_defaults.confidence,
      py::arg("edf_noise") = std::string(ToString(allan_defaults.edf_noise)),
      py::arg("threads") = allan_defaults.threads,
      "Allan deviation (or a relative: adev, oadev, mdev, tdev, hdev, ohdev, totdev) of rates y (shape (N,), "
      "e.g. rad/s) sampled every tau0_s seconds, at taus 'octave', 'decade', 'all', 'per-decade:K' or a "
      "sequence of taus in s, with confidence intervals. What `imufit allan` writes for one column.");

  m.def(
      "allan_options", [] { return DescribeKeywords(AllanOptionTable()); },
      "{name: (default, description)} of the options imufit.allan() takes by name (`imufit allan`'s).");

  BindNoiseTerms(m);
  m.def(
      "noise_terms", &NoiseTerms, py::arg("data"), py::arg("tau0_s") = py::none(), py::arg("taus") = "octave",
      py::arg("min_clusters") = NoiseFitOptions().min_clusters, py::arg("terms") = py::none(),
      "The IEEE 952 noise terms (quantization, ARW, bias instability, RRW, ramp) with 1-sigma, fitted to the "
      "overlapping Allan deviation of rates `data` (shape (N,), every tau0_s seconds, at `taus`) or to an "
      "AllanResult (adev, oadev or totdev). `terms` limits the fit to the named terms.");
  m.def(
      "noise_terms_options", [] { return DescribeKeywords(NoiseFitOptionTable()); },
      "{name: (default, description)} of the noise fit's options (min_clusters is noise_terms()'s).");
  m.def(
      "record_length",
      [](double random_walk, double bias_instability, double rate_random_walk, double tau0_s,
         double precision) {
        const std::string where = "imufit.record_length";
        if (!(tau0_s > 0.0)) ThrowBadArgument(where, "tau0_s must be positive");
        if (!(precision > 0.0 && precision < 1.0)) ThrowBadArgument(where, "precision must lie in (0, 1)");
        for (double figure : {random_walk, bias_instability, rate_random_walk}) {
          if (!(figure >= 0.0) || !std::isfinite(figure))
            ThrowBadArgument(where, "the figures must be >= 0 (SI)");
        }
        const RecordLength r =
            RecordLengthFor(random_walk, bias_instability, rate_random_walk, tau0_s, precision);
        py::dict d;
        d["random_walk_s"] = r.random_walk_s;
        d["bias_instability_s"] = r.bias_instability_s;
        d["bias_instability_tau_s"] = r.bias_instability_tau_s;
        d["rate_random_walk_s"] = r.rate_random_walk_s;
        d["rate_random_walk_tau_s"] = r.rate_random_walk_tau_s;
        return d;
      },
      py::arg("random_walk"), py::arg("bias_instability"), py::arg("rate_random_walk"), py::arg("tau0_s"),
      py::arg("precision") = 0.25,
      "How long a static log must be (s) to resolve each term to a relative 2-sigma interval `precision`, "
      "from a short log's figures or a data sheet's (SI: N in rad/sqrt(s), B in rad/s, K in rad/s/sqrt(s); 0 "
      "for a term the sensor lacks). docs/allan.md, \"How long to record\".");
}

}  // namespace imufit::python
