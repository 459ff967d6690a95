// Multimesh construction across topology: several components, holes, cuts and openings
// (S-Sec.1, S-Alg.1): valid in every shape, boundary loops, cohesive pairs closed where drawn.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "solver/geometry/polygon.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

Points Circle(Point c, double r, int n, bool positive = true) {
  Points p;
  for (int i = 0; i < n; ++i) {
    const double a = (positive ? 2 : -2) * M_PI * i / n;
    p.push_back(c + r * Point(std::cos(a), std::sin(a)));
  }
  return p;
}

Points Rect(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

double Area(const Multimesh& m, int s) {
  double a = 0;
  for (const Triangle& t : m.triangles) a += 0.5 * SignedArea2(t, m.shapes[s]);
  return a;
}

void ExpectValid(const Multimesh& m) {
  EXPECT_TRUE(ValidateMultimesh(m).ok()) << ValidateMultimesh(m);
  EXPECT_TRUE(ValidateBoundaryLoops(m).ok()) << ValidateBoundaryLoops(m);
  EXPECT_TRUE(ValidateCohesiveEdges(m).ok()) << ValidateCohesiveEdges(m);
  for (int s = 0; s < m.num_shapes(); ++s) EXPECT_EQ(CountInverted(m.triangles, m.shapes[s]), 0);
}

TEST(BuildMultimeshTopologyTest, AnnulusToAnnulusWithMovedHole) {
  Drawing a, b;
  a.outlines = {{Circle({0, 0}, 10, 48)}, {Circle({0, 0}, 4, 24, false)}};
  b.outlines = {{Rect(-12, -8, 12, 8)}, {Circle({5, 1}, 3, 24, false)}};
  MultimeshReport report;
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, {}, nullptr, nullptr, &report);
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectValid(*m);
  EXPECT_EQ(m->boundary_loops.size(), 2u);
  EXPECT_TRUE(m->cohesive_edges.empty());
  EXPECT_EQ(report.equivalence,
            (std::vector<std::string>{"1 component, 1 hole", "1 component, 1 hole"}));
  EXPECT_NEAR(Area(*m, 1), 24 * 16 - M_PI * 9, 2.0);
}

TEST(BuildMultimeshTopologyTest, TwoComponentsMatchedByPosition) {
  Drawing a, b;
  a.outlines = {{Rect(0, 0, 10, 10)}, {Circle({30, 5}, 5, 32)}};
  b.outlines = {{Circle({32, 6}, 6, 32)}, {Rect(-1, 0, 9, 12)}};  // listed the other way round
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectValid(*m);
  ASSERT_EQ(m->boundary_loops.size(), 2u);
  // Each loop stays on its side in both drawings.
  for (const auto& loop : m->boundary_loops) {
    const bool left0 = m->shapes[0][loop[0]].x() < 20;
    for (int v : loop) {
      EXPECT_EQ(m->shapes[0][v].x() < 20, left0);
      EXPECT_EQ(m->shapes[1][v].x() < 20, left0);
    }
  }
}

TEST(BuildMultimeshTopologyTest, ClosedMouthOpensThroughAnOpening) {
  Drawing closed, open;
  closed.outlines = {{Circle({0, 0}, 10, 64)}};
  closed.openings = {{{-5, 2}, {0, 2.5}, {5, 2}}};
  open.outlines = {{Circle({0, 0}, 10, 64)}};
  open.outlines.push_back({{{-5, 2}, {0, 0}, {5, 2}, {0, 5}}});  // the open mouth
  // Both orders: meshing the open mouth first means collapsing its hole onto the slit.
  for (const auto& drawings :
       {std::vector<Drawing>{closed, open}, std::vector<Drawing>{open, closed}}) {
    absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, {});
    ASSERT_TRUE(m.ok()) << m.status();
    ExpectValid(*m);
    EXPECT_EQ(m->boundary_loops.size(), 2u);
    EXPECT_FALSE(m->cohesive_edges.empty());
    const int closed_shape = drawings[0].openings.empty() ? 1 : 0;
    EXPECT_EQ(m->cohesive_closed[closed_shape].size(), m->cohesive_edges.size());
    EXPECT_TRUE(m->cohesive_closed[1 - closed_shape].empty());
    EXPECT_NEAR(Area(*m, 1 - closed_shape), M_PI * 100 - 25, 1.5);
  }
}

