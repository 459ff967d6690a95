// Comesh optimization: inner loop (L-BFGS with a scalar CHOLMOD Laplacian initial Hessian,
// blending, curing and an inversion-free line search over all shapes at once) alternating with
// the outer topology loop (comesh_topology.h). See comesh_optimizer.h.
#include "solver/comesh/comesh_optimizer.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "solver/comesh/comesh_hessian.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_outline.h"
#include "solver/comesh/comesh_relax.h"
#include "solver/comesh/comesh_topology.h"
#include "solver/comesh/mips_energy.h"
#include "solver/core/cancellable_call.h"
#include "solver/core/parallel_chunks.h"
#include "solver/core/sparse_cholesky.h"

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
// (in that shape) moves along that line; with `outlines` (one per shape, may be null), in a shape
// whose outline has a soft corner (ShapeOutline::curved) any other boundary vertex that lies on
// the reference outline away from a hard point moves by arc length along it (comesh_outline.h);
// every other vertex is fixed.
class Layout {
 public:
  // With a `cancel` token (may be null) the edge list polls it (~0.1 s at 311k vertices); if it
  // was set, cancelled() is true and the layout is empty.
  Layout(const Multimesh& mesh, bool slide_boundary, const std::vector<ShapeOutline>* outlines,
         const CancelToken* cancel = nullptr) {
    const int n = mesh.num_vertices();
    num_vertices_ = n;
    num_shapes_ = mesh.num_shapes();
    std::vector<char> used(n, 0), pinned(n, 0);
    for (const Triangle& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) used[t[k]] = 1;
    }
    std::vector<std::pair<std::pair<int, int>, int>> uses;
    if (!EdgeUses(mesh.triangles, std::vector<char>(mesh.triangles.size(), 1), cancel, &uses)) {
      cancelled_ = true;
      return;
    }
    std::vector<std::vector<int>> boundary_nbrs(n);
    for (const auto& [edge, count] : uses) {
      if (count % 2 == 0) continue;  // as before: an edge used an odd number of times
      boundary_nbrs[edge.first].push_back(edge.second);
      boundary_nbrs[edge.second].push_back(edge.first);
    }
    std::vector<char> on_boundary(n, 0);
    for (int v = 0; v < n; ++v) on_boundary[v] = !boundary_nbrs[v].empty();
    for (int v : mesh.boundary) {
      if (!on_boundary[v]) pinned[v] = 1;  // listed as boundary but inside the mesh: keep it
    }
    for (const auto& c : mesh.cohesive_edges) {
      for (int v : c) pinned[v] = 1;
    }
    for (int v : mesh.pinned) pinned[v] = 1;  // correspondence marks
    index_.assign(num_shapes_, std::vector<int>(n, -1));
    for (int s = 0; s < num_shapes_; ++s) {
      const Points& x = mesh.shapes[s];
      // A shape without soft corners keeps the straight sliders (ShapeOutline::curved).
      const ShapeOutline* outline =
          outlines != nullptr && (*outlines)[s].curved() ? &(*outlines)[s] : nullptr;
      const double tolerance = outline != nullptr ? outline->tolerance() : 0.0;
      for (int v = 0; v < n; ++v) {
        if (!used[v] || pinned[v]) continue;
        Var var{s, v, size_, false, Point::Zero(), x[v]};
        if (on_boundary[v]) {
          if (!slide_boundary || boundary_nbrs[v].size() != 2) continue;
          // On the reference outline: it slides along it, or stays at a hard point. (A straight
          // slider there could follow its line off the outline once a neighbour has moved along
          // a curve.)
          const std::optional<ShapeOutline::Location> at =
              outline != nullptr ? outline->Locate(x[v], tolerance) : std::nullopt;
          if (at) {
            if (outline->AtHardPoint(at->loop, at->u, tolerance)) continue;
            var.direction = outline->Tangent(at->loop, at->u);
            if (!(var.direction.squaredNorm() > 0.5)) continue;  // a degenerate stretch: fixed
            var.slider = true;
            var.outline = at->loop;
            var.u0 = at->u;
            var.prev = boundary_nbrs[v][0];
            var.next = boundary_nbrs[v][1];
            std::tie(var.lo, var.hi) = outline->Stretch(at->loop, at->u);
            ++num_outline_;
          } else {
            // Otherwise (no outlines, or a vertex off them): along the straight segment of its
            // neighbours if it lies strictly inside it, else fixed.
            const Point a = x[boundary_nbrs[v][0]], b = x[boundary_nbrs[v][1]];
            if (!StrictlyInsideSegment(a, b, x[v])) continue;
            var.slider = true;
            var.direction = (b - a).normalized();
          }
        }
        index_[s][v] = static_cast<int>(vars_.size());
        size_ += var.slider ? 1 : 2;
        vars_.push_back(var);
        tangent_.push_back(var.direction);
        sides_.emplace_back(var.direction, var.direction);
        if (var.outline >= 0) UpdateTangents(*outline, vars_.size() - 1, var.u0);
      }
    }
    outlines_ = num_outline_ > 0 ? outlines : nullptr;
  }

  struct Var {
    int shape;
    int vertex;
    int offset;       // into z
    bool slider;      // one unknown (position = base + z * direction) instead of two
    Point direction;  // unit, sliders only; for outline sliders the tangent where the run began
    Point base;       // position at the start, sliders only
    // Outline sliders: the loop of the shape's outline, the arc length where the run began (the
    // unknown is the arc length itself) and the stretch between hard points it stays in.
    int outline = -1;
    double u0 = 0.0, lo = 0.0, hi = 0.0;
    int prev = -1, next = -1;  // outline sliders: the two boundary neighbours
  };

  bool cancelled() const { return cancelled_; }
  int size() const { return size_; }
  int num_shapes() const { return num_shapes_; }
  int num_vertices() const { return num_vertices_; }
  const std::vector<Var>& vars() const { return vars_; }
  int index(int shape, int v) const { return index_[shape][v]; }

  VectorXd Gather(const std::vector<Points>& shapes) const {
    VectorXd z(size_);
    for (const Var& var : vars_) {
      const Point& p = shapes[var.shape][var.vertex];
      if (var.outline >= 0) {
        z[var.offset] = var.u0;
      } else if (var.slider) {
        z[var.offset] = (p - var.base).dot(var.direction);
      } else {
        z.segment<2>(var.offset) = p;
      }
    }
    return z;
  }
  // The gradient in the unknowns; a slider's is the 2D gradient along its current tangent (see
  // Track). An outline slider at a polyline point, where the path bends, takes the one-sided
  // derivative of the side along which the objective falls (0 if it rises both ways), and its
  // tangent (for Displacements) becomes that side's.
  VectorXd GatherGradient(const std::vector<Points>& gradient) {
    VectorXd g(size_);
    for (size_t i = 0; i < vars_.size(); ++i) {
      const Var& var = vars_[i];
      const Point& p = gradient[var.shape][var.vertex];
      if (var.outline >= 0 && sides_[i].first != sides_[i].second) {
        const double forward = p.dot(sides_[i].second), back = p.dot(sides_[i].first);
        if (forward < 0.0) {
          g[var.offset] = forward;
          tangent_[i] = sides_[i].second;
        } else if (back > 0.0) {
          g[var.offset] = back;
          tangent_[i] = sides_[i].first;
        } else {
          g[var.offset] = 0.0;
          tangent_[i] = sides_[i].second;
        }
      } else if (var.slider) {
        g[var.offset] = p.dot(tangent_[i]);
      } else {
        g.segment<2>(var.offset) = p;
      }
    }
    return g;
  }
  void Scatter(const VectorXd& z, std::vector<Points>* shapes) const {
    for (const Var& var : vars_) {
      Point& p = (*shapes)[var.shape][var.vertex];
      if (var.outline >= 0) {
        p = OutlinePoint(var, z[var.offset]);
      } else {
        p = var.slider ? Point(var.base + z[var.offset] * var.direction)
                       : Point(z.segment<2>(var.offset));
      }
    }
  }
  // Every vertex's displacement in every shape for the step z -> z + d (zero where fixed), to
  // first order: a slider moves along its current tangent.
  void Displacements(const VectorXd& d, std::vector<Points>* out) const {
    out->resize(num_shapes_);
    for (Points& shape : *out) shape.assign(num_vertices_, Point::Zero());
    for (size_t i = 0; i < vars_.size(); ++i) {
      const Var& var = vars_[i];
      (*out)[var.shape][var.vertex] =
          var.slider ? Point(d[var.offset] * tangent_[i]) : Point(d.segment<2>(var.offset));
    }
  }
  // Moves the outline sliders' current tangents to the arc lengths in z (after an accepted step;
  // a straight slider's tangent is its direction throughout).
  // Where outline slider i (var.outline >= 0) is at unknown value u.
  Point OutlinePoint(const Var& var, double u) const {
    return (*outlines_)[var.shape].At(var.outline, std::clamp(u, var.lo, var.hi));
  }
  void Track(const VectorXd& z) {
    if (num_outline_ == 0) return;
    for (size_t i = 0; i < vars_.size(); ++i) {
      const Var& var = vars_[i];
      if (var.outline < 0) continue;
      UpdateTangents((*outlines_)[var.shape], i, std::clamp(z[var.offset], var.lo, var.hi));
    }
  }

 private:
  // Outline slider i's tangent and sides at arc length u of its loop of `outline`.
  void UpdateTangents(const ShapeOutline& outline, size_t i, double u) {
    const int loop = vars_[i].outline;
    const Point t = outline.Tangent(loop, u);
    if (t.squaredNorm() > 0.5) tangent_[i] = t;  // (zero only on a zero-length segment)
    sides_[i] = outline.Tangents(loop, u);
    if (!(sides_[i].first.squaredNorm() > 0.5 && sides_[i].second.squaredNorm() > 0.5)) {
      sides_[i] = {tangent_[i], tangent_[i]};
    }
  }

  int num_shapes_ = 0;
  int num_vertices_ = 0;
  int size_ = 0;
  int num_outline_ = 0;
  bool cancelled_ = false;
  std::vector<Var> vars_;
  std::vector<Point> tangent_;  // per var: a slider's current unit tangent
  // Per var: an outline slider's tangents just before and after where it is (equal inside a
  // segment; a straight slider's direction twice).
  std::vector<std::pair<Point, Point>> sides_;
  const std::vector<ShapeOutline>* outlines_ = nullptr;
  std::vector<std::vector<int>> index_;  // [shape][vertex] -> var or -1
};

