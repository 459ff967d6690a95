// An Inbetween stream's frames as plain render data (client/render), for every exporter.
#pragma once

#include "client/inbetween_client.h"
#include "client/render/frame_set.h"

namespace inbetween::client {

render::FrameSet ToFrameSet(const FramesResult& frames);

}  // namespace inbetween::client
