// S-eq.3 blended over examples in a fixed per-triangle reference (see blended_arap.h).
#include "solver/interp/blended_arap.h"

#include <Eigen/LU>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/core/parallel_chunks.h"
#include "solver/interp/example_rotations.h"
#include "solver/interp/polar.h"

namespace inbetween::solver {
namespace {

Eigen::Matrix2d EdgeMatrix(const Points& x, const Triangle& t) {
  Eigen::Matrix2d d;
  d.col(0) = x[t[1]] - x[t[0]];
  d.col(1) = x[t[2]] - x[t[0]];
  return d;
}

// R = closest rotation to J A^T (maximizes tr(R^T J A^T)); returns R A.
inline Eigen::Matrix2d RotatedExample(const Eigen::Matrix2d& j, const Eigen::Matrix2d& a) {
  const double m00 = j(0, 0) * a(0, 0) + j(0, 1) * a(0, 1);
  const double m01 = j(0, 0) * a(1, 0) + j(0, 1) * a(1, 1);
  const double m10 = j(1, 0) * a(0, 0) + j(1, 1) * a(0, 1);
  const double m11 = j(1, 0) * a(1, 0) + j(1, 1) * a(1, 1);
  double c = m00 + m11;
  double s = m10 - m01;
  const double r = std::sqrt(c * c + s * s);  // hypot's overflow care is not needed here
  if (r > 0.0) {
    c /= r;
    s /= r;
  } else {
    c = 1.0;
    s = 0.0;
  }
  Eigen::Matrix2d ra;
  ra(0, 0) = c * a(0, 0) - s * a(1, 0);
  ra(0, 1) = c * a(0, 1) - s * a(1, 1);
  ra(1, 0) = s * a(0, 0) + c * a(1, 0);
  ra(1, 1) = s * a(0, 1) + c * a(1, 1);
  return ra;
}

// Triangles per chunk of the parallel loops: fixed, so results do not depend on the thread count;
// loops below 8192 triangles stay on the caller's thread (ParallelChunks' cut-off).
constexpr int kChunk = 1024;

}  // namespace

absl::StatusOr<BlendedArap> BlendedArap::Create(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& shapes,
                                                const std::vector<double>& stiffness) {
  if (shapes.empty()) return absl::InvalidArgumentError("no example shapes");
  // Validates indices, areas and stiffness per shape with messages naming the shape.
  for (size_t i = 0; i < shapes.size(); ++i) {
    absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(triangles, shapes[i], stiffness);
    if (!e.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("shape ", i, ": ", e.status().message()));
    }
  }
  const int n = static_cast<int>(shapes[0].size());
  const int num_t = static_cast<int>(triangles.size());
  const int num_shapes = static_cast<int>(shapes.size());
  ExampleRotations rotations = ComputeExampleRotations(triangles, shapes);

