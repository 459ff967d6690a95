// Comesh optimization inner loop: L-BFGS with a Laplacian initial Hessian and an
// inversion-free line search over all shapes at once (see comesh_optimizer.h).
#include "solver/comesh/comesh_optimizer.h"

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <set>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "solver/comesh/comesh_objective.h"

namespace inbetween::solver {
namespace {

using Eigen::VectorXd;

absl::Status ValidateInput(const Multimesh& mesh) {
  if (mesh.shapes.empty()) return absl::InvalidArgumentError("multimesh has no shapes");
  const int n = mesh.num_vertices();
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    if (static_cast<int>(mesh.shapes[s].size()) != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("shape ", s, " has ", mesh.shapes[s].size(), " vertices, shape 0 has ", n));
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("triangle ", t, " has vertex index ", tri[k], " outside [0, ", n, ")"));
      }
    }
    for (int s = 0; s < mesh.num_shapes(); ++s) {
      const Points& x = mesh.shapes[s];
      const Point ab = x[tri[1]] - x[tri[0]];
      const Point ac = x[tri[2]] - x[tri[0]];
      const double area2 = ab.x() * ac.y() - ab.y() * ac.x();
      if (!(area2 > 0.0)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "triangle %d (%d, %d, %d) is inverted or degenerate in shape %d (signed area %g)", t,
            tri[0], tri[1], tri[2], s, 0.5 * area2));
      }
    }
  }
  for (int v : mesh.boundary) {
    if (v < 0 || v >= n) {
      return absl::InvalidArgumentError(absl::StrCat("boundary vertex ", v, " out of range"));
    }
  }
  for (const auto& c : mesh.cohesive_edges) {
    for (int v : c) {
      if (v < 0 || v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("cohesive edge vertex ", v, " out of range"));
      }
    }
  }
  return absl::OkStatus();
}

// Per shape, which vertices move and how: interior vertices move freely in 2D; with sliding on,
// a boundary vertex that lies strictly between its two boundary neighbours on a straight line
// (in that shape) moves along that line; every other vertex is fixed.
class Layout {
 public:
  Layout(const Multimesh& mesh, bool slide_boundary) {
    const int n = mesh.num_vertices();
    num_shapes_ = mesh.num_shapes();
    std::vector<char> used(n, 0), pinned(n, 0);
    std::set<std::pair<int, int>> once;
    for (const Triangle& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        used[t[k]] = 1;
        const std::pair<int, int> e = std::minmax(t[k], t[(k + 1) % 3]);
        if (!once.insert(e).second) once.erase(e);
      }
    }
    std::vector<std::vector<int>> boundary_nbrs(n);
    for (const auto& [a, b] : once) {
      boundary_nbrs[a].push_back(b);
      boundary_nbrs[b].push_back(a);
    }
    std::vector<char> on_boundary(n, 0);
    for (int v = 0; v < n; ++v) on_boundary[v] = !boundary_nbrs[v].empty();
    for (int v : mesh.boundary) {
      if (!on_boundary[v]) pinned[v] = 1;  // listed as boundary but inside the mesh: keep it
    }
    for (const auto& c : mesh.cohesive_edges) {
      for (int v : c) pinned[v] = 1;
    }
    index_.assign(num_shapes_, std::vector<int>(n, -1));
    for (int s = 0; s < num_shapes_; ++s) {
      const Points& x = mesh.shapes[s];
      for (int v = 0; v < n; ++v) {
        if (!used[v] || pinned[v]) continue;
        Var var{s, v, size_, false, Point::Zero(), x[v]};
        if (on_boundary[v]) {
          if (!slide_boundary || boundary_nbrs[v].size() != 2) continue;
          const Point a = x[boundary_nbrs[v][0]], b = x[boundary_nbrs[v][1]];
          const Point ab = b - a, av = x[v] - a;
          const double len2 = ab.squaredNorm();
          const double along = av.dot(ab);
          if (!(len2 > 0.0) || std::abs(ab.x() * av.y() - ab.y() * av.x()) > 1e-9 * len2 ||
              along <= 0.0 || along >= len2) {
            continue;  // a corner (or degenerate): pinned
          }
          var.slider = true;
          var.direction = ab / std::sqrt(len2);
        }
        index_[s][v] = static_cast<int>(vars_.size());
        size_ += var.slider ? 1 : 2;
        vars_.push_back(var);
      }
    }
  }

  struct Var {
    int shape;
    int vertex;
    int offset;       // into z
    bool slider;      // one unknown (position = base + z * direction) instead of two
    Point direction;  // unit, sliders only
    Point base;       // position at the start, sliders only
  };

  int size() const { return size_; }
  int num_shapes() const { return num_shapes_; }
  const std::vector<Var>& vars() const { return vars_; }
  int index(int shape, int v) const { return index_[shape][v]; }

  VectorXd Gather(const std::vector<Points>& shapes) const {
    VectorXd z(size_);
    for (const Var& var : vars_) {
      const Point& p = shapes[var.shape][var.vertex];
      if (var.slider) {
        z[var.offset] = (p - var.base).dot(var.direction);
      } else {
        z.segment<2>(var.offset) = p;
      }
    }
    return z;
  }
  VectorXd GatherGradient(const std::vector<Points>& gradient) const {
    VectorXd g(size_);
    for (const Var& var : vars_) {
      const Point& p = gradient[var.shape][var.vertex];
      if (var.slider) {
        g[var.offset] = p.dot(var.direction);
      } else {
        g.segment<2>(var.offset) = p;
      }
    }
    return g;
  }
  void Scatter(const VectorXd& z, std::vector<Points>* shapes) const {
    for (const Var& var : vars_) {
      (*shapes)[var.shape][var.vertex] = var.slider
                                             ? Point(var.base + z[var.offset] * var.direction)
                                             : Point(z.segment<2>(var.offset));
    }
  }
  // Displacement of vertex v of shape s for the step z -> z + d.
  Point Displacement(const VectorXd& d, int s, int v) const {
    const int i = index_[s][v];
    if (i < 0) return Point::Zero();
    const Var& var = vars_[i];
    return var.slider ? Point(d[var.offset] * var.direction) : Point(d.segment<2>(var.offset));
  }

 private:
  int num_shapes_ = 0;
  int size_ = 0;
  std::vector<Var> vars_;
  std::vector<std::vector<int>> index_;  // [shape][vertex] -> var or -1
};

