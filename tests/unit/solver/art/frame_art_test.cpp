// ArtForFrame: key frames give the key's art, corresponding layers morph (midway paint at 0.5),
// the others cross-fade in key order, named layers keep each key's paint order.
#include "solver/art/frame_art.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/unit/solver/art/art_test_helpers.h"

namespace inbetween::solver {
namespace {

using art_test::DistanceToPolyline;
using art_test::ExpectSameLayers;
using art_test::FillLayer;
using art_test::JitteredGrid;
using art_test::StrokeLayer;

// Two keys on an 8 x 6 grid: shape 1 is shape 0 rotated and stretched.
Multimesh TwoShapes() {
  Multimesh mesh = JitteredGrid(8, 6, 0.25);
  Points second;
  for (const Point& p : interp_test::Rotated(mesh.shapes[0], 0.4, Point(4, 3))) {
    second.emplace_back(1.5 * p.x(), p.y());
  }
  mesh.shapes.push_back(second);
  return mesh;
}

Points Mix(const Points& a, const Points& b, double s) {
  Points out;
  for (size_t i = 0; i < a.size(); ++i) out.push_back((1 - s) * a[i] + s * b[i]);
  return out;
}

std::vector<EmbeddedArt> Embed(const Multimesh& mesh, const std::vector<ArtLayer>& art0,
                               const std::vector<ArtLayer>& art1) {
  return {*EmbedArt(mesh, 0, art0), *EmbedArt(mesh, 1, art1)};
}

std::vector<ArtLayer> Frame(const std::vector<EmbeddedArt>& keys, const Points& x,
                            std::vector<double> weights, const FrameArtOptions& options = {}) {
  absl::StatusOr<std::vector<ArtLayer>> art = ArtForFrame(keys, x, weights, options);
  EXPECT_TRUE(art.ok()) << art.status();
  return art.ok() ? *art : std::vector<ArtLayer>{};
}

// Same structure in both keys (morphs by order): a head and a stroke across it.
std::vector<ArtLayer> Head(const Point& shift, uint32_t fill, double width) {
  std::vector<ArtLayer> art;
  art.push_back(FillLayer({{1, 1}, {6, 1.2}, {6.5, 4.5}, {1.2, 4.8}}, fill, 0.9));
  art.push_back(StrokeLayer({{0.5, 0.5}, {7.5, 5.5}, {3, 5.5}}, 0x000000, width));
  for (ArtLayer& layer : art) {
    for (Point& p : layer.paths[0].points) p += shift;
  }
  return art;
}

TEST(FrameArtTest, KeyFramesGiveEachKeysArt) {
  const Multimesh mesh = TwoShapes();
  const std::vector<ArtLayer> morphing0 = Head({0, 0}, 0x204060, 1.0);
  const std::vector<ArtLayer> morphing1 = Head({0.3, 0.2}, 0x60a020, 3.0);
  std::vector<ArtLayer> fading1 = morphing1;
  fading1.push_back(FillLayer({{2, 2}, {3, 2}, {3, 3}}, 0xff0000));
  for (const auto& art1 : {morphing1, fading1}) {
    const std::vector<EmbeddedArt> keys = Embed(mesh, morphing0, art1);
    ExpectSameLayers(Frame(keys, mesh.shapes[0], {1, 0}), *PlaceArt(keys[0], mesh.shapes[0]));
    ExpectSameLayers(Frame(keys, mesh.shapes[1], {0, 1}), *PlaceArt(keys[1], mesh.shapes[1]));
  }
}

TEST(FrameArtTest, CorrespondingLayersBlendMidway) {
  Multimesh mesh = JitteredGrid(8, 6, 0.25);
  mesh.shapes.push_back(mesh.shapes[0]);  // one geometry: the art's own motion is all there is
  std::vector<ArtLayer> a = Head({0, 0}, 0x204060, 1.0);
  std::vector<ArtLayer> b = Head({0.5, 0.25}, 0x60a020, 3.0);
  a[0].fill->opacity = 0.2;
  b[0].fill->opacity = 0.6;
  b[0].opacity = 0.5;
  a[1].stroke->dashes = {2, 2};
  b[1].stroke->dashes = {4, 6};
  a[1].stroke->cap = LineCap::kRound;
  b[1].stroke->rgb = 0x0000ff;
  const std::vector<ArtLayer> out = Frame(Embed(mesh, a, b), mesh.shapes[0], {0.5, 0.5});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].fill->rgb, 0x407040u);
  EXPECT_DOUBLE_EQ(out[0].fill->opacity, 0.4);
  EXPECT_DOUBLE_EQ(out[0].opacity, 0.75);
  EXPECT_EQ(out[1].stroke->rgb, 0x000080u);  // 127.5 rounds up
  EXPECT_DOUBLE_EQ(out[1].stroke->width, 2.0);
  EXPECT_EQ(out[1].stroke->dashes, (std::vector<double>{3, 4}));
  EXPECT_EQ(out[1].stroke->cap, LineCap::kRound);  // equal weights: the lower key's
  // Positions: on the drawn paths shifted half-way, every corner of it present.
  const std::vector<ArtLayer> middle = Head({0.25, 0.125}, 0, 1.0);
  for (size_t l = 0; l < 2; ++l) {
    const ArtPath& expected = middle[l].paths[0];
    const Points& got = out[l].paths[0].points;
    for (const Point& p : got)
      EXPECT_LT(DistanceToPolyline(expected.points, expected.closed, p), 1e-9);
    for (const Point& corner : expected.points) {
      double nearest = 1e9;
      for (const Point& p : got) nearest = std::min(nearest, (p - corner).norm());
      EXPECT_LT(nearest, 1e-9);
    }
  }
}

