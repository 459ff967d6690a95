// frames.json "art" both ways (see art_json.h).
#include "client/render/art_json.h"

#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "client/render/color.h"

namespace inbetween::render {
namespace {

absl::Status PathError(const std::string& path, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat("frames.json: ", path, ": ", what));
}

std::string RgbHex(uint32_t rgb) {
  return HexColor({static_cast<uint8_t>(rgb >> 16), static_cast<uint8_t>(rgb >> 8),
                   static_cast<uint8_t>(rgb), 255});
}

constexpr const char* CapName(solver::LineCap cap) {
  switch (cap) {
    case solver::LineCap::kRound:
      return "round";
    case solver::LineCap::kSquare:
      return "square";
    default:
      return "butt";
  }
}

constexpr const char* JoinName(solver::LineJoin join) {
  switch (join) {
    case solver::LineJoin::kRound:
      return "round";
    case solver::LineJoin::kBevel:
      return "bevel";
    default:
      return "miter";
  }
}

nlohmann::json LayerToJson(const solver::EmbeddedLayer& layer) {
  const solver::ArtLayer& paint = layer.paint;
  nlohmann::json out = {{"id", paint.id}, {"name", paint.name}, {"opacity", paint.opacity}};
  if (paint.fill) {
    out["fill"] = {{"color", RgbHex(paint.fill->rgb)},
                   {"opacity", paint.fill->opacity},
                   {"rule", paint.fill->even_odd ? "evenodd" : "nonzero"}};
  }
  if (paint.stroke) {
    const solver::StrokePaint& s = *paint.stroke;
    out["stroke"] = {{"color", RgbHex(s.rgb)},   {"opacity", s.opacity},
                     {"width", s.width},         {"cap", CapName(s.cap)},
                     {"join", JoinName(s.join)}, {"miter_limit", s.miter_limit},
                     {"dashes", s.dashes},       {"dash_offset", s.dash_offset}};
  }
  nlohmann::json paths = nlohmann::json::array();
  for (const solver::EmbeddedPath& path : layer.paths) {
    nlohmann::json points = nlohmann::json::array();
    for (const solver::EmbeddedPoint& p : path.points) {
      points.push_back({p.triangle, p.barycentric[0], p.barycentric[1], p.barycentric[2]});
    }
    paths.push_back({{"closed", path.closed}, {"points", std::move(points)}});
  }
  out["paths"] = std::move(paths);
  return out;
}

// A number member of `obj` (`fallback` when absent), finite and within [lo, hi].
absl::StatusOr<double> Number(const nlohmann::json& obj, const char* key, const std::string& path,
                              double fallback, double lo, double hi) {
  if (!obj.contains(key)) return fallback;
  const nlohmann::json& v = obj[key];
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
      v.get<double>() > hi) {
    return PathError(absl::StrCat(path, ".", key),
                     absl::StrCat("expected a number in [", lo, ", ", hi, "]"));
  }
  return v.get<double>();
}

absl::StatusOr<uint32_t> Color(const nlohmann::json& obj, const std::string& path) {
  if (!obj.contains("color") || !obj["color"].is_string()) {
    return PathError(path + ".color", "expected a colour string");
  }
  absl::StatusOr<Rgba8> c = ParseColor(obj["color"].get<std::string>());
  if (!c.ok()) return PathError(path + ".color", std::string(c.status().message()));
  return (uint32_t{c->r} << 16) | (uint32_t{c->g} << 8) | c->b;
}

absl::StatusOr<std::string> Text(const nlohmann::json& obj, const char* key,
                                 const std::string& path) {
  if (!obj.contains(key)) return std::string();
  if (!obj[key].is_string()) return PathError(absl::StrCat(path, ".", key), "expected a string");
  return obj[key].get<std::string>();
}

// A name of `names` (index returned), or an error listing them.
template <size_t N>
absl::StatusOr<int> Choice(const nlohmann::json& obj, const char* key, const std::string& path,
                           const std::array<const char*, N>& names) {
  if (!obj.contains(key)) return 0;
  if (obj[key].is_string()) {
    for (size_t i = 0; i < N; ++i) {
      if (obj[key].get<std::string>() == names[i]) return static_cast<int>(i);
    }
  }
  std::string list;
  for (const char* n : names) absl::StrAppend(&list, list.empty() ? "" : ", ", n);
  return PathError(absl::StrCat(path, ".", key), absl::StrCat("expected one of ", list));
}

