// Lottie export (see lottie_export.h). Schema: lottie-docs (https://lottiefiles.github.io/
// lottie-docs/): animation, shape layer (ty 4), group (gr) with path (sh), fill (fl) and
// transform (tr). Path keyframes carry "s" only; since 5.5 players take the end value from the
// next keyframe, so "v" is 5.7.
#include "client/render/lottie_export.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/render/atomic_write.h"
#include "client/render/boundary_loops.h"
#include "client/render/color.h"
#include "client/render/lottie_json.h"
#include "client/render/viewport.h"

namespace inbetween::render {
namespace {

using lottie::Animated;
using lottie::Document;
using lottie::GroupTransform;
using lottie::json;
using lottie::LayerTransform;
using lottie::Rgba;
using lottie::Round3;
using lottie::ShapeLayer;
using lottie::Static;

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

// The silhouette: one layer, a path per boundary loop, one fill (see the header).
absl::StatusOr<json> SilhouetteAnimation(const FrameSet& frames, const LottieOptions& options,
                                         const Viewport& viewport, const Rgba8& fill) {
  absl::StatusOr<std::vector<Loop>> loops = BoundaryLoops(frames.triangles);
  if (!loops.ok()) return loops.status();
  const int count = static_cast<int>(frames.frames.size());
  json items = json::array();
  for (size_t l = 0; l < loops->size(); ++l) {
    json keyframes = json::array();
    for (int f = 0; f < count; ++f) {
      json key = {{"t", f}, {"s", {LoopPath((*loops)[l], frames.frames[f].vertices, viewport)}}};
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
  json color = Static(Rgba(fill));
  if (options.drawing_fills && !frames.fills.empty()) {
    std::vector<json> per_frame;
    for (int f = 0; f < count; ++f) per_frame.push_back(Rgba(*FrameFill(frames, f)));
    color = Animated(per_frame, 0);
  }
  items.push_back({{"ty", "fl"},
                   {"nm", "Fill"},
                   {"c", std::move(color)},
                   {"o", Static(100 * fill.a / 255.0)},
                   {"r", 1}});  // nonzero: holes wind the other way
  items.push_back(GroupTransform());
  return Document(
      options, viewport, count,
      json::array({ShapeLayer(1, "Shape", LayerTransform(), std::move(items), 0, count)}));
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
  if (options.art && !frames.art.empty()) return lottie::ArtAnimation(frames, options, *viewport);
  return SilhouetteAnimation(frames, options, *viewport, *fill);
}

absl::Status WriteLottie(const std::filesystem::path& path, const FrameSet& frames,
                         const LottieOptions& options) {
  absl::StatusOr<json> doc = LottieAnimation(frames, options);
  if (!doc.ok()) return doc.status();
  return WriteFileAtomically(path,
                             doc->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace inbetween::render
