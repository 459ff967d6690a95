// SVG frame export (see svg_frames.h): the frame's art, or the shape as its boundary outline; the
// mesh optional.
#include "client/render/svg_frames.h"

#include <optional>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/render/atomic_write.h"
#include "client/render/boundary_loops.h"
#include "client/render/bounds.h"
#include "solver/art/art_svg.h"

namespace inbetween::render {

std::string FrameSvg(const FrameSet& frames, size_t f, const SvgFrameOptions& options) {
  const Bounds b = FrameSetBounds(frames);
  const double margin = 0.05 * b.extent();
  const double seam = 0.002 * b.extent();
  const FrameData& frame = frames.frames[f];
  const auto& v = frame.vertices;
  std::optional<Rgba8> own = options.drawing_fills ? FrameFill(frames, f) : std::nullopt;
  const std::string fill = own ? HexColor(*own) : options.fill;
  std::ostringstream triangles;
  for (const auto& t : frames.triangles) {
    triangles << absl::StrFormat("M%.6g %.6gL%.6g %.6gL%.6g %.6gZ", v[t[0]][0], v[t[0]][1],
                                 v[t[1]][0], v[t[1]][1], v[t[2]][0], v[t[2]][1]);
  }
  std::string svg = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.6g %.6g %.6g %.6g\">\n"
      "<!-- inbetween frame %d, time %.6f -->\n",
      b.min_x - margin, b.min_y - margin, b.width() + 2 * margin, b.height() + 2 * margin,
      frame.index, frame.time);
  // The outline: one subpath per boundary loop, holes winding the other way (nonzero fill), so
  // there are no seams between triangles. A mesh BoundaryLoops rejects (inconsistent orientation)
  // still draws as its triangles, stroked in the fill colour to hide their hairline seams.
  absl::StatusOr<std::vector<solver::ArtLayer>> art = options.art && !frames.art.empty()
                                                          ? FrameArt(frames, f)
                                                          : absl::FailedPreconditionError("no art");
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(frames.triangles);
  if (art.ok()) {
    absl::StrAppend(&svg, solver::ArtToSvgPaths(*art));
  } else if (loops.ok()) {
    std::ostringstream outline;
    for (const Loop& loop : *loops) {
      for (size_t i = 0; i < loop.size(); ++i) {
        outline << absl::StrFormat("%c%.6g %.6g", i == 0 ? 'M' : 'L', v[loop[i]][0], v[loop[i]][1]);
      }
      outline << "Z";
    }
    absl::StrAppend(&svg, "<path fill=\"", fill, "\" fill-rule=\"nonzero\" d=\"", outline.str(),
                    "\"/>\n");
  } else {
    absl::StrAppend(&svg, "<path fill=\"", fill, "\" stroke=\"", fill, "\" stroke-width=\"",
                    absl::StrFormat("%.6g", seam), "\" d=\"", triangles.str(), "\"/>\n");
  }
  if (options.mesh_overlay) {
    absl::StrAppend(&svg, "<path fill=\"none\" stroke=\"#222\" stroke-width=\"",
                    absl::StrFormat("%.6g", seam), "\" d=\"", triangles.str(), "\"/>\n");
  }
  absl::StrAppend(&svg, "</svg>\n");
  return svg;
}

absl::Status WriteSvgFrames(const std::filesystem::path& dir, const FrameSet& frames,
                            const SvgFrameOptions& options) {
  for (size_t f = 0; f < frames.frames.size(); ++f) {
    const auto path = dir / absl::StrFormat("frame_%04d.svg", frames.frames[f].index);
    if (absl::Status s = WriteFileAtomically(path, FrameSvg(frames, f, options)); !s.ok()) return s;
  }
  return absl::OkStatus();
}

}  // namespace inbetween::render
