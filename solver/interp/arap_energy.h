// S-eq.3 discretized with linear (P1) triangles: the ARAP energy of a deformed shape x relative
// to one example X,
//   W_D(X, x) = sum_t kappa_t A_t || J_t(x) - R_t ||_F^2,  J_t(x) = [x_b-x_a, x_c-x_a] D_t^{-1},
// D_t = [X_b-X_a, X_c-X_a] the example's edge matrix, A_t its area, R_t in SO(2).
// Local step: the minimizing R_t is the closest rotation to J_t (polar.h). Global step: with the
// per-triangle targets T_t fixed (rotations, or Alexa's blended matrices) the energy is quadratic
// and separable in the x and y coordinates,
//   W = tr(x^T K x) - 2 tr(x^T B(T)) + sum_t kappa_t A_t ||T_t||^2,
// K = sum_t kappa_t A_t G_t^T G_t the stiffness-weighted cotangent Laplacian of X (G_t: the
// gradients of the triangle's three hat functions), so one factorization of K serves both columns.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"

namespace inbetween::solver {

// Vertex positions as an n x 2 matrix, one row per vertex.
using Coords = Eigen::Matrix<double, Eigen::Dynamic, 2>;

Coords ToCoords(const Points& points);
Points ToPoints(const Coords& coords);

class ArapEnergy {
 public:
  // `rest` is the example X. Fails (InvalidArgument) on an index out of range, a repeated index
  // in a triangle, a triangle without positive area in `rest`, or a stiffness vector that is not
  // empty (= all 1) or one positive finite value per triangle.
  static absl::StatusOr<ArapEnergy> Create(const std::vector<Triangle>& triangles,
                                           const Points& rest,
                                           const std::vector<double>& stiffness = {});

  int num_vertices() const { return num_vertices_; }
  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  double rest_area(int t) const { return areas_[t]; }

  // J_t(x): the deformation gradient of triangle t from the example to x.
  Eigen::Matrix2d DeformationGradient(const Coords& x, int t) const;

  // Local step: R_t = closest rotation to J_t(x), per triangle.
  std::vector<Eigen::Matrix2d> FitRotations(const Coords& x) const;

  // sum_t kappa_t A_t ||J_t(x) - T_t||^2 for given per-triangle targets.
  double Value(const Coords& x, const std::vector<Eigen::Matrix2d>& targets) const;
  // W_D(X, x) = Value(x, FitRotations(x)).
  double Value(const Coords& x) const;

  // dW_D/dx (n x 2). The rotations sit at their minimum, so by the envelope theorem the gradient
  // is that of the quadratic with R_t frozen: 2 kappa_t A_t (J_t - R_t) G_t per triangle.
  Coords Gradient(const Coords& x) const;

  // K (n x n, symmetric PSD, kernel = constants per connected component). Its sparsity pattern
  // depends only on the triangle list, so it is identical for every example of a multimesh.
  const Eigen::SparseMatrix<double>& Laplacian() const { return laplacian_; }

  // *b += scale * B(targets), B's row v = sum_{t ni v} kappa_t A_t (T_t g_{t,v})^T.
  void AddRhs(const std::vector<Eigen::Matrix2d>& targets, double scale, Coords* b) const;

 private:
  ArapEnergy() = default;

  int num_vertices_ = 0;
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Matrix<double, 2, 3>> gradients_;  // columns: grad of hat a, b, c
  std::vector<double> areas_;                           // A_t
  std::vector<double> weights_;                         // kappa_t A_t
  Eigen::SparseMatrix<double> laplacian_;
};

// K = sum_t weights[t] G_t^T G_t on num_vertices vertices, G_t = gradients[t] (columns: the
// gradients of triangle t's hat functions). Nine triplets per triangle, in triangle order, summed
// by setFromTriplets: explicit zeros are kept, so the pattern depends on the triangle list only.
// Shared by ArapEnergy and BlendedArap.
Eigen::SparseMatrix<double> AssembleLaplacian(
    int num_vertices, const std::vector<Triangle>& triangles,
    const std::vector<Eigen::Matrix<double, 2, 3>>& gradients, const std::vector<double>& weights);

}  // namespace inbetween::solver
