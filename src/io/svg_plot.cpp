#include "vrdeform/io/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string_view>

#include "io/xml_escape.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

/// Matplotlib's "tab10": distinct, and readable on white. Series beyond ten reuse them in order.
constexpr std::string_view kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

// Room around the plot area, in pixels: title above, tick labels and axis label below and left.
constexpr double kMarginTop = 36.0;
constexpr double kMarginBottom = 52.0;
constexpr double kMarginLeft = 72.0;
constexpr double kMarginRight = 16.0;
constexpr double kMinPlotSize = 40.0;
// Legend to the right of the plot area: a swatch line, then the label.
constexpr double kLegendSwatch = 22.0;
constexpr double kLegendRowHeight = 18.0;
constexpr double kCharWidth = 7.0;  // rough width of a 12 px sans-serif character
// Aimed-for distance between ticks, in pixels.
constexpr double kTickSpacingX = 80.0;
constexpr double kTickSpacingY = 50.0;
// Points far outside a fixed y range would map to huge or infinite pixels; they are clipped anyway.
constexpr double kMaxPixel = 1e7;
// Tolerance, in steps, for a value that lies on a tick but missed it by rounding.
constexpr double kTickEps = 1e-9;

/// An axis from lo to hi with ticks at the multiples of step in between.
struct Axis {
  double lo, hi, step;
};

/// 1, 2 or 5 x 10^k: the smallest such step that divides `span` into at most `ticks` intervals.
double niceStep(double span, double ticks) {
  const double raw = span / ticks;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * magnitude;
}

double tickCount(double pixels, double spacing) { return std::max(2.0, std::floor(pixels / spacing)); }

/// An axis for data in [lo, hi] (lo > hi: no data), widened to whole ticks.
Axis fitAxis(double lo, double hi, double pixels, double spacing) {
  if (!(lo <= hi)) {
    lo = 0.0;
    hi = 1.0;
  } else if (lo == hi) {
    const double pad = lo == 0.0 ? 1.0 : 0.5 * std::abs(lo);
    lo -= pad;
    hi += pad;
  }
  const double step = niceStep(hi - lo, tickCount(pixels, spacing));
  return {std::floor(lo / step + kTickEps) * step, std::ceil(hi / step - kTickEps) * step, step};
}

/// The tick values of `axis`, at most a few hundred even when rounding ruins the step.
std::vector<double> ticks(const Axis& axis) {
  const double first = std::ceil(axis.lo / axis.step - kTickEps);
  const double last = std::floor(axis.hi / axis.step + kTickEps);
  std::vector<double> values;
  for (int i = 0; i <= int(std::min(last - first, 200.0)); ++i) values.push_back((first + i) * axis.step);
  return values;
}

/// Enough decimals to tell ticks `step` apart; rounding noise near zero reads as 0, not -0 or 1e-17.
std::string tickLabel(double value, double step) {
  if (std::abs(value) < 1e-6 * step) value = 0.0;
  const int decimals = std::max(0, -int(std::floor(std::log10(step) + kTickEps)));
  if (decimals > 6 || std::abs(value) >= 1e7) return fmt::format("{:g}", value);
  return fmt::format("{:.{}f}", value, decimals);
}

/// Characters (not bytes) of UTF-8 text, for sizing the legend.
std::size_t characters(std::string_view text) {
  return std::size_t(std::count_if(text.begin(), text.end(), [](char c) { return (c & 0xC0) != 0x80; }));
}

/// Data to pixels: the plot area and the axes spanning it.
struct Frame {
  double left, top, right, bottom;
  Axis x, y;

  double px(double v) const { return clampPixel(left + (v - x.lo) / (x.hi - x.lo) * (right - left)); }
  double py(double v) const { return clampPixel(bottom - (v - y.lo) / (y.hi - y.lo) * (bottom - top)); }
  static double clampPixel(double p) { return std::clamp(p, -kMaxPixel, kMaxPixel); }
};

void validate(const Plot& plot) {
  for (const PlotSeries& s : plot.series) {
    if (s.x.size() != s.y.size()) {
      throw Error(fmt::format("svgPlot: series '{}' has {} x values but {} y values", s.label, s.x.size(), s.y.size()));
    }
  }
  if (plot.yRange) {
    const auto [lo, hi] = *plot.yRange;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) {
      throw Error(fmt::format("svgPlot: y range ({}, {}) must be finite and increasing", lo, hi));
    }
  }
}