// Each drawing closes a different mouth, so whichever is meshed first, one hole must collapse
// onto a slit (2*pi at its tips): the boundary fans there get enough triangles.
TEST(BuildMultimeshTopologyTest, TwoMouthsClosedInDifferentDrawings) {
  Drawing a, b;
  a.outlines = {{Rect(0, 0, 40, 20)}};
  b.outlines = {{Rect(0, 0, 40, 20)}};
  a.openings = {{{5, 10}, {10, 11}, {15, 10}}};
  b.outlines.push_back({{{5, 10}, {10, 7}, {15, 10}, {10, 13}}});
  a.outlines.push_back({{{25, 10}, {30, 7}, {35, 10}, {30, 13}}});
  b.openings = {{{25, 10}, {30, 11}, {35, 10}}};
  for (const auto& drawings : {std::vector<Drawing>{a, b}, std::vector<Drawing>{b, a}}) {
    absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, {});
    ASSERT_TRUE(m.ok()) << m.status();
    ExpectValid(*m);
    EXPECT_EQ(m->boundary_loops.size(), 3u);
    EXPECT_FALSE(m->cohesive_closed[0].empty());
    EXPECT_FALSE(m->cohesive_closed[1].empty());
    EXPECT_NEAR(Area(*m, 0), 800 - 30, 1e-6);
    EXPECT_NEAR(Area(*m, 1), 800 - 30, 1e-6);
  }
}

TEST(BuildMultimeshTopologyTest, CutSplitsOneShapeIntoTwo) {
  Drawing whole, parts;
  whole.outlines = {{Rect(0, 0, 20, 10)}};
  whole.cuts = {{{10, -1}, {10, 11}}};
  parts.outlines = {{Rect(-5, 0, 8, 10)}, {Rect(12, 2, 25, 12)}};
  for (const auto& drawings :
       {std::vector<Drawing>{whole, parts}, std::vector<Drawing>{parts, whole}}) {
    absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, {});
    ASSERT_TRUE(m.ok()) << m.status();
    ExpectValid(*m);
    EXPECT_EQ(m->boundary_loops.size(), 2u);
    const int whole_shape = drawings[0].cuts.empty() ? 1 : 0;
    EXPECT_FALSE(m->cohesive_edges.empty());
    EXPECT_EQ(m->cohesive_closed[whole_shape].size(), m->cohesive_edges.size());
    EXPECT_NEAR(Area(*m, whole_shape), 200, 1e-6);
  }
}

// A fine size bound makes CGAL put Steiner points on the cut sides of the meshed drawing; each
// is mirrored onto the twin side, so the cut's two sides carry the same points where it is
// closed, whichever drawing is meshed.
TEST(BuildMultimeshTopologyTest, BoundarySteinerPointsMirroredAcrossCuts) {
  Drawing whole, parts;
  whole.outlines = {{Rect(0, 0, 20, 10)}};
  whole.cuts = {{{10, -1}, {10.5, 5}, {10, 11}}};
  parts.outlines = {{Rect(-5, 0, 8, 10)}, {Rect(12, 2, 25, 12)}};
  MultimeshOptions options;
  options.boundary_vertices = 16;
  options.max_edge_relative = 0.03;
  for (const auto& drawings :
       {std::vector<Drawing>{whole, parts}, std::vector<Drawing>{parts, whole}}) {
    absl::StatusOr<Multimesh> m = BuildMultimesh(drawings, options);
    ASSERT_TRUE(m.ok()) << m.status();
    ExpectValid(*m);
    const int w = drawings[0].cuts.empty() ? 1 : 0;
    // Boundary vertices on the cut (away from the outline) come in collocated pairs.
    std::map<std::pair<double, double>, int> on_cut;
    for (int v : m->boundary) {
      const Point p = m->shapes[w][v];
      if (p.y() > 1e-9 && p.y() < 10 - 1e-9 && p.x() > 1 && p.x() < 19) ++on_cut[{p.x(), p.y()}];
    }
    EXPECT_GT(on_cut.size(), 8u);  // more than the 16-vertex boundary alone would give
    for (const auto& [p, count] : on_cut) {
      EXPECT_EQ(count, 2) << "(" << p.first << ", " << p.second << ")";
    }
    EXPECT_EQ(m->cohesive_edges.size(), on_cut.size() + 1);
  }
}

