// Local relaxation of single vertices for the comesh inner loop. See comesh_relax.h.
#include "solver/comesh/comesh_relax.h"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "solver/comesh/mips_energy.h"
#include "solver/comesh/odt_energy.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Which corner of t is v.
int CornerOf(const Triangle& t, int v) { return t[0] == v ? 0 : (t[1] == v ? 1 : 2); }

}  // namespace

VertexRelaxer::VertexRelaxer(const ComeshObjective& objective)
    : objective_(objective), begin_(objective.num_vertices() + 1, 0) {
  const std::vector<Triangle>& triangles = objective.triangles();
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) ++begin_[t[k] + 1];
  }
  for (int v = 0; v < objective.num_vertices(); ++v) begin_[v + 1] += begin_[v];
  ring_.resize(3 * triangles.size());
  std::vector<int> fill(begin_.begin(), begin_.end() - 1);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) ring_[fill[triangles[t][k]]++] = static_cast<int>(t);
  }
}

double VertexRelaxer::VertexEnergy(const std::vector<Points>& shapes, int s, int v, const Point& p,
                                   Point* grad) const {
  const int n = static_cast<int>(shapes.size());
  const double w = objective_.map_weight();
  const double odt_scale = (1.0 - w) / objective_.mesh_scale(s);
  // MIPS (s -> s + 1), weighted by shape s's rest area, and (s - 1 -> s) by shape s - 1's.
  const int next = (s + 1) % n, prev = (s + n - 1) % n;
  const double next_scale = w / objective_.map_scale(s);
  const double prev_scale = w / objective_.map_scale(prev);
  double e = 0.0;
  grad->setZero();
  std::array<Point, 3> g_odt, g_i, g_j;
  for (int r = begin_[v]; r < begin_[v + 1]; ++r) {
    const Triangle& t = objective_.triangles()[ring_[r]];
    const int k = CornerOf(t, v);
    auto corners = [&](int shape) {
      std::array<Point, 3> c = {shapes[shape][t[0]], shapes[shape][t[1]], shapes[shape][t[2]]};
      if (shape == s) c[k] = p;
      return c;
    };
    const std::array<Point, 3> cs = corners(s);
    const double d = OdtTriangleEnergy(cs[0], cs[1], cs[2], &g_odt);
    if (!std::isfinite(d)) return kInf;
    e += odt_scale * d;
    *grad += odt_scale * g_odt[k];
    const double c1 = MipsTriangleEnergy(cs, corners(next), &g_i, &g_j);
    if (!std::isfinite(c1)) return kInf;
    e += next_scale * c1;
    *grad += next_scale * g_i[k];
    if (n == 1) {  // C(X_s, X_s): the one term has p on both sides
      *grad += next_scale * g_j[k];
      continue;
    }
    const double c2 = MipsTriangleEnergy(corners(prev), cs, &g_i, &g_j);
    if (!std::isfinite(c2)) return kInf;
    e += prev_scale * c2;
    *grad += prev_scale * g_j[k];
  }
  return e;
}

