// Writes an Inbetween stream's frames to disk: DIR/frames.json and DIR/frame_NNNN.svg.
#pragma once

#include <filesystem>

#include "absl/status/status.h"
#include "client/inbetween_client.h"
#include "nlohmann/json.hpp"

namespace inbetween::client {

// The frames.json document (format in docs/file-formats.md):
// {"triangles": [[i,j,k],...], "keys": [...], "frames": [{"index","time","weights","vertices"}]}
nlohmann::json FramesToJson(const FramesResult& frames);

struct SvgFrameOptions {
  const char* fill = "#3b7dd8";
  bool mesh_overlay = false;  // draw triangle edges on top
};

// One SVG per frame, all with the same viewBox (the union of every frame's bounds) so that a
// sequence plays without jumping.
absl::Status WriteFrames(const std::filesystem::path& dir, const FramesResult& frames,
                         const SvgFrameOptions& options = {});

}  // namespace inbetween::client
