#include "imufit/factory/allan_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "imufit/io/noise_file.h"

namespace imufit {

PlotFigure AllanPlot(const std::vector<ColumnAnalysis>& results, const std::string& title, bool in_dph) {
  constexpr int kModelPoints = 120;
  std::vector<ColumnKind> kinds;
  for (const ColumnAnalysis& r : results) {
    if (std::find(kinds.begin(), kinds.end(), r.kind) == kinds.end()) kinds.push_back(r.kind);
  }
  PlotFigure figure;
  figure.title = title;
  figure.cols = static_cast<int>(kinds.size());
  figure.width_px = kinds.size() > 1 ? 1600 : 1100;
  figure.height_px = 760;
  for (ColumnKind kind : kinds) {
    const bool dph = in_dph && kind == ColumnKind::kGyro;
    const double scale = dph ? UnitsOf(ColumnKind::kGyro, kBiasInstability).engineer_per_si : 1.0;
    const AllanEstimator estimator = results.front().curve.estimator;
    Plot plot;
    plot.log_x = plot.log_y = true;
    plot.x_label = "averaging time tau, s";
    const std::string unit = dph ? "deg/h" : SiUnit(kind);
    plot.y_label = std::string(ToString(estimator)) + " (" + unit +
                   (estimator == AllanEstimator::kTdev ? " s" : "") + ")";
    plot.title = std::string(ToString(kind)) + " columns";
    plot.labels_at_bottom = true;
    // The IEEE 952 model is the Allan variance's: drawn over Allan-variance curves only.
    const bool draw_model = estimator == AllanEstimator::kOadev || estimator == AllanEstimator::kAdev ||
                            estimator == AllanEstimator::kTotdev;
    for (size_t c = 0; c < results.size(); ++c) {
      const ColumnAnalysis& r = results[c];
      if (r.kind != kind) continue;
      const int color = static_cast<int>(c);
      PlotSeries curve;
      curve.style = PlotSeries::Style::kErrorBars;
      curve.title = r.name;
      curve.color = PlotColor(color);
      curve.point_size = 0.7;
      for (const AllanPoint& p : r.curve.points) {
        if (!(p.dev > 0.0)) continue;  // a constant column has nothing to show on a log scale
        curve.x.push_back(p.tau_s);
        curve.y.push_back(p.dev * scale);
        curve.lo.push_back((std::isfinite(p.dev_lo) ? p.dev_lo : p.dev) * scale);
        curve.hi.push_back((std::isfinite(p.dev_hi) ? p.dev_hi : p.dev) * scale);
      }
      plot.series.push_back(curve);
      if (!r.fit.fitted || !draw_model || curve.x.empty()) continue;
      PlotSeries model;
      model.title = r.name + " model";
      model.color = curve.color;
      model.line_width = 2;
      std::array<PlotSeries, kNoiseTerms> terms;
      const double first = curve.x.front(), last = curve.x.back();
      for (int i = 0; i <= kModelPoints; ++i) {
        const double tau = first * std::pow(last / first, static_cast<double>(i) / kModelPoints);
        model.x.push_back(tau);
        model.y.push_back(r.fit.ModelDeviation(tau) * scale);
        for (int k = 0; k < kNoiseTerms; ++k) {
          terms[k].x.push_back(tau);
          terms[k].y.push_back(r.fit.TermDeviation(k, tau) * scale);
        }
      }
      plot.series.push_back(model);
      for (int k = 0; k < kNoiseTerms; ++k) {
        if (!(r.fit.variance[k] > 0.0)) continue;
        terms[k].color = curve.color;
        terms[k].dashed = true;
        terms[k].line_width = 1;
        plot.series.push_back(terms[k]);
      }
      PlotSeries readout;
      readout.style = PlotSeries::Style::kPoints;
      readout.color = curve.color;
      readout.point_type = 6;
      readout.point_size = 2.2;
      if (std::isfinite(r.fit.readout_random_walk)) {
        readout.x.push_back(1.0);
        readout.y.push_back(r.fit.readout_random_walk * scale);
      }
      if (std::isfinite(r.fit.readout_bias_instability)) {
        readout.x.push_back(r.fit.readout_bias_tau_s);
        readout.y.push_back(0.664 * r.fit.readout_bias_instability * scale);
      }
      if (std::isfinite(r.fit.readout_rate_random_walk)) {
        readout.x.push_back(3.0);
        readout.y.push_back(r.fit.readout_rate_random_walk * scale);
      }
      plot.series.push_back(readout);
      const NoiseTermUnits& n = UnitsOf(kind, kRandomWalk);
      const NoiseTermUnits& b = UnitsOf(kind, kBiasInstability);
      const bool engineer = *n.engineer_key != '\0';
      const auto term_text = [&](int k, const NoiseTermUnits& u) {
        if (!IsResolved(r.fit, k)) return std::string("not resolved");
        char text[96];
        std::snprintf(text, sizeof text, "%.3g %s", r.fit.value[k] * (engineer ? u.engineer_per_si : 1.0),
                      engineer ? u.engineer_unit : u.si_unit);
        return std::string(text);
      };
      plot.labels.push_back({r.name + ": " + (kind == ColumnKind::kAccel ? "VRW " : "ARW ") +
                             term_text(kRandomWalk, n) + ", bias instability " +
                             term_text(kBiasInstability, b)});
    }
    figure.panels.push_back(plot);
  }
  return figure;
}

}  // namespace imufit
