// Tests client/render/lottie_export.cpp against the structural rules of the Lottie 5.x schema
// that lottie-web relies on: required keys and types, one path keyframe per frame, every path
// closed with equal v/i/o lengths and the same vertex count in every keyframe. With art: every
// whole frame shows FrameArt's layers (paths, paints, opacities) in its paint order, a layer per
// art layer followed through the frames, cross-fades as opacity keyframes.
#include "client/render/lottie_export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "client/render/viewport.h"
#include "solver/art/art_embedding.h"
#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

using json = nlohmann::json;

void ExpectStaticNumber(const json& property, const std::string& what) {
  ASSERT_TRUE(property.is_object()) << what;
  EXPECT_EQ(property.value("a", -1), 0) << what;
  ASSERT_TRUE(property.contains("k")) << what;
  EXPECT_TRUE(property["k"].is_number() || property["k"].is_array()) << what;
}

// A bezier path object: closed, v/i/o arrays of [x, y] pairs of equal length.
void ExpectClosedPath(const json& path, size_t vertices, double w, double h) {
  ASSERT_TRUE(path.is_object());
  EXPECT_EQ(path.value("c", false), true);
  for (const char* key : {"v", "i", "o"}) {
    ASSERT_TRUE(path.contains(key) && path[key].is_array()) << key;
    ASSERT_EQ(path[key].size(), vertices) << key;
    for (const json& p : path[key]) {
      ASSERT_TRUE(p.is_array() && p.size() == 2 && p[0].is_number() && p[1].is_number()) << key;
    }
  }
  for (const json& p : path["v"]) {  // inside the composition
    EXPECT_GE(p[0].get<double>(), 0);
    EXPECT_LE(p[0].get<double>(), w);
    EXPECT_GE(p[1].get<double>(), 0);
    EXPECT_LE(p[1].get<double>(), h);
  }
  for (const json& p : path["i"]) EXPECT_EQ(p, json::parse("[0, 0]"));
}

void ExpectValidLottie(const json& doc, int frames, size_t loops) {
  ASSERT_TRUE(doc.is_object());
  ASSERT_TRUE(doc["v"].is_string());
  EXPECT_EQ(doc["v"].get<std::string>().substr(0, 2), "5.");
  for (const char* key : {"fr", "ip", "op", "w", "h"}) {
    ASSERT_TRUE(doc.contains(key) && doc[key].is_number()) << key;
  }
  EXPECT_EQ(doc["ip"], 0);
  EXPECT_EQ(doc["op"], frames);
  EXPECT_GT(doc["w"].get<int>(), 0);
  EXPECT_GT(doc["h"].get<int>(), 0);
  ASSERT_TRUE(doc["layers"].is_array());
  ASSERT_EQ(doc["layers"].size(), 1u);
  const json& layer = doc["layers"][0];
  EXPECT_EQ(layer["ty"], 4);
  EXPECT_EQ(layer["ip"], 0);
  EXPECT_EQ(layer["op"], frames);
  EXPECT_EQ(layer["st"], 0);
  ASSERT_TRUE(layer["ks"].is_object());
  for (const char* key : {"o", "r", "p", "a", "s"}) ExpectStaticNumber(layer["ks"][key], key);
  ASSERT_TRUE(layer["shapes"].is_array());
  ASSERT_EQ(layer["shapes"].size(), 1u);
  const json& group = layer["shapes"][0];
  EXPECT_EQ(group["ty"], "gr");
  ASSERT_TRUE(group["it"].is_array());
  const json& items = group["it"];
  ASSERT_EQ(items.size(), loops + 2);  // paths, fill, transform (transform last)
  EXPECT_EQ(items.back()["ty"], "tr");
  for (const char* key : {"p", "a", "s", "r", "o"}) ExpectStaticNumber(items.back()[key], key);
  const json& fill = items[loops];
  EXPECT_EQ(fill["ty"], "fl");
  ExpectStaticNumber(fill["c"], "fill colour");
  ASSERT_EQ(fill["c"]["k"].size(), 4u);
  for (const json& c : fill["c"]["k"]) {
    EXPECT_GE(c.get<double>(), 0);
    EXPECT_LE(c.get<double>(), 1);
  }
  ExpectStaticNumber(fill["o"], "fill opacity");
  const double w = doc["w"], h = doc["h"];
  for (size_t l = 0; l < loops; ++l) {
    const json& sh = items[l];
    EXPECT_EQ(sh["ty"], "sh");
    const json& ks = sh["ks"];
    if (frames == 1) {
      EXPECT_EQ(ks["a"], 0);
      ExpectClosedPath(ks["k"], ks["k"]["v"].size(), w, h);
      continue;
    }
    EXPECT_EQ(ks["a"], 1);
    ASSERT_TRUE(ks["k"].is_array());
    ASSERT_EQ(ks["k"].size(), static_cast<size_t>(frames));  // one keyframe per frame
    const size_t vertices = ks["k"][0]["s"][0]["v"].size();
    EXPECT_GE(vertices, 3u);
    for (int f = 0; f < frames; ++f) {
      const json& key = ks["k"][f];
      EXPECT_EQ(key["t"], f);
      ASSERT_TRUE(key["s"].is_array());
      ASSERT_EQ(key["s"].size(), 1u);
      ExpectClosedPath(key["s"][0], vertices, w, h);  // same count: players interpolate
      if (f + 1 < frames) {
        for (const char* e : {"i", "o"}) {
          ASSERT_TRUE(key[e].is_object()) << e;
          EXPECT_TRUE(key[e]["x"].is_number() && key[e]["y"].is_number()) << e;
        }
      }
    }
  }
}