  BlendedArap e;
  e.num_vertices_ = n;
  e.triangles_ = triangles;
  e.gradients_.resize(num_t);
  e.areas_.resize(num_t);
  e.weights_.resize(num_t);
  // Sbar_t first, so that the examples' stretches are freed before the A_it are allocated (peak
  // memory with many examples).
  e.mean_stretch_.assign(num_t, Eigen::Matrix2d::Zero());
  for (int i = 0; i < num_shapes; ++i) {
    for (int t = 0; t < num_t; ++t) e.mean_stretch_[t] += rotations.stretches[i][t];
    std::vector<Eigen::Matrix2d>().swap(rotations.stretches[i]);
  }
  // A mean of symmetric positive definite matrices is one: the reference triangle is positive.
  for (Eigen::Matrix2d& mean : e.mean_stretch_) mean /= static_cast<double>(num_shapes);
  e.angles_ = std::move(rotations.angles);
  e.examples_.assign(num_shapes, std::vector<Eigen::Matrix2d>(num_t));
  for (int t = 0; t < num_t; ++t) {
    const Triangle& tri = triangles[t];
    const Eigen::Matrix2d d = e.mean_stretch_[t] * EdgeMatrix(shapes[0], tri);
    const Eigen::Matrix2d d_inv = d.inverse();
    for (int i = 0; i < num_shapes; ++i) e.examples_[i][t] = EdgeMatrix(shapes[i], tri) * d_inv;
    Eigen::Matrix<double, 2, 3> g;
    g.col(1) = d_inv.row(0).transpose();
    g.col(2) = d_inv.row(1).transpose();
    g.col(0) = -g.col(1) - g.col(2);
    e.gradients_[t] = g;
    e.areas_[t] = 0.5 * d.determinant();
    e.weights_[t] = (stiffness.empty() ? 1.0 : stiffness[t]) * e.areas_[t];
  }
  e.laplacian_ = AssembleLaplacian(n, triangles, e.gradients_, e.weights_);
  e.incidence_start_.assign(n + 1, 0);
  for (const Triangle& tri : triangles) {
    for (int v : tri) ++e.incidence_start_[v + 1];
  }
  for (int v = 0; v < n; ++v) e.incidence_start_[v + 1] += e.incidence_start_[v];
  e.incidence_.resize(3 * static_cast<size_t>(num_t));
  std::vector<int> fill(e.incidence_start_.begin(), e.incidence_start_.end() - 1);
  for (int t = 0; t < num_t; ++t) {
    for (int k = 0; k < 3; ++k) e.incidence_[fill[triangles[t][k]]++] = 3 * t + k;
  }
  return e;
}

Eigen::Matrix2d BlendedArap::DeformationGradient(const Coords& x, int t) const {
  const Triangle& tri = triangles_[t];
  const Eigen::Matrix<double, 2, 3>& g = gradients_[t];
  const double x0 = x(tri[0], 0), y0 = x(tri[0], 1);
  const double x1 = x(tri[1], 0), y1 = x(tri[1], 1);
  const double x2 = x(tri[2], 0), y2 = x(tri[2], 1);
  Eigen::Matrix2d j;
  j(0, 0) = x0 * g(0, 0) + x1 * g(0, 1) + x2 * g(0, 2);
  j(0, 1) = x0 * g(1, 0) + x1 * g(1, 1) + x2 * g(1, 2);
  j(1, 0) = y0 * g(0, 0) + y1 * g(0, 1) + y2 * g(0, 2);
  j(1, 1) = y0 * g(1, 0) + y1 * g(1, 1) + y2 * g(1, 2);
  return j;
}

double BlendedArap::LocalStep(const Coords& x, const std::vector<double>& w,
                              std::vector<Eigen::Matrix2d>* targets, int threads) const {
  const int num_t = num_triangles();
  targets->resize(num_t);
  // The examples that take part, gathered once.
  std::vector<int> active;
  for (int i = 0; i < num_examples(); ++i) {
    if (w[i] != 0.0) active.push_back(i);
  }
  std::vector<double> chunk_energy(NumChunks(num_t, kChunk), 0.0);
  ParallelChunks(num_t, kChunk, ResolveThreads(threads), [&](int chunk, int begin, int end) {
    double energy = 0.0;
    for (int t = begin; t < end; ++t) {
      const Eigen::Matrix2d j = DeformationGradient(x, t);
      Eigen::Matrix2d target = Eigen::Matrix2d::Zero();
      double e = 0.0;
      for (int i : active) {
        const Eigen::Matrix2d ra = RotatedExample(j, examples_[i][t]);
        target += w[i] * ra;
        e += w[i] * (j - ra).squaredNorm();
      }
      (*targets)[t] = target;
      energy += weights_[t] * e;
    }
    chunk_energy[chunk] = energy;
  });
  double energy = 0.0;
  for (double e : chunk_energy) energy += e;
  return energy;
}

double BlendedArap::LocalStepToRest(const Coords& x, const std::vector<Eigen::Matrix2d>& rest,
                                    std::vector<Eigen::Matrix2d>* targets) const {
  const int num_t = num_triangles();
  targets->resize(num_t);
  double energy = 0.0;
  for (int t = 0; t < num_t; ++t) {
    const Eigen::Matrix2d j = DeformationGradient(x, t);
    (*targets)[t] = RotatedExample(j, rest[t]);
    energy += weights_[t] * (j - (*targets)[t]).squaredNorm();
  }
  return energy;
}