TEST(BuildMultimeshTopologyTest, DifferentClassesNameEachDrawing) {
  Drawing disk, ring;
  disk.outlines = {{Circle({0, 0}, 10, 32)}};
  ring.outlines = {{Circle({0, 0}, 10, 32)}, {Circle({0, 0}, 3, 16, false)}};
  absl::Status s = BuildMultimesh({disk, ring}, {}).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(),
              HasSubstr("drawing 1: 1 component, 0 holes; drawing 2: 1 component, 1 hole"));
  EXPECT_THAT(s.message(), HasSubstr("add an opening"));
}

TEST(BuildMultimeshTopologyTest, DrawingMarksUsedWhenOptionsHaveNone) {
  Drawing a, b;
  a.outlines = {{Circle({0, 0}, 10, 64)}};
  b.outlines = {{Circle({0, 0}, 10, 64)}};
  a.marks = {{7, {10, 0}}, {2, {-10, 0}}};
  b.marks = {{2, {0, -10}}, {7, {0, 10}}};
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectValid(*m);
  int pinned = 0;
  for (int v : m->boundary) {
    if ((m->shapes[0][v] - Point(10, 0)).norm() < 1e-6) {
      EXPECT_NEAR((m->shapes[1][v] - Point(0, 10)).norm(), 0, 1e-6);
      ++pinned;
    }
  }
  EXPECT_EQ(pinned, 1);
  b.marks.pop_back();
  absl::Status missing = BuildMultimesh({a, b}, {}).status();
  EXPECT_EQ(missing.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(missing.message(), HasSubstr("mark 7 is in drawing 1 but not in drawing 2"));
}

TEST(BuildMultimeshTopologyTest, MarksPinCorrespondingPoints) {
  Drawing a, b;
  a.outlines = {{Circle({0, 0}, 10, 64)}};
  b.outlines = {{Circle({0, 0}, 10, 64)}};
  MultimeshOptions options;
  // Mark 1: right of drawing 1 goes to the top of drawing 2; mark 2: left goes to the bottom.
  options.marks = {{{10, 0}, {0, 10}}, {{-10, 0}, {0, -10}}};
  absl::StatusOr<Multimesh> m = BuildMultimesh({a, b}, options);
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectValid(*m);
  std::vector<int> pinned;
  for (int v : m->boundary) {
    if ((m->shapes[0][v] - Point(10, 0)).norm() < 1e-6) {
      EXPECT_NEAR((m->shapes[1][v] - Point(0, 10)).norm(), 0, 1e-6);
      pinned.push_back(v);
    }
    if ((m->shapes[0][v] - Point(-10, 0)).norm() < 1e-6) {
      EXPECT_NEAR((m->shapes[1][v] - Point(0, -10)).norm(), 0, 1e-6);
      pinned.push_back(v);
    }
  }
  EXPECT_EQ(pinned.size(), 2u);
  // The multimesh lists them as pinned (for comesh optimization), ascending.
  std::sort(pinned.begin(), pinned.end());
  EXPECT_EQ(m->pinned, pinned);
  // Without marks nothing is pinned.
  absl::StatusOr<Multimesh> free = BuildMultimesh({a, b}, {});
  ASSERT_TRUE(free.ok()) << free.status();
  EXPECT_TRUE(free->pinned.empty());
}

}  // namespace
}  // namespace inbetween::solver
