// Tests of the lot page's numbers (part of factory_test): a figure's limit interval, capability
// (Ppk, moving-range Cpk), the LotSummary of a hand-made batch (unit labels, failed and outlying
// units, what a strip plot shows), and lots compared across a results store (LotHistory), with the
// page that draws them.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/factory/certificate.h"
#include "imufit/factory/certify.h"
#include "imufit/factory/lot_history.h"
#include "imufit/factory/lot_summary.h"
#include "imufit/factory/report.h"
#include "imufit/io/limits.h"
#include "imufit/io/units.h"
#include "imufit/report/plot.h"
#include "imufit/store/store.h"
#include "test_util.h"

namespace imufit {
namespace {

namespace fs = std::filesystem;

// Absolute tolerance of sums and ratios of a few numbers of order 1 recomputed by hand.
constexpr double kArithmeticAbsolute = 1e-12;

class LotTest : public testing::TempDirTest {
 protected:
  Limits WriteLimits(const std::string& text) const {
    return ReadLimits(Write("limits.yaml", "format: imufit-limits\nversion: 1\n" + text));
  }
};

TEST_F(LotTest, FigureLimitsAreTheTightestIntervalTheValueCriteriaAllow) {
  const Limits limits = WriteLimits(
      "nominal: {gyro_scale: 939.65, accel_scale: 208.838}\n"
      "criteria:\n"
      "  - {quantity: gyro_bias_dps, max_abs: 5}\n"
      "  - {quantity: gyro_bias_dps, max_abs: 2, axes: [x]}\n"
      "  - {quantity: gyro_bias_dps, statistic: sigma, max_abs: 0.001}\n"
      "  - {quantity: gyro_scale_error_ppm, max_abs: 20000}\n"
      "  - {quantity: gyro_scale_error_pct, max_abs: 1, axes: [z]}\n"
      "  - {quantity: accel_scale_error_pct, max_abs: 2}\n"
      "  - {quantity: gyro_residual_rms_dps, max_abs: 0.05}\n"
      "  - {quantity: fit_temp_range_c, covers: [-20, 60]}\n");
  const std::optional<LimitInterval> x = FigureLimits("gyro_bias_dps.x", limits);
  ASSERT_TRUE(x && x->lower && x->upper);
  EXPECT_EQ(*x->lower, -2.0);  // the axis-specific criterion is tighter; the sigma one bounds no value
  EXPECT_EQ(*x->upper, 2.0);
  EXPECT_TRUE(x->symmetric);
  EXPECT_EQ(*FigureLimits("gyro_bias_dps.y", limits)->upper, 5.0);
  // Scale: |S / nominal - 1| < 2 % (ppm), 1 % on z, around the nominal in raw per deg/s.
  const double nominal_per_dps = 939.65 / kRadToDeg;
  const std::optional<LimitInterval> sy = FigureLimits("gyro_scale_per_dps.y", limits);
  ASSERT_TRUE(sy && sy->lower && sy->upper);
  EXPECT_NEAR(*sy->lower, nominal_per_dps * 0.98, kArithmeticAbsolute);
  EXPECT_NEAR(*sy->upper, nominal_per_dps * 1.02, kArithmeticAbsolute);
  EXPECT_FALSE(sy->symmetric);
  EXPECT_NEAR(*FigureLimits("gyro_scale_per_dps.z", limits)->upper, nominal_per_dps * 1.01,
              kArithmeticAbsolute);
  EXPECT_NEAR(*FigureLimits("accel_scale_per_g.x", limits)->lower, 208.838 * kStandardGravityMps2 * 0.98,
              kArithmeticAbsolute);
  // A residual RMS: one-sided.
  const std::optional<LimitInterval> rms = FigureLimits("gyro_residual_rms_dps", limits);
  ASSERT_TRUE(rms);
  EXPECT_FALSE(rms->lower);
  EXPECT_EQ(*rms->upper, 0.05);
  EXPECT_FALSE(FigureLimits("accel_bias_mg.x", limits));
  EXPECT_FALSE(FigureLimits("gyro_g_sensitivity_dpsg.xx", limits));
}

TEST(LotCapability, PpkFromTheSpreadCpkFromTheMovingRange) {
  const std::vector<double> values = {1.0, 2.0, 3.0, 4.0, 5.0};
  const MeanSigma m = MeanAndSigma(values);
  EXPECT_EQ(m.count, 5);
  EXPECT_EQ(m.mean, 3.0);
  EXPECT_NEAR(m.sigma, std::sqrt(2.5), kArithmeticAbsolute);           // sum of squares 10 over n - 1 = 4
  EXPECT_NEAR(WithinSigma(values), 1.0 / 1.128, kArithmeticAbsolute);  // every moving range is 1
  const LimitInterval symmetric{-10.0, 10.0, true};
  EXPECT_NEAR(*Capability(m.mean, m.sigma, symmetric), 7.0 / (3.0 * std::sqrt(2.5)), kArithmeticAbsolute);
  LimitInterval lower_only;
  lower_only.lower = -10.0;
  EXPECT_NEAR(*Capability(m.mean, 1.0, lower_only), 13.0 / 3.0, kArithmeticAbsolute);
  EXPECT_FALSE(Capability(m.mean, 0.0, symmetric));        // no spread: no capability
  EXPECT_FALSE(Capability(m.mean, 1.0, LimitInterval()));  // no limits: none either
  EXPECT_EQ(MeanAndSigma({4.0}).sigma, 0.0);
  EXPECT_EQ(WithinSigma({4.0}), 0.0);
}

// Five units: unit-03 failed another criterion, unit-04 could not be read, unit-05 is outside the
// gyro bias limit and far from the others.
BatchResult FiveUnits() {
  BatchResult batch;
  const double bias[] = {0.10, 0.11, 0.09, 0.0, 0.50};
  for (int i = 0; i < 5; ++i) {
    UnitOutcome u;
    u.unit = "unit-0" + std::to_string(i + 1);
    u.serial = "SN" + std::to_string(i + 1);
    u.status = i == 3 ? UnitStatus::kError : UnitStatus::kFitted;
    if (i != 3) u.verdict.emplace().pass = i != 2 && i != 4;
    if (i != 3) {
      u.figures = {MakeFigure("gyro_bias_dps.x", "", "deg/s", bias[i], 0.001),
                   MakeFigure("accel_bias_mg.x", "", "mg", 10.0 + 0.1 * i, 0.01)};
    }
    batch.units.push_back(u);
  }
  batch.passed = 2;
  batch.failed = 2;
  batch.errors = 1;
  return batch;
}

TEST_F(LotTest, LotSummaryMarksFailedAndOutlyingUnitsAndChoosesWhatAStripPlotShows) {
  const Limits limits = WriteLimits(
      "name: bench limits\ncriteria:\n"
      "  - {quantity: gyro_bias_dps, max_abs: 0.3}\n"
      "  - {quantity: accel_bias_mg, max_abs: 1000}\n");
  const LotSummary s = MakeLotSummary("LOT-1", FiveUnits(), "imufit test", limits);
  EXPECT_EQ(s.limits_name, "bench limits");
  EXPECT_EQ(s.unit_prefix, "unit-");  // cut where a word ends, not inside the number
  ASSERT_EQ(s.rows.size(), 5u);
  EXPECT_EQ(s.rows[0].label, "01");
  EXPECT_EQ(s.rows[4].label, "05");
  EXPECT_DOUBLE_EQ(s.yield_pct, 40.0);
  ASSERT_EQ(s.figures.size(), 2u);

  const LotFigure& bias = s.figures[0];
  EXPECT_EQ(bias.name, "gyro_bias_dps.x");
  EXPECT_EQ(bias.row, (std::vector<int>{0, 1, 2, 4}));  // the unit that was not read leaves its row empty
  EXPECT_EQ(bias.failed, (std::vector<bool>{false, false, true, true}));
  EXPECT_EQ(bias.outside_limits, (std::vector<bool>{false, false, false, true}));
  const MeanSigma m = MeanAndSigma({0.10, 0.11, 0.09, 0.50});
  EXPECT_DOUBLE_EQ(bias.mean, m.mean);
  EXPECT_DOUBLE_EQ(bias.stdev, m.sigma);
  EXPECT_DOUBLE_EQ(bias.three_sigma[1], m.mean + 3.0 * m.sigma);
  EXPECT_DOUBLE_EQ(*bias.ppk, (0.3 - m.mean) / (3.0 * m.sigma));
  EXPECT_DOUBLE_EQ(*bias.cpk, (0.3 - m.mean) / (3.0 * WithinSigma({0.10, 0.11, 0.09, 0.50})));
  // The limits lie within the values' spread: both drawn, and the view holds them.
  EXPECT_TRUE(bias.view.lower_in_view && bias.view.upper_in_view);
  EXPECT_LE(bias.view.range[0], -0.3);
  EXPECT_GE(bias.view.range[1], 0.5);
  // unit-05 is an outlier (far by the spread and by its own sigma), listed with its serial.
  ASSERT_EQ(s.outliers.size(), 1u);
  EXPECT_EQ(s.outliers[0].unit, "unit-05");
  EXPECT_EQ(s.outliers[0].serial, "SN5");

  // +-1000 mg is far beyond 10.0 .. 10.4 mg: out of view, so the values are not squashed into a line.
  const LotFigure& accel = s.figures[1];
  EXPECT_FALSE(accel.view.lower_in_view || accel.view.upper_in_view);
  EXPECT_GT(accel.view.range[0], 9.0);
  EXPECT_LT(accel.view.range[1], 11.0);

  // The strip plot draws what the struct says: points at the units' rows, a filled square for the
  // unit outside its limit, an open one for the unit that failed elsewhere, a ring for the outlier,
  // the mean, 3 sigma and both limits.
  const std::vector<PlotFigure> plots = LotPlots(s);
  ASSERT_EQ(plots.size(), 2u);
  const Plot& strip = plots[0].panels.at(0);
  ASSERT_EQ(strip.series.size(), 4u);
  EXPECT_EQ(strip.series[0].x, (std::vector<double>{0, 1}));
  EXPECT_EQ(strip.series[1].x, (std::vector<double>{2}));
  EXPECT_EQ(strip.series[2].x, (std::vector<double>{4}));
  EXPECT_EQ(strip.series[3].x, (std::vector<double>{4}));
  EXPECT_EQ(strip.markers.size(), 5u);
  EXPECT_EQ(strip.x_tics.size(), 5u);
  EXPECT_EQ(strip.x_tics[4].label, "05");
  EXPECT_EQ(plots[1].panels.at(0).markers.size(), 3u);  // mean and 3 sigma; the limits off scale
  // No two labels of the strip's lines (limits, mean, 3 sigma) closer than a label's height.
  for (const PlotFigure& p : plots) {
    const Plot& panel = p.panels.at(0);
    for (size_t i = 0; i < panel.markers.size(); ++i) {
      for (size_t j = i + 1; j < panel.markers.size(); ++j) {
        const double a = panel.markers[i].label_at.value_or(panel.markers[i].value);
        const double b = panel.markers[j].label_at.value_or(panel.markers[j].value);
        EXPECT_GE(std::abs(a - b), MarkerLabelGap(panel, p.height_px) * (1.0 - 1e-9))
            << panel.markers[i].label << " / " << panel.markers[j].label;
      }
    }
  }
  EXPECT_NE(plots[1].panels.at(0).x_label.find("limit |value| < 1000 beyond this scale"), std::string::npos);
  // One side drawn, the other off scale: the caption names the side it does not draw, not the limit.
  LotSummary one_side = s;
  one_side.figures[1].view.lower_in_view = true;
  const std::vector<PlotFigure> one_side_plots = LotPlots(one_side);
  const Plot& lower_drawn = one_side_plots[1].panels.at(0);
  EXPECT_EQ(lower_drawn.markers.size(), 4u);
  EXPECT_NE(lower_drawn.x_label.find("upper limit 1000 above this scale"), std::string::npos)
      << lower_drawn.x_label;
  EXPECT_EQ(lower_drawn.x_label.find("beyond"), std::string::npos) << lower_drawn.x_label;
}

// Five units of which unit-03 failed on a figure that is not a main one (a misalignment's sigma):
// every key figure is in the summary and the CSV, with its sigma and U; the failing one is plotted.
TEST_F(LotTest, LotSummaryHidesNoFigureAndPlotsEveryFigureAUnitFailedOn) {
  BatchResult batch = FiveUnits();
  for (UnitOutcome& u : batch.units) {
    if (u.status != UnitStatus::kFitted) continue;
    u.calibrated_utc = "2026-11-2" + u.unit.substr(6) + "T06:00:00Z";
    u.figures.push_back(MakeFigure("accel_misalignment_mrad.xy", "", "mrad", 0.5, 0.02));
    u.figures.push_back(MakeFigure("accel_residual_rms_mg", "", "mg", 0.8, -1.0));
  }
  CriterionResult failed;
  failed.name = "sigma(accel_misalignment_mrad.xy)";
  batch.units[2].verdict->criteria.push_back(failed);
  batch.units[2].verdict->pass = false;
  batch.units[2].message = "sigma(accel_misalignment_mrad.xy) 0.02 > 0.01 mrad, badly";

  const Limits limits = WriteLimits("criteria:\n  - {quantity: gyro_bias_dps, max_abs: 0.3}\n");
  const LotSummary s = MakeLotSummary("LOT-1", batch, "imufit test", limits);
  EXPECT_EQ(s.figure_names,
            (std::vector<std::string>{"gyro_bias_dps.x", "accel_bias_mg.x", "accel_misalignment_mrad.xy",
                                      "accel_residual_rms_mg"}));
  ASSERT_EQ(s.figures.size(), 4u);
  EXPECT_TRUE(s.figures[0].plotted);  // a main figure
  EXPECT_TRUE(s.figures[1].plotted);  // a main figure
  EXPECT_TRUE(s.figures[2].plotted);  // unit-03 failed on it
  EXPECT_TRUE(s.figures[3].plotted);  // a main figure
  EXPECT_EQ(LotPlots(s).size(), 4u);
  BatchResult passing = batch;
  passing.units[2].verdict = Verdict();
  EXPECT_FALSE(MakeLotSummary("LOT-1", passing, "imufit test", limits).figures[2].plotted);
  EXPECT_EQ(LotPlots(MakeLotSummary("LOT-1", passing, "imufit test", limits)).size(), 3u);

  // Capability from 4 units: indicative, with Ppk's interval by Bissell's approximation.
  const LotFigure& bias = s.figures[0];
  ASSERT_TRUE(bias.ppk && bias.ppk_interval);
  EXPECT_TRUE(bias.few_units);
  const double half = kCapabilityZ * std::sqrt(1.0 / 36.0 + *bias.ppk * *bias.ppk / 6.0);
  EXPECT_NEAR((*bias.ppk_interval)[0], *bias.ppk - half, kArithmeticAbsolute);
  EXPECT_NEAR((*bias.ppk_interval)[1], *bias.ppk + half, kArithmeticAbsolute);
  EXPECT_NE(LotPlots(s)[0].panels.at(0).title.find("(n = 4, indicative)"), std::string::npos);
  EXPECT_FALSE(CapabilityInterval(1.0, 1));

  // The CSV: every figure with its sigma and U, the calibration date, empty cells where nothing is
  // known, a quoted message.
  const std::vector<std::string> lines = [&] {
    std::vector<std::string> out;
    std::string csv = LotSummaryCsv(batch), line;
    for (char c : csv) {
      if (c == '\n') {
        out.push_back(line);
        line.clear();
      } else {
        line += c;
      }
    }
    return out;
  }();
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0],
            "unit,serial,status,verdict,message,calibrated_utc,"
            "gyro_bias_dps.x,gyro_bias_dps.x.sigma,gyro_bias_dps.x.U,"
            "accel_bias_mg.x,accel_bias_mg.x.sigma,accel_bias_mg.x.U,"
            "accel_misalignment_mrad.xy,accel_misalignment_mrad.xy.sigma,accel_misalignment_mrad.xy.U,"
            "accel_residual_rms_mg,accel_residual_rms_mg.sigma,accel_residual_rms_mg.U");
  EXPECT_EQ(lines[1],
            "unit-01,SN1,fitted,PASS,,2026-11-21T06:00:00Z,0.1,0.001,0.002,10,0.01,0.02,0.5,0.02,0.04,0.8,,");
  EXPECT_EQ(
      lines[3].rfind(
          "unit-03,SN3,fitted,FAIL,\"sigma(accel_misalignment_mrad.xy) 0.02 > 0.01 mrad, badly\",2026", 0),
      0u);
  EXPECT_EQ(lines[4], "unit-04,SN4,error,,,,,,,,,,,,,,,");
}

