// The study's figures (io/svg_chart.h): boxes at the quartiles, Tukey's whiskers and outliers, a
// diverging colour scale, and malformed input refused.
#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>

#include "vrdeform/error.h"
#include "vrdeform/io/svg_chart.h"

namespace vrd {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SvgChart, BoxesSitAtTheQuartilesWithTukeysOutliers) {
  BoxPlot p{"t", "rating", {"A", "B"}, {"haptic"}, {{{1, 2, 3, 4, 5}, {2, 2, 2, 2, 7}}}, {1, 7}};
  const std::string svg = svgBoxPlot(p);
  // 1..5: quartiles 2 and 4, median 3; no sample beyond 1.5 IQR (-1..7).
  EXPECT_NE(svg.find("data-series=\"A\" data-median=\"3\" data-q1=\"2\" data-q3=\"4\""), std::string::npos);
  // 2, 2, 2, 2, 7: IQR 0, so 7 is an outlier: one dot.
  EXPECT_NE(svg.find("data-series=\"B\" data-median=\"2\" data-q1=\"2\" data-q3=\"2\""), std::string::npos);
  EXPECT_EQ(count(svg, "<circle"), 1u);
  EXPECT_EQ(count(svg, "class=\"box\""), 2u);
  // Whiskers from the box's edges outwards, not through the box: for A, the upper one from y(5) to
  // the box's top y(4) and the lower one from its bottom y(2) to y(1).
  const std::regex box(
      "data-series=\"A\"[^>]*>\\n"
      "<line class=\"whisker\"[^>]* y1=\"([0-9.]+)\" y2=\"([0-9.]+)\"[^>]*>\\n"
      "<line class=\"whisker\"[^>]* y1=\"([0-9.]+)\" y2=\"([0-9.]+)\"[^>]*>\\n"
      "<rect x=\"[0-9.]+\" y=\"([0-9.]+)\" width=\"[0-9.]+\" height=\"([0-9.]+)\"");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(svg, m, box));
  const double top = std::stod(m[5]), bottom = top + std::stod(m[6]);
  EXPECT_LT(std::stod(m[1]), top);  // y grows downwards: 5 above the box
  EXPECT_DOUBLE_EQ(std::stod(m[2]), top);
  EXPECT_DOUBLE_EQ(std::stod(m[3]), bottom);
  EXPECT_GT(std::stod(m[4]), bottom);                                  // 1 below it
  EXPECT_NEAR(std::stod(m[1]) - top, bottom - std::stod(m[4]), 0.11);  // one unit of the scale each
  p.values[0][1] = {std::nan(""), 3.0};                                // non-finite samples left out
  EXPECT_NE(svgBoxPlot(p).find("data-series=\"B\" data-median=\"3\""), std::string::npos);
  p.values[0].pop_back();
  EXPECT_THROW(svgBoxPlot(p), Error);
  p.values[0].push_back({});
  p.yRange = {7, 1};
  EXPECT_THROW(svgBoxPlot(p), Error);
}

TEST(SvgChart, HeatmapColoursDivergeFromWhite) {
  const Heatmap h{"items", {"H1", "H2", "H3", "H4"}, {"A - B"}, {{2.0}, {-2.0}, {0.0}, {std::nan("")}}, 2.0};
  const std::string svg = svgHeatmap(h);
  EXPECT_NE(svg.find("data-row=\"H1\" data-column=\"A - B\" data-value=\"2.00\""), std::string::npos);
  EXPECT_NE(svg.find("fill=\"#ff0000\""), std::string::npos);                                        // +range: red
  EXPECT_NE(svg.find("fill=\"#0000ff\""), std::string::npos);                                        // -range: blue
  EXPECT_NE(svg.find("fill=\"#ffffff\""), std::string::npos);                                        // 0: white
  EXPECT_NE(svg.find("data-row=\"H4\" data-column=\"A - B\" data-value=\"-\""), std::string::npos);  // NaN
  EXPECT_THROW(svgHeatmap({"x", {"H1"}, {"A - B"}, {{1.0, 2.0}}, 1.0}), Error);
  EXPECT_THROW(svgHeatmap({"x", {"H1"}, {"A - B"}, {{1.0}}, 0.0}), Error);
}

}  // namespace
}  // namespace vrd
