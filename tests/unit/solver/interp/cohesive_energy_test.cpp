// Cohesive energy (S-eq.13-16, cap S-eq.6): closed form, gradient, majorizer, and in the solver:
// a zone stays closed below tau and separates past it; alpha trades shear against opening.
#include "solver/interp/cohesive_energy.h"

#include <gtest/gtest.h>

#include <random>

#include "solver/interp/inbetweener.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver {
namespace {

using interp_test::SlitMesh;

// One pair on a unit edge; the jump varies linearly, so S-eq.13 is the exact integral.
TEST(InterpCohesiveTest, ClosedFormMatchesQuadrature) {
  const Points rest = {Point(0, 0), Point(1, 0), Point(0, 0), Point(1, 0)};
  for (double alpha : {0.0, 0.3, 0.5, 1.0}) {
    absl::StatusOr<CohesiveEnergy> c =
        CohesiveEnergy::Create({{0, 1, 2, 3}}, {rest}, {2.0, 1e9, alpha, 0.1});
    ASSERT_TRUE(c.ok()) << c.status();
    Coords x(4, 2);
    x << 0, 0, 1, 0, 0.1, 0.2, 0.9, -0.3;
    const Eigen::Vector2d g0 = x.row(0) - x.row(2), g1 = x.row(1) - x.row(3);
    const Eigen::Vector2d u = (x.row(0) + x.row(2) - x.row(1) - x.row(3)).transpose();
    const Eigen::Vector2d xhat = u.normalized();
    double integral = 0.0;
    const int steps = 20000;
    for (int k = 0; k < steps; ++k) {
      const double s = (k + 0.5) / steps;
      const Eigen::Vector2d g = (1 - s) * g0 + s * g1;
      const double tangential = xhat.dot(g);
      integral += (1 - alpha) * tangential * tangential +
                  alpha * (g.squaredNorm() - tangential * tangential);
    }
    integral *= 2.0 / steps;  // lambda = 2, length 1
    EXPECT_NEAR(c->EdgeEnergy(x, 0), integral, 1e-8) << alpha;
  }
}

TEST(InterpCohesiveTest, GradientMatchesFiniteDifferences) {
  const Multimesh mesh = SlitMesh(6, 4, 3, 0.5, 0.0, 0.0);
  for (double alpha : {0.2, 0.5, 0.8}) {
    absl::StatusOr<CohesiveEnergy> c =
        CohesiveEnergy::Create(mesh.cohesive_edges, mesh.shapes, {1.5, 1e9, alpha, 0.1});
    ASSERT_TRUE(c.ok());
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    Coords x = ToCoords(mesh.shapes[0]);
    for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] += u(rng);
    const std::vector<double> w = {1.0};
    const std::vector<double> thresholds = c->Thresholds(nullptr);
    const Coords grad = c->Gradient(x, w, thresholds);
    double max_err = 0.0, max_grad = 0.0;
    for (Eigen::Index k = 0; k < x.size(); ++k) {
      Coords xp = x, xm = x;
      xp.data()[k] += 1e-6;
      xm.data()[k] -= 1e-6;
      const double fd = (c->Value(xp, w, thresholds) - c->Value(xm, w, thresholds)) / 2e-6;
      max_err = std::max(max_err, std::abs(fd - grad.data()[k]));
      max_grad = std::max(max_grad, std::abs(grad.data()[k]));
    }
    EXPECT_GT(max_grad, 1e-3);
    EXPECT_LT(max_err, 1e-7) << alpha;
  }
}

TEST(InterpCohesiveTest, CappedEdgesCostTauAndHaveNoGradient) {
  const Multimesh mesh = SlitMesh(4, 4, 2, 1.0, 0.0, 0.0);
  absl::StatusOr<CohesiveEnergy> c =
      CohesiveEnergy::Create(mesh.cohesive_edges, mesh.shapes, {1.0, 0.01, 0.5, 0.1});
  ASSERT_TRUE(c.ok());
  Coords x = ToCoords(mesh.shapes[0]);
  for (const auto& e : mesh.cohesive_edges) x.row(e[2]) += Eigen::RowVector2d(0.5, 0.0);
  const std::vector<double> thresholds = c->Thresholds(nullptr);
  EXPECT_NEAR(c->Value(x, {1.0}, thresholds), 0.01 * 2.0, 1e-15);  // two unit edges at tau l
  EXPECT_EQ(c->Gradient(x, {1.0}, thresholds).cwiseAbs().maxCoeff(), 0.0);
  // Hysteresis: separated in the previous frame -> lower threshold, bonded -> higher.
  const std::vector<double> after_open = c->Thresholds(&x);
  const Coords closed = ToCoords(mesh.shapes[0]);
  const std::vector<double> after_closed = c->Thresholds(&closed);
  EXPECT_NEAR(after_open[0], 0.9 * 0.01, 1e-15);
  EXPECT_NEAR(after_closed[1], 1.1 * 0.01, 1e-15);
}

