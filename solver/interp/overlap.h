// Non-overlap W_O (S-eq.8/9) as a check: W_O(x) = 0 iff no boundary point of the deformed
// shape lies in its interior. Discretely (P1 boundary): no boundary vertex strictly inside a
// triangle that does not contain it, and no two boundary segments that share no vertex cross.
// Both queries go through bounding volume hierarchies (over triangles and over boundary
// segments), so a check costs O(b log T) for b boundary vertices. The hierarchies' topology is
// built on the first check and refit (O(T)) on later ones.
// Cohesive twins (the two sides of a cohesive edge pair, collocated while the zone is closed)
// are exempt from each other: a closed zone touches itself by design.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

#include "solver/core/types.h"
#include "solver/interp/arap_energy.h"

namespace inbetween::solver {

struct OverlapContact {
  int vertex = -1;  // boundary vertex inside the shape
  // Where it leaves the material it is in: the closest boundary point of that material (found by
  // a walk over triangles from the one holding the vertex, see Contacts), moved outward by 1% of
  // that segment's length so that a one-sided spring pushing the vertex past the segment's line
  // leaves it outside.
  Eigen::Vector2d target;
  Eigen::Vector2d normal;  // the segment's outward unit normal: the vertex belongs where
                           // normal . (x - target) >= 0
};

class OverlapChecker {
 public:
  // Boundary edges are the edges of exactly one triangle. `cohesive_edges` as in Multimesh.
  OverlapChecker(const std::vector<Triangle>& triangles,
                 const std::vector<std::array<int, 4>>& cohesive_edges, int num_vertices);
  OverlapChecker(OverlapChecker&&) noexcept;
  OverlapChecker& operator=(OverlapChecker&&) noexcept;
  ~OverlapChecker();

  // Boundary vertices strictly inside the shape (deeper than `margin` times the local edge
  // length) plus properly crossing boundary segment pairs.
  int Count(const Coords& x) const;

  // Boundary vertices strictly inside the shape, each with its way out. The target is searched
  // from the triangle holding the vertex outward (best first by distance, never through the
  // vertex's own triangles), so it is a boundary point of the material the vertex entered. The
  // plain closest boundary point is often the vertex's own side (its neighbours along the
  // boundary are one edge away), which pushes it along its own boundary instead of out. Every
  // vertex inside gets a contact: an empty result means no boundary vertex is inside.
  std::vector<OverlapContact> Contacts(const Coords& x) const;

  const std::vector<int>& boundary_vertices() const { return boundary_vertices_; }

  // Properly crossing boundary segment pairs only (Count = inside vertices + this).
  int Crossings(const Coords& x) const;

 private:
  using Box = Eigen::AlignedBox2d;
  class Bvh;
  // Builds *tree from `boxes` on first use, else refits it.
  const Bvh& Tree(std::vector<Box> boxes, std::unique_ptr<Bvh>* tree) const;
  bool Exempt(int v, const Triangle& t) const;
  bool Exempt(int a, int b, int c, int d) const;
  std::vector<std::pair<int, int>> Inside(const Coords& x) const;         // (vertex, triangle)
  std::vector<std::pair<int, int>> CrossingPairs(const Coords& x) const;  // segment indices

  std::vector<Triangle> triangles_;
  std::vector<std::array<int, 2>> segments_;  // boundary edges
  std::vector<int> boundary_vertices_;
  std::vector<std::array<int, 3>> neighbours_;    // per triangle, across edge k (t[k], t[k+1])
  std::vector<std::array<int, 3>> edge_segment_;  // per triangle edge: boundary segment or -1
  std::vector<std::vector<int>> twins_;         // per vertex: cohesive twins (collocated partners)
  mutable std::unique_ptr<Bvh> triangle_tree_;  // built on the first check, refit after
  mutable std::unique_ptr<Bvh> segment_tree_;
};

}  // namespace inbetween::solver
