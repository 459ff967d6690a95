// Internal to client/render: the Lottie JSON building blocks lottie_export.cpp and
// lottie_art.cpp share (schema: lottie-docs, see lottie_export.cpp), and the art animation.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/render/color.h"
#include "client/render/frame_set.h"
#include "client/render/lottie_export.h"
#include "client/render/viewport.h"
#include "nlohmann/json.hpp"

namespace inbetween::render::lottie {

using json = nlohmann::json;

// A property that does not animate.
json Static(json value);
// Pixel coordinates to 1/1000 px: exact enough, and far smaller files.
double Round3(double x);
// The identity transforms of a layer and of a group.
json LayerTransform();
json GroupTransform();
// A property with one value per frame from frame `first`: static when every value is the same
// (players reject a single keyframe), else a keyframe per frame, linear to the next. Keyframe
// values are arrays (a number n as [n], a path p as [p]), as lottie-web indexes them.
json Animated(const std::vector<json>& values, int first);
// A colour as Lottie's [r, g, b, a] in [0, 1].
json Rgba(const Rgba8& c);
json Rgba(uint32_t rgb);
// The animation document: `count` frames at options.fps, the viewport's size.
json Document(const LottieOptions& options, const Viewport& viewport, int count, json layers);
// A shape layer (ty 4) holding one group of `items`, shown in frames [ip, op).
json ShapeLayer(int ind, const std::string& name, json transform, json items, int ip, int op);

// The art: one Lottie layer per art layer followed through the frames (lottie_export.h).
absl::StatusOr<json> ArtAnimation(const FrameSet& frames, const LottieOptions& options,
                                  const Viewport& viewport);

}  // namespace inbetween::render::lottie