// Largest step t such that every triangle of every shape keeps positive area on (0, t).
double MaxNonInvertingStep(const std::vector<Triangle>& triangles,
                           const std::vector<Points>& shapes, const Layout& layout,
                           const VectorXd& d) {
  double best = std::numeric_limits<double>::infinity();
  auto cross = [](const Point& u, const Point& v) { return u.x() * v.y() - u.y() * v.x(); };
  for (int s = 0; s < static_cast<int>(shapes.size()); ++s) {
    for (const Triangle& t : triangles) {
      Point p[3], q[3];
      bool moves = false;
      for (int k = 0; k < 3; ++k) {
        p[k] = shapes[s][t[k]];
        moves |= layout.index(s, t[k]) >= 0;
        q[k] = layout.Displacement(d, s, t[k]);
      }
      if (!moves) continue;
      const Point e1 = p[1] - p[0], e2 = p[2] - p[0];
      const Point f1 = q[1] - q[0], f2 = q[2] - q[0];
      // 2 area(t) = c0 + c1 t + c2 t^2, c0 > 0.
      const double c0 = cross(e1, e2);
      const double c1 = cross(e1, f2) + cross(f1, e2);
      const double c2 = cross(f1, f2);
      double root = std::numeric_limits<double>::infinity();
      if (std::abs(c2) <= 1e-14 * (std::abs(c1) + std::abs(c0))) {
        if (c1 < 0.0) root = -c0 / c1;
      } else {
        const double disc = c1 * c1 - 4.0 * c2 * c0;
        if (disc >= 0.0) {
          const double sq = std::sqrt(disc);
          const double qq = -0.5 * (c1 + (c1 >= 0.0 ? sq : -sq));
          const double r1 = qq / c2;
          const double r2 = (qq != 0.0) ? c0 / qq : std::numeric_limits<double>::infinity();
          if (r1 > 0.0) root = std::min(root, r1);
          if (r2 > 0.0) root = std::min(root, r2);
        }
      }
      best = std::min(best, root);
    }
  }
  return best;
}

// B0 = blockdiag_s(K_s / A_s) (or identity) and H0 = B0^{-1}, before the scalar beta.
// K_s = J_s^T (L kron I_2) J_s: L the uniform graph Laplacian of the shared topology, J_s the
// linear map from shape s's unknowns to its vertex positions (identity for a 2D unknown, the
// slide direction for a slider, zero for fixed vertices, which thus act as Dirichlet values).
// Without sliders K_s is L restricted to the free vertices, once for x and once for y.
class InitialHessian {
 public:
  using Solver = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>;