Frame frameFor(const Plot& plot, int width, int height) {
  double legendWidth = 0.0;
  if (!plot.series.empty()) {
    std::size_t longest = 0;
    for (const PlotSeries& s : plot.series) longest = std::max(longest, characters(s.label));
    legendWidth = std::min(kLegendSwatch + 18.0 + kCharWidth * double(longest), width / 3.0);
  }
  Frame f{kMarginLeft, kMarginTop, width - kMarginRight - legendWidth, height - kMarginBottom, {}, {}};
  if (f.right - f.left < kMinPlotSize || f.bottom - f.top < kMinPlotSize) {
    throw Error(fmt::format("svgPlot: {}x{} pixels leave no room for a plot area", width, height));
  }
  const double inf = std::numeric_limits<double>::infinity();
  double xLo = inf, xHi = -inf, yLo = inf, yHi = -inf;
  for (const PlotSeries& s : plot.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xLo = std::min(xLo, s.x[i]);
      xHi = std::max(xHi, s.x[i]);
      yLo = std::min(yLo, s.y[i]);
      yHi = std::max(yHi, s.y[i]);
    }
  }
  f.x = fitAxis(xLo, xHi, f.right - f.left, kTickSpacingX);
  if (plot.yRange) {
    const auto [lo, hi] = *plot.yRange;
    f.y = {lo, hi, niceStep(hi - lo, tickCount(f.bottom - f.top, kTickSpacingY))};
  } else {
    f.y = fitAxis(yLo, yHi, f.bottom - f.top, kTickSpacingY);
  }
  return f;
}

using Out = std::back_insert_iterator<fmt::memory_buffer>;

void drawAxes(Out out, const Plot& plot, const Frame& f, int width, int height) {
  const std::vector<double> xTicks = ticks(f.x), yTicks = ticks(f.y);
  fmt::format_to(out, "<g class=\"grid\" stroke=\"#e5e5e5\">\n");
  for (double v : xTicks)
    fmt::format_to(out, "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\"/>\n", f.px(v), f.top,
                   f.bottom);
  for (double v : yTicks)
    fmt::format_to(out, "<line x1=\"{1:.2f}\" y1=\"{0:.2f}\" x2=\"{2:.2f}\" y2=\"{0:.2f}\"/>\n", f.py(v), f.left,
                   f.right);
  fmt::format_to(out, "</g>\n<g class=\"ticks\" stroke=\"#444\">\n");
  for (double v : xTicks)
    fmt::format_to(out, "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\"/>\n", f.px(v), f.bottom,
                   f.bottom + 5.0);
  for (double v : yTicks)
    fmt::format_to(out, "<line x1=\"{1:.2f}\" y1=\"{0:.2f}\" x2=\"{2:.2f}\" y2=\"{0:.2f}\"/>\n", f.py(v), f.left - 5.0,
                   f.left);
  fmt::format_to(out, "</g>\n<g class=\"x-ticks\" text-anchor=\"middle\">\n");
  for (double v : xTicks)
    fmt::format_to(out, "<text x=\"{:.2f}\" y=\"{:.2f}\">{}</text>\n", f.px(v), f.bottom + 19.0,
                   tickLabel(v, f.x.step));
  fmt::format_to(out, "</g>\n<g class=\"y-ticks\" text-anchor=\"end\">\n");
  // dy: 0.35em moves the text's baseline down so that its middle sits on the tick.
  for (double v : yTicks)
    fmt::format_to(out, "<text x=\"{:.2f}\" y=\"{:.2f}\" dy=\"0.35em\">{}</text>\n", f.left - 8.0, f.py(v),
                   tickLabel(v, f.y.step));
  fmt::format_to(out,
                 "</g>\n<rect class=\"plot-area\" x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" "
                 "fill=\"none\" stroke=\"#444\"/>\n",
                 f.left, f.top, f.right - f.left, f.bottom - f.top);
  const double midX = 0.5 * (f.left + f.right), midY = 0.5 * (f.top + f.bottom);
  if (!plot.title.empty()) {
    fmt::format_to(out,
                   "<text class=\"title\" x=\"{:.2f}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\" "
                   "font-weight=\"bold\">{}</text>\n",
                   0.5 * width, escapeXml(plot.title));
  }
  if (!plot.xLabel.empty()) {
    fmt::format_to(out, "<text class=\"x-label\" x=\"{:.2f}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", midX,
                   height - 12, escapeXml(plot.xLabel));
  }
  if (!plot.yLabel.empty()) {
    fmt::format_to(out,
                   "<text class=\"y-label\" x=\"18\" y=\"{0:.2f}\" transform=\"rotate(-90 18 {0:.2f})\" "
                   "text-anchor=\"middle\">{1}</text>\n",
                   midY, escapeXml(plot.yLabel));
  }
}

