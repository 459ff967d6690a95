// frames.json and per-frame SVG output for the CLI (see frames_output.h).
#include "client/frames_output.h"

#include <fstream>

#include "absl/strings/str_cat.h"

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
    out.frames.push_back(std::move(data));
  }
  return out;
}

absl::Status WriteFrames(const std::filesystem::path& dir, const FramesResult& frames,
                         const render::SvgFrameOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    return absl::UnavailableError(absl::StrCat("cannot create ", dir.string(), ": ", ec.message()));
  }
  const render::FrameSet set = ToFrameSet(frames);
  absl::Status s = render::WriteSvgFrames(dir, set, options);
  if (!s.ok()) return s;
  const auto path = dir / "frames.json";
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << render::FrameSetToJson(set).dump() << "\n";
  out.close();
  if (!out) return absl::UnavailableError(absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

}  // namespace inbetween::client
