// Cohesive energy W_C (S-eq.4-7) discretized on cohesive edge pairs (S-eq.10-16), and its
// local-global pieces for a system matrix that never changes.
//
// Edge pair e = {a, b, c, d}: a-b on one side, c-d its twin (a with c, b with d collocated in the
// examples where the zone is closed). Jumps g0 = x_a - x_c, g1 = x_b - x_d vary linearly along the
// edge (S-eq.10); with xhat the deformed edge direction (S-eq.14) and
// P = (1 - alpha) xhat xhat^T + alpha (I - xhat xhat^T) (S-eq.15), S-eq.13/16 integrate to
//   f_e(x) = lambda l_e / 3 (g0^T P g0 + g1^T P g1 + g0^T P g1),
// l_e the rest length (mean over the examples). The cap (S-eq.6) is applied per edge element to
// its mean density: the element's energy is min(f_e, tau_e l_e). Blended over the examples
// (DESIGN.md: sum_i w_i W_C(C_i, x)), C_i = the pairs collocated in X_i:
//   W_C(w, x) = sum_e c_e(w) min(f_e(x), tau_e l_e),   c_e(w) = sum_{i: e collocated in X_i} w_i.
// tau_e = tau (1 -/+ hysteresis) for an edge that was separated / bonded in the previous frame.
//
// Fixed matrix (DESIGN.md "The tau cap without refactoring"): the global matrix holds
// Hbar_e = mu lambda l_e / 3 [[I, I/2], [I/2, I]] on (g0, g1), mu = max(alpha, 1 - alpha), which
// bounds every branch's Hessian c_e H_e(xhat) from above. At the iterate x_k each edge picks its
// branch (bonded if f_e(x_k) < tau_e l_e, else separated) and contributes the majorizer
//   g^T Hbar g - 2 g^T q_e,   q_e = (Hbar - c_e H_e) g_k (bonded)  or  Hbar g_k (separated),
// which equals the chosen branch's energy at g_k up to a constant and lies above it everywhere
// (majorize-minimize): bonded zones pull the jump to 0, separated ones keep it where it is at no
// cost (the auxiliary jump p = g_k of DESIGN.md). With alpha = 1/2 and c_e = 1, q_e = 0 exactly.
// xhat is taken at x_k (lagged one iteration); for alpha = 1/2 it does not enter at all.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/interp/arap_energy.h"

namespace inbetween::solver {

struct CohesiveOptions {
  double lambda = 1.0;      // S-eq.6
  double tau = 0.1;         // S-eq.6, energy per unit length
  double alpha = 0.5;       // S-eq.7: 0 resists only shear (tangential), 1 only opening (normal)
  double hysteresis = 0.1;  // see the header comment
};

class CohesiveEnergy {
 public:
  // Fails (InvalidArgument) on an index out of range, a pair whose sides are never collocated
  // and differ in rest length, a zero-length edge, or options out of range.
  static absl::StatusOr<CohesiveEnergy> Create(const std::vector<std::array<int, 4>>& edges,
                                               const std::vector<Points>& shapes,
                                               CohesiveOptions options);

  int num_edges() const { return static_cast<int>(edges_.size()); }
  const std::array<int, 4>& edge(int e) const { return edges_[e]; }
  double length(int e) const { return lengths_[e]; }

  // c_e(w).
  double Activity(const std::vector<double>& w, int e) const;

  // Uncapped f_e(x) (S-eq.13/16).
  double EdgeEnergy(const Coords& x, int e) const;

  // Per-edge thresholds tau_e l_e for a frame whose previous frame is `previous` (nullptr: none).
  std::vector<double> Thresholds(const Coords* previous) const;

  // W_C(w, x) and its gradient (including xhat's dependence on x; not differentiable where an
  // edge sits exactly at its threshold).
  double Value(const Coords& x, const std::vector<double>& w,
               const std::vector<double>& thresholds) const;
  Coords Gradient(const Coords& x, const std::vector<double>& w,
                  const std::vector<double>& thresholds) const;

  // Hbar's entries (the same for the x and the y column), as triplets on vertex indices.
  void AddMatrix(std::vector<Eigen::Triplet<double>>* triplets) const;

  // Local step at x_k: picks every edge's branch, adds C^T q_e to *b (C: vertices -> jumps) and
  // returns W_C(w, x_k). `separated` (resized) gets 1 for the edges on the capped branch.
  double LocalStep(const Coords& x, const std::vector<double>& w,
                   const std::vector<double>& thresholds, Coords* b,
                   std::vector<char>* separated) const;

 private:
  CohesiveEnergy() = default;
  Eigen::Vector2d Direction(const Coords& x, int e) const;  // xhat (S-eq.14)

  CohesiveOptions options_;
  double mu_ = 0.5;
  std::vector<std::array<int, 4>> edges_;
  std::vector<double> lengths_;
  std::vector<Eigen::Vector2d> rest_directions_;  // fallback for a degenerate deformed edge
  std::vector<std::vector<char>> closed_;         // [edge][example]: collocated in X_i
};

}  // namespace inbetween::solver