// Twice the area of triangle t at x + s dx, as c0 + c1 s + c2 s^2.
struct AreaPolynomial {
  double c0, c1, c2;
};
AreaPolynomial AreaAlong(const Points& x, const Points& dx, const Triangle& t) {
  auto cross = [](const Point& u, const Point& v) { return u.x() * v.y() - u.y() * v.x(); };
  const Point e1 = x[t[1]] - x[t[0]], e2 = x[t[2]] - x[t[0]];
  const Point f1 = dx[t[1]] - dx[t[0]], f2 = dx[t[2]] - dx[t[0]];
  return {cross(e1, e2), cross(e1, f2) + cross(f1, e2), cross(f1, f2)};
}

// Largest step t such that every triangle of every shape keeps positive area on (0, t), for the
// displacements `disp` (Layout::Displacements). A min over triangles, so the chunked parallel
// evaluation gives the same value for any thread count. A triangle that does not move adds
// nothing (its area polynomial is constant).
double MaxNonInvertingStep(const std::vector<Triangle>& triangles,
                           const std::vector<Points>& shapes, const std::vector<Points>& disp,
                           int threads) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr int kChunk = 4096;
  const int num_triangles = static_cast<int>(triangles.size());
  std::vector<double> part(NumChunks(num_triangles, kChunk), kInf);
  ParallelChunks(num_triangles, kChunk, threads, [&](int chunk, int begin, int end) {
    double best = kInf;
    for (size_t s = 0; s < shapes.size(); ++s) {
      const Points& x = shapes[s];
      const Points& dx = disp[s];
      for (int ti = begin; ti < end; ++ti) {
        const auto [c0, c1, c2] = AreaAlong(x, dx, triangles[ti]);  // c0 > 0
        double root = kInf;
        if (std::abs(c2) <= 1e-14 * (std::abs(c1) + std::abs(c0))) {
          if (c1 < 0.0) root = -c0 / c1;
        } else {
          const double disc = c1 * c1 - 4.0 * c2 * c0;
          if (disc >= 0.0) {
            const double sq = std::sqrt(disc);
            const double qq = -0.5 * (c1 + (c1 >= 0.0 ? sq : -sq));
            const double r1 = qq / c2;
            const double r2 = (qq != 0.0) ? c0 / qq : kInf;
            if (r1 > 0.0) root = std::min(root, r1);
            if (r2 > 0.0) root = std::min(root, r2);
          }
        }
        best = std::min(best, root);
      }
    }
    part[chunk] = best;
  });
  double best = kInf;
  for (double b : part) best = std::min(best, b);
  return best;
}

// Initial inverse Hessian H0 (before the scalar 1 / beta) after BCQN: the uniform graph
// Laplacian L of the shared topology, restricted to the vertices that are movable in EVERY shape
// (interior vertices and vertices that slide in every shape; all others act as Dirichlet values),
// factored ONCE as a scalar matrix with CHOLMOD and applied to x and y of every shape in one
// multi-column solve. Shape s's block is H0_s = A_s J_s^T L^{-1} J_s, J_s lifting a slider's
// scalar to 2D along its direction (projection onto the slider tangent after the solve), so H0 is
// SPD on the reduced unknowns without ever coupling x and y in the factor. Unknowns of vertices
// that are movable in some shapes only get the Jacobi value A_s / deg(v) (deg = L's diagonal).
// The forward operator B0 (for the curvature scaling and blending) is the matching
// J_s^T L J_s / A_s product, and deg(v) / A_s on the Jacobi unknowns.
class InitialHessian {
 public:
  static absl::StatusOr<InitialHessian> Create(const std::vector<Triangle>& triangles,
                                               const Layout& layout, std::vector<double> areas,
                                               bool use_laplacian, const CancelToken* cancel) {
    InitialHessian h;
    h.areas_ = std::move(areas);
    h.use_laplacian_ = use_laplacian;
    h.layout_ = &layout;
    if (!use_laplacian) return h;
    const int n = layout.num_vertices();
    const int num_shapes = layout.num_shapes();
    h.compact_.assign(n, -1);
    for (int v = 0; v < n; ++v) {
      bool everywhere = true;
      for (int s = 0; s < num_shapes && everywhere; ++s) everywhere = layout.index(s, v) >= 0;
      if (everywhere) h.compact_[v] = h.size_++;
    }
    h.degree_.assign(n, 0.0);
    std::vector<Eigen::Triplet<double>> trip;
    for (const Triangle& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        constexpr double w = 0.5;  // each interior edge is seen from two triangles
        const int a = t[k], b = t[(k + 1) % 3];
        h.degree_[a] += w;
        h.degree_[b] += w;
        const int ca = h.compact_[a], cb = h.compact_[b];
        if (ca >= 0) trip.emplace_back(ca, ca, w);
        if (cb >= 0) trip.emplace_back(cb, cb, w);
        if (ca >= 0 && cb >= 0) {
          trip.emplace_back(ca, cb, -w);
          trip.emplace_back(cb, ca, -w);
        }
      }
    }
    if (h.size_ == 0) return h;
    h.FindFloating(triangles);
    h.matrix_.resize(h.size_, h.size_);
    h.matrix_.setFromTriplets(trip.begin(), trip.end());
    // A floating component makes L singular: regularized slightly for the factorization, and
    // ApplyInverse keeps the constant out of its right-hand sides and solutions.
    for (int k = 0; k < h.size_; ++k) h.matrix_.coeffRef(k, k) *= 1.0 + 1e-8;
    h.matrix_.makeCompressed();
    h.solver_ = std::make_unique<SparseCholesky>();
    absl::Status st = h.solver_->Analyze(h.matrix_);
    if (st.ok()) st = h.solver_->Factorize(h.matrix_, cancel);
    if (absl::IsCancelled(st)) return st;
    if (!st.ok()) {
      return absl::InternalError(
          absl::StrCat("factorizing the comesh Laplacian preconditioner: ", st.message()));
    }
    return h;
  }

  // H0 g (without 1 / beta); an empty vector if `cancel` was set during the solve.
  VectorXd ApplyInverse(const VectorXd& g, const CancelToken* cancel) const {
    if (!use_laplacian_) return g;
    const Layout& layout = *layout_;
    const int num_shapes = layout.num_shapes();
    VectorXd out(g.size());
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(size_, 2 * num_shapes);
    for (const Layout::Var& var : layout.vars()) {
      const int c = compact_[var.vertex];
      const double a = areas_[var.shape];
      if (c < 0) {
        const double jacobi = a / std::max(degree_[var.vertex], 1e-300);
        if (var.slider) {
          out[var.offset] = jacobi * g[var.offset];
        } else {
          out.segment<2>(var.offset) = jacobi * g.segment<2>(var.offset);
        }
        continue;
      }
      const Point lifted =
          var.slider ? Point(g[var.offset] * var.direction) : Point(g.segment<2>(var.offset));
      rhs(c, 2 * var.shape) = lifted.x();
      rhs(c, 2 * var.shape + 1) = lifted.y();
    }
    RemoveFloatingMeans(&rhs);
    // Fails only when cancelled, after a successful factorization.
    if (size_ > 0 && !solver_->SolveInPlace(&rhs, 1, cancel).ok()) return VectorXd();
    RemoveFloatingMeans(&rhs);
    for (const Layout::Var& var : layout.vars()) {
      const int c = compact_[var.vertex];
      if (c < 0) continue;
      const Point p(rhs(c, 2 * var.shape), rhs(c, 2 * var.shape + 1));
      const double a = areas_[var.shape];
      if (var.slider) {
        out[var.offset] = a * p.dot(var.direction);
      } else {
        out.segment<2>(var.offset) = a * p;
      }
    }
    return out;
  }

  // B0 x.
  VectorXd Apply(const VectorXd& x) const {
    if (!use_laplacian_) return x;
    const Layout& layout = *layout_;
    const int num_shapes = layout.num_shapes();
    Eigen::MatrixXd lifted = Eigen::MatrixXd::Zero(size_, 2 * num_shapes);
    VectorXd out(x.size());
    for (const Layout::Var& var : layout.vars()) {
      const int c = compact_[var.vertex];
      if (c < 0) {
        const double d = degree_[var.vertex] / areas_[var.shape];
        if (var.slider) {
          out[var.offset] = d * x[var.offset];
        } else {
          out.segment<2>(var.offset) = d * x.segment<2>(var.offset);
        }
        continue;
      }
      const Point p =
          var.slider ? Point(x[var.offset] * var.direction) : Point(x.segment<2>(var.offset));
      lifted(c, 2 * var.shape) = p.x();
      lifted(c, 2 * var.shape + 1) = p.y();
    }
    const Eigen::MatrixXd product = matrix_ * lifted;
    for (const Layout::Var& var : layout.vars()) {
      const int c = compact_[var.vertex];
      if (c < 0) continue;
      const Point p =
          Point(product(c, 2 * var.shape), product(c, 2 * var.shape + 1)) / areas_[var.shape];
      if (var.slider) {
        out[var.offset] = p.dot(var.direction);
      } else {
        out.segment<2>(var.offset) = p;
      }
    }
    return out;
  }

 private:
  // The components of L's graph (compact vertices joined by mesh edges) with no edge to a
  // Dirichlet vertex: every vertex there moves in every shape (outline sliding round a whole
  // loop, past soft corners only), so L is singular on them, its null vector the component's
  // constant (a translation, which its closed loop of sliders cannot follow). Their rows in
  // floating_rows_, one run per component (floating_begin_).
  void FindFloating(const std::vector<Triangle>& triangles) {
    std::vector<int> parent(size_);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    std::vector<char> anchored(size_, 0);
    for (const Triangle& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const int ca = compact_[t[k]], cb = compact_[t[(k + 1) % 3]];
        if (ca >= 0 && cb >= 0) {
          parent[find(ca)] = find(cb);
        } else if (ca >= 0 || cb >= 0) {
          anchored[ca >= 0 ? ca : cb] = 1;
        }
      }
    }
    std::vector<char> root_anchored(size_, 0);
    for (int k = 0; k < size_; ++k) {
      if (anchored[k]) root_anchored[find(k)] = 1;
    }
    for (int k = 0; k < size_; ++k) {
      if (!root_anchored[find(k)]) floating_rows_.push_back(k);
    }
    if (floating_rows_.empty()) return;  // the usual case
    // Grouped by component (ascending rows within each), one run per component.
    std::stable_sort(floating_rows_.begin(), floating_rows_.end(),
                     [&](int a, int b) { return find(a) < find(b); });
    floating_begin_ = {0};
    for (size_t i = 1; i <= floating_rows_.size(); ++i) {
      if (i == floating_rows_.size() || find(floating_rows_[i]) != find(floating_rows_[i - 1])) {
        floating_begin_.push_back(static_cast<int>(i));
      }
    }
  }
  // Projects every column of `m` (rows = L's) onto the complement of the floating components'
  // constants: L's pseudo-inverse there instead of the regularized inverse, whose constant part
  // (~1e8 times the rest) would swamp the direction.
  void RemoveFloatingMeans(Eigen::MatrixXd* m) const {
    for (size_t c = 0; c + 1 < floating_begin_.size(); ++c) {
      const int begin = floating_begin_[c], end = floating_begin_[c + 1];
      for (int col = 0; col < m->cols(); ++col) {
        double mean = 0.0;
        for (int i = begin; i < end; ++i) mean += (*m)(floating_rows_[i], col);
        mean /= end - begin;
        for (int i = begin; i < end; ++i) (*m)(floating_rows_[i], col) -= mean;
      }
    }
  }

  std::vector<double> areas_;
  bool use_laplacian_ = true;
  const Layout* layout_ = nullptr;
  int size_ = 0;
  std::vector<int> compact_;    // vertex -> row of L, or -1
  std::vector<double> degree_;  // L's diagonal over all vertices (Jacobi fallback)
  std::vector<int> floating_rows_, floating_begin_;  // see FindFloating
  Eigen::SparseMatrix<double> matrix_;
  std::unique_ptr<SparseCholesky> solver_;  // by pointer: keeps InitialHessian movable
};

