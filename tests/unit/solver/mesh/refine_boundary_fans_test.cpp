// Boundary fan refinement: fans grow to what the widest demanded angle needs, the mesh stays
// valid, and a hole can then be collapsed onto a slit (2*pi at its tips) without folding.
#include "solver/mesh/refine_boundary_fans.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

TEST(RefineBoundaryFansTest, InteriorAngles) {
  EXPECT_NEAR(BoundaryInteriorAngle({-1, 0}, {0, 0}, {1, 0}), M_PI, 1e-12);
  EXPECT_NEAR(BoundaryInteriorAngle({1, 0}, {0, 0}, {1, 0}), 2 * M_PI, 1e-12);  // slit tip
  // Walking (0,1) -> (0,0) -> (1,0) keeps the inside of the positive unit square on the left.
  EXPECT_NEAR(BoundaryInteriorAngle({0, 1}, {0, 0}, {1, 0}), 0.5 * M_PI, 1e-12);
  EXPECT_NEAR(BoundaryInteriorAngle({1, 0}, {0, 0}, {0, 1}), 1.5 * M_PI, 1e-12);
}

// A rectangle with a diamond hole; the hole is then collapsed onto the segment y = 10.
struct HoleMesh {
  Points vertices;
  std::vector<Triangle> triangles;
  std::vector<bool> is_boundary;
  std::vector<int> boundary;  // outer loop then hole loop
  size_t hole_begin = 0;
};

HoleMesh MakeHoleMesh() {
  const std::vector<Points> loops = {{{0, 0}, {40, 0}, {40, 20}, {0, 20}},
                                     {{15, 10}, {20, 14}, {25, 10}, {20, 6}}};
  TriangulateOptions options;
  options.max_edge = 4.0;
  absl::StatusOr<DomainTriangulation> dt = CgalTriangulateDomain(loops, options);
  EXPECT_TRUE(dt.ok()) << dt.status();
  // Keep only vertices of triangles (CGAL also refines inside the hole).
  HoleMesh m;
  std::vector<int> index(dt->vertices.size(), -1);
  auto use = [&](int v) {
    if (index[v] < 0)
      index[v] = static_cast<int>(m.vertices.size()), m.vertices.push_back(dt->vertices[v]);
    return index[v];
  };
  for (const Triangle& t : dt->triangles) m.triangles.push_back({use(t[0]), use(t[1]), use(t[2])});
  for (size_t g = 0; g < loops.size(); ++g) {
    if (g == 1) m.hole_begin = m.boundary.size();
    for (size_t k = 0; k < loops[g].size(); ++k) {
      m.boundary.push_back(use(dt->loop_vertex[g][k]));
      for (int v : dt->edge_chain[g][k]) m.boundary.push_back(use(v));
    }
  }
  m.is_boundary.assign(m.vertices.size(), false);
  for (int v : m.boundary) m.is_boundary[v] = true;
  SplitBoundaryChords(&m.vertices, &m.triangles, &m.is_boundary);
  return m;
}

TEST(RefineBoundaryFansTest, FansReachTheDemandedAngle) {
  HoleMesh m = MakeHoleMesh();
  std::vector<double> demand(m.vertices.size(), 0.0);
  for (int v : m.boundary) demand[v] = 2 * M_PI;
  const int added = RefineBoundaryFans(demand, &m.vertices, &m.triangles, &m.is_boundary);
  EXPECT_GT(added, 0);
  EXPECT_EQ(CountInverted(m.triangles, m.vertices), 0);
  EXPECT_EQ(m.is_boundary.size(), m.vertices.size());
  for (int v : m.boundary) {
    int fan = 0;
    for (const Triangle& t : m.triangles) fan += (t[0] == v) + (t[1] == v) + (t[2] == v);
    EXPECT_GE(fan, 4) << "vertex " << v;
  }
}

TEST(RefineBoundaryFansTest, HoleCollapsesOntoASlit) {
  HoleMesh m = MakeHoleMesh();
  Points target;
  for (size_t k = 0; k < m.boundary.size(); ++k) {
    const Point p = m.vertices[m.boundary[k]];
    target.push_back(k < m.hole_begin ? p : Point(p.x(), 10.0));
  }
  std::vector<double> demand(m.vertices.size(), 0.0);
  const size_t hole = m.boundary.size() - m.hole_begin;
  for (size_t k = 0; k < hole; ++k) {
    const auto at = [&](size_t j) { return target[m.hole_begin + (j + hole) % hole]; };
    demand[m.boundary[m.hole_begin + k]] = BoundaryInteriorAngle(at(k - 1), at(k), at(k + 1));
  }
  RefineBoundaryFans(demand, &m.vertices, &m.triangles, &m.is_boundary);
  MapToBoundaryOptions options;
  options.tutte_when_convex = false;
  absl::StatusOr<Points> mapped =
      MapToBoundary(m.vertices, m.triangles, m.boundary, target, options);
  ASSERT_TRUE(mapped.ok()) << mapped.status();
  EXPECT_EQ(CountInverted(m.triangles, *mapped), 0);
  for (size_t k = 0; k < m.boundary.size(); ++k) {
    EXPECT_EQ((*mapped)[m.boundary[k]], target[k]);
  }
}

}  // namespace
}  // namespace inbetween::solver
