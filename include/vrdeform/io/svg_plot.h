#pragma once
// Line plots as self-contained SVG files (force against time, force against indentation), viewable in
// any browser without a plotting library.

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vrd {

/// One line: points (x[i], y[i]). A point with a non-finite coordinate is not drawn and breaks the line.
struct PlotSeries {
  std::string label;      ///< legend text
  std::vector<double> x;  ///< abscissae, as many as y
  std::vector<double> y;  ///< ordinates
};

struct Plot {
  std::string title;
  std::string xLabel;
  std::string yLabel;
  std::vector<PlotSeries> series;
  /// Fixed y range (low, high), e.g. (0, 1) for a normalised force; by default the data's range
  /// widened to whole ticks. Lines leaving a fixed range are clipped at the plot area.
  std::optional<std::pair<double, double>> yRange;
};

/// An SVG 1.1 document of `width` x `height` pixels: title, axes with ticks at 1, 2 or 5 x 10^k and
/// light grid lines, axis labels, one polyline per unbroken run of each series (class "series",
/// data-label = the series' label) and a legend on the right. The plot area is a rect of class
/// "plot-area"; the axes span exactly from its left to its right and bottom to top edge. The x axis and
/// a free y axis run from the last tick at or below the data to the first at or above it; all-equal
/// values and a single point are padded to a range around them, and no data gives (0, 1).
/// Throws vrd::Error when a series' x and y differ in length, yRange is not finite and increasing,
/// or the picture is too small to hold a plot area.
std::string svgPlot(const Plot& plot, int width = 720, int height = 420);

/// Writes svgPlot(plot) to `path`, complete or not at all. Throws vrd::Error.
void writeSvgPlot(const std::filesystem::path& path, const Plot& plot);

}  // namespace vrd
