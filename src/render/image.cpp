#include "vrdeform/render/image.h"

#include <fmt/format.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <memory>
#include <system_error>

#include "vrdeform/error.h"

namespace vrd {

void writePng(const std::filesystem::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != std::size_t(image.width) * image.height * 4)
    throw Error(fmt::format("{}: not a whole {}x{} image", path.string(), image.width, image.height));
  // Into a temporary beside it, then renamed: a reader never sees half a frame.
  std::filesystem::path temp = path;
  temp += ".part";
  if (!stbi_write_png(temp.c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4)) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    throw Error(fmt::format("{}: cannot write the PNG file", path.string()));
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) throw Error(fmt::format("{}: {}", path.string(), ec.message()));
}

Image readPng(const std::filesystem::path& path) {
  int w = 0, h = 0, channels = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &channels, 4), stbi_image_free);
  if (!data) throw Error(fmt::format("{}: not a readable image ({})", path.string(), stbi_failure_reason()));
  Image image(w, h);
  std::copy_n(data.get(), image.rgba.size(), image.rgba.begin());
  return image;
}

}  // namespace vrd
