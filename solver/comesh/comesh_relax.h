// Local relaxation for the comesh inner loop (comesh_optimizer.h, ComeshOptions::relax_fraction).
//
// Near the end of an inner run most of the gradient sits on a handful of vertices of nearly
// degenerate triangles, where the MIPS term acts as a barrier (docs/benchmarks.md): the one
// L-BFGS scale and the inversion bound of the whole mesh then follow those few vertices, and the
// rest of the mesh takes tiny steps. Moving those vertices alone to (near) their own optimum
// between two global steps takes them out of the way.
//
// A target is one vertex in one shape. It moves alone, by damped Newton steps (the 2 x 2 Hessian
// from central differences of the analytic gradient, its eigenvalues floored; a slider along its
// line only) on the part of the objective that depends on its position: the ODT terms of its
// one-ring in that shape and the two MIPS terms of the cycle that involve that shape. Each step is
// inversion-free (with one moving corner, each ring triangle's area is linear in the step: the
// step starts at 0.8 of the first zero) and must satisfy Armijo's condition, so the objective
// never increases and every triangle stays positive in every shape. Targets are relaxed in the
// given order, each seeing the moves before it; results do not depend on threads.
#pragma once

#include <limits>
#include <span>
#include <vector>

#include "solver/comesh/comesh_objective.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct RelaxTarget {
  int shape = 0;
  int vertex = 0;
  bool slider = false;              // moves along `direction` only
  Point direction = Point::Zero();  // unit, sliders only
  // Sliders: the vertex stays at base + z * direction with lo <= z <= hi.
  Point base = Point::Zero();
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
};

class VertexRelaxer {
 public:
  // Keeps a reference to `objective` (and its triangles): it must outlive the relaxer.
  explicit VertexRelaxer(const ComeshObjective& objective);

  // Relaxes every target in order with up to `steps` Newton steps each and returns how many
  // moved. *shapes must be valid (every triangle positive). If `gradient` (Evaluate's layout,
  // dE/dX per shape and vertex) and `energies` are given and something moved, they are updated by
  // the change of the terms of the triangles around the targets, so they stay those of *shapes
  // (up to rounding) without a full evaluation; if nothing moved they are left untouched.
  int Relax(std::span<const RelaxTarget> targets, int steps, std::vector<Points>* shapes,
            std::vector<Points>* gradient = nullptr, ComeshEnergies* energies = nullptr) const;

  // The terms of the objective that depend on X_s(v), at X_s(v) = p (the other vertices as in
  // `shapes`), and their gradient with respect to p in *grad. +inf if a ring triangle is not
  // positive in some shape.
  double VertexEnergy(const std::vector<Points>& shapes, int s, int v, const Point& p,
                      Point* grad) const;

 private:
  struct GradientChange {
    int shape;
    int vertex;
    Point change;
  };
  bool RelaxOne(const RelaxTarget& target, int steps, std::vector<Points>* shapes) const;
  // Adds sign times the terms of `triangles` at `shapes` to the sums and, if `changes` is given,
  // appends their gradient contributions (times sign) to it, in triangle order.
  void Tally(const std::vector<int>& triangles, const std::vector<Points>& shapes, double sign,
             double* mesh_sum, double* map_sum, std::vector<GradientChange>* changes) const;

  const ComeshObjective& objective_;
  std::vector<int> begin_;  // vertex -> ring triangles, CSR
  std::vector<int> ring_;
};

}  // namespace inbetween::solver