TEST(FrameArtTest, NonCorrespondingLayersCrossFadeInKeyOrder) {
  const Multimesh mesh = TwoShapes();
  // Key 0's fill has two paths, key 1's one, far apart: no layer of one morphs into the other.
  std::vector<ArtLayer> a = {FillLayer({{1, 1}, {5, 1}, {5, 4}}, 0x111111, 0.8)};
  a[0].paths.push_back({{{5.5, 1}, {6.5, 1}, {6.5, 2}}, true});
  std::vector<ArtLayer> b = Head({0, 0}, 0x222222, 2.0);
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.75);
  const std::vector<EmbeddedArt> keys = Embed(mesh, a, b);
  const std::vector<ArtLayer> out = Frame(keys, x, {0.25, 0.75});
  ASSERT_EQ(out.size(), 3u);  // nothing corresponds
  EXPECT_EQ(out[0].fill->rgb, 0x111111u);
  EXPECT_DOUBLE_EQ(out[0].opacity, 0.25);
  EXPECT_EQ(out[0].fill->opacity, 0.8);  // the paint is kept, the layer fades
  EXPECT_EQ(out[1].fill->rgb, 0x222222u);
  EXPECT_DOUBLE_EQ(out[1].opacity, 0.75);
  EXPECT_DOUBLE_EQ(out[2].opacity, 0.75);
  // Placed from each key's own embedding.
  EXPECT_EQ(out[0].paths[0].points, PlacePath(keys[0].layers[0].paths[0], x));
  EXPECT_EQ(out[2].paths[0].points, PlacePath(keys[1].layers[1].paths[0], x));

  // The same layers in another paint order: one pair aligns (the strokes, whose colours agree,
  // outscore the fills), the fills cross-fade.
  std::vector<ArtLayer> c = Head({0, 0}, 0x333333, 2.0);
  std::swap(c[0], c[1]);  // stroke first, fill second
  const std::vector<ArtLayer> faded = Frame(Embed(mesh, b, c), x, {0.5, 0.5});
  ASSERT_EQ(faded.size(), 3u);
  int morphed_strokes = 0, faded_fills = 0;
  for (const ArtLayer& layer : faded) {
    morphed_strokes += layer.stroke && layer.opacity == 1.0;
    faded_fills += layer.fill && layer.opacity == 0.5;
  }
  EXPECT_EQ(morphed_strokes, 1);
  EXPECT_EQ(faded_fills, 2);
}

