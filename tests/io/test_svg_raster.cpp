// Figures as PNG (io/svg_raster.h): drawn at twice the SVG's size, its shapes where the SVG puts
// them, in their colours; what is not an SVG drawing refused with the file named and nothing written.
#include <cairo.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/io/svg_chart.h"
#include "vrdeform/io/svg_raster.h"

namespace vrd {
namespace {

struct Png {
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface;
  int width() const { return cairo_image_surface_get_width(surface.get()); }
  int height() const { return cairo_image_surface_get_height(surface.get()); }
  std::uint32_t argb(int x, int y) const {  // cairo's ARGB32, premultiplied: opaque pixels as written
    const unsigned char* row =
        cairo_image_surface_get_data(surface.get()) + y * cairo_image_surface_get_stride(surface.get());
    return reinterpret_cast<const std::uint32_t*>(row)[x];
  }
};

Png readPng(const std::filesystem::path& path) {
  Png png{{cairo_image_surface_create_from_png(path.c_str()), &cairo_surface_destroy}};
  EXPECT_EQ(cairo_surface_status(png.surface.get()), CAIRO_STATUS_SUCCESS) << path;
  cairo_surface_flush(png.surface.get());
  return png;
}

TEST(SvgRaster, DrawsTheShapesWhereTheSvgPutsThemAtTwiceItsSize) {
  const testing::TempDir dir;
  const std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100\" height=\"50\">"
      "<rect width=\"100\" height=\"50\" fill=\"white\"/>"
      "<rect x=\"10\" y=\"10\" width=\"20\" height=\"20\" fill=\"#ff0000\"/>"
      "<rect x=\"60\" y=\"20\" width=\"30\" height=\"20\" fill=\"#0000ff\"/></svg>";
  writeSvgAsPng(svg, dir / "shapes.png");
  const Png png = readPng(dir / "shapes.png");
  ASSERT_EQ(png.width(), 200);
  ASSERT_EQ(png.height(), 100);
  EXPECT_EQ(png.argb(40, 40), 0xffff0000u);   // inside the red square (20-60 px)
  EXPECT_EQ(png.argb(150, 60), 0xff0000ffu);  // inside the blue one (120-180, 40-80 px)
  EXPECT_EQ(png.argb(100, 20), 0xffffffffu);  // between them: the white background
  EXPECT_EQ(png.argb(61, 40), 0xffffffffu);   // just right of the red square's edge at 60 px
}

TEST(SvgRaster, AChartKeepsItsTextAndBoxes) {
  const testing::TempDir dir;
  BoxPlot p{"title", "rating", {"A", "B"}, {"haptic"}, {{{1, 2, 3, 4, 5}, {2, 3, 4, 5, 6}}}, {1, 7}};
  writeSvgAsPng(svgBoxPlot(p, 360, 210), dir / "chart.png", 1.0);
  const Png png = readPng(dir / "chart.png");
  ASSERT_EQ(png.width(), 360);
  ASSERT_EQ(png.height(), 210);
  int dark = 0, coloured = 0;
  for (int y = 0; y < png.height(); ++y)
    for (int x = 0; x < png.width(); ++x) {
      const std::uint32_t c = png.argb(x, y);
      const int r = c >> 16 & 0xff, g = c >> 8 & 0xff, b = c & 0xff;
      dark += r < 80 && g < 80 && b < 80;                          // text, axes, medians
      coloured += std::max({r, g, b}) - std::min({r, g, b}) > 60;  // the boxes' fills
    }
  EXPECT_GT(dark, 200);
  EXPECT_GT(coloured, 500);
}

TEST(SvgRaster, WhatIsNotAnSvgDrawingIsRefusedAndNothingWritten) {
  const testing::TempDir dir;
  for (const std::string& bad :
       {std::string("not xml at all"), std::string("<svg xmlns=\"http://www.w3.org/2000/svg\""),
        std::string("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"0\" height=\"0\"/>")}) {
    try {
      writeSvgAsPng(bad, dir / "bad.png");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.png"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(dir.files().empty());
  }
  EXPECT_THROW(writeSvgAsPng("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"/>",
                             dir / "no-folder" / "x.png"),
               Error);
}

}  // namespace
}  // namespace vrd
