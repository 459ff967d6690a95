// PNG I/O via cairo (see png_io.h).
#include "client/render/png_io.h"

#include "absl/strings/str_cat.h"
#include "client/render/atomic_write.h"
#include "client/render/cairo_image.h"

namespace inbetween::render {
namespace {

cairo_status_t AppendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

absl::StatusOr<std::string> EncodePng(const RgbaImage& image) {
  if (image.width <= 0 || image.height <= 0) {
    return absl::InvalidArgumentError("cannot encode an empty image as PNG");
  }
  CairoSurface surface = SurfaceFromImage(image);
  std::string bytes;
  const cairo_status_t status =
      cairo_surface_write_to_png_stream(surface.get(), AppendToString, &bytes);
  if (status != CAIRO_STATUS_SUCCESS) {
    return absl::InternalError(
        absl::StrCat("PNG encoding failed: ", cairo_status_to_string(status)));
  }
  return bytes;
}

absl::Status WritePng(const std::filesystem::path& path, const RgbaImage& image) {
  absl::StatusOr<std::string> bytes = EncodePng(image);
  if (!bytes.ok()) return bytes.status();
  return WriteFileAtomically(path, *bytes);
}

absl::StatusOr<RgbaImage> ReadPng(const std::filesystem::path& path) {
  CairoSurface surface(cairo_image_surface_create_from_png(path.c_str()));
  const cairo_status_t status = cairo_surface_status(surface.get());
  if (status != CAIRO_STATUS_SUCCESS) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot read PNG ", path.string(), ": ", cairo_status_to_string(status)));
  }
  return ImageFromSurface(surface.get());
}

}  // namespace inbetween::render