TEST(FrameArtTest, NamedLayersMorphAndKeepPaintOrder) {
  const Multimesh mesh = TwoShapes();
  ArtLayer body = FillLayer({{1, 1}, {7, 1}, {7, 5}, {1, 5}}, 0xf0c080);
  body.name = "body";
  ArtLayer eye = FillLayer({{2, 2}, {3, 2}, {3, 3}}, 0x000000);
  eye.name = "eye";
  const ArtLayer mouth = StrokeLayer({{2, 4}, {5, 4}}, 0x800000, 0.3);
  ArtLayer eye_outlined = eye;
  eye_outlined.stroke = StrokePaint{};
  eye_outlined.stroke->opacity = 0.5;
  const std::vector<EmbeddedArt> keys = Embed(mesh, {body, eye}, {body, mouth, eye_outlined});
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.5);
  const std::vector<ArtLayer> out = Frame(keys, x, {0.6, 0.4});
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].name, "body");
  EXPECT_DOUBLE_EQ(out[0].opacity, 1.0);
  EXPECT_FALSE(out[1].fill.has_value());  // the mouth, under the eye as in key 2
  EXPECT_DOUBLE_EQ(out[1].opacity, 0.4);
  EXPECT_EQ(out[2].name, "eye");
  ASSERT_TRUE(out[2].stroke.has_value());  // the outline key 1 lacks fades in
  EXPECT_DOUBLE_EQ(out[2].stroke->opacity, 0.4 * 0.5);
  EXPECT_DOUBLE_EQ(out[2].fill->opacity, 1.0);

  // Names off: the bodies align in paint order; the eyes (a fill, a fill and a stroke) and the
  // mouth cross-fade.
  FrameArtOptions by_order_only;
  by_order_only.match_by_name = false;
  EXPECT_EQ(Frame(keys, x, {0.6, 0.4}, by_order_only).size(), 4u);
}

// A redrawn face whose eyes change from two dots to two strokes: the face and its outline keep
// morphing (full opacity mid-way), only the eyes cross-fade.
TEST(FrameArtTest, AddedAndDroppedLayersLeaveTheOthersMorphing) {
  const Multimesh mesh = TwoShapes();
  const ArtLayer face = FillLayer({{1, 1}, {7, 1}, {7, 5}, {1, 5}}, 0xfcea2b);
  ArtLayer outline = face;
  outline.fill.reset();
  outline.stroke = StrokePaint{};
  outline.stroke->width = 0.2;
  const std::vector<ArtLayer> dots = {face, FillLayer({{2, 2}, {2.5, 2}, {2.5, 2.5}}, 0),
                                      FillLayer({{5, 2}, {5.5, 2}, {5.5, 2.5}}, 0), outline};
  const std::vector<ArtLayer> lines = {face, StrokeLayer({{2, 2}, {3, 2.3}}, 0, 0.2),
                                       StrokeLayer({{5, 2.3}, {6, 2}}, 0, 0.2), outline};
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.5);
  const std::vector<ArtLayer> out = Frame(Embed(mesh, dots, lines), x, {0.5, 0.5});
  ASSERT_EQ(out.size(), 6u);  // face, 2 + 2 eyes, outline
  EXPECT_EQ(out.front().fill->rgb, 0xfcea2bu);
  EXPECT_DOUBLE_EQ(out.front().opacity, 1.0);
  ASSERT_TRUE(out.back().stroke.has_value());
  EXPECT_FALSE(out.back().fill.has_value());
  EXPECT_DOUBLE_EQ(out.back().opacity, 1.0);
  for (size_t i = 1; i + 1 < out.size(); ++i) EXPECT_DOUBLE_EQ(out[i].opacity, 0.5);
}

// Of two open strokes of one colour in the other key, a stroke pairs with the one lying where it
// lies: the mouth morphs into the mouth while two dots turn into two strokes beside it.
TEST(FrameArtTest, StrokesPairWithTheNearestOfTheirKind) {
  const Multimesh mesh = TwoShapes();
  const std::vector<ArtLayer> a = {FillLayer({{2, 2}, {2.5, 2}, {2.5, 2.5}}, 0),
                                   StrokeLayer({{2, 4.5}, {6, 4.5}}, 0, 0.2)};
  const std::vector<ArtLayer> b = {StrokeLayer({{2, 2}, {3, 2.3}}, 0, 0.2),
                                   StrokeLayer({{2, 4.2}, {6, 4.6}}, 0, 0.2)};
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.5);
  const std::vector<EmbeddedArt> keys = Embed(mesh, a, b);
  const std::vector<ArtLayer> out = Frame(keys, x, {0.5, 0.5});
  ASSERT_EQ(out.size(), 3u);  // the dot and the eye stroke cross-fade, the mouths morph
  const Point mouths = 0.5 * (PlacePath(keys[0].layers[1].paths[0], x).front() +
                              PlacePath(keys[1].layers[1].paths[0], x).front());
  int morphed = 0;
  for (const ArtLayer& layer : out) {
    if (layer.opacity != 1.0) continue;
    ++morphed;
    ASSERT_TRUE(layer.stroke.has_value());
    EXPECT_LT((layer.paths[0].points.front() - mouths).norm(), 1e-9);  // mouth to mouth
  }
  EXPECT_EQ(morphed, 1);
}