void BlendedArap::AlexaTargets(const std::vector<double>& w, std::vector<Eigen::Matrix2d>* targets,
                               int threads) const {
  // R(theta(w)) S(w) Sbar^{-1} = sum_i w_i R(theta(w) - theta_it) A_it, as A_it =
  // R(theta_it) S_it Sbar^{-1}: the examples' stretches need not be stored (memory with many
  // examples), at one sin/cos per example with w_i != 0.
  const int num_t = num_triangles();
  targets->resize(num_t);
  std::vector<int> active;
  for (int i = 0; i < num_examples(); ++i) {
    if (w[i] != 0.0) active.push_back(i);
  }
  ParallelChunks(num_t, kChunk, ResolveThreads(threads), [&](int, int begin, int end) {
    for (int t = begin; t < end; ++t) {
      double angle = 0.0;
      for (int i : active) angle += w[i] * angles_[i][t];
      Eigen::Matrix2d target = Eigen::Matrix2d::Zero();
      for (int i : active) {
        target += w[i] * (RotationMatrix(angle - angles_[i][t]) * examples_[i][t]);
      }
      (*targets)[t] = target;
    }
  });
}

double BlendedArap::Value(const Coords& x, const std::vector<double>& w) const {
  std::vector<Eigen::Matrix2d> targets;
  return LocalStep(x, w, &targets);
}

Coords BlendedArap::Gradient(const Coords& x, const std::vector<double>& w) const {
  // d/dx sum_i w_i kappa abar ||J - R_i A_i||^2 = 2 kappa abar (J - T) gbar, as sum_i w_i = 1.
  std::vector<Eigen::Matrix2d> targets;
  LocalStep(x, w, &targets);
  double sum = 0.0;
  for (double wi : w) sum += wi;
  Coords grad = Coords::Zero(num_vertices_, 2);
  for (int t = 0; t < num_triangles(); ++t) {
    const Eigen::Matrix<double, 2, 3> gt =
        2.0 * weights_[t] * (sum * DeformationGradient(x, t) - targets[t]) * gradients_[t];
    for (int k = 0; k < 3; ++k) grad.row(triangles_[t][k]) += gt.col(k).transpose();
  }
  return grad;
}

void BlendedArap::AddRhs(const std::vector<Eigen::Matrix2d>& targets, Coords* b,
                         int threads) const {
  ParallelChunks(num_vertices_, kChunk, ResolveThreads(threads), [&](int, int begin, int end) {
    for (int v = begin; v < end; ++v) {
      double bx = (*b)(v, 0), by = (*b)(v, 1);
      for (int q = incidence_start_[v]; q < incidence_start_[v + 1]; ++q) {
        const int t = incidence_[q] / 3, k = incidence_[q] % 3;
        const Eigen::Vector2d tg = targets[t] * gradients_[t].col(k);
        bx += weights_[t] * tg(0);
        by += weights_[t] * tg(1);
      }
      (*b)(v, 0) = bx;
      (*b)(v, 1) = by;
    }
  });
}

double BlendedArap::AngleOffset(const Coords& x, const std::vector<double>& w,
                                const std::vector<int>& group) const {
  double sum = 0.0;
  double area = 0.0;
  for (int t : group) {
    double target = 0.0;
    for (int i = 0; i < num_examples(); ++i) {
      if (w[i] != 0.0) target += w[i] * angles_[i][t];
    }
    // Relative to example 0: E D_0^{-1} = Jbar Sbar.
    const double angle =
        UnwrapAngle(ClosestRotationAngle(DeformationGradient(x, t) * mean_stretch_[t]), target);
    sum += areas_[t] * (angle - target);
    area += areas_[t];
  }
  return area > 0.0 ? sum / area : 0.0;
}

}  // namespace inbetween::solver
