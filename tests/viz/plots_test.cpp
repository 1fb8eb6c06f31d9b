#include "autograv/viz/plots.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/image/image_comparison.h"
#include "autograv/viz/image.h"
#include "viz_test_support.h"

namespace autograv::viz {
namespace {

using testing::analyticGravity;
using testing::countPixels;
using testing::FixtureSpec;
using testing::makeFixtureMap;

PlotOptions smallPlot() {
  PlotOptions options;
  options.width_px = 480;
  options.height_px = 360;
  return options;
}

// The plot colours (plots.cpp): blue Delta_j, orange M_hat_j, red failures, green errors.
bool isBlue(int r, int g, int b) {
  return std::abs(r - 31) < 25 && std::abs(g - 120) < 25 && b > 150;
}
bool isOrange(int r, int g, int b) { return r > 200 && std::abs(g - 115) < 30 && b < 50; }
bool isRed(int r, int g, int b) { return r > 180 && g < 70 && b < 70; }
bool isGreen(int r, int g, int b) { return r < 90 && g > 130 && b < 90; }

TEST(HistogramTest, IterationsSplitByOutcome) {
  FixtureSpec spec;
  spec.failed = {0, 1, 2};
  spec.not_visited = {124};
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  const IterationHistogram histogram = iterationHistogram(map);
  // makeFixtureMap: iterations = 6 + (7 i) mod 9, so 6..14.
  EXPECT_DOUBLE_EQ(histogram.converged.first_lower, 6.0);
  EXPECT_DOUBLE_EQ(histogram.converged.width, 1.0);
  ASSERT_EQ(histogram.converged.counts.size(), 9u);
  ASSERT_EQ(histogram.not_converged.counts.size(), 9u);
  EXPECT_EQ(histogram.converged.total(), 121);
  EXPECT_EQ(histogram.not_converged.total(), 3);
  // Vertices 0, 1, 2 took 6, 13 and 11 iterations.
  EXPECT_EQ(histogram.not_converged.counts[0], 1);
  EXPECT_EQ(histogram.not_converged.counts[7], 1);
  EXPECT_EQ(histogram.not_converged.counts[5], 1);
  int expected_converged_at_6 = 0;
  for (int i = 3; i < 124; ++i) expected_converged_at_6 += (6 + (i * 7) % 9) == 6 ? 1 : 0;
  EXPECT_EQ(histogram.converged.counts[0], expected_converged_at_6);
}

TEST(HistogramTest, RelativeErrorAgainstTruth) {
  const GravityMap map = makeFixtureMap(analyticGravity);  // 1 % of |G| times a wobble
  const Histogram histogram = relativeErrorHistogram(map, analyticGravity, 10);
  ASSERT_EQ(histogram.counts.size(), 10u);
  EXPECT_EQ(histogram.total(), 125);
  double largest = 0.0;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    const Eigen::Vector3d t = analyticGravity(map.grid().vertexPosition(i));
    largest = std::max(largest, 100.0 * (map.vertices()[i].gravity_n - t).norm() / t.norm());
  }
  // The range is the next round number above the largest error (1, 2, 2.5, 5 x 10^k).
  const double top = histogram.first_lower + 10 * histogram.width;
  EXPECT_GE(top, largest);
  EXPECT_LT(top, 2.0 * largest);
  EXPECT_GT(histogram.counts.back() + histogram.counts[histogram.counts.size() - 2], 0);
}

TEST(HistogramTest, RefusesMapsWithNothingToCount) {
  FixtureSpec spec;
  for (int i = 0; i < 125; ++i) spec.not_visited.push_back(i);
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  EXPECT_THROW(iterationHistogram(map), Error);
  EXPECT_THROW(relativeErrorHistogram(map, analyticGravity), Error);
  const GravityMap good = makeFixtureMap(analyticGravity);
  EXPECT_THROW(relativeErrorHistogram(good, analyticGravity, 0), Error);
  EXPECT_THROW(relativeErrorHistogram(good, GroundTruth{}), Error);
}

TEST(ConvergencePlotTest, RefusesBadVerticesBeforeRendering) {
  FixtureSpec spec;
  spec.not_visited = {7};
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  EXPECT_THROW(renderConvergencePlot(map, -1, smallPlot()), Error);
  EXPECT_THROW(renderConvergencePlot(map, 125, smallPlot()), Error);
  try {
    renderConvergencePlot(map, 7, smallPlot());
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("no iteration history"), std::string::npos);
  }
  PlotOptions tiny = smallPlot();
  tiny.width_px = 4;
  EXPECT_THROW(renderConvergencePlot(map, 0, tiny), Error);
}

