// Closed boundary loops of a triangle mesh. The boundary is the set of edges that belong to
// exactly one triangle; each is taken in its triangle's vertex order, so the shape lies on the
// same side of every loop: outer loops keep the triangles' orientation (positive signed area),
// holes get the opposite one. Lottie paths and outline fills need these instead of triangles.
#pragma once

#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "client/render/frame_set.h"

namespace inbetween::render {

using Loop = std::vector<int>;  // vertex indices; the closing edge back to front() is implied

// The boundary loops of `triangles`, which depend on topology only, so one call serves every
// frame. Deterministic: loops are ordered by their first boundary edge in triangle order and
// start there. Where components touch at a vertex, each loop follows its own fan of triangles
// around that vertex, so touching components stay separate loops. Fails, naming the triangles,
// when a triangle repeats a vertex or two triangles share an edge in the same direction
// (inconsistent orientation or a non-manifold edge).
absl::StatusOr<std::vector<Loop>> BoundaryLoops(const std::vector<std::array<int, 3>>& triangles);

// Signed area 0.5 * sum(p_i x p_i+1) of a loop (positive = the triangles' orientation).
double LoopSignedArea(const Loop& loop, const std::vector<Vertex>& vertices);

}  // namespace inbetween::render