absl::StatusOr<solver::FillPaint> FillFromJson(const nlohmann::json& j, const std::string& path) {
  if (!j.is_object()) return PathError(path, "expected an object");
  solver::FillPaint fill;
  absl::StatusOr<uint32_t> rgb = Color(j, path);
  if (!rgb.ok()) return rgb.status();
  fill.rgb = *rgb;
  absl::StatusOr<double> opacity = Number(j, "opacity", path, 1.0, 0.0, 1.0);
  if (!opacity.ok()) return opacity.status();
  fill.opacity = *opacity;
  absl::StatusOr<int> rule = Choice<2>(j, "rule", path, {"nonzero", "evenodd"});
  if (!rule.ok()) return rule.status();
  fill.even_odd = *rule == 1;
  return fill;
}

absl::StatusOr<solver::StrokePaint> StrokeFromJson(const nlohmann::json& j,
                                                   const std::string& path) {
  if (!j.is_object()) return PathError(path, "expected an object");
  solver::StrokePaint stroke;
  absl::StatusOr<uint32_t> rgb = Color(j, path);
  if (!rgb.ok()) return rgb.status();
  stroke.rgb = *rgb;
  constexpr double kHuge = 1e12;
  for (auto [key, out, fallback, lo] :
       {std::tuple{"opacity", &stroke.opacity, 1.0, 0.0},
        std::tuple{"width", &stroke.width, 1.0, 0.0},
        std::tuple{"miter_limit", &stroke.miter_limit, 4.0, 1.0},
        std::tuple{"dash_offset", &stroke.dash_offset, 0.0, -kHuge}}) {
    absl::StatusOr<double> v =
        Number(j, key, path, fallback, lo, std::string_view(key) == "opacity" ? 1.0 : kHuge);
    if (!v.ok()) return v.status();
    *out = *v;
  }
  absl::StatusOr<int> cap = Choice<3>(j, "cap", path, {"butt", "round", "square"});
  if (!cap.ok()) return cap.status();
  stroke.cap =
      std::array{solver::LineCap::kButt, solver::LineCap::kRound, solver::LineCap::kSquare}[*cap];
  absl::StatusOr<int> join = Choice<3>(j, "join", path, {"miter", "round", "bevel"});
  if (!join.ok()) return join.status();
  stroke.join = std::array{solver::LineJoin::kMiter, solver::LineJoin::kRound,
                           solver::LineJoin::kBevel}[*join];
  if (j.contains("dashes")) {
    const nlohmann::json& d = j["dashes"];
    if (!d.is_array()) return PathError(path + ".dashes", "expected an array of lengths");
    for (size_t i = 0; i < d.size(); ++i) {
      if (!d[i].is_number() || !std::isfinite(d[i].get<double>()) || d[i].get<double>() < 0) {
        return PathError(absl::StrCat(path, ".dashes[", i, "]"), "expected a length >= 0");
      }
      stroke.dashes.push_back(d[i].get<double>());
    }
  }
  return stroke;
}

absl::StatusOr<solver::EmbeddedPath> PathFromJson(
    const nlohmann::json& j, const std::string& path,
    const std::vector<std::array<int, 3>>& triangles) {
  if (!j.is_object() || !j.contains("points") || !j["points"].is_array()) {
    return PathError(path, "expected an object with a points array");
  }
  solver::EmbeddedPath out;
  if (j.contains("closed")) {
    if (!j["closed"].is_boolean()) return PathError(path + ".closed", "expected true or false");
    out.closed = j["closed"].get<bool>();
  }
  const nlohmann::json& points = j["points"];
  for (size_t i = 0; i < points.size(); ++i) {
    const std::string pp = absl::StrCat(path, ".points[", i, "]");
    const nlohmann::json& p = points[i];
    if (!p.is_array() || p.size() != 4 || !p[0].is_number_integer() || !p[1].is_number() ||
        !p[2].is_number() || !p[3].is_number()) {
      return PathError(pp, "expected [triangle, b0, b1, b2]");
    }
    solver::EmbeddedPoint e;
    e.triangle = p[0].get<int>();
    if (e.triangle < 0 || static_cast<size_t>(e.triangle) >= triangles.size()) {
      return PathError(
          pp, absl::StrCat("triangle ", e.triangle, " out of range [0, ", triangles.size(), ")"));
    }
    const auto& t = triangles[e.triangle];
    e.corners = {t[0], t[1], t[2]};
    for (int c = 0; c < 3; ++c) {
      e.barycentric[c] = p[c + 1].get<double>();
      if (!std::isfinite(e.barycentric[c])) return PathError(pp, "expected finite coordinates");
    }
    out.points.push_back(e);
  }
  return out;
}

