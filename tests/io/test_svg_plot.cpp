// SVG line plots: parsed back as XML, data points checked against the pixels the axes promise.
#include <gtest/gtest.h>

#include <pugixml.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_support.h"
#include "vrdeform/io/svg_plot.h"

namespace vrd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Point {
  double x, y;
};

struct Rect {
  double left, top, right, bottom;
};

/// The SVG parsed; a failure when it is not well-formed XML with an <svg> root.
pugi::xml_document parse(const std::string& svg) {
  pugi::xml_document doc;
  const pugi::xml_parse_result result = doc.load_string(svg.c_str());
  EXPECT_TRUE(result) << result.description() << " at offset " << result.offset << "\n" << svg;
  EXPECT_STREQ(doc.document_element().name(), "svg");
  return doc;
}

std::vector<pugi::xml_node> nodes(const pugi::xml_document& doc, const char* xpath) {
  std::vector<pugi::xml_node> out;
  for (const pugi::xpath_node& n : doc.select_nodes(xpath)) out.push_back(n.node());
  return out;
}

/// The series' polylines, in document order.
std::vector<pugi::xml_node> polylines(const pugi::xml_document& doc) {
  return nodes(doc, "//polyline[@class='series']");
}

std::vector<Point> points(const pugi::xml_node& polyline) {
  std::string text = polyline.attribute("points").value();
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream in(text);
  std::vector<Point> out;
  for (Point p; in >> p.x >> p.y;) out.push_back(p);
  EXPECT_TRUE(in.eof()) << "unreadable points: " << polyline.attribute("points").value();
  return out;
}

Rect plotArea(const pugi::xml_document& doc) {
  const pugi::xml_node r = doc.select_node("//rect[@class='plot-area']").node();
  EXPECT_TRUE(r) << "no plot-area rect";
  const double x = r.attribute("x").as_double(), y = r.attribute("y").as_double();
  return {x, y, x + r.attribute("width").as_double(), y + r.attribute("height").as_double()};
}

/// Tick label texts of one axis ("x-ticks" or "y-ticks").
std::vector<std::string> tickLabels(const pugi::xml_document& doc, const std::string& axis) {
  std::vector<std::string> out;
  for (const pugi::xml_node& t : nodes(doc, ("//g[@class='" + axis + "']/text").c_str())) out.push_back(t.text().get());
  return out;
}

PlotSeries series(std::string label, std::vector<double> x, std::vector<double> y) {
  return {std::move(label), std::move(x), std::move(y)};
}