// Two markers' labels closer than a label's height are moved apart (the lines stay); a label pushed
// beyond the top of the axis comes back down with the others.
TEST(PlotAxes, MarkerLabelsNeverOverlap) {
  Plot plot;
  plot.y_range = std::array<double, 2>{0.0, 1.0};
  plot.markers = {{0.99, "0.99", "#b00000"}, {0.5, "mean"}, {0.98, "+3s"}, {0.3, "x", "#000000", true}};
  const int height_px = 180;
  SpreadMarkerLabels(height_px, &plot);
  const double gap = MarkerLabelGap(plot, height_px);
  EXPECT_NEAR(gap, 14.0 / (0.6 * 180.0), kArithmeticAbsolute);
  EXPECT_EQ(plot.markers[0].value, 0.99);  // the line where it was
  EXPECT_NEAR(*plot.markers[0].label_at, 1.0, kArithmeticAbsolute);
  EXPECT_NEAR(*plot.markers[2].label_at, 1.0 - gap, kArithmeticAbsolute);
  EXPECT_EQ(*plot.markers[1].label_at, 0.5);
  EXPECT_FALSE(plot.markers[3].label_at);  // a vertical marker's label is above the panel
}

// Records one unit's fit of `lot` with a gyro bias x of `bias_dps`.
void Record(ResultsStore* store, const std::string& lot, const std::string& unit, const std::string& time,
            const std::string& status, const std::string& verdict, double bias_dps) {
  StoredFit fit;
  fit.serial = lot + "/" + unit;
  fit.unit = unit;
  fit.lot = lot;
  fit.time_utc = time;
  fit.software = "imufit test";
  fit.status = status;
  fit.verdict = verdict;
  if (status == "fitted")
    fit.figures = {StoredFigureOf(MakeFigure("gyro_bias_dps.x", "", "deg/s", bias_dps, 0.01))};
  store->Record(fit);
}

