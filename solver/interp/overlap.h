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
  int vertex = -1;         // boundary vertex inside the shape
  Eigen::Vector2d target;  // closest point on a boundary segment not incident to it
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

  // Boundary vertices strictly inside the shape, each with the closest point on the boundary.
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
  std::vector<std::pair<int, int>> Inside(const Coords& x) const;  // (vertex, triangle)

  std::vector<Triangle> triangles_;
  std::vector<std::array<int, 2>> segments_;  // boundary edges
  std::vector<int> boundary_vertices_;
  std::vector<std::vector<int>> twins_;         // per vertex: cohesive twins (collocated partners)
  mutable std::unique_ptr<Bvh> triangle_tree_;  // built on the first check, refit after
  mutable std::unique_ptr<Bvh> segment_tree_;
};

}  // namespace inbetween::solver