absl::StatusOr<solver::EmbeddedLayer> LayerFromJson(
    const nlohmann::json& j, const std::string& path,
    const std::vector<std::array<int, 3>>& triangles) {
  if (!j.is_object() || !j.contains("paths") || !j["paths"].is_array()) {
    return PathError(path, "expected an object with a paths array");
  }
  solver::EmbeddedLayer layer;
  absl::StatusOr<std::string> id = Text(j, "id", path);
  if (!id.ok()) return id.status();
  absl::StatusOr<std::string> name = Text(j, "name", path);
  if (!name.ok()) return name.status();
  layer.paint.id = *id;
  layer.paint.name = *name;
  absl::StatusOr<double> opacity = Number(j, "opacity", path, 1.0, 0.0, 1.0);
  if (!opacity.ok()) return opacity.status();
  layer.paint.opacity = *opacity;
  if (j.contains("fill")) {
    absl::StatusOr<solver::FillPaint> fill = FillFromJson(j["fill"], path + ".fill");
    if (!fill.ok()) return fill.status();
    layer.paint.fill = *fill;
  }
  if (j.contains("stroke")) {
    absl::StatusOr<solver::StrokePaint> stroke = StrokeFromJson(j["stroke"], path + ".stroke");
    if (!stroke.ok()) return stroke.status();
    layer.paint.stroke = *stroke;
  }
  const nlohmann::json& paths = j["paths"];
  for (size_t i = 0; i < paths.size(); ++i) {
    absl::StatusOr<solver::EmbeddedPath> p =
        PathFromJson(paths[i], absl::StrCat(path, ".paths[", i, "]"), triangles);
    if (!p.ok()) return p.status();
    layer.paths.push_back(*std::move(p));
  }
  return layer;
}

}  // namespace

nlohmann::json ArtToJson(const std::vector<solver::EmbeddedArt>& art) {
  nlohmann::json out = nlohmann::json::array();
  for (const solver::EmbeddedArt& key : art) {
    nlohmann::json layers = nlohmann::json::array();
    for (const solver::EmbeddedLayer& layer : key.layers) layers.push_back(LayerToJson(layer));
    out.push_back({{"key", key.key}, {"layers", std::move(layers)}});
  }
  return out;
}

absl::StatusOr<std::vector<solver::EmbeddedArt>> ArtFromJson(
    const nlohmann::json& art, const std::vector<std::array<int, 3>>& triangles, int num_vertices) {
  if (!art.is_array()) return PathError("art", "expected an array (one entry per key drawing)");
  std::vector<solver::EmbeddedArt> out;
  for (size_t k = 0; k < art.size(); ++k) {
    const std::string kp = absl::StrCat("art[", k, "]");
    const nlohmann::json& j = art[k];
    if (!j.is_object() || !j.contains("layers") || !j["layers"].is_array()) {
      return PathError(kp, "expected an object with a layers array");
    }
    solver::EmbeddedArt key;
    key.key = static_cast<int>(k);
    if (j.contains("key") &&
        (!j["key"].is_number_integer() || j["key"].get<int64_t>() != key.key)) {
      return PathError(kp + ".key", absl::StrCat("expected ", k, " (keys in input order)"));
    }
    key.num_vertices = num_vertices;
    const nlohmann::json& layers = j["layers"];
    for (size_t l = 0; l < layers.size(); ++l) {
      absl::StatusOr<solver::EmbeddedLayer> layer =
          LayerFromJson(layers[l], absl::StrCat(kp, ".layers[", l, "]"), triangles);
      if (!layer.ok()) return layer.status();
      key.layers.push_back(*std::move(layer));
    }
    out.push_back(std::move(key));
  }
  return out;
}

}  // namespace inbetween::render