/// One polyline per run of finite points. A run of one point is written twice: a zero-length line with
/// round caps draws as a dot, widened to be seen.
void drawSeries(Out out, const PlotSeries& s, std::string_view colour, const Frame& f) {
  const std::string label = escapeXml(s.label);
  fmt::memory_buffer points;
  std::size_t runLength = 0;
  auto flush = [&] {
    if (runLength == 0) return;
    std::string_view dot;
    if (runLength == 1) {
      const std::string point = fmt::to_string(points);
      fmt::format_to(std::back_inserter(points), " {}", point);
      dot = " stroke-width=\"4\"";
    }
    fmt::format_to(out, "<polyline class=\"series\" data-label=\"{}\" stroke=\"{}\"{} points=\"{}\"/>\n", label, colour,
                   dot, std::string_view(points.data(), points.size()));
    points.clear();
    runLength = 0;
  };
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
      flush();
      continue;
    }
    fmt::format_to(std::back_inserter(points), "{}{:.2f},{:.2f}", runLength ? " " : "", f.px(s.x[i]), f.py(s.y[i]));
    ++runLength;
  }
  flush();
}

void drawLegend(Out out, const Plot& plot, const Frame& f) {
  fmt::format_to(out, "<g class=\"legend\">\n");
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const double x = f.right + 12.0, y = f.top + 8.0 + kLegendRowHeight * double(i);
    fmt::format_to(out,
                   "<line x1=\"{:.2f}\" y1=\"{:.2f}\" x2=\"{:.2f}\" y2=\"{:.2f}\" stroke=\"{}\" stroke-width=\"2\"/>\n",
                   x, y, x + kLegendSwatch, y, kPalette[i % std::size(kPalette)]);
    fmt::format_to(out, "<text x=\"{:.2f}\" y=\"{:.2f}\" dy=\"0.35em\">{}</text>\n", x + kLegendSwatch + 6.0, y,
                   escapeXml(plot.series[i].label));
  }
  fmt::format_to(out, "</g>\n");
}

}  // namespace

std::string svgPlot(const Plot& plot, int width, int height) {
  validate(plot);
  const Frame f = frameFor(plot, width, height);
  fmt::memory_buffer buffer;
  Out out(buffer);
  fmt::format_to(out,
                 "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0}\" height=\"{1}\" "
                 "viewBox=\"0 0 {0} {1}\" font-family=\"sans-serif\" font-size=\"12\">\n"
                 "<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
                 "<defs><clipPath id=\"plot-clip\"><rect x=\"{2:.2f}\" y=\"{3:.2f}\" width=\"{4:.2f}\" "
                 "height=\"{5:.2f}\"/></clipPath></defs>\n",
                 width, height, f.left, f.top, f.right - f.left, f.bottom - f.top);
  drawAxes(out, plot, f, width, height);
  fmt::format_to(out,
                 "<g clip-path=\"url(#plot-clip)\" fill=\"none\" stroke-width=\"1.5\" stroke-linejoin=\"round\" "
                 "stroke-linecap=\"round\">\n");
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    drawSeries(out, plot.series[i], kPalette[i % std::size(kPalette)], f);
  }
  fmt::format_to(out, "</g>\n");
  drawLegend(out, plot, f);
  fmt::format_to(out, "</svg>\n");
  return fmt::to_string(buffer);
}

void writeSvgPlot(const std::filesystem::path& path, const Plot& plot) { writeFile(path, svgPlot(plot)); }

}  // namespace vrd
