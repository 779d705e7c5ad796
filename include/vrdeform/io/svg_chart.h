#pragma once
// The user study's figures as self-contained SVG files (docs/study.md): box plots of ratings per
// group and condition (the paper's Figs. 8 and 9) and a diverging heatmap of per-item differences
// (its Fig. 10).

#include <string>
#include <utility>
#include <vector>

namespace vrd {

/// Groups along x (e.g. the dimensions), each with one box per series (e.g. the conditions).
struct BoxPlot {
  std::string title;
  std::string yLabel;
  std::vector<std::string> series;  ///< legend, one colour each
  std::vector<std::string> groups;  ///< labels along x
  /// values[group][series]: the samples of one box (non-finite ones left out; empty: no box).
  std::vector<std::vector<std::vector<double>>> values;
  std::pair<double, double> yRange{0.0, 1.0};  ///< the scale's ends, e.g. 1..7
};

/// Tukey boxes: quartiles (type 7, metrics/sample_stats.h), the median as a line, whiskers to the
/// furthest samples within 1.5 IQR of the box, the samples beyond as dots; each box a <g
/// class="box" data-group data-series data-median data-q1 data-q3> for readers and tests. Throws
/// vrd::Error when values does not match groups x series or the y range is not increasing.
std::string svgBoxPlot(const BoxPlot& plot, int width = 720, int height = 420);

/// A table of values coloured from blue (-range) through white (0) to red (+range), each cell
/// labelled with its value (two decimals); NaN cells grey and labelled "-".
struct Heatmap {
  std::string title;
  std::vector<std::string> rows, columns;
  std::vector<std::vector<double>> values;  ///< [row][column]
  double range = 1.0;
};

/// Each cell a <rect class="cell" data-row data-column data-value>. Throws vrd::Error when values
/// does not match rows x columns or range is not positive.
std::string svgHeatmap(const Heatmap& map);

}  // namespace vrd
