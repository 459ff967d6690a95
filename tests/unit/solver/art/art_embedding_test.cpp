// EmbedArt / PlaceArt: every point embedded, the key reproduced, affine motions carried exactly,
// outside points on the nearest triangle, long segments split where they cross edges.
#include "solver/art/art_embedding.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "solver/art/triangle_grid.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/art/art_test_helpers.h"

namespace inbetween::solver {
namespace {

using art_test::FillLayer;
using art_test::JitteredGrid;
using art_test::StrokeLayer;
using ::testing::HasSubstr;

// A face on a 8 x 6 grid: a filled head, eyes, a long stroke across it, a dot outside.
std::vector<ArtLayer> Face() {
  std::vector<ArtLayer> art;
  art.push_back(FillLayer({{0.5, 0.5}, {7.5, 0.6}, {7.4, 5.5}, {0.6, 5.4}}, 0xf0c080));
  ArtLayer eyes = FillLayer({{2, 2}, {2.6, 2}, {2.6, 2.5}, {2, 2.5}}, 0x202020);
  eyes.paths.push_back({{{5, 2}, {5.6, 2.1}, {5.5, 2.6}}, true});
  eyes.fill->even_odd = true;
  art.push_back(eyes);
  art.push_back(StrokeLayer({{0.2, 0.3}, {7.8, 5.7}, {4.0, 5.9}}, 0x000000, 0.2));
  art.push_back(StrokeLayer({{-0.3, 3.0}, {8.2, 6.1}}, 0x804000, 0.1));  // both ends outside
  return art;
}

// The drawn points of `placed`'s path (the ones not inserted), in order.
Points Drawn(const EmbeddedPath& path, const Points& placed) {
  Points out;
  for (size_t i = 0; i < placed.size(); ++i) {
    if (!path.points[i].inserted) out.push_back(placed[i]);
  }
  return out;
}

TEST(ArtEmbeddingTest, EveryPointEmbeddedAndKeyReproduced) {
  const Multimesh mesh = JitteredGrid(8, 6, 0.25);
  const std::vector<ArtLayer> art = Face();
  ArtEmbeddingReport report;
  absl::StatusOr<EmbeddedArt> embedded = EmbedArt(mesh, 0, art, {}, &report);
  ASSERT_TRUE(embedded.ok()) << embedded.status();
  ASSERT_EQ(embedded->layers.size(), art.size());
  absl::StatusOr<std::vector<ArtLayer>> placed = PlaceArt(*embedded, mesh.shapes[0]);
  ASSERT_TRUE(placed.ok());
  int points = 0, inserted = 0;
  for (size_t l = 0; l < art.size(); ++l) {
    EXPECT_EQ((*placed)[l].fill.has_value(), art[l].fill.has_value());
    EXPECT_EQ((*placed)[l].stroke.has_value(), art[l].stroke.has_value());
    ASSERT_EQ((*placed)[l].paths.size(), art[l].paths.size());
    for (size_t k = 0; k < art[l].paths.size(); ++k) {
      const ArtPath& drawn = art[l].paths[k];
      const EmbeddedPath& path = embedded->layers[l].paths[k];
      const Points& out = (*placed)[l].paths[k].points;
      EXPECT_EQ((*placed)[l].paths[k].closed, drawn.closed);
      const Points original = Drawn(path, out);
      ASSERT_EQ(original.size(), drawn.points.size());
      for (size_t i = 0; i < original.size(); ++i) {
        EXPECT_LT((original[i] - drawn.points[i]).norm(), 1e-9 * drawn.points[i].norm() + 1e-15);
      }
      // Inserted points lie on their drawn segment, in order along it.
      const size_t n = drawn.points.size();
      size_t segment = 0;
      double along = 0.0;
      for (size_t i = 1; i < out.size(); ++i) {
        if (!path.points[i].inserted) {
          ++segment, along = 0.0;
          continue;
        }
        const Point& a = drawn.points[segment];
        const Point& b = drawn.points[(segment + 1) % n];
        EXPECT_LT(DistanceToSegment(out[i], a, b), 1e-12);
        const double t = (out[i] - a).dot(b - a) / (b - a).squaredNorm();
        EXPECT_GT(t, along);
        along = t;
      }
      points += static_cast<int>(out.size());
      for (const EmbeddedPoint& e : path.points) inserted += e.inserted;
    }
  }
  EXPECT_EQ(report.points, points);
  EXPECT_EQ(report.inserted, inserted);
  EXPECT_GT(report.inserted, 20);
  // The last stroke's ends, and on it the feet of the boundary vertices its ends pass.
  EXPECT_EQ(report.outside, 4);
  EXPECT_GT(report.max_outside, 0.0);
}

TEST(ArtEmbeddingTest, AffineMotionOfVerticesMovesArtByIt) {
  const Multimesh mesh = JitteredGrid(8, 6, 0.25);
  absl::StatusOr<EmbeddedArt> embedded = EmbedArt(mesh, 0, Face());
  ASSERT_TRUE(embedded.ok());
  const std::vector<ArtLayer> key = *PlaceArt(*embedded, mesh.shapes[0]);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix2d m;
    m << u(rng), u(rng), u(rng), u(rng);  // any linear part, reflections and flattening included
    const Point t(u(rng) * 50, u(rng) * 50);
    Points moved;
    for (const Point& p : mesh.shapes[0]) moved.push_back(m * p + t);
    const std::vector<ArtLayer> placed = *PlaceArt(*embedded, moved);
    for (size_t l = 0; l < key.size(); ++l) {
      for (size_t k = 0; k < key[l].paths.size(); ++k) {
        const Points& a = key[l].paths[k].points;
        const Points& b = placed[l].paths[k].points;
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) EXPECT_LT((m * a[i] + t - b[i]).norm(), 1e-9);
      }
    }
  }
}