TEST(InterpCohesiveTest, MajorizerTouchesAndBoundsTheBondedEnergy) {
  // alpha = 1/2 (no xhat dependence), activity 0.6: the quadratic model with the fixed matrix
  // lies above W_C and touches it at x_k.
  const Multimesh mesh = SlitMesh(4, 4, 3, 1.0, 0.0, 0.0);
  std::vector<Points> shapes = mesh.shapes;
  shapes.push_back(shapes[0]);
  for (int v = 0; v < static_cast<int>(shapes[1].size()); ++v) shapes[1][v].x() *= 1.01;
  for (const auto& e : mesh.cohesive_edges) shapes[1][e[2]].x() += 0.3;  // open in shape 1
  absl::StatusOr<CohesiveEnergy> c =
      CohesiveEnergy::Create(mesh.cohesive_edges, shapes, {1.0, 1e9, 0.5, 0.1});
  ASSERT_TRUE(c.ok());
  const std::vector<double> w = {0.6, 0.4};
  EXPECT_DOUBLE_EQ(c->Activity(w, 0), 0.6);
  std::vector<Eigen::Triplet<double>> triplets;
  c->AddMatrix(&triplets);
  const int n = static_cast<int>(shapes[0].size());
  Eigen::SparseMatrix<double> h(n, n);
  h.setFromTriplets(triplets.begin(), triplets.end());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  Coords xk = ToCoords(shapes[0]);
  for (Eigen::Index k = 0; k < xk.size(); ++k) xk.data()[k] += u(rng);
  const std::vector<double> thresholds = c->Thresholds(nullptr);
  Coords q = Coords::Zero(n, 2);
  std::vector<char> separated;
  const double ek = c->LocalStep(xk, w, thresholds, &q, &separated);
  auto model = [&](const Coords& x) {
    return (x.transpose() * (h * x)).trace() - 2.0 * (x.transpose() * q).trace();
  };
  const double offset = ek - model(xk);
  for (int trial = 0; trial < 20; ++trial) {
    Coords x = xk;
    for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] += u(rng);
    EXPECT_GE(model(x) + offset, c->Value(x, w, thresholds) - 1e-12);
  }
}

// Mid-frame jump (largest |x_a - x_c| over the slit) of a two-key inbetween.
double MidJump(const Multimesh& two_keys, InbetweenOptions o, FrameReport* report = nullptr) {
  o.max_iterations = 400;
  o.displacement_tolerance = 1e-9;
  absl::StatusOr<Inbetweener> ib = Inbetweener::Create(two_keys, o);
  EXPECT_TRUE(ib.ok()) << ib.status();
  FrameReport local;
  absl::StatusOr<Frame> f = ib->Solve({0.5, 0.5}, Frame{}, nullptr, &local);
  EXPECT_TRUE(f.ok()) << f.status();
  EXPECT_EQ(local.inverted, 0);
  if (report != nullptr) *report = local;
  double jump = 0.0;
  for (const auto& e : two_keys.cohesive_edges) {
    jump = std::max(jump, (f->vertices[e[0]] - f->vertices[e[2]]).norm());
  }
  return jump;
}

TEST(InterpCohesiveTest, ZoneStaysClosedBelowTauAndSeparatesPastIt) {
  const Multimesh mesh = SlitMesh(8, 6, 4, 0.25, 0.3, 0.0);  // opens in shape 1
  ASSERT_EQ(mesh.num_shapes(), 2);
  InbetweenOptions o;
  o.lambda = 200.0;
  o.tau = 1e9;  // never separates
  FrameReport closed_report;
  const double closed = MidJump(mesh, o, &closed_report);
  o.tau = 0.0;  // always separated
  FrameReport open_report;
  const double open = MidJump(mesh, o, &open_report);
  o.lambda = 0.0;  // no cohesion at all
  const double free = MidJump(mesh, o);
  EXPECT_EQ(closed_report.separated_edges, 0);
  EXPECT_EQ(open_report.separated_edges, 4);
  EXPECT_GT(free, 0.1);
  EXPECT_LT(closed, 0.05 * free);
  EXPECT_NEAR(open, free, 0.02 * free);
}

TEST(InterpCohesiveTest, AlphaTradesShearAgainstOpening) {
  const Multimesh opening = SlitMesh(8, 6, 4, 0.25, 0.3, 0.0);
  const Multimesh shearing = SlitMesh(8, 6, 4, 0.25, 0.0, 0.3);
  InbetweenOptions o;
  o.lambda = 5.0;
  o.tau = 1e9;
  o.alpha = 0.9;  // resists the normal jump (opening) most
  const double open_stiff = MidJump(opening, o);
  const double shear_soft = MidJump(shearing, o);
  o.alpha = 0.1;  // resists the tangential jump (shear) most
  const double open_soft = MidJump(opening, o);
  const double shear_stiff = MidJump(shearing, o);
  EXPECT_LT(open_stiff, 0.8 * open_soft);
  EXPECT_LT(shear_stiff, 0.8 * shear_soft);
}

}  // namespace
}  // namespace inbetween::solver
