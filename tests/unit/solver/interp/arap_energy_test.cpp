// S-eq.3 ARAP energy: finite-difference gradient, rigid invariance, local-global pieces.
#include "solver/interp/arap_energy.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::GridMesh;

Coords Perturbed(const Points& rest, double amount, int seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  Coords x = ToCoords(rest);
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] += u(rng);
  return x;
}

TEST(InterpArapEnergyTest, GradientMatchesFiniteDifferences) {
  const Multimesh mesh = GridMesh(4, 3, 0.5);
  std::vector<double> stiffness(mesh.triangles.size());
  for (size_t t = 0; t < stiffness.size(); ++t) stiffness[t] = 1.0 + 0.1 * t;
  absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(mesh.triangles, mesh.shapes[0], stiffness);
  ASSERT_TRUE(e.ok()) << e.status();
  // A rotated, scaled, noisy configuration (far from the rest shape, no polar singularity).
  Coords x = Perturbed(mesh.shapes[0], 0.1, 1) * 1.3;
  x = (x * RotationMatrix(0.7).transpose()).eval();
  const Coords grad = e->Gradient(x);
  const double h = 1e-6;
  double max_err = 0.0, max_grad = 0.0;
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    Coords xp = x, xm = x;
    xp.data()[k] += h;
    xm.data()[k] -= h;
    const double fd = (e->Value(xp) - e->Value(xm)) / (2 * h);
    max_err = std::max(max_err, std::abs(fd - grad.data()[k]));
    max_grad = std::max(max_grad, std::abs(grad.data()[k]));
  }
  EXPECT_GT(max_grad, 1e-2);
  EXPECT_LT(max_err, 1e-6 * std::max(1.0, max_grad));
}

TEST(InterpArapEnergyTest, GradientEqualsGlobalStepResidual) {
  const Multimesh mesh = GridMesh(3, 3);
  absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(mesh.triangles, mesh.shapes[0]);
  ASSERT_TRUE(e.ok());
  const Coords x = Perturbed(mesh.shapes[0], 0.2, 2);
  Coords b = Coords::Zero(x.rows(), 2);
  e->AddRhs(e->FitRotations(x), 1.0, &b);
  const Coords residual = 2.0 * (e->Laplacian() * x - b);
  EXPECT_LT((residual - e->Gradient(x)).cwiseAbs().maxCoeff(), 1e-12);
  // W = tr(x^T K x) - 2 tr(x^T B) + sum_t kappa A ||R||^2 (= 2 * total area for kappa = 1).
  const double quadratic =
      (x.transpose() * (e->Laplacian() * x)).trace() - 2.0 * (x.transpose() * b).trace() + 2 * 9;
  EXPECT_NEAR(quadratic, e->Value(x), 1e-10);
}

TEST(InterpArapEnergyTest, ZeroForRigidMotionsAndLaplacianKillsConstants) {
  const Multimesh mesh = GridMesh(3, 2);
  absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(mesh.triangles, mesh.shapes[0]);
  ASSERT_TRUE(e.ok());
  const Points moved = interp_test::Translated(
      interp_test::Rotated(mesh.shapes[0], 2.5, Point(1.0, 0.5)), Point(-3.0, 7.0));
  EXPECT_LT(e->Value(ToCoords(moved)), 1e-24);
  EXPECT_LT(e->Gradient(ToCoords(moved)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(e->Value(Perturbed(mesh.shapes[0], 0.1, 3)), 1e-6);
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(mesh.num_vertices());
  EXPECT_LT((e->Laplacian() * ones).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(InterpArapEnergyTest, RejectsBadInput) {
  Multimesh mesh = GridMesh(2, 1);
  std::swap(mesh.triangles[1][1], mesh.triangles[1][2]);  // negative orientation
  absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(mesh.triangles, mesh.shapes[0]);
  EXPECT_EQ(e.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(e.status().message().find("triangle 1"), std::string::npos) << e.status();

  mesh = GridMesh(2, 1);
  EXPECT_EQ(ArapEnergy::Create(mesh.triangles, mesh.shapes[0], {1.0}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(
      ArapEnergy::Create(mesh.triangles, mesh.shapes[0], {1.0, 1.0, 0.0, 1.0}).status().code(),
      absl::StatusCode::kInvalidArgument);
  mesh.triangles[0][2] = 99;
  EXPECT_EQ(ArapEnergy::Create(mesh.triangles, mesh.shapes[0]).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inbetween::solver