TEST(ArtEmbeddingTest, OutsidePointRidesNearestTriangleExtrapolated) {
  const Multimesh mesh = JitteredGrid(8, 6, 0.25);
  const Points& x = mesh.shapes[0];
  for (const Point& p : {Point(-0.4, 2.3), Point(8.05, 6.02), Point(100.0, -50.0)}) {
    ArtLayer dot = FillLayer({p}, 0);
    ArtEmbeddingReport report;
    absl::StatusOr<EmbeddedArt> embedded = EmbedArt(mesh, 0, {dot}, {}, &report);
    ASSERT_TRUE(embedded.ok());
    EXPECT_EQ(report.outside, 1);
    const EmbeddedPoint& e = embedded->layers[0].paths[0].points[0];
    double nearest = std::numeric_limits<double>::infinity();
    for (const Triangle& t : mesh.triangles) {
      nearest = std::min(nearest, DistanceToTriangle(x[t[0]], x[t[1]], x[t[2]], p));
    }
    const Triangle& t = mesh.triangles[e.triangle];
    EXPECT_EQ(DistanceToTriangle(x[t[0]], x[t[1]], x[t[2]], p), nearest);
    EXPECT_EQ(report.max_outside, nearest);
    EXPECT_LT(e.barycentric.minCoeff(), 0.0);
    EXPECT_NEAR(e.barycentric.sum(), 1.0, 1e-12);
    EXPECT_LT((PlacePath(embedded->layers[0].paths[0], x)[0] - p).norm(), 1e-9 * p.norm());
  }
}

// Each piece between consecutive embedded points lies in one triangle: in a bent frame, the
// midpoint of a piece, embedded on its own, lands on the chord of the placed piece.
TEST(ArtEmbeddingTest, LongSegmentSplitWhereItCrossesEdges) {
  Multimesh mesh = JitteredGrid(16, 1, 0.0);
  const Points bent = interp_test::Bent(mesh.shapes[0], 16.0, 2.0);
  const ArtLayer line = StrokeLayer({{0.1, 0.3}, {15.9, 0.6}}, 0, 0.1);
  ArtEmbeddingReport report;
  absl::StatusOr<EmbeddedArt> embedded = EmbedArt(mesh, 0, {line}, {}, &report);
  ASSERT_TRUE(embedded.ok());
  EXPECT_GE(report.inserted, 31);  // 15 vertical edges and 16 diagonals at least
  const Points key = PlacePath(embedded->layers[0].paths[0], mesh.shapes[0]);
  const Points frame = PlacePath(embedded->layers[0].paths[0], bent);
  double max_length = 0.0;
  for (size_t i = 0; i + 1 < key.size(); ++i) {
    max_length = std::max(max_length, (key[i + 1] - key[i]).norm());
    const ArtLayer mid = FillLayer({0.5 * (key[i] + key[i + 1])}, 0);
    const Point m = PlacePath(EmbedArt(mesh, 0, {mid})->layers[0].paths[0], bent)[0];
    EXPECT_LT(DistanceToSegment(m, frame[i], frame[i + 1]), 1e-9);
  }
  EXPECT_LT(max_length, 1.1);  // no piece longer than a triangle

  // Without splitting the segment is a single chord in every frame.
  ArtEmbeddingOptions no_split;
  no_split.split_at_edges = false;
  ArtEmbeddingReport plain;
  ASSERT_TRUE(EmbedArt(mesh, 0, {line}, no_split, &plain).ok());
  EXPECT_EQ(plain.inserted, 0);
  EXPECT_EQ(plain.points, 2);
}

