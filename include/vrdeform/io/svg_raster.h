#pragma once
// An SVG drawing as a PNG image (librsvg and cairo), for figures that go where SVG does not: slides,
// word processors, journals' submission systems.

#include <filesystem>
#include <string_view>

namespace vrd {

/// Renders `svg` at `scale` times its own size in pixels (2: sharp on a high-density screen and in
/// print) on its own background, and writes it to `png` complete or not at all. Throws vrd::Error
/// naming `png` when the SVG cannot be read, has no size, or the file cannot be written.
void writeSvgAsPng(std::string_view svg, const std::filesystem::path& png, double scale = 2.0);

}  // namespace vrd