TEST(LottieExportTest, AnimationFollowsTheSchema) {
  const FrameSet set = testing::MorphingRing(15);
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 400, .fps = 30, .fill = "#ff8000"});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectValidLottie(*doc, 15, 2);
  EXPECT_EQ((*doc)["fr"], 30.0);
  EXPECT_EQ((*doc)["w"], 400);
  EXPECT_EQ((*doc)["layers"][0]["shapes"][0]["it"][2]["c"]["k"],
            json::parse("[1.0, 0.5019607843137255, 0.0, 1]"));
}

TEST(LottieExportTest, HolesWindAgainstTheOutsideForTheNonzeroFill) {
  const FrameSet set = testing::SquareWithHole();
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 100});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectValidLottie(*doc, 1, 2);
  const json& items = (*doc)["layers"][0]["shapes"][0]["it"];
  EXPECT_EQ(items[2]["r"], 1);  // nonzero
  std::vector<double> areas;
  for (int l = 0; l < 2; ++l) {
    const json& v = items[l]["ks"]["k"]["v"];
    double twice = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      const json& p = v[i];
      const json& q = v[(i + 1) % v.size()];
      twice += p[0].get<double>() * q[1].get<double>() - p[1].get<double>() * q[0].get<double>();
    }
    areas.push_back(twice / 2);
  }
  EXPECT_LT(areas[0] * areas[1], 0);  // opposite orientation
}

TEST(LottieExportTest, WritesAFileThatParsesBackAndReportsErrors) {
  const auto path = std::filesystem::temp_directory_path() / "inbetween_lottie_test.json";
  ASSERT_TRUE(WriteLottie(path, testing::MorphingRing(4), {.fps = 12}).ok());
  std::ifstream in(path);
  ExpectValidLottie(json::parse(in), 4, 2);
  std::filesystem::remove(path);
  EXPECT_FALSE(LottieAnimation(testing::MorphingRing(4), {.fps = 0}).ok());
  EXPECT_FALSE(LottieAnimation(testing::MorphingRing(4), {.fill = "nope"}).ok());
  EXPECT_FALSE(LottieAnimation(FrameSet{}).ok());
}

// ---- Art ----