// A segment along the boundary, a little outside it (a fill whose outline is the drawing's
// outline), crosses no triangle edge; split at the feet of the boundary vertices it passes, it
// follows the boundary when a frame bends it instead of cutting across as one chord.
TEST(ArtEmbeddingTest, SegmentAlongTheBoundaryFollowsItWhenBent) {
  const Multimesh mesh = JitteredGrid(16, 1, 0.0);
  const Points bent = interp_test::Bent(mesh.shapes[0], 16.0, 2.0);
  const ArtLayer edge = StrokeLayer({{0.0, -0.01}, {16.0, -0.01}}, 0, 0.1);
  // The bent bottom boundary, as a polyline.
  Points bottom;
  for (int i = 0; i <= 16; ++i) bottom.push_back(bent[i]);
  auto farthest = [&](const Points& placed) {
    double worst = 0.0;
    for (size_t k = 0; k + 1 < placed.size(); ++k) {
      for (double t = 0.0; t <= 1.0; t += 0.125) {
        const Point p = placed[k] + t * (placed[k + 1] - placed[k]);
        double d = std::numeric_limits<double>::infinity();
        for (size_t j = 0; j + 1 < bottom.size(); ++j) {
          d = std::min(d, DistanceToSegment(p, bottom[j], bottom[j + 1]));
        }
        worst = std::max(worst, d);
      }
    }
    return worst;
  };
  ArtEmbeddingReport report;
  absl::StatusOr<EmbeddedArt> along = EmbedArt(mesh, 0, {edge}, {}, &report);
  ASSERT_TRUE(along.ok()) << along.status();
  EXPECT_EQ(report.inserted, 15);  // the inner bottom vertices' feet
  EXPECT_LT(farthest(PlacePath(along->layers[0].paths[0], bent)), 0.05);
  // The key itself is unchanged: the feet lie on the drawn segment.
  for (const Point& p : PlacePath(along->layers[0].paths[0], mesh.shapes[0])) {
    EXPECT_NEAR(p.y(), -0.01, 1e-12);
  }

  // Without the split it is one chord, far off.
  ArtEmbeddingOptions no_split;
  no_split.split_at_edges = false;
  absl::StatusOr<EmbeddedArt> chord = EmbedArt(mesh, 0, {edge}, no_split);
  ASSERT_TRUE(chord.ok());
  EXPECT_GT(farthest(PlacePath(chord->layers[0].paths[0], bent)), 1.0);
}

TEST(ArtEmbeddingTest, ThousandsOfPointsOnThousandsOfTriangles) {
  const Multimesh mesh = JitteredGrid(60, 40, 0.3);  // 4800 triangles
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> ux(0.0, 60.0), uy(0.0, 40.0);
  ArtLayer scribble = StrokeLayer({}, 0, 0.5);
  for (int i = 0; i < 5000; ++i) scribble.paths[0].points.emplace_back(ux(rng), uy(rng));
  ArtEmbeddingReport report;
  absl::StatusOr<EmbeddedArt> embedded = EmbedArt(mesh, 0, {scribble}, {}, &report);
  ASSERT_TRUE(embedded.ok());
  const Points placed = PlacePath(embedded->layers[0].paths[0], mesh.shapes[0]);
  const Points original = Drawn(embedded->layers[0].paths[0], placed);
  ASSERT_EQ(original.size(), scribble.paths[0].points.size());
  double error = 0.0;
  for (size_t i = 0; i < original.size(); ++i) {
    error = std::max(error, (original[i] - scribble.paths[0].points[i]).norm());
  }
  EXPECT_LT(error, 1e-12);
  EXPECT_EQ(report.outside, 0);
  RecordProperty("seconds", std::to_string(report.seconds));
}

TEST(ArtEmbeddingTest, Deterministic) {
  const Multimesh mesh = JitteredGrid(8, 6, 0.25);
  const EmbeddedArt a = *EmbedArt(mesh, 0, Face());
  const EmbeddedArt b = *EmbedArt(mesh, 0, Face());
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (size_t l = 0; l < a.layers.size(); ++l) {
    for (size_t k = 0; k < a.layers[l].paths.size(); ++k) {
      const auto& pa = a.layers[l].paths[k].points;
      const auto& pb = b.layers[l].paths[k].points;
      ASSERT_EQ(pa.size(), pb.size());
      for (size_t i = 0; i < pa.size(); ++i) {
        EXPECT_EQ(pa[i].triangle, pb[i].triangle);
        EXPECT_EQ(pa[i].barycentric, pb[i].barycentric);
      }
    }
  }
}

