// Lottie (Bodymovin 5.x JSON) export: one shape layer whose group holds one path ("sh") per
// boundary loop, each with a keyframe per frame, and one nonzero fill, so holes stay holes.
// Coordinates use the same Viewport as the raster output (w = width px, y down, as Lottie).
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/statusor.h"
#include "client/render/frame_set.h"
#include "nlohmann/json.hpp"

namespace inbetween::render {

struct LottieOptions {
  int width = 512;               // composition width "w"; "h" follows the frames' aspect ratio
  double fps = 24;               // "fr"; frame i of the set is Lottie frame i
  std::string fill = "#3b7dd8";  // fill colour (see ParseColor); the background is transparent
  // FrameSet::fills instead of `fill` when present: a static colour when every frame has the same,
  // else the colour animated with one keyframe per frame.
  bool drawing_fills = true;
  std::string name = "inbetween";
};

// The Lottie document: v, fr, ip = 0, op = frame count, w, h, layers = [one shape layer].
// Linear interpolation between consecutive keyframes, so players may render sub-frames.
absl::StatusOr<nlohmann::json> LottieAnimation(const FrameSet& frames,
                                               const LottieOptions& options = {});

// LottieAnimation written compactly to `path` (temp name, then rename).
absl::Status WriteLottie(const std::filesystem::path& path, const FrameSet& frames,
                         const LottieOptions& options = {});

}  // namespace inbetween::render
