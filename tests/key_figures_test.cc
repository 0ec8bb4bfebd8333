// Tests of the key-figure table (io/key_figures.h): consistent in itself, with the model's layout and
// the limits reader, and listed as it is by the docs (docs/factory.md's key figures, docs/spec.md's
// limits quantities), so that the lists cannot drift.
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/io/error.h"
#include "imufit/io/key_figures.h"
#include "imufit/io/limits.h"
#include "imufit/model/sensor_model.h"
#include "test_util.h"

namespace imufit {
namespace {

// The rows of the Markdown table whose header line is `header` in `page` (its rule line excluded).
std::vector<std::string> TableRows(const std::string& page, const std::string& header) {
  const size_t at = page.find(header + "\n");
  EXPECT_NE(at, std::string::npos) << header;
  std::vector<std::string> rows;
  if (at == std::string::npos) return rows;
  size_t line = page.find('\n', page.find('\n', at) + 1) + 1;  // after the rule
  while (line < page.size() && page[line] == '|') {
    const size_t end = page.find('\n', line);
    rows.push_back(page.substr(line, end - line));
    line = end == std::string::npos ? page.size() : end + 1;
  }
  return rows;
}

// The quantities named in the first cell of `rows`: each `name`, `name.{x,y,z}` or `name.*` in
// backquotes, without its axes.
std::set<std::string> QuantitiesIn(const std::vector<std::string>& rows) {
  std::set<std::string> quantities;
  for (const std::string& row : rows) {
    const std::string cell = row.substr(1, row.find('|', 1) - 1);
    for (size_t open = cell.find('`'); open != std::string::npos; open = cell.find('`', open + 1)) {
      const size_t close = cell.find('`', open + 1);
      if (close == std::string::npos) break;
      const std::string name = cell.substr(open + 1, close - open - 1);
      quantities.insert(name.substr(0, name.find('.')));
      open = close;
    }
  }
  return quantities;
}

std::string Docs(const char* page) { return testing::ReadFile(std::string(IMUFIT_DOCS_DIR) + "/" + page); }

TEST(KeyFigureTableTest, NamesAreUniqueAndFoundByNameAndByFigure) {
  std::set<std::string> names;
  for (const KeyFigure& figure : kKeyFigures) {
    EXPECT_TRUE(names.insert(figure.name).second) << figure.name;
    EXPECT_EQ(FindKeyFigure(figure.name), &figure);
    for (const std::string& axis : KeyFigureAxes(figure))
      EXPECT_EQ(FindKeyFigure(std::string(figure.name) + "." + axis), &figure);
    EXPECT_NE(std::string(figure.title), "");
    EXPECT_NE(std::string(figure.unit), "");
    EXPECT_EQ(figure.record != nullptr, figure.source == FigureSource::kFitRecord) << figure.name;
    EXPECT_EQ(figure.noise_term >= 0, figure.source == FigureSource::kNoise) << figure.name;
  }
  EXPECT_EQ(FindKeyFigure("gyro_bias"), nullptr);
  EXPECT_EQ(FindLimitQuantity("gyro_bias_dps.x"), nullptr);     // a limits file names quantities
  EXPECT_EQ(FindLimitQuantity("gyro_scale_per_dps"), nullptr);  // judged by its scale error
  EXPECT_NE(FindLimitQuantity("gyro_scale_error_ppm"), nullptr);
}

// A coefficient group's axes are the model's coefficients of that group, in the model's order.
TEST(KeyFigureTableTest, CoefficientAxesFollowTheModelLayout) {
  for (const KeyFigure& figure : kKeyFigures) {
    if (figure.source != FigureSource::kCoefficient && figure.source != FigureSource::kScaleError) continue;
    const std::string path = figure.path;
    const std::string group = path.substr(path.find('.') + 1);
    EXPECT_EQ(path.substr(0, path.find('.')), IsGyroFigure(figure) ? "gyro" : "accel") << figure.name;
    std::vector<std::string> axes;
    for (const CoefficientName& n : kCoefficientNames) {
      if (group == n.group) axes.push_back(n.axis);
    }
    EXPECT_EQ(KeyFigureAxes(figure), axes) << figure.name;
  }
}

// The limits reader knows exactly the table's limits quantities, with the table's kind and unit.
using KeyFigureLimitsTest = testing::TempDirTest;

TEST_F(KeyFigureLimitsTest, LimitsReaderTakesTheTablesQuantities) {
  for (const KeyFigure& figure : kKeyFigures) {
    EXPECT_EQ(FindLimitQuantity(figure.name) != nullptr, figure.in_limits) << figure.name;
    if (!figure.in_limits) {
      EXPECT_EQ(LimitQuantityNames().find(std::string(figure.name) + ","), std::string::npos);
      continue;
    }
    const std::string criterion = LimitKindOf(figure) == LimitKind::kCoverage
                                      ? "{quantity: " + std::string(figure.name) + ", covers: [-20, 60]}"
                                      : "{quantity: " + std::string(figure.name) + ", max_abs: 1}";
    const std::string path = Write("limits.yaml",
                                   "format: imufit-limits\nversion: 1\nnominal: {gyro_scale: 939.65, "
                                   "accel_scale: 208.838}\ncriteria:\n  - " +
                                       criterion + "\n");
    const Limits limits = ReadLimits(path);
    ASSERT_EQ(limits.criteria.size(), 1u);
    EXPECT_EQ(limits.criteria[0].kind, LimitKindOf(figure)) << figure.name;
    EXPECT_EQ(limits.criteria[0].unit, figure.unit) << figure.name;
    EXPECT_EQ(limits.criteria[0].axes, KeyFigureAxes(figure)) << figure.name;
  }
}

// docs/factory.md's table of key figures lists the figures a calibration has (KeyFigures()).
TEST(KeyFigureTableTest, FactoryDocsListTheKeyFigures) {
  std::set<std::string> table;
  for (const KeyFigure& figure : kKeyFigures) {
    if (figure.source == FigureSource::kCoefficient || figure.source == FigureSource::kNoise ||
        figure.source == FigureSource::kFitRecord)
      table.insert(figure.name);
  }
  EXPECT_EQ(QuantitiesIn(TableRows(Docs("factory.md"), "| figure | from the calibration | unit |")), table);
}

// docs/spec.md's table of limits quantities lists the quantities a limits file may name.
TEST(KeyFigureTableTest, SpecDocsListTheLimitsQuantities) {
  std::set<std::string> table;
  for (const KeyFigure& figure : kKeyFigures) {
    if (figure.in_limits) table.insert(figure.name);
  }
  EXPECT_EQ(QuantitiesIn(TableRows(Docs("spec.md"), "| quantity | axes | unit, from |")), table);
}

}  // namespace
}  // namespace imufit
