// Basic predicates on closed polygons (an Outline's points): point containment, convexity and
// the first self-intersection; the signed area (PolygonSignedArea) is in primitives.h, included
// here for its callers. Shared by SVG import, correspondence and the mesh builder.
#pragma once

#include <cstdint>
#include <optional>

#include "solver/core/types.h"
#include "solver/geometry/primitives.h"  // PolygonSignedArea

namespace inbetween::solver {

// Even-odd point-in-polygon test (points exactly on the boundary may go either way).
bool PolygonContains(const Points& polygon, const Point& q);

// True when the closed polygon is convex (collinear vertices allowed) with positive area.
bool IsConvexPositive(const Points& polygon);

struct SelfIntersection {
  int segment_a = 0;  // segment i joins polygon[i] and polygon[(i + 1) % n]
  int segment_b = 0;
  Point location;  // a point where the two segments meet
};

// Returns a pair of segments of the closed polygon that cross, touch or overlap (other than
// consecutive segments meeting at their shared vertex), or nullopt for a simple polygon.
// Decided with exact predicates (solver/mesh/cgal_predicates.h). Sweep over x-sorted segment
// bounding boxes: worst case O(n^2) (e.g. a comb of long parallel teeth), so `max_pair_checks`
// (> 0) bounds the candidate pairs examined; when it is reached the search stops, returns
// nullopt and sets *gave_up (if given). -1 = no bound.
std::optional<SelfIntersection> FindSelfIntersection(const Points& polygon,
                                                     int64_t max_pair_checks = -1,
                                                     bool* gave_up = nullptr);

// Orients non-crossing closed outlines by even-odd nesting (types.h convention): outlines nested
// inside an even number of others become positive (outer), the rest negative (holes). The first
// point of each outline is kept.
void OrientByNesting(std::vector<Outline>* outlines);

}  // namespace inbetween::solver
