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

struct GObjectUnref {
  void operator()(void* p) const { g_object_unref(p); }
};
struct SurfaceDestroy {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDestroy {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

void writeSvgAsPng(std::string_view svg, const std::filesystem::path& png, double scale) {
  const auto fail = [&](std::string_view why) { return Error(fmt::format("{}: {}", png.string(), why)); };
  if (!(std::isfinite(scale) && scale > 0.0 && scale <= 16.0)) throw fail(fmt::format("bad scale {}", scale));
  GError* error = nullptr;
  const std::unique_ptr<RsvgHandle, GObjectUnref> handle(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error));
  if (!handle) {
    const std::string why = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    throw fail("not an SVG drawing: " + why);
  }
  double width = 0.0, height = 0.0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle.get(), &width, &height) || !(width >= 1.0 && height >= 1.0) ||
      width * scale > 16384.0 || height * scale > 16384.0)
    throw fail("the SVG drawing has no width and height in pixels, or too large ones");
  const int w = int(std::ceil(width * scale)), h = int(std::ceil(height * scale));
  const std::unique_ptr<cairo_surface_t, SurfaceDestroy> surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h));
  const std::unique_ptr<cairo_t, ContextDestroy> cr(cairo_create(surface.get()));
  const RsvgRectangle viewport{0.0, 0.0, double(w), double(h)};
  if (!rsvg_handle_render_document(handle.get(), cr.get(), &viewport, &error)) {
    const std::string why = error ? error->message : "unknown error";
    if (error) g_error_free(error);
    throw fail("cannot draw the SVG: " + why);
  }
  cairo_surface_flush(surface.get());
  std::string bytes;
  if (cairo_surface_write_to_png_stream(surface.get(), append, &bytes) != CAIRO_STATUS_SUCCESS)
    throw fail("cannot encode the PNG");
  writeFile(png, bytes);
}

}  // namespace vrd