bool VertexRelaxer::RelaxOne(const RelaxTarget& target, int steps,
                             std::vector<Points>* shapes) const {
  const int s = target.shape, v = target.vertex;
  const std::vector<Triangle>& triangles = objective_.triangles();
  Point& x = (*shapes)[s][v];
  bool moved = false;
  for (int it = 0; it < steps; ++it) {
    Point g;
    const double e0 = VertexEnergy(*shapes, s, v, x, &g);
    if (!std::isfinite(e0)) return moved;
    // Hessian by central differences of the analytic gradient, at the scale of the ring.
    double scale = 0.0;
    for (int r = begin_[v]; r < begin_[v + 1]; ++r) {
      const Triangle& t = triangles[ring_[r]];
      for (int q = 0; q < 3; ++q) scale = std::max(scale, ((*shapes)[s][t[q]] - x).norm());
    }
    const double h = 1e-6 * scale;
    Eigen::Matrix2d hess;
    for (int a = 0; a < 2; ++a) {
      Point e = Point::Zero();
      e[a] = h;
      Point gp = Point::Zero(), gm = Point::Zero();
      if (!std::isfinite(VertexEnergy(*shapes, s, v, x + e, &gp)) ||
          !std::isfinite(VertexEnergy(*shapes, s, v, x - e, &gm))) {
        return moved;  // within 1e-6 of folding: leave it to the global step
      }
      hess.col(a) = (gp - gm) / (2.0 * h);
    }
    hess = 0.5 * (hess + hess.transpose()).eval();
    Point d;
    if (target.slider) {
      const double c = target.direction.dot(hess * target.direction);
      if (!(c > 0.0)) return moved;
      const double z = (x - target.base).dot(target.direction);
      const double move = std::clamp(-target.direction.dot(g) / c, target.lo - z, target.hi - z);
      if (move == 0.0) return moved;
      d = move * target.direction;
    } else {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(hess);
      Eigen::Vector2d lambda = eig.eigenvalues();
      if (!(lambda[1] > 0.0)) return moved;
      lambda = lambda.cwiseMax(1e-6 * lambda[1]);
      d = -(eig.eigenvectors() * lambda.cwiseInverse().asDiagonal() *
            eig.eigenvectors().transpose() * g);
    }
    const double slope = g.dot(d);
    if (!(slope < 0.0)) return moved;
    // Twice the area of ring triangle (x, a, b) at x + t d: cross(a - x, b - x) - t cross(d, b -
    // a).
    double t_max = kInf;
    for (int r = begin_[v]; r < begin_[v + 1]; ++r) {
      const Triangle& t = triangles[ring_[r]];
      const int k = CornerOf(t, v);
      const Point& a = (*shapes)[s][t[(k + 1) % 3]];
      const Point& b = (*shapes)[s][t[(k + 2) % 3]];
      const double c1 = -Cross(d, b - a);
      if (c1 < 0.0) t_max = std::min(t_max, -Cross(a - x, b - x) / c1);
    }
    double step = std::min(1.0, 0.8 * t_max);
    bool accepted = false;
    for (int tries = 0; tries < 20 && !accepted; ++tries) {
      Point unused;
      const double e1 = VertexEnergy(*shapes, s, v, x + step * d, &unused);
      accepted = std::isfinite(e1) && e1 < e0 && e1 <= e0 + 1e-4 * step * slope;
      if (!accepted) step *= 0.5;
    }
    if (!accepted) return moved;
    x += step * d;
    moved = true;
  }
  return moved;
}

void VertexRelaxer::Tally(const std::vector<int>& triangles, const std::vector<Points>& shapes,
                          double sign, double* mesh_sum, double* map_sum,
                          std::vector<GradientChange>* changes) const {
  const int n = objective_.num_shapes();
  std::vector<Point> cg(3 * n);
  for (int t : triangles) {
    const Triangle& tri = objective_.triangles()[t];
    double mesh_part = 0.0, map_part = 0.0;
    objective_.AccumulateTriangle(tri, shapes, &mesh_part, &map_part,
                                  changes != nullptr ? cg.data() : nullptr);
    *mesh_sum += sign * mesh_part;
    *map_sum += sign * map_part;
    if (changes == nullptr) continue;
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i < n; ++i) changes->push_back({i, tri[k], sign * cg[k * n + i]});
    }
  }
}

int VertexRelaxer::Relax(std::span<const RelaxTarget> targets, int steps,
                         std::vector<Points>* shapes, std::vector<Points>* gradient,
                         ComeshEnergies* energies) const {
  if (targets.empty()) return 0;
  const bool track = gradient != nullptr || energies != nullptr;
  // The triangles around the targets, each once: their terms before and after the moves.
  std::vector<int> touched;
  if (track) {
    for (const RelaxTarget& target : targets) {
      touched.insert(touched.end(), ring_.begin() + begin_[target.vertex],
                     ring_.begin() + begin_[target.vertex + 1]);
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  }
  double mesh_change = 0.0, map_change = 0.0;
  std::vector<GradientChange> changes;
  std::vector<GradientChange>* tally = gradient != nullptr ? &changes : nullptr;
  if (track) Tally(touched, *shapes, -1.0, &mesh_change, &map_change, tally);
  int moved = 0;
  for (const RelaxTarget& target : targets) moved += RelaxOne(target, steps, shapes) ? 1 : 0;
  if (!track || moved == 0) return moved;  // gradient and energies stay as they are
  Tally(touched, *shapes, 1.0, &mesh_change, &map_change, tally);
  for (const GradientChange& c : changes) (*gradient)[c.shape][c.vertex] += c.change;
  if (energies != nullptr) {
    const int n = objective_.num_shapes();
    const double w = objective_.map_weight();
    const double mesh_sum = energies->mesh * n + mesh_change;
    const double map_sum = energies->map * n + map_change;
    *energies = {(1.0 - w) * mesh_sum + w * map_sum, mesh_sum / n, map_sum / n};
  }
  return moved;
}

}  // namespace inbetween::solver
