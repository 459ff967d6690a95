// Cairo frame rendering (see raster.h).
#include "client/render/raster.h"

#include <algorithm>
#include <set>

#include "client/render/art_painter.h"
#include "client/render/cairo_image.h"

namespace inbetween::render {
namespace {

void SetSource(cairo_t* cr, const Rgba8& c) {
  cairo_set_source_rgba(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0, c.a / 255.0);
}

}  // namespace

absl::StatusOr<FrameRasterizer> FrameRasterizer::Create(const FrameSet& frames,
                                                        RasterOptions options) {
  if (absl::Status s = CheckFrameSet(frames); !s.ok()) return s;
  FrameRasterizer r;
  r.frames_ = &frames;
  absl::StatusOr<Viewport> viewport = FrameSetViewport(frames, options.width);
  if (!viewport.ok()) return viewport.status();
  r.viewport_ = *viewport;
  absl::StatusOr<Rgba8> fill = ParseColor(options.fill);
  if (!fill.ok()) return fill.status();
  r.fill_ = *fill;
  if (options.drawing_fills && !frames.fills.empty()) {
    for (size_t f = 0; f < frames.frames.size(); ++f)
      r.frame_fills_.push_back(*FrameFill(frames, f));
  }
  r.draw_art_ = options.art && !frames.art.empty();
  r.background_ = options.transparent ? Rgba8{255, 255, 255, 0} : Rgba8{255, 255, 255, 255};
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(frames.triangles);
  if (!loops.ok()) return loops.status();
  r.loops_ = *std::move(loops);
  if (options.mesh_overlay) {
    std::set<std::pair<int, int>> edges;
    for (const auto& t : frames.triangles) {
      for (int i = 0; i < 3; ++i) {
        edges.insert(std::minmax(t[i], t[(i + 1) % 3]));
      }
    }
    r.edges_.assign(edges.begin(), edges.end());
  }
  r.options_ = std::move(options);
  return r;
}

Rgba8 FrameRasterizer::FillOf(size_t f) const {
  return f < frame_fills_.size() ? frame_fills_[f] : fill_;
}

RgbaImage FrameRasterizer::Render(size_t f) const {
  const std::vector<Vertex>& v = frames_->frames[f].vertices;
  CairoSurface surface(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, viewport_.width, viewport_.height));
  Cairo cr(cairo_create(surface.get()));
  if (background_.a > 0) {
    SetSource(cr.get(), background_);
    cairo_paint(cr.get());
  }
  // CheckFrameSet (in Create) guarantees the art fits every frame; the silhouette stays as a
  // fallback so that a frame is never left blank.
  absl::StatusOr<std::vector<solver::ArtLayer>> art =
      draw_art_ ? FrameArt(*frames_, f) : absl::FailedPreconditionError("no art");
  if (art.ok()) {
    PaintArt(cr.get(), *art, viewport_);
  } else {
    // One path of every loop, filled once: no seams between triangles, holes by winding.
    cairo_set_fill_rule(cr.get(), CAIRO_FILL_RULE_WINDING);
    for (const Loop& loop : loops_) {
      for (size_t i = 0; i < loop.size(); ++i) {
        const auto [x, y] = viewport_.ToPixels(v[loop[i]]);
        if (i == 0) {
          cairo_move_to(cr.get(), x, y);
        } else {
          cairo_line_to(cr.get(), x, y);
        }
      }
      cairo_close_path(cr.get());
    }
    SetSource(cr.get(), FillOf(f));
    cairo_fill(cr.get());
  }
  if (!edges_.empty()) {
    for (const auto& [a, b] : edges_) {
      const auto [xa, ya] = viewport_.ToPixels(v[a]);
      const auto [xb, yb] = viewport_.ToPixels(v[b]);
      cairo_move_to(cr.get(), xa, ya);
      cairo_line_to(cr.get(), xb, yb);
    }
    // Hairlines scale with the image a little so large renders stay readable.
    cairo_set_line_width(cr.get(), std::max(0.75, viewport_.width / 1024.0));
    cairo_set_line_cap(cr.get(), CAIRO_LINE_CAP_ROUND);
    SetSource(cr.get(), kMeshOverlayColor);
    cairo_stroke(cr.get());
  }
  return ImageFromSurface(surface.get());
}

}  // namespace inbetween::render