// A closed path drawn from another corner, or the other way round, in the other key still
// morphs in place: the same square in both keys (one geometry) stays that square midway, where
// blending from each key's drawn first point turned and shrank it (to half its area).
TEST(FrameArtTest, ClosedPathsDrawnFromOtherStartsMorphInPlace) {
  Multimesh mesh = JitteredGrid(8, 6, 0.25);
  mesh.shapes.push_back(mesh.shapes[0]);
  const Points square = {{1, 1}, {6, 1}, {6, 5}, {1, 5}};
  const Points from_third = {{6, 5}, {1, 5}, {1, 1}, {6, 1}};
  const Points reversed = {{6, 1}, {1, 1}, {1, 5}, {6, 5}};
  for (const Points& other : {from_third, reversed}) {
    const std::vector<EmbeddedArt> keys =
        Embed(mesh, {FillLayer(square, 0x204060)}, {FillLayer(other, 0x204060)});
    for (double s : {0.25, 0.5, 0.75}) {
      const std::vector<ArtLayer> out = Frame(keys, mesh.shapes[0], {1 - s, s});
      ASSERT_EQ(out.size(), 1u);
      const Points& got = out[0].paths[0].points;
      for (const Point& p : got) EXPECT_LT(DistanceToPolyline(square, true, p), 1e-9) << s;
      for (const Point& corner : square) {
        EXPECT_LT(DistanceToPolyline(got, true, corner), 1e-9) << s;
      }
    }
  }
}

// A fill that gains a hole (a mouth that opens) morphs instead of fading: its outline pairs with
// the other key's outline, and the hole, which the other key lacks, is carried by the mesh. A
// fill whose outline would pair only with a far path (one cell that becomes two) cross-fades.
TEST(FrameArtTest, FillsThatGainAHoleMorphAndCellsThatSplitCrossFade) {
  Multimesh mesh = JitteredGrid(8, 6, 0.25);
  mesh.shapes.push_back(mesh.shapes[0]);
  const Points face = {{1, 1}, {7, 1}, {7, 5}, {1, 5}};
  ArtLayer open = FillLayer(face, 0x204060);
  open.paths.push_back({{{3, 2}, {5, 2}, {5, 3}, {3, 3}}, true});
  const std::vector<EmbeddedArt> keys = Embed(mesh, {FillLayer(face, 0x204060)}, {open});
  std::vector<ArtLayerSource> sources;
  absl::StatusOr<std::vector<ArtLayer>> out =
      ArtForFrame(keys, mesh.shapes[0], {0.5, 0.5}, {}, &sources);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->size(), 1u);
  EXPECT_DOUBLE_EQ((*out)[0].opacity, 1.0);
  ASSERT_EQ((*out)[0].paths.size(), 2u);
  for (const Point& p : (*out)[0].paths[0].points) {
    EXPECT_LT(DistanceToPolyline(face, true, p), 1e-9);
  }
  EXPECT_EQ((*out)[0].paths[1].points, PlacePath(keys[1].layers[0].paths[1], mesh.shapes[0]));
  ASSERT_EQ(sources.size(), 1u);
  EXPECT_EQ(sources[0].members.size(), 2u);

  ArtLayer two = FillLayer({{0.5, 1}, {3, 1}, {3, 5}, {0.5, 5}}, 0x204060);
  two.paths.push_back({{{5, 1}, {7.5, 1}, {7.5, 5}, {5, 5}}, true});
  const std::vector<EmbeddedArt> split = Embed(mesh, {FillLayer(face, 0x204060)}, {two});
  const std::vector<ArtLayer> faded = Frame(split, mesh.shapes[0], {0.25, 0.75});
  ASSERT_EQ(faded.size(), 2u);
  EXPECT_DOUBLE_EQ(faded[0].opacity, 0.25);
  EXPECT_DOUBLE_EQ(faded[1].opacity, 0.75);
  EXPECT_EQ(faded[1].paths.size(), 2u);
}