// A square mesh moving 20 to the right over `count` frames, keys at the ends, with each key's
// art (in that key's place) embedded.
FrameSet ArtSet(const std::vector<solver::ArtLayer>& key0,
                const std::vector<solver::ArtLayer>& key1, int count = 5) {
  FrameSet set;
  set.triangles = {{0, 1, 2}, {0, 2, 3}};
  set.keys = {0, count - 1};
  const auto square = [](double dx) {
    return std::vector<Vertex>{{dx, 0}, {dx + 10, 0}, {dx + 10, 10}, {dx, 10}};
  };
  for (int f = 0; f < count; ++f) {
    const double t = static_cast<double>(f) / (count - 1);
    set.frames.push_back({f, t, {1 - t, t}, square(20 * t)});
  }
  solver::Multimesh mesh;
  for (const auto& t : set.triangles) mesh.triangles.push_back({t[0], t[1], t[2]});
  for (int f : {0, count - 1}) {
    solver::Points shape;
    for (const Vertex& v : set.frames[f].vertices) shape.emplace_back(v[0], v[1]);
    mesh.shapes.push_back(shape);
  }
  int k = 0;
  for (const auto* art : {&key0, &key1}) {
    absl::StatusOr<solver::EmbeddedArt> embedded = solver::EmbedArt(mesh, k++, *art);
    EXPECT_TRUE(embedded.ok()) << embedded.status();
    set.art.push_back(*std::move(embedded));
  }
  return set;
}

solver::ArtLayer Layer(std::string name, std::vector<solver::Points> paths, bool closed,
                       double dx) {
  solver::ArtLayer layer;
  layer.name = std::move(name);
  for (solver::Points& p : paths) {
    for (solver::Point& q : p) q.x() += dx;
    layer.paths.push_back({std::move(p), closed});
  }
  return layer;
}

// A face: a head (even-odd fill, round-joined stroke), an eye, a dashed mouth. Key 1 has an
// octagonal head (other point count: the morph resamples), a wider stroke, two eyes in one layer
// (another path count: the eye layers cross-fade) and other dashes.
std::vector<solver::ArtLayer> Face(int key, int place = -1) {
  const double dx = 20.0 * (place < 0 ? key : place);  // key 0's place, or key 1's
  std::vector<solver::ArtLayer> art;
  solver::ArtLayer head =
      key == 0 ? Layer("head", {{{1, 1}, {9, 1}, {9, 9}, {1, 9}}}, true, dx)
               : Layer("head", {{{3, 1}, {7, 1}, {9, 3}, {9, 7}, {7, 9}, {3, 9}, {1, 7}, {1, 3}}},
                       true, dx);
  head.fill = solver::FillPaint{.rgb = key == 0 ? 0xf0c080u : 0xe0a060u, .even_odd = true};
  head.stroke = solver::StrokePaint{
      .rgb = 0x202020, .width = key == 0 ? 0.5 : 1.0, .join = solver::LineJoin::kRound};
  art.push_back(head);
  solver::ArtLayer eye =
      key == 0 ? Layer("eye", {{{3, 3}, {4, 3}, {4, 4}}}, true, dx)
               : Layer("eye", {{{3, 3}, {4, 3}, {4, 4}}, {{6, 3}, {7, 3}, {7, 4}}}, true, dx);
  eye.fill = solver::FillPaint{.rgb = 0x000000};
  art.push_back(eye);
  solver::ArtLayer mouth = Layer("mouth", {{{3, 7}, {5, key == 0 ? 7.5 : 8.0}, {7, 7}}}, false, dx);
  mouth.stroke = solver::StrokePaint{
      .rgb = 0x800000,
      .width = 0.4,
      .cap = solver::LineCap::kRound,
      .dashes = key == 0 ? std::vector<double>{1, 0.5} : std::vector<double>{2, 1}};
  art.push_back(mouth);
  return art;
}

// A property's value at whole frame f: the static value or the keyframe at t = f (numbers and
// paths are wrapped in one-element arrays there, colours are not).
json ValueAt(const json& property, int f) {
  if (property["a"] == 0) return property["k"];
  for (const json& key : property["k"]) {
    if (key["t"] == f) return key["s"].size() == 1 ? key["s"][0] : key["s"];
  }
  ADD_FAILURE() << "no keyframe at " << f;
  return nullptr;
}

const json* Item(const json& layer, const std::string& ty) {
  for (const json& item : layer["shapes"][0]["it"]) {
    if (item["ty"] == ty) return &item;
  }
  return nullptr;
}