TEST(ConvergencePlotTest, DrawsBothCurvesAndTheTrueMass) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const GravityMap map = makeFixtureMap(analyticGravity);
  PlotOptions options = smallPlot();
  const RgbImage plain = renderConvergencePlot(map, 62, options);
  ASSERT_EQ(plain.width_px, 480);
  ASSERT_EQ(plain.height_px, 360);
  EXPECT_GT(countPixels(plain, isBlue), 150);
  EXPECT_GT(countPixels(plain, isOrange), 150);
  // Delta_j (blue) sits in the top chart, M_hat_j (orange) in the bottom one.
  RgbImage top_half = plain;
  top_half.height_px = 180;
  top_half.rgb.resize(480 * 180 * 3);
  EXPECT_GT(countPixels(top_half, isBlue), 0.9 * countPixels(plain, isBlue));
  EXPECT_LT(countPixels(top_half, isOrange), 0.1 * countPixels(plain, isOrange));
  // With the truth, the dashed true-mass line and its legend entry appear.
  options.ground_truth = analyticGravity;
  const RgbImage with_truth = renderConvergencePlot(map, 62, options);
  EXPECT_FALSE(compareImages(with_truth, plain).passed);
  const auto dark = [](int r, int g, int b) { return r + g + b < 120; };
  EXPECT_GT(countPixels(with_truth, dark), countPixels(plain, dark) + 100);
}

TEST(SummaryPlotTest, IterationsAloneOrWithTheErrorHistogram) {
  AUTOGRAV_REQUIRE_DISPLAY();
  FixtureSpec spec;
  spec.failed = {0, 1, 2, 3, 4, 5};
  const GravityMap map = makeFixtureMap(analyticGravity, spec);
  PlotOptions options = smallPlot();
  options.width_px = 720;
  const RgbImage alone = renderSummaryPlot(map, options);
  EXPECT_GT(countPixels(alone, isBlue), 500);
  EXPECT_GT(countPixels(alone, isRed), 50);  // the failed vertices, stacked
  EXPECT_EQ(countPixels(alone, isGreen), 0);
  options.ground_truth = analyticGravity;
  const RgbImage both = renderSummaryPlot(map, options);
  EXPECT_GT(countPixels(both, isGreen), 500);
}

TEST(SweepPlotTest, OneLinePerSeriesInEveryPanel) {
  const std::vector<std::string> levels = {"none", "low", "typical", "high"};
  const std::vector<SweepPanel> panels = {
      {"iterations", {{"sim:omega", {4.0, 6.0, 7.0, 9.0}}, {"sim:omni", {5.0, 7.0, 8.0, 12.0}}}},
      {"residual [mN]", {{"sim:omega", {1.0, 2.0, 3.0, std::nan("")}}}}};
  EXPECT_THROW(renderSweepPlot(levels, "friction", {{"bad", {{"short", {1.0, 2.0}}}}}),
               autograv::Error);
  EXPECT_THROW(renderSweepPlot(levels, "friction", {}), autograv::Error);
  AUTOGRAV_REQUIRE_DISPLAY();
  PlotOptions options = smallPlot();
  options.width_px = 720;
  const RgbImage picture = renderSweepPlot(levels, "friction", panels, options);
  EXPECT_EQ(picture.width_px, 720);
  EXPECT_GT(countPixels(picture, isBlue), 300);    // sim:omega in both panels
  EXPECT_GT(countPixels(picture, isOrange), 150);  // sim:omni in the first
}

TEST(SweepPlotTest, LegendStandsBesideThePanelsAndColoursDoNotRepeat) {
  AUTOGRAV_REQUIRE_DISPLAY();
  const std::vector<std::string> levels = {"none", "low", "typical", "high"};
  SweepPanel panel{"iterations", {}};
  for (int k = 0; k < 6; ++k) {
    const double value = 2.0 * (k + 1);
    panel.series.push_back({"series " + std::to_string(k), {value, value, value, value}});
  }
  PlotOptions options = smallPlot();
  options.width_px = 720;
  const RgbImage picture = renderSweepPlot(levels, "friction", {panel}, options);
  // The fifth series is sky blue, not the first one's blue again.
  const auto is_sky_blue = [](int r, int g, int b) {
    return std::abs(r - 87) < 25 && std::abs(g - 181) < 25 && std::abs(b - 232) < 25;
  };
  EXPECT_GT(countPixels(picture, is_sky_blue), 100);
  // The legend has a column of its own right of the chart: the blue of its first entry is there,
  // and there is no line under it.
  int blue_in_legend_column = 0;
  for (int y = 0; y < picture.height_px; ++y) {
    for (int x = picture.width_px * 3 / 4; x < picture.width_px; ++x) {
      const std::uint8_t* p = picture.pixel(x, y);
      if (isBlue(p[0], p[1], p[2])) ++blue_in_legend_column;
    }
  }
  EXPECT_GT(blue_in_legend_column, 10);
  EXPECT_LT(blue_in_legend_column, 300);

  // Series given one colour share it: no blue at all when both are orange.
  SweepPanel paired{"iterations",
                    {{"a", {1.0, 2.0, 3.0, 4.0}, 1, false}, {"b", {2.0, 3.0, 4.0, 5.0}, 1, true}}};
  const RgbImage orange_only = renderSweepPlot(levels, "friction", {paired}, options);
  EXPECT_GT(countPixels(orange_only, isOrange), 300);
  EXPECT_EQ(countPixels(orange_only, isBlue), 0);
}

}  // namespace
}  // namespace autograv::viz
