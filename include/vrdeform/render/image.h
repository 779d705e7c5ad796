#pragma once
// An 8-bit RGBA image, rows from top to bottom, as rendered frames and screenshots are kept, and
// its PNG file form.

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace vrd {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  ///< width * height * 4 bytes, row 0 at the top

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(std::size_t(w) * std::size_t(h) * 4, 0) {}
  std::array<std::uint8_t, 4> pixel(int x, int y) const {
    const std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
    return {p[0], p[1], p[2], p[3]};
  }
};

/// Writes the image as a PNG file (written whole or not at all). Throws vrd::Error.
void writePng(const std::filesystem::path& path, const Image& image);
/// Reads a PNG file as RGBA. Throws vrd::Error naming the file.
Image readPng(const std::filesystem::path& path);

}  // namespace vrd