TEST_F(LotTest, LotHistoryHasEveryLotsYieldAndMeans) {
  ResultsStore store((dir_ / "store.db").string());
  Record(&store, "lot-a", "u1", "2026-01-01T00:00:00Z", "fitted", "PASS", 1.0);
  Record(&store, "lot-a", "u2", "2026-01-01T00:01:00Z", "fitted", "PASS", 1.2);
  // lot-b: u1 failed, was refitted and passed: its latest fit counts, in the yield and the mean.
  Record(&store, "lot-b", "u1", "2026-02-01T00:00:00Z", "fitted", "FAIL", 9.0);
  Record(&store, "lot-b", "u2", "2026-02-01T00:01:00Z", "fitted", "PASS", 2.2);
  Record(&store, "lot-b", "u3", "2026-02-01T00:02:00Z", "fitted", "PASS", 2.4);
  Record(&store, "lot-b", "u1", "2026-02-02T00:00:00Z", "fitted", "PASS", 2.0);
  // lot-c: one unit not fitted (no figures), one that passed.
  Record(&store, "lot-c", "u1", "2026-03-01T00:00:00Z", "not-fitted", "", 0.0);
  Record(&store, "lot-c", "u2", "2026-03-01T00:01:00Z", "fitted", "PASS", 3.0);
  Record(&store, "", "single", "2026-03-02T00:00:00Z", "fitted", "PASS", 50.0);  // imufit fit: no lot

  const Limits limits = WriteLimits("criteria:\n  - {quantity: gyro_bias_dps, max_abs: 4}\n");
  const LotHistory h = MakeLotHistory(&store, "lot-b", &limits, {"gyro_bias_dps.x", "accel_bias_mg.x"});
  ASSERT_EQ(h.lots.size(), 3u);
  EXPECT_EQ(h.lots[0].lot, "lot-a");
  EXPECT_EQ(h.lots[2].lot, "lot-c");
  EXPECT_EQ(h.current, 1);
  EXPECT_EQ(h.yield_pct, (std::vector<double>{100.0, 100.0, 50.0}));
  EXPECT_EQ(h.lots[2].not_fitted, 1);
  ASSERT_EQ(h.trends.size(), 1u);  // no lot has accel_bias_mg.x
  const LotTrend& t = h.trends[0];
  EXPECT_EQ(t.unit, "deg/s");
  EXPECT_EQ(t.count, (std::vector<int>{2, 3, 1}));
  EXPECT_NEAR(t.mean[0], 1.1, kArithmeticAbsolute);
  EXPECT_NEAR(t.mean[1], 2.2, kArithmeticAbsolute);
  EXPECT_NEAR(t.sigma[1], 0.2, kArithmeticAbsolute);
  EXPECT_EQ(t.mean[2], 3.0);
  EXPECT_EQ(t.sigma[2], 0.0);
  ASSERT_TRUE(t.limits);
  EXPECT_EQ(*t.limits->upper, 4.0);
  EXPECT_TRUE(t.view.upper_in_view);
  EXPECT_EQ(MakeLotHistory(&store, "lot-z", nullptr).current, -1);

  // The plots: yield bars with this lot apart, then the lot means with their sigmas.
  const std::vector<PlotFigure> plots = LotHistoryPlots(h);
  ASSERT_EQ(plots.size(), 2u);
  const Plot& yield = plots[0].panels.at(0);
  ASSERT_EQ(yield.series.size(), 2u);
  EXPECT_EQ(yield.series[0].style, PlotSeries::Style::kBoxes);
  EXPECT_EQ(yield.series[0].y, (std::vector<double>{100.0, 50.0}));
  EXPECT_EQ(yield.series[1].x, (std::vector<double>{1.0}));
  EXPECT_EQ(yield.x_tics.at(2).label, "lot-c");
  // The bars read as the table does ("50.0 %"), not rounded otherwise.
  ASSERT_EQ(yield.notes.size(), 3u);
  EXPECT_EQ(yield.notes[2].text, "50.0 %");
  const Plot& trend = plots[1].panels.at(0);
  EXPECT_EQ(trend.series[1].y.size(), 1u);
  EXPECT_NEAR(trend.series[1].error.at(0), 0.2, kArithmeticAbsolute);

  // The lot page of lot-b carries the section, its table and (with gnuplot) the charts.
  LotSummary summary = MakeLotSummary("lot-b", FiveUnits(), "imufit test", limits);
  summary.history = h;
  const std::string page = LotPageHtml(summary);
  EXPECT_NE(page.find("data-key=\"history\""), std::string::npos);
  EXPECT_NE(page.find("<tr data-history-lot=\"lot-b\" class=\"current\">"), std::string::npos);
  EXPECT_NE(page.find("data-yield=\"50\""), std::string::npos);
  if (GnuplotAvailable()) {
    size_t svgs = 0;
    for (size_t at = page.find("<svg"); at != std::string::npos; at = page.find("<svg", at + 1)) ++svgs;
    EXPECT_EQ(svgs, LotPlots(summary).size() + plots.size());
  }
}

