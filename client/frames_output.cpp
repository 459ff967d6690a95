// FramesResult -> render::FrameSet (see frames_output.h).
#include "client/frames_output.h"

#include "absl/strings/str_cat.h"
#include "server/proto_convert.h"

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

absl::Status AddHeaderArt(const v1::InbetweenHeader& header, render::FrameSet* frames) {
  frames->art.clear();
  if (header.art_size() == 0) return absl::OkStatus();
  const int num_vertices =
      frames->frames.empty() ? 0 : static_cast<int>(frames->frames[0].vertices.size());
  std::vector<solver::EmbeddedArt> art;
  for (int k = 0; k < header.art_size(); ++k) {
    absl::StatusOr<solver::EmbeddedArt> key = server::EmbeddedArtFromProto(
        header.art(k), frames->triangles, num_vertices, absl::StrCat("header.art[", k, "]"));
    if (!key.ok()) return key.status();
    art.push_back(*std::move(key));
  }
  frames->art = std::move(art);
  absl::Status fits = render::CheckFrameSet(*frames);
  if (!fits.ok()) frames->art.clear();
  return fits;
}

}  // namespace inbetween::client
