// Adds triangles to the fans of boundary vertices that must open wide in some shape (e.g. the
// tip of a slit, whose interior angle is 2*pi), so an injective map into that shape exists.
#pragma once

#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// Interior angle (radians, in (0, 2*pi]) at `v` of a boundary walked prev -> v -> next with the
// shape on the left (types.h orientation); 2*pi when prev and next coincide (a slit tip).
double BoundaryInteriorAngle(const Point& prev, const Point& v, const Point& next);

// A triangle's angle must stay below pi in every shape, so a boundary vertex whose interior
// angle reaches `demand[v]` (radians) in some shape needs at least demand / max_angle triangles
// around it. For every boundary vertex with fewer, the triangle with the widest angle at v (in
// `vertices`, a valid positive mesh) is split through its opposite edge, which is always
// interior once boundary chords are split (split_boundary_chords.h): its midpoint becomes a new
// interior vertex (appended; `is_boundary` extended). Returns the number of vertices added.
int RefineBoundaryFans(const std::vector<double>& demand, Points* vertices,
                       std::vector<Triangle>* triangles, std::vector<bool>* is_boundary,
                       double max_angle = 1.75);

}  // namespace inbetween::solver
