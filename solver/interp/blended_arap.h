// S-eq.3 blended over n examples, measured in one fixed per-triangle reference so that the
// local-global system matrix does not depend on the example weights (the kZhu17 energy).
//
// For example i and triangle t let D_it be the edge matrix of X_i, and fix a reference edge
// matrix Dbar_t = Sbar_t D_0t, Sbar_t = (1/n) sum_i S_it the mean of the examples' stretches
// relative to example 0 (D_it D_0t^{-1} = R(theta_it) S_it, example_rotations.h). With
// Jbar_t(x) = E_t(x) Dbar_t^{-1} (E_t(x) the deformed edge matrix), A_it = D_it Dbar_t^{-1} and
// abar_t = det(Dbar_t) / 2 the reference area,
//   Wbar(w, x) = sum_i w_i Wbar_i(x),
//   Wbar_i(x)  = sum_t kappa_t abar_t min_{R in SO(2)} || Jbar_t(x) - R A_it ||_F^2.
// Relation to S-eq.3: J_it(x) = Jbar_t(x) A_it^{-1} is S-eq.3's deformation gradient from X_i and
// abar_t det(A_it) = a_it its area, so
//   Wbar_i(x) = sum_t kappa_t a_it min_R || (J_it - R) A_it ||_F^2 / det(A_it):
// S-eq.3 with the Frobenius norm weighted by A_it. It equals W_D(X_i, x) exactly where A_it is a
// similarity (the example is a rotated, uniformly scaled reference triangle) and lies within
// [sigma_2/sigma_1, sigma_1/sigma_2] (A_it's singular values) times it otherwise; with the mean
// reference the examples' anisotropies are split evenly. Its minimizers have the same defining
// properties: zero exactly at rigid motions of a key for w = e_k (so keys are exact), invariant to
// rigid motions of x. Because sum_i w_i = 1, the part quadratic in x is
// sum_t kappa_t abar_t ||Jbar_t||^2 = tr(x^T Kbar x) for every w, Kbar the cotangent Laplacian of
// the reference triangles, so one factorization serves every iteration of every frame:
//   local:  R_it = closest rotation to Jbar_t A_it^T;  T_t = sum_i w_i R_it A_it;
//   global: Kbar x = B(T), B's row v = sum_{t ni v} kappa_t abar_t (T_t gbar_{t,v})^T.
// Both steps minimise Wbar exactly in their variables, so Wbar never increases.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/interp/arap_energy.h"

namespace inbetween::solver {

class BlendedArap {
 public:
  // `shapes` share `triangles`. Fails (InvalidArgument) on a bad index, a triangle without
  // positive area in some shape (naming it), or a bad stiffness vector (empty = 1 everywhere).
  static absl::StatusOr<BlendedArap> Create(const std::vector<Triangle>& triangles,
                                            const std::vector<Points>& shapes,
                                            const std::vector<double>& stiffness = {});

  int num_vertices() const { return num_vertices_; }
  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  int num_examples() const { return static_cast<int>(angles_.size()); }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  double reference_area(int t) const { return areas_[t]; }
  double stiffness(int t) const { return weights_[t] / areas_[t]; }

  // Jbar_t(x).
  Eigen::Matrix2d DeformationGradient(const Coords& x, int t) const;

  // Local step at x: fills `targets` (resized) with T_t = sum_i w_i R_it A_it for the optimal
  // R_it and returns Wbar(w, x). Examples with w_i == 0 are skipped. `threads` (<= 0: all
  // cores) splits the triangles into fixed-size chunks whose energies are summed in chunk order,
  // so the result is bit-identical for every thread count.
  double LocalStep(const Coords& x, const std::vector<double>& w,
                   std::vector<Eigen::Matrix2d>* targets, int threads = 1) const;

  // Local step towards one given rest configuration instead of the examples: per triangle
  // R_t = closest rotation to Jbar_t(x) rest_t^T, T_t = R_t rest_t (rest_t = Jbar_t(Phi) for a
  // rest shape Phi); returns sum_t kappa_t abar_t ||Jbar_t(x) - R_t rest_t||^2 (the dynamics
  // term W_D(Phi, x) of S-eq.29 in this reference).
  double LocalStepToRest(const Coords& x, const std::vector<Eigen::Matrix2d>& rest,
                         std::vector<Eigen::Matrix2d>* targets) const;

  // Alexa et al. 2000 targets in this reference: T_t = R(theta_t(w)) S_t(w) Sbar_t^{-1},
  // theta_t(w) = sum_i w_i theta_it, S_t(w) = sum_i w_i S_it (= the local step's targets for the
  // rotations R_it = R(theta_t(w) - theta_it)).
  void AlexaTargets(const std::vector<double>& w, std::vector<Eigen::Matrix2d>* targets,
                    int threads = 1) const;

  // Wbar(w, x) and its gradient (envelope theorem: rotations frozen at their optimum).
  double Value(const Coords& x, const std::vector<double>& w) const;
  Coords Gradient(const Coords& x, const std::vector<double>& w) const;

  // Kbar (n x n, symmetric PSD, kernel = constants per edge-connected component).
  const Eigen::SparseMatrix<double>& Laplacian() const { return laplacian_; }

  // *b += B(targets), gathered per vertex over its triangles in increasing order (the order a
  // scatter over the triangles would add them), so it is bit-identical for every thread count.
  void AddRhs(const std::vector<Eigen::Matrix2d>& targets, Coords* b, int threads = 1) const;

  // Rotation gauge: area-weighted mean over the triangles of `group` of the angle of x relative to
  // example 0, each unwrapped to the nearest branch of the blended example angle theta_t(w),
  // minus the same mean of theta_t(w). Rotating the group by minus this value makes it 0.
  double AngleOffset(const Coords& x, const std::vector<double>& w,
                     const std::vector<int>& group) const;

  // Angle of triangle t of example i relative to example 0, unwrapped (example_rotations.h).
  double example_angle(int i, int t) const { return angles_[i][t]; }

 private:
  BlendedArap() = default;

  int num_vertices_ = 0;
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Matrix<double, 2, 3>> gradients_;  // gbar: grad of hat a, b, c
  std::vector<double> areas_;                           // abar_t
  std::vector<double> weights_;                         // kappa_t abar_t
  std::vector<Eigen::Matrix2d> mean_stretch_;           // Sbar_t
  std::vector<std::vector<Eigen::Matrix2d>> examples_;  // A_it [example][triangle]
  std::vector<std::vector<double>> angles_;             // theta_it
  std::vector<double> example_norms_;                   // sum_t kappa abar ||A_it||^2, per example
  std::vector<int> incidence_start_;                    // per vertex, into incidence_
  std::vector<int> incidence_;                          // 3 t + corner, by vertex, t increasing
  Eigen::SparseMatrix<double> laplacian_;
};

}  // namespace inbetween::solver
