#include "vrdeform/io/svg_raster.h"

#include <cairo.h>
#include <fmt/format.h>
#include <librsvg/rsvg.h>

#include <cmath>
#include <memory>
#include <string>

#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

// A GError's message, the error freed.
std::string take(GError* error) {
  if (!error) return "unknown error";
  std::string message = error->message;
  g_error_free(error);
  return message;
}

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

void writeSvgAsPng(std::string_view svg, const std::filesystem::path& png, double scale) {
  const auto fail = [&](std::string_view why) { return Error(fmt::format("{}: {}", png.string(), why)); };
  if (!(std::isfinite(scale) && scale > 0.0 && scale <= 16.0)) throw fail(fmt::format("bad scale {}", scale));
  GError* error = nullptr;
  const std::unique_ptr<RsvgHandle, decltype(&g_object_unref)> handle(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error), &g_object_unref);
  if (!handle) throw fail("not an SVG drawing: " + take(error));
  double width = 0.0, height = 0.0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle.get(), &width, &height) || !(width >= 1.0 && height >= 1.0) ||
      width * scale > 16384.0 || height * scale > 16384.0)
    throw fail("the SVG drawing has no width and height in pixels, or too large ones");
  const int w = int(std::ceil(width * scale)), h = int(std::ceil(height * scale));
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h), &cairo_surface_destroy);
  const std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), &cairo_destroy);
  const RsvgRectangle viewport{0.0, 0.0, double(w), double(h)};
  if (!rsvg_handle_render_document(handle.get(), cr.get(), &viewport, &error))
    throw fail("cannot draw the SVG: " + take(error));
  cairo_surface_flush(surface.get());
  std::string bytes;
  if (cairo_surface_write_to_png_stream(surface.get(), append, &bytes) != CAIRO_STATUS_SUCCESS)
    throw fail("cannot encode the PNG");
  writeFile(png, bytes);
}

}  // namespace vrd