TEST(PlotAxes, NiceTicksAndCategoryLabels) {
  const AxisScale a = NiceAxis(16.5507, 16.5516);
  EXPECT_NEAR(a.step, 0.0002, 1e-15);
  EXPECT_EQ(a.format, "%.4f");
  EXPECT_LE(a.lo, 16.5507);
  EXPECT_GE(a.hi, 16.5516);
  EXPECT_EQ(NiceAxis(0.0, 100.0).format, "%.0f");
  const AxisScale flat = NiceAxis(2.0, 2.0);  // one value: a small range around it
  EXPECT_LT(flat.lo, 2.0);
  EXPECT_GT(flat.hi, 2.0);

  std::vector<std::string> few = {"01", "02", "03"}, many;
  for (int i = 0; i < 100; ++i) many.push_back("SN24011" + std::to_string(1000 + i));
  const CategoryAxis flat_axis = CategoryTics(few, 40, 64);
  EXPECT_EQ(flat_axis.tics.size(), 3u);
  EXPECT_EQ(flat_axis.rotate_deg, 0);
  EXPECT_EQ(flat_axis.range[1], 2.5);
  const CategoryAxis upright = CategoryTics(many, 40, 64);
  EXPECT_EQ(upright.tics.size(), 34u);  // every third of 100
  EXPECT_EQ(upright.tics[1].value, 3.0);
  EXPECT_EQ(upright.rotate_deg, 90);
}

}  // namespace
}  // namespace imufit