TEST(SvgPlot, IsAnSvgDocumentWithTitleLabelsAndLegend) {
  Plot plot{"Fingertip force", "time [s]", "force [N]", {}, {}};
  plot.series.push_back(series("index", {0, 1, 2}, {0, 1, 0}));
  plot.series.push_back(series("thumb", {0, 1, 2}, {1, 2, 3}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const pugi::xml_node svg = doc.document_element();
  EXPECT_STREQ(svg.attribute("xmlns").value(), "http://www.w3.org/2000/svg");
  EXPECT_STREQ(svg.attribute("width").value(), "720");
  EXPECT_STREQ(svg.attribute("height").value(), "420");
  EXPECT_STREQ(doc.select_node("//text[@class='title']").node().text().get(), "Fingertip force");
  EXPECT_STREQ(doc.select_node("//text[@class='x-label']").node().text().get(), "time [s]");
  EXPECT_STREQ(doc.select_node("//text[@class='y-label']").node().text().get(), "force [N]");

  const std::vector<pugi::xml_node> lines = polylines(doc);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_STREQ(lines[0].attribute("data-label").value(), "index");
  EXPECT_STREQ(lines[1].attribute("data-label").value(), "thumb");
  EXPECT_STRNE(lines[0].attribute("stroke").value(), lines[1].attribute("stroke").value());
  EXPECT_EQ(points(lines[0]).size(), 3u);
  const std::vector<pugi::xml_node> legend = nodes(doc, "//g[@class='legend']/text");
  ASSERT_EQ(legend.size(), 2u);
  EXPECT_STREQ(legend[1].text().get(), "thumb");
  EXPECT_GE(tickLabels(doc, "x-ticks").size(), 3u);
  EXPECT_GE(tickLabels(doc, "y-ticks").size(), 3u);
}

TEST(SvgPlot, DataOnWholeTicksSpanThePlotAreaExactly) {
  // x in [0, 10] and y in [0, 4]: every 1-2-5 step that fits divides both, so the axes are the data's range.
  Plot plot;
  std::vector<double> x, y;
  for (int i = 0; i <= 20; ++i) {
    x.push_back(0.5 * i);
    y.push_back(0.04 * x.back() * x.back());
  }
  plot.series.push_back(series("force", x, y));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const Rect area = plotArea(doc);
  const std::vector<Point> p = points(polylines(doc).at(0));
  ASSERT_EQ(p.size(), 21u);
  EXPECT_NEAR(p.front().x, area.left, 0.5);
  EXPECT_NEAR(p.front().y, area.bottom, 0.5);  // SVG's y grows downwards
  EXPECT_NEAR(p.back().x, area.right, 0.5);
  EXPECT_NEAR(p.back().y, area.top, 0.5);
  // (5, 1): halfway across, a quarter of the way up.
  EXPECT_NEAR(p[10].x, 0.5 * (area.left + area.right), 0.5);
  EXPECT_NEAR(p[10].y, area.bottom - 0.25 * (area.bottom - area.top), 0.5);
  const std::vector<std::string> xt = tickLabels(doc, "x-ticks"), yt = tickLabels(doc, "y-ticks");
  EXPECT_EQ(xt.front(), "0");
  EXPECT_EQ(xt.back(), "10");
  EXPECT_EQ(yt.front(), "0");
  EXPECT_EQ(yt.back(), "4");
}

TEST(SvgPlot, AxesWidenToNiceTicksAroundTheData) {
  Plot plot;
  plot.series.push_back(series("a", {0.3, 9.6}, {-0.2, 3.7}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const Rect area = plotArea(doc);
  // The outermost ticks sit on the plot area's edges; read the axes' ranges from their labels.
  const std::vector<std::string> xt = tickLabels(doc, "x-ticks"), yt = tickLabels(doc, "y-ticks");
  ASSERT_GE(xt.size(), 3u);
  ASSERT_GE(yt.size(), 3u);
  const double x0 = std::stod(xt.front()), x1 = std::stod(xt.back());
  const double y0 = std::stod(yt.front()), y1 = std::stod(yt.back());
  const double xStep = std::stod(xt[1]) - x0, yStep = std::stod(yt[1]) - y0;
  for (double step : {xStep, yStep}) {
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 || std::abs(mantissa - 5) < 1e-9)
        << step;
  }
  // Widened by less than a step on each side.
  EXPECT_LE(x0, 0.3);
  EXPECT_GT(x0, 0.3 - xStep);
  EXPECT_GE(x1, 9.6);
  EXPECT_LT(x1, 9.6 + xStep);
  EXPECT_LE(y0, -0.2);
  EXPECT_GT(y0, -0.2 - yStep);
  EXPECT_GE(y1, 3.7);
  EXPECT_LT(y1, 3.7 + yStep);
  const std::vector<Point> p = points(polylines(doc).at(0));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NEAR(p[0].x, area.left + (0.3 - x0) / (x1 - x0) * (area.right - area.left), 0.5);
  EXPECT_NEAR(p[0].y, area.bottom - (-0.2 - y0) / (y1 - y0) * (area.bottom - area.top), 0.5);
  EXPECT_NEAR(p[1].x, area.left + (9.6 - x0) / (x1 - x0) * (area.right - area.left), 0.5);
  EXPECT_NEAR(p[1].y, area.bottom - (3.7 - y0) / (y1 - y0) * (area.bottom - area.top), 0.5);
}

TEST(SvgPlot, NonFinitePointsBreakTheLine) {
  Plot plot;
  plot.series.push_back(series("broken", {0, 1, 2, 3, 4, 5}, {0, 1, kNaN, 3, 4, 5}));
  plot.series.push_back(series("inf x", {0, std::numeric_limits<double>::infinity(), 2}, {1, 1, 2}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const std::vector<pugi::xml_node> lines = polylines(doc);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_STREQ(lines[0].attribute("data-label").value(), "broken");
  EXPECT_STREQ(lines[1].attribute("data-label").value(), "broken");
  EXPECT_EQ(points(lines[0]).size(), 2u);
  EXPECT_EQ(points(lines[1]).size(), 3u);
  // A run of one point is drawn as a dot: the point twice.
  const std::vector<Point> dot = points(lines[2]);
  ASSERT_EQ(dot.size(), 2u);
  EXPECT_EQ(dot[0].x, dot[1].x);
  EXPECT_EQ(dot[0].y, dot[1].y);
}

TEST(SvgPlot, SeriesWithoutFinitePointsIsOnlyInTheLegend) {
  Plot plot;
  plot.series.push_back(series("ok", {0, 1}, {0, 1}));
  plot.series.push_back(series("all NaN", {kNaN, 1}, {0, kNaN}));
  plot.series.push_back(series("empty", {}, {}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  EXPECT_EQ(polylines(doc).size(), 1u);
  EXPECT_EQ(nodes(doc, "//g[@class='legend']/text").size(), 3u);
}

TEST(SvgPlot, EscapesTextInContentAndAttributes) {
  Plot plot{"a < b & \"c\" > d", "x", "y", {}, {}};
  plot.series.push_back(series("<F> & \"G\"\x01", {0, 1}, {0, 1}));
  const std::string svg = svgPlot(plot);
  EXPECT_NE(svg.find("a &lt; b &amp; &quot;c&quot; &gt; d"), std::string::npos);
  const pugi::xml_document doc = parse(svg);
  EXPECT_STREQ(doc.select_node("//text[@class='title']").node().text().get(), "a < b & \"c\" > d");
  EXPECT_STREQ(polylines(doc).at(0).attribute("data-label").value(), "<F> & \"G\"");  // control character dropped
}

TEST(SvgPlot, EmptyPlotIsStillAValidDocument) {
  const pugi::xml_document doc = parse(svgPlot(Plot{}));
  EXPECT_TRUE(polylines(doc).empty());
  const Rect area = plotArea(doc);
  EXPECT_GT(area.right - area.left, 100.0);
  EXPECT_EQ(tickLabels(doc, "x-ticks").front(), "0.0");  // no data: (0, 1)
  EXPECT_EQ(tickLabels(doc, "x-ticks").back(), "1.0");
}

TEST(SvgPlot, FixedYRangeIsKeptAndLinesOutsideAreClipped) {
  Plot plot;
  plot.yRange = std::pair(0.0, 1.0);
  plot.series.push_back(series("normalised", {0, 1, 2}, {0.5, 0.25, 2.0}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const Rect area = plotArea(doc);
  const std::vector<std::string> yt = tickLabels(doc, "y-ticks");
  EXPECT_EQ(yt.front(), "0.0");
  EXPECT_EQ(yt.back(), "1.0");
  const std::vector<Point> p = points(polylines(doc).at(0));
  ASSERT_EQ(p.size(), 3u);
  const double h = area.bottom - area.top;
  EXPECT_NEAR(p[0].y, area.bottom - 0.5 * h, 0.5);
  EXPECT_NEAR(p[1].y, area.bottom - 0.25 * h, 0.5);
  EXPECT_NEAR(p[2].y, area.bottom - 2.0 * h, 0.5);  // above the area, cut off by the clip path
  EXPECT_STREQ(polylines(doc).at(0).parent().attribute("clip-path").value(), "url(#plot-clip)");
  EXPECT_TRUE(doc.select_node("//clipPath[@id='plot-clip']/rect"));

  plot.yRange = std::pair(1.0, 1.0);
  EXPECT_NE(testing::errorOf([&] { svgPlot(plot); }).find("y range"), std::string::npos);
}

TEST(SvgPlot, SinglePointAndConstantValuesGetARangeAroundThem) {
  Plot plot;
  plot.series.push_back(series("one", {2.0}, {3.0}));
  const pugi::xml_document doc = parse(svgPlot(plot));
  const Rect area = plotArea(doc);
  const std::vector<Point> p = points(polylines(doc).at(0));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_GT(p[0].x, area.left + 1.0);
  EXPECT_LT(p[0].x, area.right - 1.0);
  EXPECT_GT(p[0].y, area.top + 1.0);
  EXPECT_LT(p[0].y, area.bottom - 1.0);

  Plot flat;
  flat.series.push_back(series("zero", {0, 1, 2}, {0, 0, 0}));
  const pugi::xml_document flatDoc = parse(svgPlot(flat));
  const Rect flatArea = plotArea(flatDoc);
  for (const Point& q : points(polylines(flatDoc).at(0))) {
    EXPECT_NEAR(q.y, 0.5 * (flatArea.top + flatArea.bottom), 0.5);  // zero padded to (-1, 1)
  }
  EXPECT_GE(tickLabels(flatDoc, "y-ticks").size(), 3u);
}

TEST(SvgPlot, RejectsSeriesOfUnequalLengthAndTooSmallPictures) {
  Plot plot;
  plot.series.push_back(series("bad", {0, 1, 2}, {0, 1}));
  EXPECT_NE(testing::errorOf([&] { svgPlot(plot); }).find("'bad' has 3 x values but 2 y values"), std::string::npos);
  EXPECT_NE(testing::errorOf([] { svgPlot(Plot{}, 50, 50); }).find("50x50"), std::string::npos);
}

TEST(SvgPlot, WriteSvgPlotWritesTheDocument) {
  testing::TempDir dir;
  Plot plot{"t", "x", "y", {series("s", {0, 1}, {1, 0})}, {}};
  const std::filesystem::path path = dir.path() / "plot.svg";
  writeSvgPlot(path, plot);
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, svgPlot(plot));
}

}  // namespace
}  // namespace vrd
