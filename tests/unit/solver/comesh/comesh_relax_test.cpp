// Tests for the local relaxation of single vertices (comesh_relax.h): its energy is exactly the
// part of the objective that depends on one vertex, its gradient is right, and a relaxation lowers
// the objective, keeps every triangle positive and sliders on their lines, and keeps the tracked
// gradient and energies equal to a fresh evaluation, for one, two and three shapes.
#include "solver/comesh/comesh_relax.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "solver/comesh/comesh_objective.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::solver {
namespace {

// The square grid, its Tutte hexagon and (for three shapes) a smoothly distorted square.
Multimesh Shapes(int k, int count) {
  Multimesh m = testing::SquareGrid(k);
  if (count >= 2) m.shapes.push_back(testing::TutteHexagon(m));
  if (count >= 3) m.shapes.push_back(testing::SmoothlyDistorted(m.shapes[0], -0.08));
  return m;
}

ComeshObjective MakeObjective(const Multimesh& m) {
  absl::StatusOr<ComeshObjective> objective = ComeshObjective::Create(m.triangles, m.shapes, 0.5);
  EXPECT_TRUE(objective.ok()) << objective.status();
  return *std::move(objective);
}

// Every vertex of the grid's interior in every shape, plus the middle of the bottom side of the
// square (a slider in shape 0: the square's side is straight there), largest gradient first.
std::vector<RelaxTarget> Targets(const Multimesh& m, const std::vector<Points>& gradient, int k) {
  std::vector<std::pair<double, RelaxTarget>> all;
  for (int s = 0; s < m.num_shapes(); ++s) {
    for (int j = 1; j < k; ++j) {
      for (int i = 1; i < k; ++i) {
        const int v = j * (k + 1) + i;
        all.push_back({gradient[s][v].squaredNorm(), RelaxTarget{s, v, false, Point::Zero()}});
      }
    }
  }
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<RelaxTarget> targets;
  for (const auto& [norm, target] : all) targets.push_back(target);
  targets.push_back(RelaxTarget{0, k / 2, true, Point(1.0, 0.0)});
  return targets;
}

TEST(VertexRelaxerTest, VertexEnergyIsThePartOfTheObjectiveThatDependsOnTheVertex) {
  for (int count : {1, 2, 3}) {
    const int k = 6;
    const Multimesh m = Shapes(k, count);
    const ComeshObjective objective = MakeObjective(m);
    const VertexRelaxer relaxer(objective);
    const int v = 2 * (k + 1) + 3;  // an interior vertex
    for (int s = 0; s < count; ++s) {
      const Point step(0.004, -0.003);
      std::vector<Points> moved = m.shapes;
      moved[s][v] += step;
      Point unused;
      const double local = relaxer.VertexEnergy(m.shapes, s, v, m.shapes[s][v] + step, &unused) -
                           relaxer.VertexEnergy(m.shapes, s, v, m.shapes[s][v], &unused);
      const double full = objective.Evaluate(moved) - objective.Evaluate(m.shapes);
      EXPECT_NEAR(local, full, 1e-12) << count << " shapes, shape " << s;
      EXPECT_GT(std::abs(full), 1e-7);  // the move changes something
    }
  }
}

TEST(VertexRelaxerTest, VertexEnergyGradientMatchesFiniteDifferences) {
  for (int count : {1, 2, 3}) {
    Multimesh m = Shapes(6, count);
    m.shapes[count - 1] = testing::SmoothlyDistorted(m.shapes[count - 1], 0.05);
    const ComeshObjective objective = MakeObjective(m);
    const VertexRelaxer relaxer(objective);
    std::vector<Points> gradient;
    objective.Evaluate(m.shapes, &gradient);
    for (int s = 0; s < count; ++s) {
      for (int v : {8, 17, 24, 30}) {  // interior vertices of the 7 x 7 grid
        Point grad;
        relaxer.VertexEnergy(m.shapes, s, v, m.shapes[s][v], &grad);
        // The full objective's gradient at that vertex is the same vector.
        EXPECT_NEAR((grad - gradient[s][v]).norm(), 0.0, 1e-9 * (1.0 + gradient[s][v].norm()));
        for (int a = 0; a < 2; ++a) {
          Point e = Point::Zero();
          e[a] = 1e-6;
          Point unused;
          const double fd = (relaxer.VertexEnergy(m.shapes, s, v, m.shapes[s][v] + e, &unused) -
                             relaxer.VertexEnergy(m.shapes, s, v, m.shapes[s][v] - e, &unused)) /
                            2e-6;
          EXPECT_NEAR(grad[a], fd, 1e-6 * (1.0 + std::abs(fd)))
              << count << " shapes, shape " << s << ", vertex " << v << ", axis " << a;
        }
      }
    }
  }
}

TEST(VertexRelaxerTest, RelaxLowersTheObjectiveAndTracksGradientAndEnergies) {
  for (int count : {1, 2, 3}) {
    const int k = 8;
    Multimesh m = Shapes(k, count);
    m.shapes[0] = testing::SmoothlyDistorted(m.shapes[0], 0.06);  // the bottom side stays straight
    const ComeshObjective objective = MakeObjective(m);
    const VertexRelaxer relaxer(objective);
    std::vector<Points> shapes = m.shapes;
    std::vector<Points> gradient;
    ComeshEnergies energies;
    const double before = objective.Evaluate(shapes, &gradient, &energies);
    const std::vector<RelaxTarget> targets = Targets(m, gradient, k);
    const Point slider_start = shapes[0][k / 2];
    const int moved = relaxer.Relax(targets, 3, &shapes, &gradient, &energies);
    EXPECT_GT(moved, static_cast<int>(targets.size()) / 2) << count << " shapes";

    std::vector<Points> fresh_gradient;
    ComeshEnergies fresh;
    const double after = objective.Evaluate(shapes, &fresh_gradient, &fresh);
    EXPECT_LT(after, before - 1e-4) << count << " shapes";
    for (const Points& x : shapes) EXPECT_EQ(testing::CountNonPositive(m.triangles, x), 0);
    EXPECT_NEAR(energies.objective, after, 1e-12 * after);
    EXPECT_NEAR(energies.mesh, fresh.mesh, 1e-12 * fresh.mesh);
    EXPECT_NEAR(energies.map, fresh.map, 1e-12 * fresh.map);
    double scale = 0.0, error = 0.0;
    for (int s = 0; s < count; ++s) {
      for (int v = 0; v < m.num_vertices(); ++v) {
        scale = std::max(scale, fresh_gradient[s][v].norm());
        error = std::max(error, (gradient[s][v] - fresh_gradient[s][v]).norm());
      }
    }
    EXPECT_LT(error, 1e-10 * scale) << count << " shapes";
    // The slider moved along the bottom side of the square and stayed on it.
    EXPECT_EQ(shapes[0][k / 2].y(), slider_start.y());
    EXPECT_NE(shapes[0][k / 2].x(), slider_start.x());
  }
}

TEST(VertexRelaxerTest, NoTargetsOrNoStepsChangeNothing) {
  const Multimesh m = Shapes(6, 2);
  const ComeshObjective objective = MakeObjective(m);
  const VertexRelaxer relaxer(objective);
  std::vector<Points> shapes = m.shapes;
  EXPECT_EQ(relaxer.Relax({}, 3, &shapes), 0);
  const RelaxTarget target{1, 20, false, Point::Zero()};
  std::vector<Points> gradient;
  ComeshEnergies energies;
  objective.Evaluate(shapes, &gradient, &energies);
  const std::vector<Points> gradient_before = gradient;
  const ComeshEnergies energies_before = energies;
  EXPECT_EQ(relaxer.Relax({&target, 1}, 0, &shapes, &gradient, &energies), 0);
  EXPECT_EQ(shapes, m.shapes);
  EXPECT_EQ(gradient, gradient_before);  // untouched, not changed and changed back
  EXPECT_EQ(energies.objective, energies_before.objective);
  EXPECT_EQ(energies.mesh, energies_before.mesh);
  EXPECT_EQ(energies.map, energies_before.map);
}

}  // namespace
}  // namespace inbetween::solver
