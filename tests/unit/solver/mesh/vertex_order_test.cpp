// Tests for vertex_order.h: Hilbert numbering is a permutation, idempotent, keeps the multimesh
// (same triangles, orientation, boundary and cohesive data) and makes triangles' corners close in
// index; BuildMultimesh hands out meshes already in that order.
#include "solver/mesh/vertex_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include "solver/io/svg_import.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/io/read_example.h"

namespace inbetween::solver {
namespace {

// A k x k grid of vertices (two triangles per cell, CCW) over [0, 1]^2 in shape 0 and a sheared
// copy in shape 1, numbered in a random order; boundary loop counter-clockwise.
Multimesh ShuffledGrid(int k, unsigned seed) {
  const int n = k * k;
  std::vector<int> label(n);
  std::iota(label.begin(), label.end(), 0);
  std::mt19937 rng(seed);
  std::shuffle(label.begin(), label.end(), rng);
  auto id = [&](int i, int j) { return label[j * k + i]; };
  Multimesh mesh;
  mesh.shapes.assign(2, Points(n));
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const Point p(i / (k - 1.0), j / (k - 1.0));
      mesh.shapes[0][id(i, j)] = p;
      mesh.shapes[1][id(i, j)] = Point(p.x() + 0.3 * p.y(), 1.2 * p.y());
    }
  }
  for (int j = 0; j + 1 < k; ++j) {
    for (int i = 0; i + 1 < k; ++i) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  std::vector<int> loop;
  for (int i = 0; i + 1 < k; ++i) loop.push_back(id(i, 0));
  for (int j = 0; j + 1 < k; ++j) loop.push_back(id(k - 1, j));
  for (int i = k - 1; i > 0; --i) loop.push_back(id(i, k - 1));
  for (int j = k - 1; j > 0; --j) loop.push_back(id(0, j));
  mesh.boundary = loop;
  mesh.boundary_loops = {loop};
  return mesh;
}

double MeanEdgeIndexDistance(const Multimesh& mesh) {
  double sum = 0.0;
  for (const Triangle& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) sum += std::abs(t[c] - t[(c + 1) % 3]);
  }
  return sum / (3.0 * mesh.triangles.size());
}

// Each triangle as its corner positions in shape s, starting at the lexicographically smallest
// corner (so the cyclic order, hence the orientation, is compared too).
std::multiset<std::array<double, 6>> TrianglesByPosition(const Multimesh& mesh, int s) {
  std::multiset<std::array<double, 6>> out;
  for (const Triangle& t : mesh.triangles) {
    int first = 0;
    for (int c = 1; c < 3; ++c) {
      const Point& a = mesh.shapes[s][t[c]];
      const Point& b = mesh.shapes[s][t[first]];
      if (a.x() < b.x() || (a.x() == b.x() && a.y() < b.y())) first = c;
    }
    std::array<double, 6> key;
    for (int c = 0; c < 3; ++c) {
      const Point& p = mesh.shapes[s][t[(first + c) % 3]];
      key[2 * c] = p.x();
      key[2 * c + 1] = p.y();
    }
    out.insert(key);
  }
  return out;
}

TEST(VertexOrderTest, HilbertOrderIsAPermutationAndIdempotent) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Points points(2000);
  for (Point& p : points) p = Point(u(rng), u(rng));
  points[7] = points[8];  // a tie: same cell, kept in index order
  const std::vector<int> to = HilbertOrder(points);
  std::vector<int> sorted = to;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < static_cast<int>(sorted.size()); ++k) ASSERT_EQ(sorted[k], k);
  EXPECT_LT(to[7], to[8]);
  Points moved(points.size());
  for (size_t v = 0; v < points.size(); ++v) moved[to[v]] = points[v];
  const std::vector<int> again = HilbertOrder(moved);
  for (int k = 0; k < static_cast<int>(again.size()); ++k) ASSERT_EQ(again[k], k);
  // Consecutive points on the curve are neighbours in the plane: the mean step is far below the
  // mean distance between random points (~5.2 here).
  double step = 0.0;
  for (size_t k = 1; k < moved.size(); ++k) step += (moved[k] - moved[k - 1]).norm();
  EXPECT_LT(step / (moved.size() - 1), 0.6);
  EXPECT_TRUE(HilbertOrder({}).empty());
}

TEST(VertexOrderTest, RenumberKeepsTheMultimeshAndBringsCornersClose) {
  Multimesh mesh = ShuffledGrid(60, 5);
  mesh.cohesive_edges = {{mesh.boundary[0], mesh.boundary[1], mesh.boundary[3], mesh.boundary[2]}};
  ASSERT_TRUE(
      ValidateMultimesh(
          Multimesh{mesh.triangles, mesh.shapes, mesh.boundary, {}, mesh.boundary_loops, {}})
          .ok());
  const Multimesh before = mesh;
  RenumberSpatially(&mesh);
  for (int s = 0; s < 2; ++s) {
    EXPECT_EQ(TrianglesByPosition(mesh, s), TrianglesByPosition(before, s)) << "shape " << s;
    EXPECT_EQ(CountInverted(mesh.triangles, mesh.shapes[s]), 0);
  }
  ASSERT_EQ(mesh.boundary.size(), before.boundary.size());
  for (size_t k = 0; k < mesh.boundary.size(); ++k) {
    EXPECT_EQ(mesh.shapes[1][mesh.boundary[k]], before.shapes[1][before.boundary[k]]);
    EXPECT_EQ(mesh.boundary_loops[0][k], mesh.boundary[k]);
  }
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(mesh.shapes[0][mesh.cohesive_edges[0][c]],
              before.shapes[0][before.cohesive_edges[0][c]]);
  }
  // Shuffled: a corner pair is ~n / 3 apart; on the curve a few rows of the grid at most.
  EXPECT_GT(MeanEdgeIndexDistance(before), 1000.0);
  EXPECT_LT(MeanEdgeIndexDistance(mesh), 100.0);
  // Triangles by their smallest corner.
  for (size_t t = 1; t < mesh.triangles.size(); ++t) {
    const Triangle& a = mesh.triangles[t - 1];
    const Triangle& b = mesh.triangles[t];
    EXPECT_LE(std::min({a[0], a[1], a[2]}), std::min({b[0], b[1], b[2]}));
  }
  const Multimesh once = mesh;
  RenumberSpatially(&mesh);
  EXPECT_EQ(mesh.triangles, once.triangles);
  EXPECT_EQ(mesh.shapes, once.shapes);
  EXPECT_EQ(mesh.boundary, once.boundary);
}

TEST(VertexOrderTest, BuildMultimeshNumbersAlongTheCurve) {
  std::vector<Drawing> drawings;
  for (const char* name : {"square_hexagon/square.svg", "square_hexagon/hexagon.svg"}) {
    absl::StatusOr<Drawing> d = ImportSvg(ReadExample(name));
    ASSERT_TRUE(d.ok()) << d.status();
    drawings.push_back(*d);
  }
  MultimeshOptions options;
  options.max_edge_relative = 0.03;
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, options);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_GT(mesh->num_vertices(), 1000);
  const std::vector<int> to = HilbertOrder(mesh->shapes[0]);
  for (int v = 0; v < static_cast<int>(to.size()); ++v) ASSERT_EQ(to[v], v);
  EXPECT_LT(MeanEdgeIndexDistance(*mesh), 0.05 * mesh->num_vertices());
}

}  // namespace
}  // namespace inbetween::solver
