// Tests for comesh_hessian.h: the edge-space Hessians against central differences of the
// closed-form gradients of odt_energy.h and mips_energy.h, and the positive definite projection.
#include "solver/comesh/comesh_hessian.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <functional>
#include <random>

#include "solver/comesh/mips_energy.h"
#include "solver/comesh/odt_energy.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

using Corners = std::array<Point, 3>;
using GradientFn = std::function<Corners(const Corners&)>;

Corners RandomTriangle(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    Corners c = {Point(u(rng), u(rng)), Point(u(rng), u(rng)), Point(u(rng), u(rng))};
    if (SignedArea2(c[0], c[1], c[2]) > 0.2) return c;
  }
}

// Column j of the corner Hessian by central differences of `gradient` (x, y interleaved).
Matrix6 DifferenceHessian(const Corners& x, const GradientFn& gradient) {
  constexpr double h = 1e-6;
  Matrix6 out;
  for (int j = 0; j < 6; ++j) {
    Corners plus = x, minus = x;
    plus[j / 2][j % 2] += h;
    minus[j / 2][j % 2] -= h;
    const Corners gp = gradient(plus), gm = gradient(minus);
    for (int i = 0; i < 6; ++i) out(i, j) = (gp[i / 2][i % 2] - gm[i / 2][i % 2]) / (2 * h);
  }
  return out;
}

void ExpectNear(const Matrix6& actual, const Matrix6& expected) {
  const double scale = std::max(1.0, expected.cwiseAbs().maxCoeff());
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), 1e-5 * scale) << "actual\n"
                                                                     << actual << "\nexpected\n"
                                                                     << expected;
}

TEST(ComeshHessianTest, OdtMatchesDifferencedGradient) {
  std::mt19937 rng(11);
  for (int i = 0; i < 50; ++i) {
    const Corners x = RandomTriangle(rng);
    const GradientFn gradient = [](const Corners& c) {
      Corners g;
      OdtTriangleEnergy(c[0], c[1], c[2], &g);
      return g;
    };
    ExpectNear(CornerHessian(OdtEdgeHessian(EdgeMatrix(x))), DifferenceHessian(x, gradient));
  }
}

// A random pair of triangles and the MIPS Hessian blocks of the map between them.
struct MipsPair {
  Corners xi, xj;
  Matrix4 hp, hq;
};

MipsPair RandomMipsPair(std::mt19937& rng) {
  MipsPair m;
  m.xi = RandomTriangle(rng);
  m.xj = RandomTriangle(rng);
  MipsEdgeHessians(EdgeMatrix(m.xi), EdgeMatrix(m.xj), &m.hp, &m.hq);
  return m;
}

TEST(ComeshHessianTest, MipsBlocksMatchDifferencedGradients) {
  std::mt19937 rng(12);
  for (int i = 0; i < 50; ++i) {
    const MipsPair m = RandomMipsPair(rng);
    const GradientFn in_p = [&](const Corners& c) {
      Corners g;
      MipsTriangleEnergy(c, m.xj, &g, nullptr);
      return g;
    };
    const GradientFn in_q = [&](const Corners& c) {
      Corners g;
      MipsTriangleEnergy(m.xi, c, nullptr, &g);
      return g;
    };
    ExpectNear(CornerHessian(m.hp), DifferenceHessian(m.xi, in_p));
    ExpectNear(CornerHessian(m.hq), DifferenceHessian(m.xj, in_q));
    // H_P is positive semidefinite by construction (a quadratic form over det Q > 0).
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Matrix4>(m.hp).eigenvalues().minCoeff(), -1e-12);
  }
}

// sigma* is invariant under scaling a triangle in the target shape (C(P, sQ) = C(P, Q)), so by
// Euler's identity H_Q u = -grad_Q for u = vec(Q): no curvature along the scaling (u^T H_Q u =
// 0), the null direction ComeshOptions::mips_damping is for. The source side is homogeneous of
// degree 2 (an area weight): u^T H_P u = 2 C there.
TEST(ComeshHessianTest, MipsTargetBlockHasNoCurvatureAlongTheTrianglesScaling) {
  std::mt19937 rng(14);
  for (int i = 0; i < 50; ++i) {
    const MipsPair m = RandomMipsPair(rng);
    Corners gi, gj;
    const double c = MipsTriangleEnergy(m.xi, m.xj, &gi, &gj);
    const Eigen::Matrix2d p = EdgeMatrix(m.xi), q = EdgeMatrix(m.xj);
    const Eigen::Vector4d up(p(0, 0), p(1, 0), p(0, 1), p(1, 1));
    const Eigen::Vector4d uq(q(0, 0), q(1, 0), q(0, 1), q(1, 1));
    // Edge-space gradient: the corner gradients of corners 1 and 2 (corner 0 = minus their sum).
    const Eigen::Vector4d grad_q(gj[1].x(), gj[1].y(), gj[2].x(), gj[2].y());
    const double scale = m.hq.cwiseAbs().maxCoeff() * uq.squaredNorm();
    EXPECT_LE((m.hq * uq + grad_q).norm(), 1e-9 * (1.0 + scale));
    EXPECT_LE(std::abs(uq.dot(m.hq * uq)), 1e-9 * (1.0 + scale));
    EXPECT_NEAR(up.dot(m.hp * up), 2.0 * c, 1e-9 * (1.0 + c));
  }
}

TEST(ComeshHessianTest, ProjectionClampsOnlyNegativeEigenvalues) {
  std::mt19937 rng(13);
  std::normal_distribution<double> n(0.0, 1.0);
  int definite = 0, indefinite = 0;
  for (int i = 0; i < 200; ++i) {
    Matrix4 a;
    for (int k = 0; k < 16; ++k) a(k / 4, k % 4) = n(rng);
    // Half of the cases shifted to be definite (the eigensolver-free path).
    const Matrix4 h = a + a.transpose() + (i % 2 ? 8.0 : 0.0) * Matrix4::Identity();
    const Eigen::Vector4d before = Eigen::SelfAdjointEigenSolver<Matrix4>(h).eigenvalues();
    const Matrix4 p = ProjectPositiveDefinite(h, 1e-3);
    const Eigen::Vector4d after = Eigen::SelfAdjointEigenSolver<Matrix4>(p).eigenvalues();
    const double top = std::max(before.maxCoeff(), 0.0);
    if (before.minCoeff() > 0.1) {
      // Unchanged but for a diagonal floor between 1e-3 * (largest eigenvalue) and 1e-3 * (the
      // largest absolute row sum).
      ++definite;
      const double shift = p(0, 0) - h(0, 0);
      EXPECT_LE((p - h - shift * Matrix4::Identity()).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_GE(shift, 1e-3 * top * (1.0 - 1e-12));
      EXPECT_LE(shift, 1e-3 * h.cwiseAbs().rowwise().sum().maxCoeff() * (1.0 + 1e-12));
    } else if (before.minCoeff() < 0.0) {
      ++indefinite;
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(after[k], std::max(before[k], 0.0) + 1e-3 * top, 1e-9 * (1.0 + top));
      }
    }
    EXPECT_GT(after.minCoeff(), 0.0);
  }
  EXPECT_GT(definite, 20);
  EXPECT_GT(indefinite, 20);
}

}  // namespace
}  // namespace inbetween::solver
