// Lottie export (see lottie_export.h). Schema: lottie-docs (https://lottiefiles.github.io/
// lottie-docs/): animation, shape layer (ty 4), group (gr) with path (sh), fill (fl) and
// transform (tr). Path keyframes carry "s" only; since 5.5 players take the end value from the
// next keyframe, so "v" is 5.7.
#include "client/render/lottie_export.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "client/render/atomic_write.h"
#include "client/render/boundary_loops.h"
#include "client/render/color.h"
#include "client/render/viewport.h"

namespace inbetween::render {
namespace {

using json = nlohmann::json;

json Static(json value) { return {{"a", 0}, {"k", std::move(value)}}; }

// Pixel coordinates to 1/1000 px: exact enough, and far smaller files.
double Round3(double x) { return std::round(x * 1000.0) / 1000.0; }

json LayerTransform() {
  return {{"o", Static(100)},
          {"r", Static(0)},
          {"p", Static({0, 0, 0})},
          {"a", Static({0, 0, 0})},
          {"s", Static({100, 100, 100})}};
}

json GroupTransform() {
  return {{"ty", "tr"},          {"nm", "Transform"},       {"p", Static({0, 0})},
          {"a", Static({0, 0})}, {"s", Static({100, 100})}, {"r", Static(0)},
          {"o", Static(100)},    {"sk", Static(0)},         {"sa", Static(0)}};
}

// Closed polygon path (straight edges: zero tangents).
json LoopPath(const Loop& loop, const std::vector<Vertex>& vertices, const Viewport& viewport) {
  json v = json::array(), tangents = json::array();
  for (int i : loop) {
    const auto [x, y] = viewport.ToPixels(vertices[i]);
    v.push_back({Round3(x), Round3(y)});
    tangents.push_back({0, 0});
  }
  return {{"c", true}, {"v", std::move(v)}, {"i", tangents}, {"o", tangents}};
}

}  // namespace

absl::StatusOr<json> LottieAnimation(const FrameSet& frames, const LottieOptions& options) {
  if (absl::Status s = CheckFrameSet(frames); !s.ok()) return s;
  if (!(options.fps > 0) || !std::isfinite(options.fps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("Lottie frame rate ", options.fps, " must be positive"));
  }
  absl::StatusOr<Viewport> viewport = FrameSetViewport(frames, options.width);
  if (!viewport.ok()) return viewport.status();
  absl::StatusOr<Rgba8> fill = ParseColor(options.fill);
  if (!fill.ok()) return fill.status();
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(frames.triangles);
  if (!loops.ok()) return loops.status();

  const int count = static_cast<int>(frames.frames.size());
  json items = json::array();
  for (size_t l = 0; l < loops->size(); ++l) {
    json keyframes = json::array();
    for (int f = 0; f < count; ++f) {
      json key = {{"t", f}, {"s", {LoopPath((*loops)[l], frames.frames[f].vertices, *viewport)}}};
      if (f + 1 < count) {  // linear easing to the next keyframe
        key["o"] = {{"x", 0}, {"y", 0}};
        key["i"] = {{"x", 1}, {"y", 1}};
      }
      keyframes.push_back(std::move(key));
    }
    // A single frame is a static path: players reject one keyframe on an animated property.
    json ks = count == 1 ? Static(keyframes[0]["s"][0]) : json{{"a", 1}, {"k", keyframes}};
    items.push_back({{"ty", "sh"}, {"nm", absl::StrCat("Loop ", l + 1)}, {"ks", std::move(ks)}});
  }
  const auto rgba = [](const Rgba8& c) {
    return json::array({c.r / 255.0, c.g / 255.0, c.b / 255.0, 1});
  };
  json color = Static(rgba(*fill));
  if (options.drawing_fills && !frames.fills.empty()) {
    std::vector<Rgba8> per_frame;
    for (int f = 0; f < count; ++f) per_frame.push_back(*FrameFill(frames, f));
    const bool constant = std::all_of(per_frame.begin(), per_frame.end(),
                                      [&](const Rgba8& c) { return c == per_frame[0]; });
    if (constant) {
      color = Static(rgba(per_frame[0]));
    } else {
      json keyframes = json::array();
      for (int f = 0; f < count; ++f) {
        json key = {{"t", f}, {"s", rgba(per_frame[f])}};
        if (f + 1 < count) {
          key["o"] = {{"x", 0}, {"y", 0}};
          key["i"] = {{"x", 1}, {"y", 1}};
        }
        keyframes.push_back(std::move(key));
      }
      color = {{"a", 1}, {"k", std::move(keyframes)}};
    }
  }
  items.push_back({{"ty", "fl"},
                   {"nm", "Fill"},
                   {"c", std::move(color)},
                   {"o", Static(100 * fill->a / 255.0)},
                   {"r", 1}});  // nonzero: holes wind the other way
  items.push_back(GroupTransform());

  json layer = {
      {"ind", 1},
      {"ty", 4},
      {"nm", "Shape"},
      {"sr", 1},
      {"ks", LayerTransform()},
      {"ao", 0},
      {"shapes", json::array({{{"ty", "gr"}, {"nm", "Shape"}, {"it", std::move(items)}}})},
      {"ip", 0},
      {"op", count},
      {"st", 0}};
  return json{{"v", "5.7.4"},
              {"nm", options.name},
              {"fr", options.fps},
              {"ip", 0},
              {"op", count},
              {"w", viewport->width},
              {"h", viewport->height},
              {"assets", json::array()},
              {"layers", json::array({std::move(layer)})}};
}

absl::Status WriteLottie(const std::filesystem::path& path, const FrameSet& frames,
                         const LottieOptions& options) {
  absl::StatusOr<json> doc = LottieAnimation(frames, options);
  if (!doc.ok()) return doc.status();
  return WriteFileAtomically(path,
                             doc->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace inbetween::render
