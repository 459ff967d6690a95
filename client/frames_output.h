// An Inbetween stream's frames as plain render data (client/render), for every exporter.
#pragma once

#include "absl/status/status.h"
#include "client/inbetween_client.h"
#include "client/render/frame_set.h"

namespace inbetween::client {

render::FrameSet ToFrameSet(const FramesResult& frames);

// The header's art (InbetweenHeader.art, chunks appended by InbetweenClient::Inbetween) as
// `frames->art`, so every exporter draws it. Nothing when the header has no art. Errors leave
// `frames->art` empty: art that does not fit the header's triangles (INVALID_ARGUMENT naming the
// field) or the frames' weights (render::CheckFrameSet).
absl::Status AddHeaderArt(const v1::InbetweenHeader& header, render::FrameSet* frames);

}  // namespace inbetween::client
