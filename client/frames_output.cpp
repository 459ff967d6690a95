// FramesResult -> render::FrameSet (see frames_output.h).
#include "client/frames_output.h"

namespace inbetween::client {

render::FrameSet ToFrameSet(const FramesResult& frames) {
  render::FrameSet out;
  for (const auto& t : frames.header.triangles()) {
    out.triangles.push_back({static_cast<int>(t.a()), static_cast<int>(t.b()),
                             static_cast<int>(t.c())});
  }
  out.keys.assign(frames.header.keys().begin(), frames.header.keys().end());
  for (const auto& f : frames.frames) {
    render::FrameData data;
    data.index = static_cast<int>(f.index());
    data.time = f.time();
    data.weights.assign(f.weights().begin(), f.weights().end());
    for (const auto& p : f.vertices()) data.vertices.push_back({p.x(), p.y()});
    if (f.has_stats()) {
      render::FrameValidity valid;
      valid.inverted_triangles = static_cast<int>(f.stats().inverted_triangles());
      valid.boundary_overlaps = static_cast<int>(f.stats().boundary_overlaps());
      valid.min_area_ratio = f.stats().min_area_ratio();
      valid.max_area_ratio = f.stats().max_area_ratio();
      valid.hold_back = f.stats().overlap_hold_back();
      data.valid = valid;
    }
    out.frames.push_back(std::move(data));
  }
  return out;
}

}  // namespace inbetween::client
