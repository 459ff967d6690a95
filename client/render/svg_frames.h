// SVG export: one SVG document per frame, all with the same viewBox (the union of every frame's
// bounds) so that a sequence plays without jumping.
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/status.h"
#include "client/render/frame_set.h"

namespace inbetween::render {

struct SvgFrameOptions {
  std::string fill = "#3b7dd8";
  bool drawing_fills = true;  // FrameSet::fills (blended per frame) win over `fill` when present
  bool mesh_overlay = false;  // draw triangle edges on top
  // Draw FrameSet::art when the set has art (its layers as <path>s with their paint, in paint
  // order); false (or no art): the one-colour silhouette.
  bool art = true;
};

// The SVG text of frame `f` of `frames`.
std::string FrameSvg(const FrameSet& frames, size_t f, const SvgFrameOptions& options = {});

// Writes DIR/frame_NNNN.svg for every frame.
absl::Status WriteSvgFrames(const std::filesystem::path& dir, const FrameSet& frames,
                            const SvgFrameOptions& options = {});

}  // namespace inbetween::render