double DistanceToSegment(const solver::Point& p, const solver::Point& a, const solver::Point& b) {
  const solver::Point ab = b - a;
  const double t =
      ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// The Lottie path draws `art` (through `viewport`): the same closure, every art point is a vertex
// and every vertex lies on the art's polyline (padding adds points on its edges only).
void ExpectDrawsPath(const json& path, const solver::ArtPath& art, const Viewport& viewport,
                     const std::string& what) {
  constexpr double kTol = 2e-3;  // Round3
  EXPECT_EQ(path["c"], art.closed) << what;
  solver::Points v, a;
  for (const json& p : path["v"]) v.emplace_back(p[0].get<double>(), p[1].get<double>());
  for (const solver::Point& p : art.points) {
    const auto [x, y] = viewport.ToPixels({p.x(), p.y()});
    a.emplace_back(x, y);
  }
  ASSERT_GE(v.size(), a.size()) << what;
  EXPECT_EQ(path["i"].size(), v.size()) << what;
  EXPECT_EQ(path["o"].size(), v.size()) << what;
  // In order: each art point found at or after the previous one's vertex.
  size_t at = 0;
  for (const solver::Point& p : a) {
    while (at < v.size() && (v[at] - p).norm() > kTol) ++at;
    EXPECT_LT(at, v.size()) << what << ": art point (" << p.x() << ", " << p.y() << ") missing";
  }
  const size_t edges = art.closed ? a.size() : a.size() - 1;
  for (const solver::Point& p : v) {
    double nearest = (p - a[0]).norm();
    for (size_t i = 0; i < edges; ++i) {
      nearest = std::min(nearest, DistanceToSegment(p, a[i], a[(i + 1) % a.size()]));
    }
    EXPECT_LT(nearest, kTol) << what << ": vertex off the art";
  }
}

// Every whole frame shows FrameArt's layers: the Lottie layers with ip <= f < op, bottom first,
// are the frame's layers in paint order with their paths, paints and opacities.
void ExpectEveryFrameDrawsTheArt(const FrameSet& set, const json& doc, int width) {
  const Viewport viewport = *FrameSetViewport(set, width);
  for (int f = 0; f < static_cast<int>(set.frames.size()); ++f) {
    absl::StatusOr<std::vector<solver::ArtLayer>> art = FrameArt(set, f);
    ASSERT_TRUE(art.ok()) << art.status();
    std::vector<const json*> shown;
    for (const json& layer : doc["layers"]) {
      if (layer["ip"].get<int>() <= f && f < layer["op"].get<int>())
        shown.insert(shown.begin(), &layer);
    }
    ASSERT_EQ(shown.size(), art->size()) << "frame " << f;
    for (size_t l = 0; l < art->size(); ++l) {
      const solver::ArtLayer& want = (*art)[l];
      const json& got = *shown[l];
      const std::string what = absl::StrCat("frame ", f, " layer ", l, " (", want.name, ")");
      EXPECT_EQ(got["nm"], want.name) << what;
      EXPECT_NEAR(ValueAt(got["ks"]["o"], f).get<double>(), 100 * want.opacity, 1e-3) << what;
      std::vector<const json*> paths;
      for (const json& item : got["shapes"][0]["it"]) {
        if (item["ty"] == "sh") paths.push_back(&item);
      }
      ASSERT_EQ(paths.size(), want.paths.size()) << what;
      for (size_t j = 0; j < paths.size(); ++j) {
        ExpectDrawsPath(ValueAt((*paths[j])["ks"], f), want.paths[j], viewport, what);
      }
      const json* fill = Item(got, "fl");
      ASSERT_EQ(fill != nullptr, want.fill.has_value()) << what;
      if (fill) {
        const json c = ValueAt((*fill)["c"], f);
        for (int i = 0; i < 3; ++i) {
          EXPECT_NEAR(c[i].get<double>(), ((want.fill->rgb >> (16 - 8 * i)) & 0xff) / 255.0, 1e-9)
              << what;
        }
        EXPECT_NEAR(ValueAt((*fill)["o"], f).get<double>(), 100 * want.fill->opacity, 1e-3);
        EXPECT_EQ((*fill)["r"], want.fill->even_odd ? 2 : 1) << what;
      }
      const json* stroke = Item(got, "st");
      ASSERT_EQ(stroke != nullptr, want.stroke.has_value()) << what;
      if (stroke) {
        EXPECT_NEAR(ValueAt((*stroke)["w"], f).get<double>(), want.stroke->width * viewport.scale,
                    2e-3)
            << what;
        EXPECT_NEAR(ValueAt((*stroke)["o"], f).get<double>(), 100 * want.stroke->opacity, 1e-3);
      }
    }
  }
}

TEST(LottieExportTest, ArtFollowsEachLayerThroughTheFrames) {
  const FrameSet set = ArtSet(Face(0), Face(1));
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 200});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectEveryFrameDrawsTheArt(set, *doc, 200);
  EXPECT_EQ((*doc)["op"], 5);
  // Top first: the mouth, key 2's eyes fading in over key 1's eye fading out, the head. The head
  // and mouth morph (one Lottie layer from key frame to key frame), the eyes cross-fade.
  const json& layers = (*doc)["layers"];
  ASSERT_EQ(layers.size(), 4u);
  const std::vector<std::string> names = {"mouth", "eye", "eye", "head"};
  const std::vector<std::pair<int, int>> spans = {{0, 5}, {1, 5}, {0, 4}, {0, 5}};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(layers[i]["nm"], names[i]);
    EXPECT_EQ(layers[i]["ind"], static_cast<int>(i) + 1);
    EXPECT_EQ(layers[i]["ip"], spans[i].first) << i;
    EXPECT_EQ(layers[i]["op"], spans[i].second) << i;
  }
  // Cross-fades: the layer's opacity keyframed per frame, linear; morphs stay opaque.
  const json linear_out = {{"x", 0}, {"y", 0}}, linear_in = {{"x", 1}, {"y", 1}};
  const auto expect_keyframes = [&](const json& property, int first, std::vector<double> values) {
    ASSERT_EQ(property["a"], 1);
    ASSERT_EQ(property["k"].size(), values.size());
    for (size_t k = 0; k < values.size(); ++k) {
      const json& key = property["k"][k];
      EXPECT_EQ(key["t"], first + static_cast<int>(k));
      EXPECT_NEAR(key["s"][0].get<double>(), values[k], 1e-3);
      EXPECT_FALSE(key.contains("h"));
      EXPECT_EQ(key.contains("o"), k + 1 < values.size());
      if (k + 1 < values.size()) {
        EXPECT_EQ(key["o"], linear_out);
        EXPECT_EQ(key["i"], linear_in);
      }
    }
  };
  expect_keyframes(layers[1]["ks"]["o"], 1, {25, 50, 75, 100});
  expect_keyframes(layers[2]["ks"]["o"], 0, {100, 75, 50, 25});
  EXPECT_EQ(layers[0]["ks"]["o"], json({{"a", 0}, {"k", 100.0}}));
  EXPECT_EQ(layers[3]["ks"]["o"], json({{"a", 0}, {"k", 100.0}}));
  // The head: a path keyframe per frame, one vertex count throughout (lottie-web keeps the first
  // keyframe's) although the key frames have 4 and 8 points and the morph more.
  const json& head = layers[3]["shapes"][0]["it"];
  ASSERT_EQ(head.size(), 4u);  // path, stroke over fill, transform
  EXPECT_EQ(head[0]["ty"], "sh");
  EXPECT_EQ(head[1]["ty"], "st");
  EXPECT_EQ(head[2]["ty"], "fl");
  EXPECT_EQ(head[3]["ty"], "tr");
  const json& keys = head[0]["ks"]["k"];
  ASSERT_EQ(keys.size(), 5u);
  const size_t count = keys[0]["s"][0]["v"].size();
  EXPECT_GT(count, 8u);
  for (const json& key : keys) EXPECT_EQ(key["s"][0]["v"].size(), count);
  EXPECT_EQ(head[2]["r"], 2);       // even-odd
  EXPECT_EQ(head[1]["lj"], 2);      // round join
  EXPECT_EQ(head[1]["lc"], 1);      // butt cap
  EXPECT_EQ(head[1]["w"]["a"], 1);  // the stroke widens
  EXPECT_EQ(head[2]["c"]["a"], 1);  // the colour blends
  // The mouth: dashes (dash, gap, offset) scaled to pixels and keyframed as they change.
  const json* mouth = Item(layers[0], "st");
  ASSERT_NE(mouth, nullptr);
  EXPECT_EQ((*mouth)["lc"], 2);
  ASSERT_TRUE(mouth->contains("d"));
  const json& dashes = (*mouth)["d"];
  ASSERT_EQ(dashes.size(), 3u);
  EXPECT_EQ(dashes[0]["n"], "d");
  EXPECT_EQ(dashes[1]["n"], "g");
  EXPECT_EQ(dashes[2]["n"], "o");
  const double scale = FrameSetViewport(set, 200)->scale;
  EXPECT_NEAR(ValueAt(dashes[0]["v"], 0).get<double>(), 1 * scale, 2e-3);
  EXPECT_NEAR(ValueAt(dashes[0]["v"], 4).get<double>(), 2 * scale, 2e-3);
}

