// Lottie (Bodymovin 5.x JSON) export, in one of two forms. Coordinates use the same Viewport as
// the raster output (w = width px, y down, as Lottie); every path has a keyframe per frame with
// linear easing to the next, so players may render sub-frames.
//
// Silhouette (no art, or LottieOptions::art off): one shape layer whose group holds one path
// ("sh") per boundary loop and one nonzero fill, so holes stay holes.
//
// Art (FrameSet::art present and LottieOptions::art): the layers solver::ArtForFrame gives each
// frame, as the raster output paints them (art_painter.h):
//  - One shape layer per art layer followed through the frames. A frame's layer continues a
//    Lottie layer of the previous frame when their solver::ArtLayerSource members share a key
//    layer (so a key frame's layer and the morph it starts or ends are one Lottie layer) and
//    Lottie can keep its discrete paint (path count and closure, fill rule, cap, join, dash
//    count); of several candidates the one sharing most members wins (ties: the lower in the
//    previous frame's paint order). A Lottie layer thus spans one contiguous run of frames,
//    "ip" to "op"; a layer that returns after a gap is a new Lottie layer.
//  - Per path an "sh" keyframed per frame. lottie-web keeps the first keyframe's vertex count for
//    the whole property, while the morph resamples (key frames have fewer points than the
//    frames between them), so every keyframe of a path is padded to the path's largest count
//    with points on its own edges, placed at the arc-length fractions of the nearest frame that
//    has that count: whole frames draw the art exactly and sub-frames move corners to corners.
//  - A stroke ("st": colour, opacity, width, dashes "d" keyframed when they change; "lc", "lj",
//    "ml" static, ml the first value) listed before the fill ("fl", "r" 1 nonzero or 2 even-odd),
//    so the stroke is drawn over the fill. A paint missing in some frames of the layer (a morph
//    partner's stroke fading in) has opacity 0 there.
//  - The art layer's opacity (cross-fades included) keyframes the layer's transform opacity,
//    the paints' own opacities their "o". lottie-web's SVG renderer applies a layer's opacity to
//    its group as a whole, which is what art_painter does for a layer with a fill and a stroke
//    (the fill does not show through the stroke); its canvas renderer multiplies the layer
//    opacity into each paint instead, which differs only there.
//  - Paint order: the layers are listed top first (Lottie draws the first on top) in one order
//    that agrees with every frame's paint order: frames are merged in order, a new Lottie layer
//    goes right above the layer under it in its first frame (at the bottom when none is), and a
//    continued layer whose place a frame contradicts ends there and goes on as a new one.
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
  std::string fill = "#3b7dd8";  // silhouette colour (see ParseColor); the background is clear
  // Silhouette: FrameSet::fills instead of `fill` when present: a static colour when every frame
  // has the same, else the colour animated with one keyframe per frame.
  bool drawing_fills = true;
  // The drawings' art (FrameSet::art) when the set has it; false: the silhouette.
  bool art = true;
  std::string name = "inbetween";
};

// The Lottie document: v, fr, ip = 0, op = frame count, w, h, layers (see above).
absl::StatusOr<nlohmann::json> LottieAnimation(const FrameSet& frames,
                                               const LottieOptions& options = {});

// LottieAnimation written compactly to `path` (temp name, then rename).
absl::Status WriteLottie(const std::filesystem::path& path, const FrameSet& frames,
                         const LottieOptions& options = {});

}  // namespace inbetween::render
