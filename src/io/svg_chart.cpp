#include "vrdeform/io/svg_chart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "io/xml_escape.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/sample_stats.h"

namespace vrd {
namespace {

constexpr std::string_view kColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"};

std::string header(int width, int height, const std::string& title) {
  return fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
      "<text x=\"{2}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">{3}</text>\n",
      width, height, width / 2, escapeXml(title));
}

}  // namespace

std::string svgBoxPlot(const BoxPlot& plot, int width, int height) {
  const std::size_t ng = plot.groups.size(), ns = plot.series.size();
  if (plot.values.size() != ng) throw Error("box plot: values needs one entry per group");
  for (const auto& g : plot.values)
    if (g.size() != ns) throw Error("box plot: each group needs one sample list per series");
  const auto [lo, hi] = plot.yRange;
  if (!(std::isfinite(lo) && std::isfinite(hi) && lo < hi)) throw Error("box plot: the y range must be increasing");
  const double left = 60, right = width - 120.0, top = 40, bottom = height - 40.0;
  const auto y = [&](double v) { return bottom - (v - lo) / (hi - lo) * (bottom - top); };
  std::string svg = header(width, height, plot.title);
  for (int k = 0; k <= 6; ++k) {  // grid lines and labels at seven even steps of the scale
    const double v = lo + (hi - lo) * k / 6.0;
    svg += fmt::format(
        "<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>\n"
        "<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{:g}</text>\n",
        left, right, y(v), y(v), left - 6, y(v) + 4, std::round(v * 100) / 100);
  }
  svg += fmt::format("<text transform=\"translate(16 {:.1f}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
                     (top + bottom) / 2, escapeXml(plot.yLabel));
  const double groupWidth = (right - left) / double(std::max<std::size_t>(ng, 1));
  const double boxWidth = groupWidth * 0.7 / double(std::max<std::size_t>(ns, 1));
  for (std::size_t g = 0; g < ng; ++g) {
    const double x0 = left + groupWidth * double(g) + groupWidth * 0.15;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n",
                       left + groupWidth * (double(g) + 0.5), bottom + 18, escapeXml(plot.groups[g]));
    for (std::size_t s = 0; s < ns; ++s) {
      std::vector<double> v;
      for (double x : plot.values[g][s])
        if (std::isfinite(x)) v.push_back(x);
      if (v.empty()) continue;
      std::sort(v.begin(), v.end());
      const double q1 = percentileOfSorted(v, 0.25), median = percentileOfSorted(v, 0.5),
                   q3 = percentileOfSorted(v, 0.75), reach = 1.5 * (q3 - q1);
      double low = q1, high = q3;
      for (double x : v) {
        if (x >= q1 - reach) low = std::min(low, x);
        if (x <= q3 + reach) high = std::max(high, x);
      }
      const std::string_view colour = kColours[s % std::size(kColours)];
      const double xl = x0 + boxWidth * double(s) + boxWidth * 0.1, xr = xl + boxWidth * 0.8, xm = (xl + xr) / 2;
      svg += fmt::format(
          "<g class=\"box\" data-group=\"{}\" data-series=\"{}\" data-median=\"{:g}\" data-q1=\"{:g}\" "
          "data-q3=\"{:g}\">\n"
          "<line class=\"whisker\" x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#333\"/>\n"
          "<line class=\"whisker\" x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#333\"/>\n"
          "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\" fill-opacity=\"0.5\" "
          "stroke=\"{}\"/>\n"
          "<line x1=\"{:.1f}\" x2=\"{:.1f}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#000\" stroke-width=\"2\"/>\n",
          escapeXml(plot.groups[g]), escapeXml(plot.series[s]), median, q1, q3, xm, xm, y(high), y(q3), xm, xm, y(q1),
          y(low), xl, y(q3), xr - xl, std::max(0.5, y(q1) - y(q3)), colour, colour, xl, xr, y(median), y(median));
      for (double x : v)
        if (x < low || x > high)
          svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"{}\"/>\n", xm, y(x), colour);
      svg += "</g>\n";
    }
  }
  for (std::size_t s = 0; s < ns; ++s)
    svg += fmt::format(
        "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"14\" height=\"14\" fill=\"{}\" fill-opacity=\"0.5\"/>"
        "<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n",
        right + 16, top + 20.0 * double(s), kColours[s % std::size(kColours)], right + 36, top + 20.0 * double(s) + 12,
        escapeXml(plot.series[s]));
  return svg + "</svg>\n";
}

std::string svgHeatmap(const Heatmap& map) {
  const std::size_t nr = map.rows.size(), nc = map.columns.size();
  if (map.values.size() != nr) throw Error("heatmap: values needs one row per row label");
  for (const auto& r : map.values)
    if (r.size() != nc) throw Error("heatmap: each row needs one value per column");
  if (!(map.range > 0 && std::isfinite(map.range))) throw Error("heatmap: the range must be positive");
  constexpr double kCell = 56, kRow = 24, kLeft = 80, kTop = 60;
  const int width = int(std::max(kLeft + kCell * double(nc) + 20, 8.0 * double(map.title.size()) + 40)),
            height = int(kTop + kRow * double(nr) + 20);
  std::string svg = header(width, height, map.title);
  for (std::size_t c = 0; c < nc; ++c)
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\">{}</text>\n",
                       kLeft + kCell * (double(c) + 0.5), kTop - 8, escapeXml(map.columns[c]));
  for (std::size_t r = 0; r < nr; ++r) {
    const double yTop = kTop + kRow * double(r);
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", kLeft - 8, yTop + 16,
                       escapeXml(map.rows[r]));
    for (std::size_t c = 0; c < nc; ++c) {
      const double v = map.values[r][c];
      std::string fill = "#ccc", label = "-";
      if (std::isfinite(v)) {  // white to red above 0, white to blue below
        const double t = std::clamp(std::abs(v) / map.range, 0.0, 1.0);
        const int fade = int(std::lround(255 * (1 - t)));
        fill = v >= 0 ? fmt::format("#ff{0:02x}{0:02x}", fade) : fmt::format("#{0:02x}{0:02x}ff", fade);
        label = fmt::format("{:.2f}", v);
      }
      svg += fmt::format(
          "<rect class=\"cell\" data-row=\"{}\" data-column=\"{}\" data-value=\"{}\" x=\"{:.1f}\" y=\"{:.1f}\" "
          "width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"white\"/>\n<text x=\"{:.1f}\" y=\"{:.1f}\" "
          "text-anchor=\"middle\">{}</text>\n",
          escapeXml(map.rows[r]), escapeXml(map.columns[c]), label, kLeft + kCell * double(c), yTop, kCell, kRow, fill,
          kLeft + kCell * (double(c) + 0.5), yTop + 16, label);
    }
  }
  return svg + "</svg>\n";
}

}  // namespace vrd