  static absl::StatusOr<InitialHessian> Create(const std::vector<Triangle>& triangles,
                                               const Layout& layout, std::vector<double> areas,
                                               bool use_laplacian) {
    InitialHessian h;
    h.areas_ = std::move(areas);
    h.use_laplacian_ = use_laplacian;
    if (!use_laplacian) return h;
    const int num_shapes = layout.num_shapes();
    h.blocks_.resize(num_shapes);
    // Unknowns are stored shape after shape: find each shape's contiguous range of z.
    for (Block& b : h.blocks_) b.begin = b.end = -1;
    for (const Layout::Var& var : layout.vars()) {
      Block& b = h.blocks_[var.shape];
      if (b.begin < 0) b.begin = var.offset;
      b.end = var.offset + (var.slider ? 1 : 2);
    }
    for (int s = 0; s < num_shapes; ++s) {
      Block& block = h.blocks_[s];
      if (block.begin < 0) continue;
      const int m = block.end - block.begin;
      // (local row, direction) pairs of the unknowns of vertex v: J's nonzero columns.
      auto columns = [&](int v, std::pair<int, Point> out[2]) -> int {
        const int i = layout.index(s, v);
        if (i < 0) return 0;
        const Layout::Var& var = layout.vars()[i];
        const int r = var.offset - block.begin;
        if (var.slider) {
          out[0] = {r, var.direction};
          return 1;
        }
        out[0] = {r, Point(1, 0)};
        out[1] = {r + 1, Point(0, 1)};
        return 2;
      };
      std::vector<Eigen::Triplet<double>> trip;
      std::vector<double> diag(m, 0.0);
      std::pair<int, Point> ca[2], cb[2];
      for (const Triangle& t : triangles) {
        for (int k = 0; k < 3; ++k) {
          // Each interior edge is seen from two triangles: weight 1/2 each.
          constexpr double w = 0.5;
          const int na = columns(t[k], ca), nb = columns(t[(k + 1) % 3], cb);
          for (int i = 0; i < na; ++i) {
            for (int j = 0; j < na; ++j)
              trip.emplace_back(ca[i].first, ca[j].first, w * ca[i].second.dot(ca[j].second));
          }
          for (int i = 0; i < nb; ++i) {
            for (int j = 0; j < nb; ++j)
              trip.emplace_back(cb[i].first, cb[j].first, w * cb[i].second.dot(cb[j].second));
          }
          for (int i = 0; i < na; ++i) {
            for (int j = 0; j < nb; ++j) {
              const double value = -w * ca[i].second.dot(cb[j].second);
              trip.emplace_back(ca[i].first, cb[j].first, value);
              trip.emplace_back(cb[j].first, ca[i].first, value);
            }
          }
        }
      }
      block.matrix.resize(m, m);
      block.matrix.setFromTriplets(trip.begin(), trip.end());
      // A free component touching no fixed vertex would make K singular: regularize slightly.
      for (int k = 0; k < m; ++k) block.matrix.coeffRef(k, k) *= 1.0 + 1e-8;
      block.solver = std::make_unique<Solver>(block.matrix);
      if (block.solver->info() != Eigen::Success) {
        return absl::InternalError("factorizing the comesh Laplacian preconditioner failed");
      }
    }
    return h;
  }

  VectorXd ApplyInverse(const VectorXd& g) const { return Apply(g, /*inverse=*/true); }  // H0 g
  VectorXd Apply(const VectorXd& x) const { return Apply(x, /*inverse=*/false); }        // B0 x

 private:
  struct Block {
    int begin = -1, end = -1;  // this shape's range of z
    Eigen::SparseMatrix<double> matrix;
    std::unique_ptr<Solver> solver;  // by pointer: Eigen's factorizations are not movable
  };

  VectorXd Apply(const VectorXd& x, bool inverse) const {
    if (!use_laplacian_) return x;
    VectorXd out(x.size());
    for (size_t s = 0; s < blocks_.size(); ++s) {
      const Block& b = blocks_[s];
      if (b.begin < 0) continue;
      const int m = b.end - b.begin;
      if (inverse) {
        out.segment(b.begin, m) = areas_[s] * b.solver->solve(x.segment(b.begin, m));
      } else {
        out.segment(b.begin, m) = b.matrix * x.segment(b.begin, m) / areas_[s];
      }
    }
    return out;
  }

  std::vector<double> areas_;
  bool use_laplacian_ = true;
  std::vector<Block> blocks_;
};

}  // namespace

absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status st = ValidateInput(mesh); !st.ok()) return st;
  if (options.max_iterations < 0 || options.history < 0 || !(options.max_step_fraction > 0.0) ||
      !(options.max_step_fraction < 1.0)) {
    return absl::InvalidArgumentError(
        "comesh options: max_iterations and history must be >= 0, max_step_fraction in (0, 1)");
  }
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh.triangles, mesh.shapes, options.map_weight);
  if (!objective.ok()) return objective.status();

  ComeshReport rep;
  rep.vertices_before = rep.vertices_after = mesh.num_vertices();
  const Layout layout(mesh, options.slide_boundary);
  std::vector<Points> shapes = mesh.shapes;
  std::vector<Points> grad_shapes;
  ComeshEnergies energies;
  double f = objective->Evaluate(shapes, &grad_shapes, &energies);
  rep.energy_evaluations = 1;
  rep.map_energy_before = rep.map_energy = energies.map;
  rep.mesh_energy_before = rep.mesh_energy = energies.mesh;
  rep.objective_before = rep.objective_after = f;
  auto finish = [&](std::string reason) -> absl::StatusOr<Multimesh> {
    rep.stop_reason = std::move(reason);
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (report != nullptr) *report = rep;
    Multimesh out = mesh;
    out.shapes = shapes;
    return out;
  };
  if (layout.size() == 0) return finish("no_free");

  std::vector<double> areas;
  for (int s = 0; s < mesh.num_shapes(); ++s) areas.push_back(objective->rest_area(s));
  absl::StatusOr<InitialHessian> h0 = InitialHessian::Create(
      mesh.triangles, layout, std::move(areas), options.laplacian_preconditioner);
  if (!h0.ok()) return h0.status();

  VectorXd z = layout.Gather(shapes);
  VectorXd g = layout.GatherGradient(grad_shapes);
  const double g0 = g.norm();
  struct Pair {
    VectorXd s, y;
    double rho;
  };
  std::deque<Pair> pairs;
  double beta = 1.0;
  int small_decreases = 0;
  std::vector<Points> trial = shapes;
  std::vector<Points> trial_grad;
  ComeshEnergies trial_energies;

  for (int iter = 0;; ++iter) {
    if (cancel != nullptr && cancel->IsCancelled()) {
      return absl::CancelledError(
          absl::StrCat("comesh optimization cancelled at iteration ", iter));
    }
    if (g.norm() <= options.gradient_tolerance * g0) return finish("gradient");
    if (iter >= options.max_iterations) return finish("max_iterations");

    // L-BFGS two-loop recursion with H0 = B0^{-1} / beta.
    VectorXd d;
    auto direction = [&]() {
      VectorXd q = g;
      std::vector<double> alpha(pairs.size());
      for (int i = static_cast<int>(pairs.size()) - 1; i >= 0; --i) {
        alpha[i] = pairs[i].rho * pairs[i].s.dot(q);
        q -= alpha[i] * pairs[i].y;
      }
      VectorXd r = h0->ApplyInverse(q) / beta;
      for (size_t i = 0; i < pairs.size(); ++i) {
        const double b = pairs[i].rho * pairs[i].y.dot(r);
        r += (alpha[i] - b) * pairs[i].s;
      }
      return VectorXd(-r);
    };
    d = direction();
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // lost descent (non-convexity): restart from the preconditioned gradient
      pairs.clear();
      d = direction();
      slope = g.dot(d);
      if (!(slope < 0.0)) {
        d = -g;
        slope = -g.squaredNorm();
      }
    }

    // Inversion-free backtracking line search.
    const double max_step = MaxNonInvertingStep(mesh.triangles, shapes, layout, d);
    double step = std::min(1.0, options.max_step_fraction * max_step);
    bool accepted = false;
    double f_new = f;
    VectorXd z_new;
    for (int b = 0; b <= options.max_backtracks; ++b, step *= 0.5) {
      z_new = z + step * d;
      layout.Scatter(z_new, &trial);
      f_new = objective->Evaluate(trial, &trial_grad, &trial_energies);
      ++rep.energy_evaluations;
      if (std::isfinite(f_new) && f_new <= f + options.armijo * step * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) return finish("line_search");

    const VectorXd g_new = layout.GatherGradient(trial_grad);
    Pair p{z_new - z, g_new - g, 0.0};
    const double sy = p.s.dot(p.y);
    if (sy > 1e-12 * p.s.norm() * p.y.norm() && options.history > 0) {
      p.rho = 1.0 / sy;
      beta = sy / p.s.dot(h0->Apply(p.s));
      pairs.push_back(std::move(p));
      if (static_cast<int>(pairs.size()) > options.history) pairs.pop_front();
    }
    const double decrease = (f - f_new) / std::max(std::abs(f_new), 1e-300);
    small_decreases = decrease < options.relative_decrease_tolerance ? small_decreases + 1 : 0;
    z = z_new;
    g = g_new;
    f = f_new;
    std::swap(shapes, trial);
    rep.inner = iter + 1;
    rep.objective_after = f;
    rep.map_energy = trial_energies.map;
    rep.mesh_energy = trial_energies.mesh;
    if (options.on_iterate) options.on_iterate(rep.inner, shapes);
    if (progress) {
      progress("comesh",
               options.max_iterations > 0 ? static_cast<double>(rep.inner) / options.max_iterations
                                          : 1.0,
               absl::StrFormat("iteration %d: objective %.6g, map %.5f, mesh %.5f, step %.3g",
                               rep.inner, f, rep.map_energy, rep.mesh_energy, step));
    }
    if (small_decreases >= std::max(1, options.decrease_patience)) return finish("decrease");
  }
}

}  // namespace inbetween::solver
