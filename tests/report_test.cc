// Tests of the Allan deviation plot (part of factory_test): the figure AllanPlot() describes for a
// known noise model — the ARW read on the -1/2 line at tau = 1 s, the bias-instability floor, the
// units, tau in the axis label — asserted on the plot structs, and the gnuplot script they make.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/io/units.h"
#include "imufit/report/allan_plot.h"
#include "imufit/report/plot.h"

namespace imufit {
namespace {

// Relative tolerance of a deviation recomputed here from the same model (other order of operations).
constexpr double kModelRelative = 1e-12;

// A gyro column whose measured curve is exactly the IEEE 952 model with white noise N (rad/sqrt(s))
// and bias instability B (rad/s), both resolved; octave taus from 0.01 s to 655 s.
ColumnAnalysis ModelColumn(const std::string& name, double n, double b, bool b_resolved = true) {
  ColumnAnalysis r;
  r.name = name;
  r.kind = ColumnKind::kGyro;
  r.curve.estimator = AllanEstimator::kOadev;
  r.fit.fitted = true;
  r.fit.value[kRandomWalk] = n;
  r.fit.sigma[kRandomWalk] = 0.01 * n;
  r.fit.variance[kRandomWalk] = n * n;
  r.fit.variance_sigma[kRandomWalk] = 0.02 * n * n;
  r.fit.value[kBiasInstability] = b;
  r.fit.sigma[kBiasInstability] = 0.1 * b;
  r.fit.variance[kBiasInstability] = b * b;
  r.fit.variance_sigma[kBiasInstability] = (b_resolved ? 0.2 : 0.8) * b * b;  // resolved above 2 sigma
  for (int64_t m = 1; m <= 65536; m *= 2) {
    AllanPoint p;
    p.m = m;
    p.tau_s = 0.01 * m;
    p.dev = r.fit.ModelDeviation(p.tau_s);
    p.dev_lo = 0.9 * p.dev;
    p.dev_hi = 1.1 * p.dev;
    r.curve.points.push_back(p);
  }
  r.allan = r.curve;
  return r;
}

TEST(AllanPlot, ShowsArwAtOneSecondAndTheBiasInstabilityFloorInTheChosenUnits) {
  const double n = 8.7e-5, b = 1.45e-5;  // 0.299 deg/sqrt(h), 2.99 deg/h
  const PlotFigure figure = AllanPlot({ModelColumn("gyro_x", n, b)}, "run.csv", AllanPlotUnits::kDegPerHour);
  ASSERT_EQ(figure.panels.size(), 1u);
  const Plot& plot = figure.panels[0];
  EXPECT_EQ(plot.x_label, "averaging time \xcf\x84 (s)");  // a real tau, not the word
  EXPECT_EQ(plot.y_label, "overlapping Allan deviation (\xc2\xb0/h)");
  // The ARW's mark, the floor's mark, the floor's words, the ARW's words (stacked last, from one
  // anchor above the highest ARW mark).
  ASSERT_EQ(plot.notes.size(), 4u);
  const PlotNote& arw = plot.notes[0];
  EXPECT_EQ(arw.x, 1.0);
  EXPECT_NEAR(arw.y, n * DphFromRadps(1.0), kModelRelative * arw.y);  // sigma(1 s) on the -1/2 line is N
  EXPECT_GE(arw.point_type, 0);
  const PlotNote& arw_words = plot.notes[3];
  EXPECT_EQ(arw_words.text, "ARW 0.299 \xc2\xb1 0.003 \xc2\xb0/\xe2\x88\x9ah");  // N (180/pi) 60 deg/sqrt(h)
  EXPECT_EQ(arw_words.x, arw.x);
  EXPECT_EQ(arw_words.y, arw.y);
  EXPECT_GT(arw_words.dy_chars, 0.0);  // above its mark
  // The floor: sqrt(2 ln 2 / pi) B = 0.664 B, at the model's minimum (the last tau here: no rate
  // random walk), labelled with B itself.
  const PlotNote& floor = plot.notes[1];
  EXPECT_NEAR(floor.y, std::sqrt(2.0 * std::log(2.0) / kPi) * b * DphFromRadps(1.0),
              kModelRelative * floor.y);
  EXPECT_NEAR(floor.x, 655.36, 1e-9);
  EXPECT_EQ(plot.notes[2].text, "bias instability 2.99 \xc2\xb1 0.3 \xc2\xb0/h");
  EXPECT_LT(plot.notes[2].dy_chars, 0.0);  // under the floor
  // The curve in deg/h; the axis covers it in whole decades.
  ASSERT_FALSE(plot.series.empty());
  EXPECT_NEAR(plot.series[0].y[0], ModelColumn("gyro_x", n, b).curve.points[0].dev * DphFromRadps(1.0),
              kModelRelative * plot.series[0].y[0]);
  ASSERT_TRUE(plot.y_range);
  EXPECT_EQ(std::log10((*plot.y_range)[0]), std::floor(std::log10((*plot.y_range)[0])));
  EXPECT_LE((*plot.y_range)[1], 1e4);

  // Native units (rad/s): the same notes' words, the marks where the curve is in rad/s.
  const PlotFigure native = AllanPlot({ModelColumn("gyro_x", n, b)}, "run.csv");
  EXPECT_EQ(native.panels[0].y_label, "overlapping Allan deviation (rad/s)");
  EXPECT_NEAR(native.panels[0].notes[0].y, n, kModelRelative * n);
  EXPECT_EQ(native.panels[0].notes[3].text, arw_words.text);

  // The gnuplot script writes tau and the notes as UTF-8 text, not enhanced-text escapes.
  const std::string script = GnuplotScript(figure, "svg", "out.svg");
  EXPECT_NE(script.find("set encoding utf8"), std::string::npos);
  EXPECT_NE(script.find("\"averaging time \xcf\x84 (s)\""), std::string::npos);
  EXPECT_EQ(script.find("{/Symbol"), std::string::npos);
  EXPECT_NE(script.find("\"ARW 0.299"), std::string::npos);
}

TEST(AllanPlot, NamesColumnsWhenSeveralShareAPanelAndSaysWhatIsNotResolved) {
  const PlotFigure figure =
      AllanPlot({ModelColumn("gyro_x", 8.7e-5, 1.45e-5), ModelColumn("gyro_y", 8.0e-5, 1.2e-5, false)}, "t",
                AllanPlotUnits::kDegPerSecond);
  const Plot& plot = figure.panels.at(0);
  EXPECT_EQ(plot.y_label, "overlapping Allan deviation (\xc2\xb0/s)");
  std::vector<const PlotNote*> words;
  int marks = 0;
  for (const PlotNote& n : plot.notes) {
    if (!n.text.empty()) words.push_back(&n);
    marks += n.point_type >= 0 ? 1 : 0;
  }
  // Two ARW notes (named) and gyro_x's floor: gyro_y's bias instability is not resolved.
  EXPECT_EQ(marks, 3);
  ASSERT_EQ(words.size(), 3u);
  EXPECT_EQ(words[0]->text.rfind("gyro_x bias instability", 0), 0u);
  EXPECT_EQ(words[1]->text.rfind("gyro_x ARW ", 0), 0u);
  EXPECT_EQ(words[2]->text.rfind("gyro_y ARW ", 0), 0u);
  // One anchor for the ARW words, one line apart, the first column's on top: they never overlap
  // (issue 33: accel_y's VRW label was hidden under accel_z's).
  EXPECT_EQ(words[1]->x, words[2]->x);
  EXPECT_EQ(words[1]->y, words[2]->y);
  EXPECT_GE(words[1]->dy_chars - words[2]->dy_chars, 1.0);
  ASSERT_EQ(plot.labels.size(), 1u);
  EXPECT_EQ(plot.labels[0].text, "gyro_y: bias instability not resolved");
}

TEST(AllanPlot, UnitNames) {
  AllanPlotUnits units = AllanPlotUnits::kDegPerHour;
  EXPECT_TRUE(ParseAllanPlotUnits("rad/s", &units));
  EXPECT_EQ(units, AllanPlotUnits::kNative);
  EXPECT_TRUE(ParseAllanPlotUnits("deg/h", &units));
  EXPECT_EQ(units, AllanPlotUnits::kDegPerHour);
  EXPECT_TRUE(ParseAllanPlotUnits("deg/s", &units));
  EXPECT_EQ(units, AllanPlotUnits::kDegPerSecond);
  EXPECT_TRUE(ParseAllanPlotUnits("native", &units));
  EXPECT_EQ(units, AllanPlotUnits::kNative);
  EXPECT_FALSE(ParseAllanPlotUnits("dph", &units));
  EXPECT_EQ(units, AllanPlotUnits::kNative);  // untouched
}

// With engineer plot units an accelerometer panel is drawn in micro-g, the unit its bias
// instability is printed in (the panel's words and the curve agree), not in m/s^2.
TEST(AllanPlotTest, AnAccelerometerPanelIsInTheUnitItsFiguresArePrintedIn) {
  ColumnAnalysis accel = ModelColumn("accel_z", 6e-4, 2e-5);  // m/s/sqrt(s), m/s^2
  accel.kind = ColumnKind::kAccel;
  const double ug_per_mps2 = 1e6 / kStandardGravityMps2;
  const PlotFigure figure = AllanPlot({accel}, "", AllanPlotUnits::kDegPerHour);
  ASSERT_EQ(figure.panels.size(), 1u);
  const Plot& plot = figure.panels[0];
  EXPECT_EQ(plot.y_label, "overlapping Allan deviation (\xc2\xb5g)");
  ASSERT_FALSE(plot.series.empty());
  EXPECT_NEAR(plot.series[0].y[0], accel.curve.points[0].dev * ug_per_mps2,
              kModelRelative * plot.series[0].y[0]);
  // Native units keep the column's own.
  const PlotFigure native = AllanPlot({accel}, "");
  EXPECT_EQ(native.panels[0].y_label, "overlapping Allan deviation (m/s\xc2\xb2)");
  EXPECT_NEAR(native.panels[0].series[0].y[0], accel.curve.points[0].dev,
              kModelRelative * accel.curve.points[0].dev);
}

}  // namespace
}  // namespace imufit
