// frames.json <-> FrameSet (see frame_set.h).
#include "client/render/frame_set.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "client/render/art_json.h"
#include "solver/art/frame_art.h"

namespace inbetween::render {
namespace {

absl::Status PathError(const std::string& path, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat("frames.json: ", path, ": ", what));
}

absl::StatusOr<FrameSet> FrameSetFromJsonUnchecked(const nlohmann::json& doc);

absl::Status CheckTriangleIndices(const std::vector<std::array<int, 3>>& triangles,
                                  size_t num_vertices) {
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int i : triangles[t]) {
      if (i < 0 || static_cast<size_t>(i) >= num_vertices) {
        return PathError(absl::StrCat("triangles[", t, "]"),
                         absl::StrCat("vertex index ", i, " out of range [0, ", num_vertices, ")"));
      }
    }
  }
  return absl::OkStatus();
}

// The art rules of CheckFrameSet (frames and triangles already checked): what ArtForFrame needs
// to succeed on every frame, so that renderers can rely on FrameArt.
absl::Status CheckArt(const FrameSet& frames) {
  if (frames.art.empty() || frames.frames.empty()) return absl::OkStatus();
  const size_t num_vertices = frames.frames[0].vertices.size();
  for (size_t k = 0; k < frames.art.size(); ++k) {
    const solver::EmbeddedArt& art = frames.art[k];
    if (static_cast<size_t>(art.num_vertices) != num_vertices) {
      return PathError(absl::StrCat("art[", k, "]"),
                       absl::StrCat("embedded in a mesh of ", art.num_vertices,
                                    " vertices, the frames have ", num_vertices));
    }
    for (size_t l = 0; l < art.layers.size(); ++l) {
      for (size_t p = 0; p < art.layers[l].paths.size(); ++p) {
        for (const solver::EmbeddedPoint& e : art.layers[l].paths[p].points) {
          for (int c : e.corners) {
            if (c < 0 || static_cast<size_t>(c) >= num_vertices) {
              return PathError(absl::StrCat("art[", k, "].layers[", l, "].paths[", p, "]"),
                               absl::StrCat("vertex index ", c, " out of range"));
            }
          }
        }
      }
    }
  }
  for (size_t f = 0; f < frames.frames.size(); ++f) {
    const std::vector<double>& w = frames.frames[f].weights;
    if (w.size() != frames.art.size()) {
      return PathError(
          absl::StrCat("frames[", f, "].weights"),
          absl::StrCat("has ", w.size(), " weights, art has ", frames.art.size(), " key drawings"));
    }
    bool positive = false;
    for (double x : w) {
      if (!std::isfinite(x)) {
        return PathError(absl::StrCat("frames[", f, "].weights"), "expected finite numbers");
      }
      positive = positive || x > 0;
    }
    if (!positive) return PathError(absl::StrCat("frames[", f, "].weights"), "none is > 0");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<FrameSet> FrameSetFromJson(const nlohmann::json& doc) {
  // Every access below is type-checked first; the catch keeps a missed case from throwing
  // across the library boundary.
  try {
    return FrameSetFromJsonUnchecked(doc);
  } catch (const nlohmann::json::exception& e) {
    return PathError("$", e.what());
  }
}

absl::Status CheckFrameSet(const FrameSet& frames) {
  if (frames.frames.empty()) return PathError("frames", "no frames");
  const size_t num_vertices = frames.frames[0].vertices.size();
  for (size_t f = 0; f < frames.frames.size(); ++f) {
    const auto& verts = frames.frames[f].vertices;
    if (verts.size() != num_vertices) {
      return PathError(
          absl::StrCat("frames[", f, "]"),
          absl::StrCat("has ", verts.size(), " vertices, frames[0] has ", num_vertices));
    }
    for (size_t v = 0; v < verts.size(); ++v) {
      if (!std::isfinite(verts[v][0]) || !std::isfinite(verts[v][1])) {
        return PathError(absl::StrCat("frames[", f, "].vertices[", v, "]"),
                         "expected [x, y] finite numbers");
      }
    }
  }
  if (absl::Status s = CheckTriangleIndices(frames.triangles, num_vertices); !s.ok()) return s;
  return CheckArt(frames);
}

namespace {

absl::StatusOr<FrameValidity> ValidityFromJson(const nlohmann::json& v, const std::string& fp) {
  if (!v.is_object()) return PathError(fp + ".valid", "expected an object");
  FrameValidity validity;
  for (const char* key : {"inverted_triangles", "boundary_overlaps"}) {
    if (!v.contains(key) || !v[key].is_number_integer() || v[key].get<int64_t>() < 0) {
      return PathError(absl::StrCat(fp, ".valid.", key), "expected a count >= 0");
    }
  }
  for (const char* key : {"min_area_ratio", "max_area_ratio"}) {
    if (!v.contains(key) || !v[key].is_number()) {
      return PathError(absl::StrCat(fp, ".valid.", key), "expected a number");
    }
  }
  validity.inverted_triangles = v["inverted_triangles"].get<int>();
  validity.boundary_overlaps = v["boundary_overlaps"].get<int>();
  validity.min_area_ratio = v["min_area_ratio"].get<double>();
  validity.max_area_ratio = v["max_area_ratio"].get<double>();
  if (v.contains("hold_back")) {  // optional: frames.json files written before it existed
    if (!v["hold_back"].is_number() || v["hold_back"].get<double>() < 0 ||
        v["hold_back"].get<double>() > 1) {
      return PathError(fp + ".valid.hold_back", "expected a number in [0, 1]");
    }
    validity.hold_back = v["hold_back"].get<double>();
  }
  return validity;
}

// frames[f]: index (default f), time, weights, valid, vertices.
absl::StatusOr<FrameData> FrameFromJson(const nlohmann::json& fr, size_t f) {
  const std::string fp = absl::StrCat("frames[", f, "]");
  if (!fr.is_object() || !fr.contains("vertices") || !fr["vertices"].is_array()) {
    return PathError(fp, "expected an object with a vertices array");
  }
  FrameData data;
  data.index = static_cast<int>(f);
  if (fr.contains("index")) {
    if (!fr["index"].is_number_integer()) {
      return PathError(fp + ".index", "expected an integer frame index");
    }
    data.index = fr["index"].get<int>();
  }
  if (fr.contains("time")) {
    if (!fr["time"].is_number()) return PathError(fp + ".time", "expected a number");
    data.time = fr["time"].get<double>();
  }
  if (fr.contains("weights")) {
    if (!fr["weights"].is_array()) return PathError(fp + ".weights", "expected an array");
    for (size_t w = 0; w < fr["weights"].size(); ++w) {
      if (!fr["weights"][w].is_number()) {
        return PathError(absl::StrCat(fp, ".weights[", w, "]"), "expected a number");
      }
      data.weights.push_back(fr["weights"][w].get<double>());
    }
  }
  if (fr.contains("valid")) {
    absl::StatusOr<FrameValidity> validity = ValidityFromJson(fr["valid"], fp);
    if (!validity.ok()) return validity.status();
    data.valid = *validity;
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
  return data;
}

// The optional fills: one colour per key drawing.
absl::StatusOr<std::vector<Rgba8>> FillsFromJson(const nlohmann::json& fills) {
  if (!fills.is_array()) return PathError("fills", "expected an array of colours");
  std::vector<Rgba8> out;
  for (size_t i = 0; i < fills.size(); ++i) {
    const std::string fp = absl::StrCat("fills[", i, "]");
    if (!fills[i].is_string()) return PathError(fp, "expected a colour string");
    absl::StatusOr<Rgba8> c = ParseColor(fills[i].get<std::string>());
    if (!c.ok()) return PathError(fp, std::string(c.status().message()));
    out.push_back(*c);
  }
  return out;
}

absl::StatusOr<FrameSet> FrameSetFromJsonUnchecked(const nlohmann::json& doc) {
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
    absl::StatusOr<FrameData> data = FrameFromJson(frames[f], f);
    if (!data.ok()) return data.status();
    if (f == 0) num_vertices = data->vertices.size();
    if (data->vertices.size() != num_vertices) {
      return PathError(absl::StrCat("frames[", f, "]"),
                       absl::StrCat("has ", data->vertices.size(), " vertices, frames[0] has ",
                                    num_vertices));
    }
    out.frames.push_back(*std::move(data));
  }
  if (absl::Status s = CheckTriangleIndices(out.triangles, num_vertices); !s.ok()) return s;
  if (doc.contains("fills")) {  // optional (added field): one colour per key drawing
    absl::StatusOr<std::vector<Rgba8>> fills = FillsFromJson(doc["fills"]);
    if (!fills.ok()) return fills.status();
    out.fills = *std::move(fills);
  }
  if (doc.contains("art")) {  // optional (added field): the key drawings' art in the mesh
    absl::StatusOr<std::vector<solver::EmbeddedArt>> art =
        ArtFromJson(doc["art"], out.triangles, static_cast<int>(num_vertices));
    if (!art.ok()) return art.status();
    out.art = *std::move(art);
    if (absl::Status s = CheckArt(out); !s.ok()) return s;
  }
  return out;
}

}  // namespace

nlohmann::json FrameSetToJson(const FrameSet& frames) {
  nlohmann::json out_frames = nlohmann::json::array();
  for (const auto& f : frames.frames) {
    nlohmann::json frame = {
        {"index", f.index}, {"time", f.time}, {"weights", f.weights}, {"vertices", f.vertices}};
    if (f.valid) {
      frame["valid"] = {{"inverted_triangles", f.valid->inverted_triangles},
                        {"boundary_overlaps", f.valid->boundary_overlaps},
                        {"min_area_ratio", f.valid->min_area_ratio},
                        {"max_area_ratio", f.valid->max_area_ratio},
                        {"hold_back", f.valid->hold_back}};
    }
    out_frames.push_back(std::move(frame));
  }
  nlohmann::json doc = {
      {"triangles", frames.triangles}, {"keys", frames.keys}, {"frames", out_frames}};
  if (!frames.fills.empty()) {
    std::vector<std::string> fills;
    for (const Rgba8& c : frames.fills) fills.push_back(HexColor(c));
    doc["fills"] = fills;
  }
  if (!frames.art.empty()) doc["art"] = ArtToJson(frames.art);
  return doc;
}

absl::StatusOr<std::vector<solver::ArtLayer>> FrameArt(const FrameSet& frames, size_t f) {
  if (f >= frames.frames.size()) {
    return absl::OutOfRangeError(absl::StrCat("frame ", f, " of ", frames.frames.size()));
  }
  const FrameData& frame = frames.frames[f];
  solver::Points vertices;
  vertices.reserve(frame.vertices.size());
  for (const Vertex& v : frame.vertices) vertices.emplace_back(v[0], v[1]);
  return solver::ArtForFrame(frames.art, vertices, frame.weights);
}

std::optional<Rgba8> FrameFill(const FrameSet& frames, size_t f) {
  if (frames.fills.empty()) return std::nullopt;
  if (f >= frames.frames.size()) return frames.fills[0];
  const std::vector<double>& w = frames.frames[f].weights;
  if (w.size() != frames.fills.size()) return frames.fills[0];
  // Blend in sRGB like the shapes blend: weights sum to 1 (Catmull-Rom ones may be negative).
  double r = 0, g = 0, b = 0, a = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    r += w[i] * frames.fills[i].r;
    g += w[i] * frames.fills[i].g;
    b += w[i] * frames.fills[i].b;
    a += w[i] * frames.fills[i].a;
  }
  const auto channel = [](double v) {
    return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
  };
  return Rgba8{channel(r), channel(g), channel(b), channel(a)};
}

}  // namespace inbetween::render