// Each shape's SparseCholesky, kept from one inner run to the next: a new analysis then reuses
// the previous factor's value array (hundreds of MB at 311k vertices, its pages already mapped;
// see SparseCholesky) instead of allocating and faulting in a new one.
using SharedFactors = std::vector<std::shared_ptr<SparseCholesky>>;

// Newton-type initial Hessian: the comesh objective's Hessian, block diagonal by shape (the mixed
// shape-shape MIPS blocks are left out) and made positive definite per triangle and shape
// (comesh_hessian.h: the edge-space 4 x 4 sum of that shape's ODT term and its two MIPS terms,
// projected), in the reduced unknowns (a slider's row is the 2D row projected on its direction).
// Each shape's unknowns are contiguous in z, so every shape has its own sparse matrix and
// CHOLMOD factor (supernodal when CHOLMOD finds it pays: large meshes); their sparsity patterns
// (unknowns adjacent in the mesh) are built once per inner run, and Update() recomputes the values
// at new positions and refactors on the same patterns. Shapes are assembled, factored and solved on
// separate threads (large meshes only): each touches only its own block, in a fixed order, so
// results do not depend on the thread count.
class HessianPreconditioner {
 public:
  static absl::StatusOr<HessianPreconditioner> Create(
      const std::vector<Triangle>& triangles, const Layout& layout,
      const ComeshObjective& objective, const std::vector<Points>& shapes, int background_analysis,
      bool float_substitutions, double mips_damping, const CancelToken* cancel,
      SharedFactors* factors) {
    HessianPreconditioner h;
    h.background_analysis_ = background_analysis;
    h.mips_damping_ = mips_damping;
    h.triangles_ = &triangles;
    h.layout_ = &layout;
    h.objective_ = &objective;
    const int n = layout.num_vertices();
    const int num_shapes = layout.num_shapes();
    // Each vertex's neighbours and itself, ascending: nbrs(v) (compressed rows, one allocation).
    // The loops below poll `cancel` every kSetUpPoll items: at 311k vertices the pattern took
    // ~0.56 s, the node graph and matrix ~0.37 s, these neighbour lists ~0.12 s.
    std::vector<int> start(n + 1, 0), list(9 * triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
      if (t % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
      for (int a = 0; a < 3; ++a) start[triangles[t][a] + 1] += 3;
    }
    for (int v = 0; v < n; ++v) start[v + 1] += start[v];
    {
      std::vector<int> fill(start.begin(), start.end() - 1);
      for (size_t t = 0; t < triangles.size(); ++t) {
        if (t % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) list[fill[triangles[t][a]]++] = triangles[t][b];
        }
      }
    }
    std::vector<int> count(n);
    for (int v = 0; v < n; ++v) {
      if (v % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
      auto begin = list.begin() + start[v], end = list.begin() + start[v + 1];
      std::sort(begin, end);
      count[v] = static_cast<int>(std::unique(begin, end) - begin);
    }
    auto nbrs = [&](int v) {
      return std::span<const int>(list.data() + start[v], static_cast<size_t>(count[v]));
    };
    if (Cancelled(cancel)) return SetUpCancelled();
    // Shape s's unknowns are z[begin_[s], begin_[s + 1]) (Layout numbers them shape by shape).
    h.begin_.assign(num_shapes + 1, layout.size());
    for (int i = static_cast<int>(layout.vars().size()) - 1; i >= 0; --i) {
      h.begin_[layout.vars()[i].shape] = layout.vars()[i].offset;
    }
    for (int s = num_shapes - 1; s >= 0; --s) h.begin_[s] = std::min(h.begin_[s], h.begin_[s + 1]);
    h.blocks_.resize(num_shapes);
    // Column-major pattern of each symmetric block: column j = unknown j, rows = the unknowns of
    // the same shape at the vertex and its neighbours, ascending (offsets grow with the vertex).
    std::vector<std::vector<int>> outer(num_shapes), inner(num_shapes);
    for (int s = 0; s < num_shapes; ++s) outer[s].assign(h.begin_[s + 1] - h.begin_[s] + 1, 0);
    // Room for every entry first (at most 2 rows per neighbour and column): growing by doubling
    // copied ~16 MB at once at 311k vertices, ~0.1 s without a poll.
    {
      std::vector<size_t> bound(num_shapes, 0);
      for (size_t i = 0; i < layout.vars().size(); ++i) {
        if (i % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
        const Layout::Var& var = layout.vars()[i];
        bound[var.shape] += (var.slider ? 2 : 4) * static_cast<size_t>(count[var.vertex]);
      }
      for (int s = 0; s < num_shapes; ++s) {
        inner[s].reserve(bound[s]);
        // As many graph entries as vertex neighbours at most (rows <= column, below).
        h.blocks_[s].node_inner.reserve(bound[s] / 2);
      }
    }
    for (size_t i = 0; i < layout.vars().size(); ++i) {
      if (i % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
      const Layout::Var& var = layout.vars()[i];
      const int s = var.shape;
      for (int c = 0; c < (var.slider ? 1 : 2); ++c) {
        outer[s][var.offset + c - h.begin_[s]] = static_cast<int>(inner[s].size());
        for (int w : nbrs(var.vertex)) {
          const int i = layout.index(s, w);
          if (i < 0) continue;
          const Layout::Var& other = layout.vars()[i];
          inner[s].push_back(other.offset - h.begin_[s]);
          if (!other.slider) inner[s].push_back(other.offset + 1 - h.begin_[s]);
        }
      }
    }
    // The vertex graph of each shape (one node per free or sliding vertex, in unknown order), for
    // the fill-reducing ordering: AMD on it, each node expanded to its 1 or 2 unknowns, costs a
    // quarter of AMD on the unknowns' graph and orders a vertex's two unknowns together anyway.
    std::vector<int> node(layout.vars().size(), -1);
    for (size_t i = 0; i < layout.vars().size(); ++i) {
      if (i % kSetUpPoll == 0 && Cancelled(cancel)) return SetUpCancelled();
      Block& block = h.blocks_[layout.vars()[i].shape];
      node[i] = static_cast<int>(block.node_unknowns.size());
      block.node_unknowns.push_back(layout.vars()[i].offset - h.begin_[layout.vars()[i].shape]);
      block.node_outer.push_back(static_cast<int>(block.node_inner.size()));
      for (int w : nbrs(layout.vars()[i].vertex)) {
        const int j = layout.index(layout.vars()[i].shape, w);
        if (j >= 0 && node[j] >= 0) block.node_inner.push_back(node[j]);  // rows <= column
      }
    }
    for (Block& block : h.blocks_) {
      block.node_outer.push_back(static_cast<int>(block.node_inner.size()));
    }
    if (Cancelled(cancel)) return SetUpCancelled();
    // The blocks' patterns (fresh memory, its pages faulted in as they are written): copied in
    // polled spans, as AssembleShape zeroes the values.
    auto copy_polled = [cancel](const std::vector<int>& from, int* to) {
      return InPolledSpans(from.size(), cancel, [&](size_t begin, size_t end) {
        std::copy(from.begin() + begin, from.begin() + end, to + begin);
      });
    };
    for (int s = 0; s < num_shapes; ++s) {
      Block& block = h.blocks_[s];
      const int size = h.begin_[s + 1] - h.begin_[s];
      outer[s][size] = static_cast<int>(inner[s].size());
      block.matrix = std::make_shared<Eigen::SparseMatrix<double>>(size, size);
      block.matrix->resizeNonZeros(static_cast<Eigen::Index>(inner[s].size()));
      if (!copy_polled(outer[s], block.matrix->outerIndexPtr()) ||
          !copy_polled(inner[s], block.matrix->innerIndexPtr())) {
        return SetUpCancelled();
      }
      if (factors->size() <= static_cast<size_t>(s)) factors->resize(s + 1);
      std::shared_ptr<SparseCholesky>& solver = (*factors)[s];
      if (solver == nullptr) {
        solver = std::make_shared<SparseCholesky>(SparseCholesky::Method::kAuto);
      }
      solver->set_float_substitutions(float_substitutions);
      block.solver = solver;
    }
    h.threads_ = layout.size() >= kParallelUnknowns ? objective.threads() : 1;
    if (absl::Status st = h.Refactor(shapes, /*analyze=*/true, cancel); !st.ok()) return st;
    return h;
  }

  absl::Status Update(const std::vector<Points>& shapes, const CancelToken* cancel) {
    return Refactor(shapes, false, cancel);
  }

  // H0 g; an empty vector if `cancel` was set during the solves (each shape's solve polls it).
  VectorXd ApplyInverse(const VectorXd& g, const CancelToken* cancel) const {
    VectorXd x = g;
    std::atomic<bool> cancelled{false};
    ForEachShape([&](int s) {
      const int size = begin_[s + 1] - begin_[s];
      if (size == 0) return;
      Eigen::MatrixXd part = x.segment(begin_[s], size);
      // Fails only when cancelled, after a successful factorization.
      if (!blocks_[s].solver->SolveInPlace(&part, 1, cancel).ok()) {
        cancelled = true;
        return;
      }
      x.segment(begin_[s], size) = part.col(0);
    });
    return cancelled ? VectorXd() : x;
  }
  // H x; empty if `cancel` was set. Each block's product runs over spans of kApplyColumns columns
  // with a poll before each (one product took ~0.1 s at 311k vertices); Eigen accumulates a
  // column-major product column by column, so the sums are the same, in the same order.
  VectorXd Apply(const VectorXd& x, const CancelToken* cancel) const {
    constexpr int kApplyColumns = 1 << 14;
    VectorXd out = VectorXd::Zero(x.size());
    std::atomic<bool> cancelled{false};
    ForEachShape([&](int s) {
      const int begin = begin_[s], size = begin_[s + 1] - begin_[s];
      for (int j = 0; j < size; j += kApplyColumns) {
        if (Cancelled(cancel)) {
          cancelled = true;
          return;
        }
        const int columns = std::min(kApplyColumns, size - j);
        out.segment(begin, size).noalias() +=
            blocks_[s].matrix->middleCols(j, columns) * x.segment(begin + j, columns);
      }
    });
    return cancelled ? VectorXd() : out;
  }

 private:
  static constexpr double kDiagonalShift = 1e-10;  // relative to the largest diagonal entry
  // Below this many unknowns a thread start costs more than it saves (measured: from 4,000 on,
  // the 2k and 4k rows of S-Table 2 took 10% and 20% less than with 20,000).
  static constexpr int kParallelUnknowns = 4000;

  static absl::Status SetUpCancelled() {
    return absl::CancelledError("comesh Hessian set-up cancelled");
  }

  struct Block {
    // The vertex graph (see Create): node k's first unknown, and its upper-triangle pattern.
    std::vector<int> node_unknowns, node_outer, node_inner;
    // Shared with a symbolic analysis left running after a cancel (Analyze).
    std::shared_ptr<Eigen::SparseMatrix<double>> matrix;
    std::shared_ptr<SparseCholesky> solver;
    absl::Status status;
  };

  template <typename F>
  void ForEachShape(F&& f) const {
    ParallelChunks(
        static_cast<int>(blocks_.size()), 1, threads_, [&](int s, int, int) { f(s); },
        /*min_parallel=*/2);
  }

  // Polls `cancel` before each step and inside the factorizations (SparseCholesky::Factorize), so a
  // cancelled set-up ends within one step: assembly or analysis of one shape (tens of ms at 35k
  // vertices) or one supernode.
  absl::Status Refactor(const std::vector<Points>& shapes, bool analyze,
                        const CancelToken* cancel) {
    ForEachShape([&](int s) {
      Block& block = blocks_[s];
      block.status = absl::OkStatus();
      if (!AssembleShape(s, shapes, cancel)) {
        block.status = SetUpCancelled();
        return;
      }
      if (block.matrix->rows() == 0) return;
      if (analyze) block.status = Analyze(&block, background_analysis_, cancel);
      if (block.status.ok() && Cancelled(cancel)) block.status = SetUpCancelled();
      if (block.status.ok()) block.status = block.solver->Factorize(*block.matrix, cancel);
    });
    for (size_t s = 0; s < blocks_.size(); ++s) {
      if (absl::IsCancelled(blocks_[s].status)) return blocks_[s].status;
    }
    for (size_t s = 0; s < blocks_.size(); ++s) {
      if (!blocks_[s].status.ok()) {
        return absl::Status(
            blocks_[s].status.code(),
            absl::StrCat("comesh Hessian of shape ", s, ": ", blocks_[s].status.message()));
      }
    }
    return absl::OkStatus();
  }

  // Symbolic analysis with the vertex graph's AMD ordering expanded to the unknowns. AMD and
  // CHOLMOD's analysis are single library calls that grow with the mesh (at 311k vertices up to
  // ~1 s per shape, far past the 100 ms a cancel may take): on blocks of `background` unknowns
  // or more they run on a helper thread (RunCancellable) that owns its inputs (a copy of the node
  // graph, the matrix and solver shared), so a cancel returns at once and the helper finishes
  // the abandoned analysis on its own.
  static absl::Status Analyze(Block* block, int background, const CancelToken* cancel) {
    if (Cancelled(cancel)) return SetUpCancelled();
    struct Job {
      std::vector<int> node_outer, node_inner, node_unknowns;
      std::shared_ptr<Eigen::SparseMatrix<double>> matrix;
      std::shared_ptr<SparseCholesky> solver;
      absl::Status status;
    };
    // Copies of the node graph: ~1 ms against AMD's ~0.3 s at 311k vertices.
    auto job = std::make_shared<Job>(Job{block->node_outer, block->node_inner, block->node_unknowns,
                                         block->matrix, block->solver, absl::OkStatus()});
    auto work = [job] {
      absl::StatusOr<std::vector<int>> nodes =
          SparseCholesky::AmdOrdering(job->node_outer, job->node_inner);
      if (!nodes.ok()) {
        job->status = nodes.status();
        return;
      }
      const int size = static_cast<int>(job->matrix->rows());
      std::vector<int> ordering;
      ordering.reserve(size);
      for (int k : *nodes) {
        const int first = job->node_unknowns[k];
        const int end =
            k + 1 < static_cast<int>(job->node_unknowns.size()) ? job->node_unknowns[k + 1] : size;
        for (int u = first; u < end; ++u) ordering.push_back(u);
      }
      job->status = job->solver->Analyze(*job->matrix, &ordering);
    };
    const bool helper = background > 0 && block->matrix->rows() >= background;
    if (!RunCancellable(work, helper ? cancel : nullptr)) return SetUpCancelled();
    return job->status;
  }
  static constexpr int kSetUpPoll = 4096;

  // Calls f(begin, end) over [0, n) in spans of kSetUpPoll * 256 items, polling `cancel` before
  // each span and after the last; false (work partly done) if it was set.
  template <typename F>
  static bool InPolledSpans(size_t n, const CancelToken* cancel, F&& f) {
    constexpr size_t kSpan = size_t{kSetUpPoll} * 256;
    for (size_t begin = 0; begin < n; begin += kSpan) {
      if (Cancelled(cancel)) return false;
      f(begin, std::min(n, begin + kSpan));
    }
    return !Cancelled(cancel);
  }

  // Adds `value` at (row, col) of a block (binary search in the column).
  static void Add(Eigen::SparseMatrix<double>* m, int row, int col, double value) {
    const int* begin = m->innerIndexPtr() + m->outerIndexPtr()[col];
    const int* end = m->innerIndexPtr() + m->outerIndexPtr()[col + 1];
    m->valuePtr()[std::lower_bound(begin, end, row) - m->innerIndexPtr()] += value;
  }

  // Adds a at (row, col) and b at (row + 1, col): the rows of a free vertex's two unknowns are
  // next to each other in every column.
  static void AddPair(Eigen::SparseMatrix<double>* m, int row, int col, double a, double b) {
    const int* begin = m->innerIndexPtr() + m->outerIndexPtr()[col];
    const int* end = m->innerIndexPtr() + m->outerIndexPtr()[col + 1];
    double* v = m->valuePtr() + (std::lower_bound(begin, end, row) - m->innerIndexPtr());
    v[0] += a;
    v[1] += b;
  }

  // Returns false (block partly assembled) if `cancel` was set: polled at the first triangle and
  // every 4096 after it.
  bool AssembleShape(int s, const std::vector<Points>& shapes, const CancelToken* cancel) {
    const Layout& layout = *layout_;
    const ComeshObjective& obj = *objective_;
    Eigen::SparseMatrix<double>* m = blocks_[s].matrix.get();
    // Zeroing a fresh block faults its pages in (~130 ms at 311k vertices): in polled spans.
    const bool zeroed =
        InPolledSpans(static_cast<size_t>(m->nonZeros()), cancel, [m](size_t begin, size_t end) {
          std::fill(m->valuePtr() + begin, m->valuePtr() + end, 0.0);
        });
    if (!zeroed) return false;
    const int num_shapes = layout.num_shapes();
    const double w = obj.map_weight();
    const int next = (s + 1) % num_shapes, prev = (s + num_shapes - 1) % num_shapes;
    const int base = begin_[s];
    int count = 0;
    for (const Triangle& t : *triangles_) {
      if ((count++ & 4095) == 0 && Cancelled(cancel)) return false;
      int vars[3];
      bool any = false;
      for (int k = 0; k < 3; ++k) {
        vars[k] = layout.index(s, t[k]);
        any |= vars[k] >= 0;
      }
      if (!any) continue;
      const Eigen::Matrix2d e = EdgeMatrix(shapes[s], t);
      Matrix4 h4 = ((1.0 - w) / obj.odt_normalizer(s)) * OdtEdgeHessian(e);
      if (num_shapes > 1 && w > 0.0) {
        Matrix4 hp, hq;
        MipsEdgeHessians(e, EdgeMatrix(shapes[next], t), &hp, nullptr);
        MipsEdgeHessians(EdgeMatrix(shapes[prev], t), e, nullptr, &hq);
        if (mips_damping_ > 0.0) {  // ComeshOptions::mips_damping; Gershgorin bounds
          hp.diagonal().array() += mips_damping_ * hp.cwiseAbs().rowwise().sum().maxCoeff();
          hq.diagonal().array() += mips_damping_ * hq.cwiseAbs().rowwise().sum().maxCoeff();
        }
        h4 += (w / obj.rest_area(s)) * hp + (w / obj.rest_area(prev)) * hq;
      }
      const Matrix6 h6 = CornerHessian(ProjectPositiveDefinite(h4, 1e-8));
      for (int a = 0; a < 3; ++a) {
        if (vars[a] < 0) continue;
        const Layout::Var& va = layout.vars()[vars[a]];
        const int ra = va.offset - base;
        for (int b = 0; b < 3; ++b) {
          if (vars[b] < 0) continue;
          const Layout::Var& vb = layout.vars()[vars[b]];
          const int cb = vb.offset - base;
          const Eigen::Matrix2d block = h6.block<2, 2>(2 * a, 2 * b);
          if (va.slider && vb.slider) {
            Add(m, ra, cb, va.direction.dot(block * vb.direction));
          } else if (va.slider) {
            const Eigen::RowVector2d r = va.direction.transpose() * block;
            Add(m, ra, cb, r[0]);
            Add(m, ra, cb + 1, r[1]);
          } else if (vb.slider) {
            const Eigen::Vector2d c = block * vb.direction;
            AddPair(m, ra, cb, c[0], c[1]);
          } else {
            AddPair(m, ra, cb, block(0, 0), block(1, 0));
            AddPair(m, ra, cb + 1, block(0, 1), block(1, 1));
          }
        }
      }
    }
    // A tiny diagonal shift keeps the factor definite where the projection left a null direction
    // (e.g. a vertex whose every triangle has all other corners fixed along one line).
    double top = 0.0;
    for (int c = 0; c < m->cols(); ++c) top = std::max(top, m->coeff(c, c));
    for (int c = 0; c < m->cols(); ++c) Add(m, c, c, kDiagonalShift * top);
    return true;
  }

  const std::vector<Triangle>* triangles_ = nullptr;
  const Layout* layout_ = nullptr;
  const ComeshObjective* objective_ = nullptr;
  std::vector<int> begin_;  // shape s: unknowns [begin_[s], begin_[s + 1])
  std::vector<Block> blocks_;
  int threads_ = 1;
  int background_analysis_ = 0;  // ComeshOptions::background_analysis_unknowns
  double mips_damping_ = 0.0;    // ComeshOptions::mips_damping
};

// BCQN-style curing of a search direction: for every triangle of every shape, the linearised
// doubled area along d is c0 + c1 t. If the unit step would shrink it below cure_keep * c0, the
// displacements of its moving corners are scaled by (1 - cure_keep) c0 / (-c1) (the factor that
// keeps the linearised area at cure_keep * c0 if all corners are scaled alike; a vertex takes the
// smallest factor of its triangles). A few blocking triangles then no longer shrink the step of
// the whole mesh. Returns the number of scaled unknowns; `disp` is scratch (the displacements of
// the uncured d). -1 (d untouched) if `cancel` was set: polled before each chunk of triangles
// (the whole took up to ~0.14 s at 311k vertices between two polls).
int CureDirection(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes,
                  const Layout& layout, double cure_keep, int threads, const CancelToken* cancel,
                  std::vector<Points>* disp, VectorXd* d) {
  constexpr int kChunk = 4096;
  layout.Displacements(*d, disp);
  if (Cancelled(cancel)) return -1;
  // Per triangle and shape, the factor its moving corners need (1: none), in parallel; then each
  // vertex takes the smallest of its triangles' factors (serial, in triangle order).
  const int num_triangles = static_cast<int>(triangles.size());
  const int num_shapes = layout.num_shapes();
  std::vector<double> need(static_cast<size_t>(num_triangles) * num_shapes, 1.0);
  ParallelChunks(num_triangles, kChunk, threads, [&](int, int begin, int end) {
    if (Cancelled(cancel)) return;  // `need` partly filled: not used
    for (int s = 0; s < num_shapes; ++s) {
      const Points& x = shapes[s];
      const Points& dx = (*disp)[s];
      for (int ti = begin; ti < end; ++ti) {
        const auto [c0, c1, c2] = AreaAlong(x, dx, triangles[ti]);
        if (!(c0 + c1 < cure_keep * c0)) continue;
        need[static_cast<size_t>(s) * num_triangles + ti] = (1.0 - cure_keep) * c0 / (-c1);
      }
    }
  });
  if (Cancelled(cancel)) return -1;
  std::vector<double> factor(layout.vars().size(), 1.0);
  for (int s = 0; s < num_shapes; ++s) {
    for (int ti = 0; ti < num_triangles; ++ti) {
      if (ti % (16 * kChunk) == 0 && Cancelled(cancel)) return -1;
      const double c = need[static_cast<size_t>(s) * num_triangles + ti];
      if (c >= 1.0) continue;
      for (int k = 0; k < 3; ++k) {
        const int i = layout.index(s, triangles[ti][k]);
        if (i >= 0) factor[i] = std::min(factor[i], c);
      }
    }
  }
  int cured = 0;
  for (size_t i = 0; i < factor.size(); ++i) {
    if (factor[i] >= 1.0) continue;
    const Layout::Var& var = layout.vars()[i];
    const int m = var.slider ? 1 : 2;
    d->segment(var.offset, m) *= factor[i];
    cured += m;
  }
  return cured;
}

// Seconds since construction or the previous Lap().
class Stopwatch {
 public:
  double Lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Accumulated over inner runs (one per outer iteration).
struct InnerStats {
  int iterations = 0;
  int evaluations = 0;
  ComeshPhaseSeconds phases;
  std::string stop_reason;
  ComeshEnergies energies;
  double objective = 0.0;
};

// The outline guard's reference and bound per shape (ComeshOptions::outline_tolerance).
struct OutlineBounds {
  std::vector<const ShapeOutline*> reference;
  std::vector<double> tolerance;
};

// The inner loop on a fixed topology: optimizes mesh->shapes in place. `iteration_base` numbers
// iterations globally for callbacks. With `outlines` and `bounds` (may be null), every outline
// slider's chords stay within the bounds (OutlineGuard).
absl::Status InnerLoop(Multimesh* mesh, const ComeshOptions& options, int threads,
                       const std::vector<ShapeOutline>* outlines, const OutlineBounds* bounds,
                       const CancelToken* cancel, const ProgressFn& progress, int iteration_base,
                       InnerStats* stats, SharedFactors* factors) {
  Stopwatch clock;
  auto cancelled_at = [&](int iter) {
    return absl::CancelledError(
        absl::StrCat("comesh optimization cancelled at iteration ", iteration_base + iter));
  };
  // The set-up's steps each poll the token.
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh->triangles, mesh->shapes, options.map_weight, threads,
                              /*area_invariant=*/outlines != nullptr);
  if (!objective.ok()) return objective.status();
  if (Cancelled(cancel)) return cancelled_at(0);
  Layout layout(*mesh, options.slide_boundary, outlines, cancel);
  if (layout.cancelled() || Cancelled(cancel)) return cancelled_at(0);
  std::vector<Points>& shapes = mesh->shapes;
  std::vector<Points> grad_shapes;
  ComeshEnergies energies;
  double f = objective->Evaluate(shapes, &grad_shapes, &energies, cancel);
  if (Cancelled(cancel)) return cancelled_at(0);  // f is NaN then
  ++stats->evaluations;
  stats->energies = energies;
  stats->objective = f;
  if (layout.size() == 0) {
    stats->stop_reason = "no_free";
    return absl::OkStatus();
  }
  if (Cancelled(cancel)) return cancelled_at(0);
  // H0: the shape-block Hessian (Newton-type) or the Laplacian model (BCQN).
  std::optional<HessianPreconditioner> hessian;
  std::optional<InitialHessian> laplacian;
  if (options.hessian_preconditioner && mesh->num_shapes() <= options.hessian_max_shapes) {
    absl::StatusOr<HessianPreconditioner> h = HessianPreconditioner::Create(
        mesh->triangles, layout, *objective, shapes, options.background_analysis_unknowns,
        options.float_substitutions, options.mips_damping, cancel, factors);
    if (absl::IsCancelled(h.status())) return cancelled_at(0);
    if (!h.ok()) return h.status();
    hessian.emplace(*std::move(h));
  } else {
    std::vector<double> areas;
    for (int s = 0; s < mesh->num_shapes(); ++s) areas.push_back(objective->rest_area(s));
    absl::StatusOr<InitialHessian> h = InitialHessian::Create(
        mesh->triangles, layout, std::move(areas), options.laplacian_preconditioner, cancel);
    if (absl::IsCancelled(h.status())) return cancelled_at(0);
    if (!h.ok()) return h.status();
    laplacian.emplace(*std::move(h));
  }
  auto apply_inverse = [&](const VectorXd& v) {
    return hessian ? hessian->ApplyInverse(v, cancel) : laplacian->ApplyInverse(v, cancel);
  };
  auto apply = [&](const VectorXd& v) {
    return hessian ? hessian->Apply(v, cancel) : laplacian->Apply(v);
  };
  std::optional<VertexRelaxer> relaxer;
  if (options.relax_fraction > 0.0) relaxer.emplace(*objective);
  // guard_slot[i]: var i's slot in the guard, or -1.
  std::optional<OutlineGuard> guard;
  std::vector<int> guard_slot(layout.vars().size(), -1);
  if (outlines != nullptr && bounds != nullptr) {
    for (size_t i = 0; i < layout.vars().size(); ++i) {
      const Layout::Var& var = layout.vars()[i];
      if (var.outline < 0) continue;
      if (!guard) guard.emplace(bounds->reference, bounds->tolerance);
      guard_slot[i] = guard->Add(var.shape, var.vertex, var.prev, var.next, shapes[var.shape]);
    }
  }
  stats->phases.hessian += clock.Lap();

  VectorXd z = layout.Gather(shapes);
  VectorXd g = layout.GatherGradient(grad_shapes);
  const double g0 = g.norm();
  struct Pair {
    VectorXd s, y;
    double rho;
  };
  std::deque<Pair> pairs;
  Pair spare{};  // storage for the next pair (see below)
  double beta = 1.0;
  std::vector<double> history = {f};  // objective per iteration, for the stopping window
  std::vector<Points> trial = shapes;
  std::vector<Points> trial_grad;
  std::vector<Points> disp;  // the direction as per-vertex displacements (step bound, curing)
  ComeshEnergies trial_energies;

  for (int iter = 0;; ++iter) {
    if (Cancelled(cancel)) return cancelled_at(iter);
    if (g.norm() <= options.gradient_tolerance * g0) {
      stats->stop_reason = "gradient";
      return absl::OkStatus();
    }
    if (iter >= options.max_iterations) {
      stats->stop_reason = "max_iterations";
      return absl::OkStatus();
    }

    if (hessian && options.hessian_refresh > 0 && iter > 0 && iter % options.hessian_refresh == 0) {
      if (absl::Status st = hessian->Update(shapes, cancel); !st.ok()) {
        return absl::IsCancelled(st) ? cancelled_at(iter) : st;
      }
      stats->phases.hessian += clock.Lap();
    }
    // L-BFGS two-loop recursion with H0 = B0^{-1} / beta.
    // Empty if `cancel` was set: polled before each pair's vector operations too (the whole
    // recursion, solves aside, took ~0.1 s at 311k vertices between two polls).
    auto direction = [&]() {
      VectorXd q = g;
      std::vector<double> alpha(pairs.size());
      for (int i = static_cast<int>(pairs.size()) - 1; i >= 0; --i) {
        if (Cancelled(cancel)) return VectorXd();
        alpha[i] = pairs[i].rho * pairs[i].s.dot(q);
        q -= alpha[i] * pairs[i].y;
      }
      VectorXd r = apply_inverse(q);
      if (r.size() == 0) return r;  // cancelled
      r /= beta;
      for (size_t i = 0; i < pairs.size(); ++i) {
        if (Cancelled(cancel)) return VectorXd();
        const double b = pairs[i].rho * pairs[i].y.dot(r);
        r += (alpha[i] - b) * pairs[i].s;
      }
      if (Cancelled(cancel)) return VectorXd();
      return VectorXd(-r);
    };
    // Besides the top of the loop and the line search's trials, the token is polled inside the
    // direction's solves and after each phase below: at 165k vertices the direction, curing,
    // step bound and first trial took up to ~150 ms between two polls.
    VectorXd d = direction();
    if (d.size() == 0) return cancelled_at(iter);
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // lost descent (non-convexity): restart from the preconditioned gradient
      pairs.clear();
      d = direction();
      if (d.size() == 0) return cancelled_at(iter);
      slope = g.dot(d);
      if (!(slope < 0.0)) {
        d = -g;
        slope = -g.squaredNorm();
      }
    }
    stats->phases.direction += clock.Lap();
    if (Cancelled(cancel)) return cancelled_at(iter);
    // disp: d as per-vertex displacements; CureDirection leaves those of the uncured d there.
    bool disp_is_d = false;
    if (options.cure) {
      VectorXd cured = d;
      disp_is_d = true;
      const int scaled = CureDirection(mesh->triangles, shapes, layout, options.cure_keep,
                                       objective->threads(), cancel, &disp, &cured);
      if (scaled < 0) return cancelled_at(iter);
      if (scaled > 0) {
        const double cured_slope = g.dot(cured);
        if (cured_slope < 0.0) {
          d = std::move(cured);
          slope = cured_slope;
          disp_is_d = false;
        }
      }
    }

    if (Cancelled(cancel)) return cancelled_at(iter);
    // Inversion-free backtracking line search.
    if (!disp_is_d) layout.Displacements(d, &disp);
    if (Cancelled(cancel)) return cancelled_at(iter);
    double max_step = MaxNonInvertingStep(mesh->triangles, shapes, disp, objective->threads());
    double step = std::min(1.0, options.max_step_fraction * max_step);
    if (guard) {
      // An outline slider whose own move (its neighbours where they are) would take a chord
      // beyond the bound stays put for this iteration, so the others still move; the line search
      // below holds the chords between two moving sliders.
      bool held = false;
      for (size_t i = 0; i < guard_slot.size(); ++i) {
        const Layout::Var& var = layout.vars()[i];
        if (guard_slot[i] < 0 || d[var.offset] == 0.0) continue;
        const Point p = layout.OutlinePoint(var, z[var.offset] + step * d[var.offset]);
        if (!guard->HoldsAt(guard_slot[i], p, shapes[var.shape])) {
          d[var.offset] = 0.0;
          held = true;
        }
      }
      if (held) {
        slope = g.dot(d);
        if (!(slope < 0.0)) {  // what is left does not descend: the free part of -g
          const VectorXd kept = d;
          d = -g;
          for (size_t i = 0; i < guard_slot.size(); ++i) {
            const int offset = layout.vars()[i].offset;
            if (guard_slot[i] >= 0 && kept[offset] == 0.0) d[offset] = 0.0;
          }
          slope = g.dot(d);
          if (!(slope < 0.0)) {
            stats->stop_reason = "outline";
            return absl::OkStatus();
          }
        }
        layout.Displacements(d, &disp);
        max_step = MaxNonInvertingStep(mesh->triangles, shapes, disp, objective->threads());
        step = std::min(1.0, options.max_step_fraction * max_step);
      }
    }
    stats->phases.step_bound += clock.Lap();
    bool accepted = false;
    double f_new = f;
    VectorXd z_new;
    for (int b = 0; b <= options.max_backtracks; ++b) {
      // Every trial is an energy evaluation (15 ms at 73k vertices): poll before each.
      if (Cancelled(cancel)) return cancelled_at(iter);
      z_new = z + step * d;
      layout.Scatter(z_new, &trial);
      if (Cancelled(cancel)) return cancelled_at(iter);
      if (guard && !guard->Holds(trial)) {
        step *= 0.5;  // a chord strays beyond the bound: shorter, like a non-finite trial
        continue;
      }
      f_new = objective->Evaluate(trial, &trial_grad, &trial_energies, cancel);
      ++stats->evaluations;
      // And after it (f_new is NaN if it was cancelled inside; ~0.1 s at 311k vertices): with
      // the curvature pair's update below, an accepted trial was the longest stretch without a
      // poll at 311k vertices (avg 188 ms, max 346 ms: ninth session).
      if (Cancelled(cancel)) return cancelled_at(iter);
      if (std::isfinite(f_new) && f_new <= f + options.armijo * step * slope) {
        accepted = true;
        break;
      }
      // Next trial: the minimizer of the quadratic through f, slope and f_new, kept within
      // [0.1, 0.5] of the failed step (plain halving when f_new is not finite).
      double next = 0.5 * step;
      if (std::isfinite(f_new)) {
        const double curvature = f_new - f - slope * step;
        if (curvature > 0.0) next = -slope * step * step / (2.0 * curvature);
        next = std::clamp(next, 0.1 * step, 0.5 * step);
      }
      step = next;
    }
    stats->phases.line_search += clock.Lap();
    if (!accepted) {
      stats->stop_reason = "line_search";
      return absl::OkStatus();
    }

    layout.Track(z_new);
    VectorXd g_new = layout.GatherGradient(trial_grad);
    if (Cancelled(cancel)) return cancelled_at(iter);
    // The pair's vectors reuse the storage of the pair last dropped from the history (or not
    // kept): two fresh vectors every iteration cost ~30 ms of page faults at 311k vertices.
    Pair p = std::move(spare);
    p.s = z_new - z;
    p.y = g_new - g;
    p.rho = 0.0;
    if (Cancelled(cancel)) return cancelled_at(iter);
    const double sy = p.s.dot(p.y);
    if (Cancelled(cancel)) return cancelled_at(iter);
    if (sy > 1e-12 * p.s.norm() * p.y.norm() && options.history > 0) {
      const VectorXd b0s = apply(p.s);  // empty if cancelled
      if (b0s.size() != p.s.size() || Cancelled(cancel)) return cancelled_at(iter);
      if (options.scaling_by_inverse) {
        const VectorXd hy = apply_inverse(p.y);
        if (hy.size() == 0) return cancelled_at(iter);
        beta = p.y.dot(hy) / sy;
      } else {
        beta = sy / p.s.dot(b0s);
      }
      if (options.blend > 0.0) {
        // Blend the measured gradient difference with the (scaled) Laplacian prediction; both
        // have curvature s^T y along s, so the pair stays positive. The weight decays with the
        // relative gradient norm: Laplacian (Sobolev) far from the minimum, L-BFGS near it.
        const double theta = std::min(1.0, options.blend * g_new.norm() / g0);
        p.y = (1.0 - theta) * p.y + theta * beta * b0s;
      }
      p.rho = 1.0 / sy;
      pairs.push_back(std::move(p));
      if (static_cast<int>(pairs.size()) > options.history) {
        spare = std::move(pairs.front());
        pairs.pop_front();
      }
    } else {
      spare = std::move(p);
    }
    stats->phases.direction += clock.Lap();
    if (relaxer && step < 1.0 && g_new.squaredNorm() > 0.0) {
      // The vertices holding at least relax_fraction of |g|^2 (and relax_over_mean times an
      // even share), largest first, at most relax_max_vertices of them.
      const double total = g_new.squaredNorm();
      const std::vector<Layout::Var>& vars = layout.vars();
      const double threshold =
          total * std::max(options.relax_fraction, options.relax_over_mean / vars.size());
      std::vector<std::pair<double, int>> picked;
      for (int i = 0; i < static_cast<int>(vars.size()); ++i) {
        // An outline slider's move changes the areas the (area-invariant) normalizers follow,
        // which the relaxer holds fixed: it moves with the global steps only.
        if (vars[i].outline >= 0) continue;
        const double part = vars[i].slider ? g_new[vars[i].offset] * g_new[vars[i].offset]
                                           : g_new.segment<2>(vars[i].offset).squaredNorm();
        if (part >= threshold) picked.emplace_back(part, i);
      }
      std::sort(picked.begin(), picked.end(), [](const auto& x, const auto& y) {
        return x.first != y.first ? x.first > y.first : x.second < y.second;
      });
      picked.resize(std::min<size_t>(picked.size(), std::max(0, options.relax_max_vertices)));
      std::vector<RelaxTarget> targets;
      for (const auto& [part, i] : picked) {
        targets.push_back({vars[i].shape, vars[i].vertex, vars[i].slider, vars[i].direction});
      }
      if (relaxer->Relax(targets, options.relax_steps, &trial, &trial_grad, &trial_energies) > 0) {
        if (Cancelled(cancel)) return cancelled_at(iter);
        // Only the picked vertices moved (a full Gather would re-round every slider's unknown).
        for (const auto& [part, i] : picked) {
          const Layout::Var& var = vars[i];
          const Point& x = trial[var.shape][var.vertex];
          if (var.slider) {
            z_new[var.offset] = (x - var.base).dot(var.direction);
          } else {
            z_new.segment<2>(var.offset) = x;
          }
        }
        if (objective->area_invariant()) {
          // The moves kept every area, but the gradient's area term on the boundary follows
          // every shape's energy: evaluate afresh.
          f_new = objective->Evaluate(trial, &trial_grad, &trial_energies, cancel);
          ++stats->evaluations;
          if (Cancelled(cancel)) return cancelled_at(iter);
        }
        g_new = layout.GatherGradient(trial_grad);
        f_new = trial_energies.objective;
      }
      stats->phases.relax += clock.Lap();
    }
    history.push_back(f_new);
    const int window = std::max(1, options.decrease_window);
    // A step capped by the inversion bound is "blocked": slow progress there may be one blocking
    // triangle rather than convergence, so it only counts as a stall over twice the window.
    const bool blocked = options.max_step_fraction * max_step < 1.0;
    auto small_decrease = [&](int over) {
      return static_cast<int>(history.size()) > over &&
             history[history.size() - 1 - over] - f_new <=
                 options.relative_decrease_tolerance * std::max(std::abs(f_new), 1e-300);
    };
    const bool stalled = (!blocked && small_decrease(window)) || small_decrease(2 * window);
    z = z_new;
    g = g_new;
    f = f_new;
    std::swap(shapes, trial);
    ++stats->iterations;
    stats->objective = f;
    stats->energies = trial_energies;
    const int global_iteration = iteration_base + iter + 1;
    if (options.on_iterate) options.on_iterate(global_iteration, shapes);
    if (progress) {
      progress("comesh",
               options.max_iterations > 0
                   ? std::min(1.0, static_cast<double>(iter + 1) / options.max_iterations)
                   : 1.0,
               absl::StrFormat("iteration %d: objective %.6g, map %.5f, mesh %.5f, vertices %d, "
                               "step %.3g of %.3g",
                               global_iteration, f, trial_energies.map, trial_energies.mesh,
                               mesh->num_vertices(), step, max_step));
    }
    if (stalled) {
      stats->stop_reason = "decrease";
      return absl::OkStatus();
    }
  }
}

}  // namespace

absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report, const ComeshCheckpoint* resume) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status st = ValidateInput(mesh); !st.ok()) return st;
  if (resume != nullptr) {
    if (absl::Status st = ValidateInput(resume->mesh); !st.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("comesh checkpoint: ", st.message()));
    }
    if (resume->outer < 0 || resume->inner < 0) {
      return absl::InvalidArgumentError("comesh checkpoint: negative pass or iteration count");
    }
    if (resume->stage != 0 && resume->stage != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("comesh checkpoint: stage ", resume->stage, " (0 or 1)"));
    }
  }
  if (options.max_iterations < 0 || options.history < 0 || !(options.max_step_fraction > 0.0) ||
      !(options.max_step_fraction < 1.0) || options.max_outer < 0 ||
      !(options.cure_keep >= 0.0 && options.cure_keep < 1.0) || !(options.blend >= 0.0) ||
      !(options.mips_damping >= 0.0 && std::isfinite(options.mips_damping)) ||
      std::isnan(options.relax_fraction) || !(options.relax_over_mean >= 0.0) ||
      options.relax_max_vertices < 0 || options.relax_steps < 0 ||
      !(options.outline_corner_degrees >= 0.0 && options.outline_corner_degrees <= 180.0) ||
      !(options.outline_tolerance >= 0.0 && std::isfinite(options.outline_tolerance))) {
    return absl::InvalidArgumentError(
        "comesh options: max_iterations, history, max_outer, relax_max_vertices and relax_steps "
        "must be >= 0, max_step_fraction in (0, 1), cure_keep in [0, 1), blend and "
        "relax_over_mean >= 0, mips_damping finite and >= 0, relax_fraction a number, "
        "outline_corner_degrees in [0, 180], outline_tolerance finite and >= 0");
  }
  if (!options.outline_reference.empty() &&
      static_cast<int>(options.outline_reference.size()) != mesh.num_shapes()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "comesh options: outline_reference has ", options.outline_reference.size(),
        " drawings' outlines for ", mesh.num_shapes(), " shapes"));
  }
  const int threads = ResolveThreads(options.threads);
  const absl::Status not_started = absl::CancelledError("comesh optimization cancelled at start");
  if (Cancelled(cancel)) return not_started;
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh.triangles, mesh.shapes, options.map_weight, threads);
  if (!objective.ok()) return objective.status();
  if (Cancelled(cancel)) return not_started;

  ComeshReport rep;
  rep.vertices_before = rep.vertices_after = mesh.num_vertices();
  ComeshEnergies energies;
  rep.objective_before = objective->Evaluate(mesh.shapes, nullptr, &energies);
  rep.map_energy_before = energies.map;
  rep.mesh_energy_before = energies.mesh;

  Multimesh current = resume != nullptr ? resume->mesh : mesh;
  current.art.clear();  // embedded in the input's triangles; the caller re-embeds (multimesh.h)
  InnerStats stats;
  double pass_start_objective = rep.objective_before;
  int first_outer = 0;
  if (resume != nullptr) {  // everything the loop below reads across passes (see the header)
    first_outer = resume->outer;
    stats.iterations = resume->inner;
    stats.evaluations = resume->energy_evaluations;
    pass_start_objective = resume->pass_start_objective;
    rep.outer = resume->outer;
    rep.flips = resume->flips;
    rep.collapses = resume->collapses;
    rep.splits = resume->splits;
    rep.objective_trace = resume->objective_trace;
  }
  // The reference outlines are the input's (also when resuming), so every inner run slides the
  // boundary along the drawn outlines, not along the chords of earlier runs.
  std::vector<ShapeOutline> outlines;
  if (options.slide_boundary && options.slide_outline) {
    std::vector<char> fixed(mesh.num_vertices(), 0);
    for (const auto& c : mesh.cohesive_edges) {
      for (int v : c) fixed[v] = 1;
    }
    for (int v : mesh.pinned) fixed[v] = 1;
    bool curved = false;
    for (int s = 0; s < mesh.num_shapes(); ++s) {
      outlines.emplace_back(mesh, s, options.outline_corner_degrees, fixed);
      curved |= outlines.back().curved();
    }
    // Polygons only (no soft corner anywhere): the straight sliders do all outline sliding would,
    // and the run is the one without it, bit for bit.
    if (!curved) outlines.clear();
  }
  // The outline guard (OutlineGuard): against each drawing's outline when given, else the input's.
  std::vector<ShapeOutline> drawn;
  std::optional<OutlineBounds> bounds;
  if (!outlines.empty() && options.outline_tolerance > 0.0) {
    bounds.emplace();
    for (const std::vector<Points>& loops : options.outline_reference) {
      drawn.emplace_back(loops, options.outline_corner_degrees);
    }
    for (int s = 0; s < mesh.num_shapes(); ++s) {
      const ShapeOutline* reference = drawn.empty() ? &outlines[s] : &drawn[s];
      bounds->reference.push_back(reference);
      bounds->tolerance.push_back(options.outline_tolerance * reference->diagonal());
    }
  }
  // What every inner run takes (its max_iterations aside); the drawings' outlines are in `bounds`,
  // so the runs' copies leave them out.
  ComeshOptions per_run = options;
  per_run.outline_reference.clear();
  SharedFactors factors;
  // Stage 0 is the run without outline sliding, to convergence; stage 1 (curved outlines with
  // slide_outline only) continues from its result with the boundary sliding along the outlines:
  // short runs and topology passes again, then a final run. Every step of stage 1 lowers the
  // objective or keeps it, so outline sliding never ends above the run without it (a run that
  // slid from the start took other topology passes and ended up to 0.17% higher on some
  // examples: docs/benchmarks.md, twentieth session).
  const int last_stage = outlines.empty() ? 0 : 1;
  int stage = resume != nullptr ? std::min(resume->stage, last_stage) : 0;
  for (; stage <= last_stage; ++stage) {
    const std::vector<ShapeOutline>* stage_outlines = stage == 1 ? &outlines : nullptr;
    auto inner = [&](int max_iterations) {
      ComeshOptions run = per_run;
      run.max_iterations = max_iterations;
      absl::Status st = InnerLoop(&current, run, threads, stage_outlines,
                                  bounds ? &*bounds : nullptr, cancel, progress,
                                  stats.iterations, &stats, &factors);
      if (st.ok()) rep.objective_trace.push_back(stats.objective);
      return st;
    };
    if (stage == 1 && !(resume != nullptr && resume->stage == 1)) {
      // The first short run is judged against stage 0's result, like a pass's run against the
      // pass before.
      first_outer = rep.outer;
      pass_start_objective = stats.objective;
      if (progress) progress("comesh", 1.0, "outline sliding");
    }
    // Topology passes, each after a short inner run (positions only need to be roughly relaxed
    // for the operations' decisions), then one inner run to convergence on the final topology.
    for (int outer = first_outer; outer < options.max_outer; ++outer) {
      if (absl::Status st = inner(std::min(options.max_iterations, options.outer_inner_iterations));
          !st.ok()) {
        return st;
      }
      if ((outer > 0 || stage > 0) && pass_start_objective - stats.objective <=
                                          options.outer_tolerance * std::abs(stats.objective)) {
        break;
      }
      pass_start_objective = stats.objective;
      if (Cancelled(cancel)) {
        return absl::CancelledError(absl::StrCat("comesh optimization cancelled at outer ", outer));
      }
      TopologyReport topo;
      Stopwatch topology_clock;
      absl::StatusOr<Multimesh> improved = ImproveTopology(
          current, options.map_weight, options.topology, &topo, cancel, stage_outlines);
      stats.phases.topology += topology_clock.Lap();
      if (absl::IsCancelled(improved.status())) {
        return absl::CancelledError(absl::StrCat("comesh optimization cancelled at outer ", outer));
      }
      if (!improved.ok()) return improved.status();
      if (topo.flips + topo.collapses + topo.splits == 0) break;
      rep.flips += topo.flips;
      rep.collapses += topo.collapses;
      rep.splits += topo.splits;
      ++rep.outer;
      current = *std::move(improved);
      rep.objective_trace.push_back(topo.objective_after);
      // The pass itself (not the short run after it) gained little: the topology has settled,
      // and further passes would only interleave restarts with the inner run (on large meshes
      // the short runs keep gaining, so the pass + run test alone keeps the loop going far too
      // long).
      const bool settled = topo.objective_before - topo.objective_after <=
                           options.outer_tolerance * std::abs(topo.objective_after);
      if (progress) {
        progress("comesh", 1.0,
                 absl::StrFormat("outer %d: %d flips, %d collapses (%d corner swaps), %d splits, "
                                 "vertices %d",
                                 rep.outer, topo.flips, topo.collapses, topo.corner_swaps,
                                 topo.splits, current.num_vertices()));
      }
      if (options.on_checkpoint) {
        options.on_checkpoint(ComeshCheckpoint{.mesh = current,
                                               .outer = rep.outer,
                                               .inner = stats.iterations,
                                               .energy_evaluations = stats.evaluations,
                                               .flips = rep.flips,
                                               .collapses = rep.collapses,
                                               .splits = rep.splits,
                                               .pass_start_objective = pass_start_objective,
                                               .objective_trace = rep.objective_trace,
                                               .stage = stage});
      }
      if (settled) break;
    }
    if (absl::Status st = inner(options.max_iterations); !st.ok()) return st;
  }
  // The last step: sliver removal. It may raise the objective a little (it judges by quality),
  // so the report's energies are evaluated afresh after it; the trace ends before it.
  // Skipped where no triangle is below min_quality (with 4 slivers the step took ~0.1 s at 165k
  // vertices; its topology editor is set up over every triangle).
  rep.worst_quality = WorstQuality(current);
  if (options.max_outer > 0 && options.min_quality > 0.0 &&
      rep.worst_quality < options.min_quality) {
    SliverReport slivers;
    Stopwatch topology_clock;
    absl::StatusOr<Multimesh> cleaned =
        RemoveSlivers(current, options.map_weight, options.min_quality, &slivers, cancel,
                      outlines.empty() ? nullptr : &outlines, &mesh);
    if (absl::IsCancelled(cleaned.status())) {
      return absl::CancelledError("comesh optimization cancelled at sliver removal");
    }
    if (!cleaned.ok()) return cleaned.status();
    rep.slivers = slivers.slivers_before;
    rep.sliver_operations = slivers.operations;
    if (slivers.operations > 0) {
      current = *std::move(cleaned);
      absl::StatusOr<ComeshObjective> final_objective =
          ComeshObjective::Create(current.triangles, current.shapes, options.map_weight, threads);
      if (!final_objective.ok()) return final_objective.status();
      stats.objective = final_objective->Evaluate(current.shapes, nullptr, &stats.energies);
      ++stats.evaluations;
    }
    rep.worst_quality = slivers.worst_quality_after;
    stats.phases.topology += topology_clock.Lap();
  }
  rep.inner = stats.iterations;
  rep.energy_evaluations = stats.evaluations + 1;
  rep.phase_seconds = stats.phases;
  rep.stop_reason = stats.stop_reason;
  rep.objective_after = stats.objective;
  rep.map_energy = stats.energies.map;
  rep.mesh_energy = stats.energies.mesh;
  rep.vertices_after = current.num_vertices();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report != nullptr) *report = rep;
  return current;
}

}  // namespace inbetween::solver
