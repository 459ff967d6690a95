// frames.json and per-frame SVG writers for the CLI (see frames_output.h).
#include "client/frames_output.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inbetween::client {
namespace {

absl::Status WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) return absl::UnavailableError(absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

struct Bounds {
  double min_x = std::numeric_limits<double>::infinity();
  double min_y = std::numeric_limits<double>::infinity();
  double max_x = -std::numeric_limits<double>::infinity();
  double max_y = -std::numeric_limits<double>::infinity();
  void Add(const v1::Point& p) {
    min_x = std::min(min_x, p.x());
    min_y = std::min(min_y, p.y());
    max_x = std::max(max_x, p.x());
    max_y = std::max(max_y, p.y());
  }
};

std::string FrameSvg(const FramesResult& frames, const v1::InbetweenFrame& frame,
                     const Bounds& b, const SvgFrameOptions& options) {
  const double margin = 0.05 * std::max(b.max_x - b.min_x, b.max_y - b.min_y);
  const double seam = 0.002 * std::max(b.max_x - b.min_x, b.max_y - b.min_y);
  std::ostringstream path;
  const auto& v = frame.vertices();
  for (const auto& t : frames.header.triangles()) {
    path << absl::StrFormat("M%.6g %.6gL%.6g %.6gL%.6g %.6gZ", v[t.a()].x(), v[t.a()].y(),
                            v[t.b()].x(), v[t.b()].y(), v[t.c()].x(), v[t.c()].y());
  }
  std::string svg = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.6g %.6g %.6g %.6g\">\n"
      "<!-- inbetween frame %u, time %.6f -->\n",
      b.min_x - margin, b.min_y - margin, b.max_x - b.min_x + 2 * margin,
      b.max_y - b.min_y + 2 * margin, frame.index(), frame.time());
  // Triangles stroked in their own colour hide the hairline seams between them.
  absl::StrAppend(&svg, "<path fill=\"", options.fill, "\" stroke=\"", options.fill,
                  "\" stroke-width=\"", absl::StrFormat("%.6g", seam), "\" d=\"", path.str(),
                  "\"/>\n");
  if (options.mesh_overlay) {
    absl::StrAppend(&svg, "<path fill=\"none\" stroke=\"#222\" stroke-width=\"",
                    absl::StrFormat("%.6g", seam), "\" d=\"", path.str(), "\"/>\n");
  }
  absl::StrAppend(&svg, "</svg>\n");
  return svg;
}

}  // namespace

nlohmann::json FramesToJson(const FramesResult& frames) {
  nlohmann::json triangles = nlohmann::json::array();
  for (const auto& t : frames.header.triangles()) triangles.push_back({t.a(), t.b(), t.c()});
  nlohmann::json out_frames = nlohmann::json::array();
  for (const auto& f : frames.frames) {
    nlohmann::json vertices = nlohmann::json::array();
    for (const auto& p : f.vertices()) vertices.push_back({p.x(), p.y()});
    out_frames.push_back({{"index", f.index()},
                          {"time", f.time()},
                          {"weights", std::vector<double>(f.weights().begin(), f.weights().end())},
                          {"vertices", std::move(vertices)}});
  }
  return {{"triangles", std::move(triangles)},
          {"keys", std::vector<uint32_t>(frames.header.keys().begin(), frames.header.keys().end())},
          {"frames", std::move(out_frames)}};
}

absl::Status WriteFrames(const std::filesystem::path& dir, const FramesResult& frames,
                         const SvgFrameOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return absl::UnavailableError(absl::StrCat("cannot create ", dir.string(), ": ",
                                                     ec.message()));
  Bounds bounds;
  for (const auto& f : frames.frames) {
    for (const auto& p : f.vertices()) bounds.Add(p);
  }
  for (const auto& f : frames.frames) {
    absl::Status s = WriteFile(dir / absl::StrFormat("frame_%04u.svg", f.index()),
                               FrameSvg(frames, f, bounds, options));
    if (!s.ok()) return s;
  }
  return WriteFile(dir / "frames.json", FramesToJson(frames).dump() + "\n");
}

}  // namespace inbetween::client