TEST(FrameArtTest, MorphTendsToEachKeyAsItsWeightTendsToOne) {
  const Multimesh mesh = TwoShapes();
  const std::vector<EmbeddedArt> keys =
      Embed(mesh, Head({0, 0}, 0, 1.0), Head({0.4, -0.3}, 0, 1.0));
  const double eps = 1e-7;
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], eps);
  const std::vector<ArtLayer> out = Frame(keys, x, {1 - eps, eps});
  const std::vector<ArtLayer> key = *PlaceArt(keys[0], mesh.shapes[0]);
  for (size_t l = 0; l < key.size(); ++l) {
    const ArtPath& k = key[l].paths[0];
    for (const Point& p : out[l].paths[0].points) {
      EXPECT_LT(DistanceToPolyline(k.points, k.closed, p), 1e-5);
    }
    for (const Point& corner : k.points) {
      EXPECT_LT(DistanceToPolyline(out[l].paths[0].points, k.closed, corner), 1e-5);
    }
  }
}

// The optional sources name every output layer's key layers in key order and leave the layers
// as they are: morphed groups list one layer per active key, cross-faded layers their own.
TEST(FrameArtTest, SourcesNameTheKeyLayersOfEachLayer) {
  const Multimesh mesh = TwoShapes();
  ArtLayer body = FillLayer({{1, 1}, {7, 1}, {7, 5}, {1, 5}}, 0xf0c080);
  body.name = "body";
  ArtLayer eye = FillLayer({{2, 2}, {3, 2}, {3, 3}}, 0x000000);
  eye.name = "eye";
  const ArtLayer mouth = StrokeLayer({{2, 4}, {5, 4}}, 0x800000, 0.3);
  const std::vector<EmbeddedArt> keys = Embed(mesh, {body, eye}, {body, mouth, eye});
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.5);
  using Refs = std::vector<ArtLayerRef>;
  std::vector<ArtLayerSource> sources = {{{{9, 9}}}};  // replaced, not appended to
  absl::StatusOr<std::vector<ArtLayer>> out = ArtForFrame(keys, x, {0.6, 0.4}, {}, &sources);
  ASSERT_TRUE(out.ok()) << out.status();
  ExpectSameLayers(*out, Frame(keys, x, {0.6, 0.4}));
  ASSERT_EQ(sources.size(), 3u);
  EXPECT_EQ(sources[0].members, (Refs{{0, 0}, {1, 0}}));  // the bodies morph
  EXPECT_EQ(sources[1].members, (Refs{{1, 1}}));          // key 2's mouth fades in
  EXPECT_EQ(sources[2].members, (Refs{{0, 1}, {1, 2}}));  // the eyes morph
  EXPECT_DOUBLE_EQ((*out)[1].opacity, 0.4);

  // A key frame: one member per layer, its own key's, in its paint order.
  out = ArtForFrame(keys, mesh.shapes[1], {0, 1}, {}, &sources);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(sources.size(), 3u);
  for (int l = 0; l < 3; ++l) EXPECT_EQ(sources[l].members, (Refs{{1, l}}));

  // Nothing corresponds (names off, no layer of one key fits one of the other): every layer
  // cross-fades, the lower key's first.
  FrameArtOptions none;
  none.match_by_name = none.match_by_order = false;
  out = ArtForFrame(keys, x, {0.5, 0.5}, none, &sources);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->size(), 5u);
  ASSERT_EQ(sources.size(), 5u);
  const std::vector<Refs> faded = {{{0, 0}}, {{0, 1}}, {{1, 0}}, {{1, 1}}, {{1, 2}}};
  for (size_t l = 0; l < 5; ++l) EXPECT_EQ(sources[l].members, faded[l]);
}

TEST(FrameArtTest, Deterministic) {
  const Multimesh mesh = TwoShapes();
  std::vector<ArtLayer> b = Head({0.2, 0.1}, 0x00ff00, 2.0);
  b.push_back(FillLayer({{2, 2}, {3, 2}, {3, 3}}, 0xff0000));
  const std::vector<EmbeddedArt> keys = Embed(mesh, Head({0, 0}, 0xff00ff, 1.0), b);
  const Points x = Mix(mesh.shapes[0], mesh.shapes[1], 0.3);
  ExpectSameLayers(Frame(keys, x, {0.7, 0.3}), Frame(keys, x, {0.7, 0.3}));
}

TEST(FrameArtTest, RejectsBadInput) {
  const Multimesh mesh = TwoShapes();
  const std::vector<EmbeddedArt> keys = Embed(mesh, Head({0, 0}, 0, 1), Head({0, 0}, 0, 1));
  const Points& x = mesh.shapes[0];
  EXPECT_EQ(ArtForFrame(keys, x, {1.0}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ArtForFrame(keys, x, {0.0, 0.0}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ArtForFrame(keys, x, {NAN, 1.0}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ArtForFrame(keys, Points(4), {0.5, 0.5}).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inbetween::solver