TEST(ArtEmbeddingTest, RejectsBadInput) {
  const Multimesh mesh = JitteredGrid(2, 2, 0.0);
  EXPECT_EQ(EmbedArt(mesh, 1, Face()).status().code(), absl::StatusCode::kInvalidArgument);
  const ArtLayer bad = FillLayer({{0.5, 0.5}, {std::nan(""), 1.0}}, 0);
  absl::Status status = EmbedArt(mesh, 0, {bad}).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("path 1: point 2"), std::string::npos) << status;
  const EmbeddedArt art = *EmbedArt(mesh, 0, Face());
  EXPECT_EQ(PlaceArt(art, Points(3)).status().code(), absl::StatusCode::kInvalidArgument);
}

// Built from two drawings (a square and a sheared square): each key's own art is reproduced in
// its own shape.
TEST(ArtEmbeddingTest, BuiltMultimeshKeysReproduceTheirArt) {
  auto sheared = [](const Point& p) { return Point(p.x() + 0.4 * p.y(), p.y()); };
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  Drawing a, b;
  a.outlines.push_back({square});
  b.outlines.emplace_back();
  for (const Point& p : square) b.outlines[0].points.push_back(sheared(p));
  absl::StatusOr<Multimesh> mesh = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const std::vector<ArtLayer> art_a = {FillLayer(square, 0xff0000),
                                       StrokeLayer({{1, 1}, {9, 9}, {9, 2}}, 0, 0.5)};
  std::vector<ArtLayer> art_b = art_a;
  for (ArtLayer& layer : art_b) {
    for (Point& p : layer.paths[0].points) p = sheared(p);
  }
  for (int key : {0, 1}) {
    const std::vector<ArtLayer>& art = key == 0 ? art_a : art_b;
    const EmbeddedArt embedded = *EmbedArt(*mesh, key, art);
    const std::vector<ArtLayer> placed = *PlaceArt(embedded, mesh->shapes[key]);
    for (size_t l = 0; l < art.size(); ++l) {
      const Points original = Drawn(embedded.layers[l].paths[0], placed[l].paths[0].points);
      ASSERT_EQ(original.size(), art[l].paths[0].points.size());
      for (size_t i = 0; i < original.size(); ++i) {
        EXPECT_LT((original[i] - art[l].paths[0].points[i]).norm(), 1e-9 * 10);
      }
    }
  }
}

// BuildMultimesh embeds every drawing's art in its own shape (Multimesh::art), and
// ValidateMultimesh refuses art that does not fit the mesh.
TEST(ArtEmbeddingTest, BuildMultimeshEmbedsTheDrawingsArt) {
  auto sheared = [](const Point& p) { return Point(p.x() + 0.4 * p.y(), p.y()); };
  const Points square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  Drawing a, b;
  a.outlines.push_back({square});
  a.art = {FillLayer(square, 0xff0000), StrokeLayer({{1, 1}, {9, 9}, {9, 2}}, 0, 0.5)};
  b = a;
  for (Point& p : b.outlines[0].points) p = sheared(p);
  for (ArtLayer& layer : b.art) {
    for (Point& p : layer.paths[0].points) p = sheared(p);
  }
  absl::StatusOr<Multimesh> mesh = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_EQ(mesh->art.size(), 2u);
  for (int key : {0, 1}) {
    const Drawing& drawing = key == 0 ? a : b;
    EXPECT_EQ(mesh->art[key].key, key);
    EXPECT_EQ(mesh->art[key].num_vertices, mesh->num_vertices());
    const std::vector<ArtLayer> placed = *PlaceArt(mesh->art[key], mesh->shapes[key]);
    ASSERT_EQ(placed.size(), drawing.art.size());
    for (size_t l = 0; l < placed.size(); ++l) {
      const Points drawn = Drawn(mesh->art[key].layers[l].paths[0], placed[l].paths[0].points);
      ASSERT_EQ(drawn.size(), drawing.art[l].paths[0].points.size());
      for (size_t i = 0; i < drawn.size(); ++i) {
        EXPECT_LT((drawn[i] - drawing.art[l].paths[0].points[i]).norm(), 1e-8);
      }
    }
  }
  EXPECT_TRUE(ValidateMultimesh(*mesh).ok());

  Multimesh bad = *mesh;
  bad.art[1].layers[0].paths[0].points[0].triangle = static_cast<int>(bad.triangles.size());
  EXPECT_THAT(ValidateMultimesh(bad).message(), HasSubstr("multimesh art 1 layer 0 path 0"));
  bad = *mesh;
  bad.art.pop_back();
  EXPECT_THAT(ValidateMultimesh(bad).message(), HasSubstr("1 drawings for 2 shapes"));

  // Without art, none.
  a.art.clear();
  b.art.clear();
  mesh = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_TRUE(mesh->art.empty());
}

}  // namespace
}  // namespace inbetween::solver
