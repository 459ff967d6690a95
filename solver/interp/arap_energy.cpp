// S-eq.3: the discrete ARAP energy, its gradient and its local-global pieces (see arap_energy.h).
#include "solver/interp/arap_energy.h"

#include <Eigen/LU>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "solver/geometry/primitives.h"
#include "solver/interp/polar.h"

namespace inbetween::solver {

Coords ToCoords(const Points& points) {
  Coords c(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t v = 0; v < points.size(); ++v) c.row(static_cast<Eigen::Index>(v)) = points[v];
  return c;
}

Points ToPoints(const Coords& coords) {
  Points p(static_cast<size_t>(coords.rows()));
  for (Eigen::Index v = 0; v < coords.rows(); ++v) p[static_cast<size_t>(v)] = coords.row(v);
  return p;
}

absl::StatusOr<ArapEnergy> ArapEnergy::Create(const std::vector<Triangle>& triangles,
                                              const Points& rest,
                                              const std::vector<double>& stiffness) {
  const int n = static_cast<int>(rest.size());
  const int num_t = static_cast<int>(triangles.size());
  if (!stiffness.empty() && static_cast<int>(stiffness.size()) != num_t) {
    return absl::InvalidArgumentError(absl::StrCat("stiffness has ", stiffness.size(),
                                                   " values, expected one per triangle (", num_t,
                                                   ") or none"));
  }
  ArapEnergy e;
  e.num_vertices_ = n;
  e.triangles_ = triangles;
  e.gradients_.resize(num_t);
  e.areas_.resize(num_t);
  e.weights_.resize(num_t);
  for (int t = 0; t < num_t; ++t) {
    const Triangle& tri = triangles[t];
    if (const std::optional<int> v = IndexOutOfRange(tri, n)) {
      return absl::InvalidArgumentError(
          absl::StrCat("triangle ", t, " has vertex index ", *v, " outside [0, ", n, ")"));
    }
    if (RepeatsVertex(tri)) {
      return absl::InvalidArgumentError(absl::StrCat("triangle ", t, " repeats a vertex (", tri[0],
                                                     ", ", tri[1], ", ", tri[2], ")"));
    }
    const double kappa = stiffness.empty() ? 1.0 : stiffness[t];
    if (!(kappa > 0.0) || !std::isfinite(kappa)) {
      return absl::InvalidArgumentError(
          absl::StrCat("stiffness[", t, "] = ", kappa, " must be positive and finite"));
    }
    Eigen::Matrix2d d;
    d.col(0) = rest[tri[1]] - rest[tri[0]];
    d.col(1) = rest[tri[2]] - rest[tri[0]];
    const double area = 0.5 * d.determinant();
    if (!(area > 0.0) || !std::isfinite(area)) {
      return absl::InvalidArgumentError(absl::StrCat("triangle ", t, " (", tri[0], ", ", tri[1],
                                                     ", ", tri[2], ") has signed area ", area,
                                                     "; every triangle must have positive area"));
    }
    const Eigen::Matrix2d d_inv = d.inverse();
    Eigen::Matrix<double, 2, 3> g;
    g.col(1) = d_inv.row(0).transpose();
    g.col(2) = d_inv.row(1).transpose();
    g.col(0) = -g.col(1) - g.col(2);
    e.gradients_[t] = g;
    e.areas_[t] = area;
    e.weights_[t] = kappa * area;
  }
  e.laplacian_ = AssembleLaplacian(n, triangles, e.gradients_, e.weights_);
  return e;
}

Eigen::SparseMatrix<double> AssembleLaplacian(
    int num_vertices, const std::vector<Triangle>& triangles,
    const std::vector<Eigen::Matrix<double, 2, 3>>& gradients, const std::vector<double>& weights) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(9 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Eigen::Matrix<double, 2, 3>& g = gradients[t];
    const Eigen::Matrix3d local = weights[t] * (g.transpose() * g);
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        triplets.emplace_back(triangles[t][j], triangles[t][k], local(j, k));
      }
    }
  }
  Eigen::SparseMatrix<double> laplacian(num_vertices, num_vertices);
  // setFromTriplets keeps explicit zeros, so the pattern depends on the triangle list only.
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  laplacian.makeCompressed();
  return laplacian;
}

Eigen::Matrix2d ArapEnergy::DeformationGradient(const Coords& x, int t) const {
  const Triangle& tri = triangles_[t];
  const Eigen::Matrix<double, 2, 3>& g = gradients_[t];
  Eigen::Matrix2d j = x.row(tri[0]).transpose() * g.col(0).transpose();
  j.noalias() += x.row(tri[1]).transpose() * g.col(1).transpose();
  j.noalias() += x.row(tri[2]).transpose() * g.col(2).transpose();
  return j;
}

std::vector<Eigen::Matrix2d> ArapEnergy::FitRotations(const Coords& x) const {
  std::vector<Eigen::Matrix2d> r(triangles_.size());
  for (int t = 0; t < num_triangles(); ++t) r[t] = ClosestRotation(DeformationGradient(x, t));
  return r;
}

double ArapEnergy::Value(const Coords& x, const std::vector<Eigen::Matrix2d>& targets) const {
  double sum = 0.0;
  for (int t = 0; t < num_triangles(); ++t) {
    sum += weights_[t] * (DeformationGradient(x, t) - targets[t]).squaredNorm();
  }
  return sum;
}

double ArapEnergy::Value(const Coords& x) const { return Value(x, FitRotations(x)); }

Coords ArapEnergy::Gradient(const Coords& x) const {
  Coords grad = Coords::Zero(num_vertices_, 2);
  for (int t = 0; t < num_triangles(); ++t) {
    const Eigen::Matrix2d j = DeformationGradient(x, t);
    const Eigen::Matrix<double, 2, 3> gt =
        2.0 * weights_[t] * (j - ClosestRotation(j)) * gradients_[t];
    for (int k = 0; k < 3; ++k) grad.row(triangles_[t][k]) += gt.col(k).transpose();
  }
  return grad;
}

void ArapEnergy::AddRhs(const std::vector<Eigen::Matrix2d>& targets, double scale,
                        Coords* b) const {
  for (int t = 0; t < num_triangles(); ++t) {
    const Eigen::Matrix<double, 2, 3> tg = (scale * weights_[t]) * (targets[t] * gradients_[t]);
    for (int k = 0; k < 3; ++k) b->row(triangles_[t][k]) += tg.col(k).transpose();
  }
}

}  // namespace inbetween::solver
