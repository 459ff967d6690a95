// Writes an Inbetween stream's frames to disk: DIR/frames.json and DIR/frame_NNNN.svg.
#pragma once

#include <filesystem>

#include "absl/status/status.h"
#include "client/inbetween_client.h"
#include "client/render/frame_set.h"
#include "client/render/svg_frames.h"

namespace inbetween::client {

// The stream's frames as plain render data.
render::FrameSet ToFrameSet(const FramesResult& frames);

// Writes DIR/frames.json (docs/file-formats.md) and one SVG per frame.
absl::Status WriteFrames(const std::filesystem::path& dir, const FramesResult& frames,
                         const render::SvgFrameOptions& options = {});

}  // namespace inbetween::client
