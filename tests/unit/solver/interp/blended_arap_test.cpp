// Fixed-reference blended ARAP (blended_arap.h): gradient, keys, rigid invariance, local-global.
#include "solver/interp/blended_arap.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::Bent;
using interp_test::GridMesh;
using interp_test::Rotated;

Multimesh Examples() {
  Multimesh mesh = GridMesh(6, 2, 0.5);
  mesh.shapes.push_back(Bent(mesh.shapes[0], 3.0, 0.5 * std::numbers::pi));
  Points stretched;
  for (const Point& p : mesh.shapes[0]) stretched.emplace_back(1.3 * p.x(), 0.8 * p.y());
  mesh.shapes.push_back(Rotated(stretched, 2.0, Point(1, 1)));
  return mesh;
}

TEST(InterpBlendedArapTest, GradientMatchesFiniteDifferences) {
  const Multimesh mesh = Examples();
  std::vector<double> stiffness(mesh.triangles.size());
  for (size_t t = 0; t < stiffness.size(); ++t) stiffness[t] = 1.0 + 0.05 * t;
  absl::StatusOr<BlendedArap> e = BlendedArap::Create(mesh.triangles, mesh.shapes, stiffness);
  ASSERT_TRUE(e.ok()) << e.status();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Coords x = ToCoords(Bent(mesh.shapes[0], 3.0, 1.0));
  for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] += u(rng);
  const std::vector<double> w = {0.2, 0.5, 0.3};
  const Coords grad = e->Gradient(x, w);
  double max_err = 0.0, max_grad = 0.0;
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    Coords xp = x, xm = x;
    xp.data()[k] += 1e-6;
    xm.data()[k] -= 1e-6;
    const double fd = (e->Value(xp, w) - e->Value(xm, w)) / 2e-6;
    max_err = std::max(max_err, std::abs(fd - grad.data()[k]));
    max_grad = std::max(max_grad, std::abs(grad.data()[k]));
  }
  EXPECT_GT(max_grad, 1e-2);
  EXPECT_LT(max_err, 1e-6 * std::max(1.0, max_grad));
}

TEST(InterpBlendedArapTest, KeysHaveZeroEnergyAndRigidMotionsAreFree) {
  const Multimesh mesh = Examples();
  absl::StatusOr<BlendedArap> e = BlendedArap::Create(mesh.triangles, mesh.shapes);
  ASSERT_TRUE(e.ok());
  for (int i = 0; i < 3; ++i) {
    std::vector<double> w(3, 0.0);
    w[i] = 1.0;
    EXPECT_LT(e->Value(ToCoords(mesh.shapes[i]), w), 1e-24);
    const Coords moved = ToCoords(Rotated(mesh.shapes[i], 1.1, Point(3, -2)));
    EXPECT_LT(e->Value(moved, w), 1e-20);
    EXPECT_GT(e->Value(ToCoords(mesh.shapes[(i + 1) % 3]), w), 1e-3);
  }
}

TEST(InterpBlendedArapTest, GlobalStepResidualIsTheGradient) {
  // W = tr(x^T K x) - 2 tr(x^T B(T)) + const with T from the local step: grad = 2 (K x - B).
  const Multimesh mesh = Examples();
  absl::StatusOr<BlendedArap> e = BlendedArap::Create(mesh.triangles, mesh.shapes);
  ASSERT_TRUE(e.ok());
  const std::vector<double> w = {0.5, 0.5, 0.0};
  const Coords x = ToCoords(Bent(mesh.shapes[0], 3.0, 0.7));
  std::vector<Eigen::Matrix2d> targets;
  e->LocalStep(x, w, &targets);
  Coords b = Coords::Zero(x.rows(), 2);
  e->AddRhs(targets, &b);
  const Coords residual = 2.0 * (e->Laplacian() * x - b);
  EXPECT_LT((residual - e->Gradient(x, w)).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(InterpBlendedArapTest, AlexaTargetsAreTheLocalStepAtBlendedAngles) {
  // Rigid examples: the Alexa targets are the rotation by the blended angle.
  Multimesh mesh = GridMesh(2, 2);
  mesh.shapes.push_back(Rotated(mesh.shapes[0], 1.0, Point(1, 1)));
  absl::StatusOr<BlendedArap> e = BlendedArap::Create(mesh.triangles, mesh.shapes);
  ASSERT_TRUE(e.ok());
  std::vector<Eigen::Matrix2d> targets;
  e->AlexaTargets({0.25, 0.75}, &targets);
  for (const Eigen::Matrix2d& t : targets) {
    EXPECT_LT((t - RotationMatrix(0.75)).norm(), 1e-12);
  }
  const Coords x = ToCoords(Rotated(mesh.shapes[0], 0.75 + 0.3, Point(0, 0)));
  EXPECT_NEAR(e->AngleOffset(x, {0.25, 0.75}, {0, 1, 2, 3, 4, 5, 6, 7}), 0.3, 1e-12);
}

}  // namespace
}  // namespace inbetween::solver