// Key frames draw the key's own art: every point of key 1's octagon and of key 2's square is a
// vertex of the padded path there, and no vertex leaves its outline.
TEST(LottieExportTest, KeyFramesDrawTheKeysPaths) {
  const FrameSet set = ArtSet(Face(1, 0), Face(0, 1));  // 8 points first, then 4
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 300});
  ASSERT_TRUE(doc.ok()) << doc.status();
  const Viewport viewport = *FrameSetViewport(set, 300);
  const json& head = (*doc)["layers"].back();
  ASSERT_EQ(head["nm"], "head");
  const json& path = head["shapes"][0]["it"][0]["ks"];
  ExpectDrawsPath(ValueAt(path, 0), Face(1, 0)[0].paths[0], viewport, "key frame 0");
  ExpectDrawsPath(ValueAt(path, 4), Face(0, 1)[0].paths[0], viewport, "key frame 4");
  EXPECT_EQ(ValueAt(path, 0)["v"].size(), ValueAt(path, 2)["v"].size());
  ExpectEveryFrameDrawsTheArt(set, *doc, 300);
}

// Named layers in another paint order in each key: where a frame's order contradicts the one
// built so far, the layer goes on as a new Lottie layer in its place, so every frame is drawn in
// its own paint order.
TEST(LottieExportTest, PaintOrderAgreesWithEveryFrame) {
  std::vector<solver::ArtLayer> a = Face(0), b = Face(1);
  b[1] = Layer("eye", {{{3, 3}, {4, 3}, {4, 4}}}, true, 20);  // the eyes morph too
  b[1].fill = solver::FillPaint{.rgb = 0x000000};
  std::swap(b[0], b[2]);  // mouth, eye, head: the head drawn last in key 2
  const FrameSet set = ArtSet(a, b, 6);
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 100});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectEveryFrameDrawsTheArt(set, *doc, 100);
  EXPECT_GT((*doc)["layers"].size(), 3u);  // a layer restarts where the order flips
}

TEST(LottieExportTest, WithoutArtTheSilhouetteIsUnchanged) {
  const FrameSet set = ArtSet(Face(0), Face(1));
  FrameSet bare = set;
  bare.art.clear();
  absl::StatusOr<json> silhouette = LottieAnimation(set, {.width = 100, .art = false});
  absl::StatusOr<json> plain = LottieAnimation(bare, {.width = 100});
  ASSERT_TRUE(silhouette.ok() && plain.ok());
  EXPECT_EQ(*silhouette, *plain);
  ExpectValidLottie(*plain, 5, 1);
  absl::StatusOr<json> art = LottieAnimation(set, {.width = 100});
  ASSERT_TRUE(art.ok());
  EXPECT_NE(*art, *plain);
}

}  // namespace
}  // namespace inbetween::render
