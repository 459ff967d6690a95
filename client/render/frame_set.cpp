// frames.json <-> FrameSet (see frame_set.h).
#include "client/render/frame_set.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace inbetween::render {
namespace {

absl::Status PathError(const std::string& path, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat("frames.json: ", path, ": ", what));
}

}  // namespace

absl::StatusOr<FrameSet> FrameSetFromJson(const nlohmann::json& doc) {
  if (!doc.is_object()) return PathError("$", "expected an object");
  FrameSet out;
  for (const char* key : {"triangles", "keys", "frames"}) {
    if (!doc.contains(key) || !doc[key].is_array()) {
      return PathError(key, "missing or not an array");
    }
  }
  const auto& tris = doc["triangles"];
  for (size_t t = 0; t < tris.size(); ++t) {
    const auto& tri = tris[t];
    if (!tri.is_array() || tri.size() != 3 || !tri[0].is_number_integer() ||
        !tri[1].is_number_integer() || !tri[2].is_number_integer()) {
      return PathError(absl::StrCat("triangles[", t, "]"), "expected [i, j, k] integers");
    }
    out.triangles.push_back({tri[0].get<int>(), tri[1].get<int>(), tri[2].get<int>()});
  }
  for (size_t k = 0; k < doc["keys"].size(); ++k) {
    if (!doc["keys"][k].is_number_integer()) {
      return PathError(absl::StrCat("keys[", k, "]"), "expected an integer frame index");
    }
    out.keys.push_back(doc["keys"][k].get<int>());
  }
  const auto& frames = doc["frames"];
  size_t num_vertices = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string fp = absl::StrCat("frames[", f, "]");
    const auto& fr = frames[f];
    if (!fr.is_object() || !fr.contains("vertices") || !fr["vertices"].is_array()) {
      return PathError(fp, "expected an object with a vertices array");
    }
    FrameData data;
    data.index = fr.value("index", static_cast<int>(f));
    data.time = fr.value("time", 0.0);
    if (fr.contains("weights") && fr["weights"].is_array()) {
      for (const auto& w : fr["weights"]) data.weights.push_back(w.get<double>());
    }
    const auto& verts = fr["vertices"];
    for (size_t v = 0; v < verts.size(); ++v) {
      const auto& p = verts[v];
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number() ||
          !std::isfinite(p[0].get<double>()) || !std::isfinite(p[1].get<double>())) {
        return PathError(absl::StrCat(fp, ".vertices[", v, "]"), "expected [x, y] finite numbers");
      }
      data.vertices.push_back({p[0].get<double>(), p[1].get<double>()});
    }
    if (f == 0) num_vertices = data.vertices.size();
    if (data.vertices.size() != num_vertices) {
      return PathError(fp, absl::StrCat("has ", data.vertices.size(), " vertices, frames[0] has ",
                                        num_vertices));
    }
    out.frames.push_back(std::move(data));
  }
  for (size_t t = 0; t < out.triangles.size(); ++t) {
    for (int i : out.triangles[t]) {
      if (i < 0 || static_cast<size_t>(i) >= num_vertices) {
        return PathError(absl::StrCat("triangles[", t, "]"),
                         absl::StrCat("vertex index ", i, " out of range [0, ", num_vertices, ")"));
      }
    }
  }
  return out;
}

nlohmann::json FrameSetToJson(const FrameSet& frames) {
  nlohmann::json out_frames = nlohmann::json::array();
  for (const auto& f : frames.frames) {
    out_frames.push_back({{"index", f.index},
                          {"time", f.time},
                          {"weights", f.weights},
                          {"vertices", f.vertices}});
  }
  return {{"triangles", frames.triangles}, {"keys", frames.keys}, {"frames", out_frames}};
}

}  // namespace inbetween::render
