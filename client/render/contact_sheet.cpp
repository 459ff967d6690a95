// Contact sheet rendering (see contact_sheet.h).
#include "client/render/contact_sheet.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "client/render/cairo_image.h"
#include "client/render/png_io.h"

namespace inbetween::render {

std::vector<size_t> ContactSheetFrames(const FrameSet& frames, int inbetweens) {
  const size_t n = frames.frames.size();
  std::set<size_t> keys;
  for (int key : frames.keys) {
    for (size_t f = 0; f < n; ++f) {
      if (frames.frames[f].index == key) keys.insert(f);
    }
  }
  std::set<size_t> shown = keys;
  // Evenly spaced over the whole sequence, endpoints excluded (they are usually keys).
  for (int i = 0; i < inbetweens && n > 0; ++i) {
    const double at = (i + 1) * static_cast<double>(n - 1) / (inbetweens + 1);
    const size_t f = static_cast<size_t>(std::lround(at));
    if (!keys.count(f)) shown.insert(f);
  }
  return {shown.begin(), shown.end()};
}

absl::StatusOr<RgbaImage> RenderContactSheet(const FrameSet& frames,
                                             const ContactSheetOptions& options) {
  if (options.columns < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("contact sheet columns ", options.columns, " must be at least 1"));
  }
  absl::StatusOr<FrameRasterizer> raster =
      FrameRasterizer::Create(frames, {.width = options.cell_width,
                                       .fill = options.fill,
                                       .drawing_fills = options.drawing_fills,
                                       .mesh_overlay = options.mesh_overlay,
                                       .transparent = false,
                                       .art = options.art});
  if (!raster.ok()) return raster.status();
  const std::vector<size_t> shown = ContactSheetFrames(frames, options.inbetweens);
  const int count = static_cast<int>(shown.size());
  const int columns = std::min(options.columns, count);
  const int rows = (count + columns - 1) / columns;
  const int cell_w = raster->width();
  const int cell_h = raster->height() + kContactSheetLabelHeight;
  if (static_cast<int64_t>(columns) * cell_w > kMaxImageSide ||
      static_cast<int64_t>(rows) * cell_h > kMaxImageSide) {
    return absl::InvalidArgumentError(absl::StrCat("contact sheet of ", columns, " x ", rows,
                                                   " cells is larger than ", kMaxImageSide,
                                                   " px; use a smaller cell size"));
  }
  CairoSurface sheet(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, columns * cell_w, rows * cell_h));
  Cairo cr(cairo_create(sheet.get()));
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  cairo_select_font_face(cr.get(), "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr.get(), 0.6 * kContactSheetLabelHeight);
  std::set<int> keys(frames.keys.begin(), frames.keys.end());
  for (int i = 0; i < count; ++i) {
    const FrameData& frame = frames.frames[shown[i]];
    const double x = (i % columns) * cell_w, y = (i / columns) * cell_h;
    CairoSurface cell = SurfaceFromImage(raster->Render(shown[i]));
    cairo_set_source_surface(cr.get(), cell.get(), x, y);
    cairo_paint(cr.get());
    const bool key = keys.count(frame.index) > 0;
    const std::string label = absl::StrCat("frame ", frame.index, key ? "  key" : "");
    cairo_set_source_rgb(cr.get(), key ? 0.75 : 0.2, 0.2, 0.2);
    cairo_move_to(cr.get(), x + 6, y + cell_h - 0.3 * kContactSheetLabelHeight);
    cairo_show_text(cr.get(), label.c_str());
    // Cell separators.
    cairo_set_source_rgb(cr.get(), 0.8, 0.8, 0.8);
    cairo_set_line_width(cr.get(), 1);
    cairo_rectangle(cr.get(), x + 0.5, y + 0.5, cell_w - 1, cell_h - 1);
    cairo_stroke(cr.get());
  }
  return ImageFromSurface(sheet.get());
}

absl::Status WriteContactSheet(const std::filesystem::path& path, const FrameSet& frames,
                               const ContactSheetOptions& options) {
  absl::StatusOr<RgbaImage> sheet = RenderContactSheet(frames, options);
  if (!sheet.ok()) return sheet.status();
  return WritePng(path, *sheet);
}

}  // namespace inbetween::render
