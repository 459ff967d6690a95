// Injective map of shape 1's mesh into another boundary.
//
// Convex target: Tutte embedding with mean-value weights (Floater 2003), injective for a convex
// boundary once boundary chords are split (see split_boundary_chords.h).
// Otherwise, in the spirit of LIM (Schueller et al. 2013): start from the identity (shape 1's
// own, valid geometry) or, when it folds nothing, its least-squares affine fit to the target
// boundary, pull the boundary vertices towards their targets with a quadratic
// penalty whose weight grows stage by stage, while minimising the symmetric Dirichlet energy
// relative to shape 1's triangles, SD(J) = |J|^2 + |J^-1|^2, which is infinite at a fold. Each
// iteration solves the SLIM proxy (Rabinovich et al. 2017: reweighted local-global system) and
// line-searches towards it, never beyond the first step at which some det(J) reaches zero
// (smallest positive root of a quadratic per triangle). At the end the boundary is placed
// exactly, checked to invert nothing, and the interior polished with the boundary fixed.
//
// The sparse systems are solved by SuiteSparse (CHOLMOD for the SPD proxy, KLU for the
// non-symmetric Tutte system), not by Eigen's sparse solvers: those are not exception-safe when
// an allocation fails (a double free, docs/hardening.md), while these report it, and the map
// answers RESOURCE_EXHAUSTED naming the system.
#include "solver/mesh/map_to_boundary.h"

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <new>

#include "absl/strings/str_cat.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/core/sparse_lu.h"
#include "solver/geometry/affine_fit.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct TriangleFrame {
  double area = 0.0;                 // source area (weight)
  Eigen::Matrix<double, 3, 2> grad;  // J(r, c) = sum_j x_j(r) * grad(j, c)
  Eigen::Matrix3d gram;              // grad grad^T
};

// The SLIM proxy's weights at Jacobian j (Rabinovich et al. 2017, symmetric Dirichlet): with
// j = U diag(s) V^T (U and V rotations, the smaller singular value negative when det(j) < 0),
// *m = W^T W = U diag(w(s)^2) U^T, w(s)^2 = (s + 1)(s^2 + 1) / s^3 with s clamped to 1e-8, and
// *rotation = U V^T, the rotation nearest j. Closed form, no trigonometry: for j = [a b; c d],
// U V^T turns by the angle of (a + d, c - b), U by half the sum of that angle and the angle of
// (a - d, c + b) (0 for a zero vector), and the singular values are |(a + d, c - b)| / 2 +-
// |(a - d, c + b)| / 2; U diag(w0, w1) U^T = (w0 + w1) / 2 I + (w0 - w1) / 2 [cos 2u, sin 2u;
// sin 2u, -cos 2u] for U's turn u.
void ProxyWeights(const Eigen::Matrix2d& j, Eigen::Matrix2d* m, Eigen::Matrix2d* rotation) {
  const double e = 0.5 * (j(0, 0) + j(1, 1)), f = 0.5 * (j(0, 0) - j(1, 1));
  const double g = 0.5 * (j(1, 0) + j(0, 1)), h = 0.5 * (j(1, 0) - j(0, 1));
  const double q = std::sqrt(e * e + h * h), r = std::sqrt(f * f + g * g);
  // Cosine and sine of the two angles.
  const double ca = q > 0 ? e / q : 1.0, sa = q > 0 ? h / q : 0.0;
  const double cb = r > 0 ? f / r : 1.0, sb = r > 0 ? g / r : 0.0;
  const double s[2] = {q + r, q - r};
  double w2[2];
  for (int i = 0; i < 2; ++i) {
    const double si = std::max(s[i], 1e-8);
    w2[i] = (si + 1) * (si * si + 1) / (si * si * si);
  }
  const double mean = 0.5 * (w2[0] + w2[1]), half = 0.5 * (w2[0] - w2[1]);
  const double cos2u = ca * cb - sa * sb, sin2u = sa * cb + ca * sb;
  (*m)(0, 0) = mean + half * cos2u;
  (*m)(1, 1) = mean - half * cos2u;
  (*m)(0, 1) = (*m)(1, 0) = half * sin2u;
  *rotation << ca, -sa, sa, ca;
}

// Which vertices move in a solve and where the fixed ones sit.
struct Constraints {
  std::vector<int> free_index;  // -1 = fixed at `fixed_at`
  int free_count = 0;
  Points fixed_at;       // positions used for fixed vertices (size n)
  double penalty = 0.0;  // weight of |x_b - y_b|^2 for free boundary vertices
};

class Mapper {
 public:
  Mapper(const Points& source, const std::vector<Triangle>& triangles,
         const std::vector<int>& boundary, const Points& target)
      : triangles_(triangles), boundary_(boundary), target_(target) {
    frames_.reserve(triangles.size());
    for (const Triangle& t : triangles) {
      Eigen::Matrix2d edges;
      edges.col(0) = source[t[1]] - source[t[0]];
      edges.col(1) = source[t[2]] - source[t[0]];
      const Eigen::Matrix2d inv = edges.inverse();
      TriangleFrame f;
      f.area = 0.5 * edges.determinant();
      f.grad.row(1) = inv.row(0);
      f.grad.row(2) = inv.row(1);
      f.grad.row(0) = -(inv.row(0) + inv.row(1));
      f.gram = f.grad * f.grad.transpose();
      total_area_ += f.area;
      frames_.push_back(f);
    }
  }

  double total_area() const { return total_area_; }

  Eigen::Matrix2d Jacobian(size_t t, const Points& x) const {
    Eigen::Matrix2d j = Eigen::Matrix2d::Zero();
    for (int k = 0; k < 3; ++k) j += x[triangles_[t][k]] * frames_[t].grad.row(k);
    return j;
  }

  // Sum of area * SD(J); infinite if any triangle is folded or degenerate.
  double Distortion(const Points& x) const {
    double e = 0.0;
    for (size_t t = 0; t < triangles_.size(); ++t) {
      const Eigen::Matrix2d j = Jacobian(t, x);
      const double det = j.determinant();
      if (!(det > 0)) return kInf;
      const double f2 = j.squaredNorm();
      e += frames_[t].area * (f2 + f2 / (det * det));
    }
    return e;
  }

  double Energy(const Points& x, const Constraints& c) const {
    double e = Distortion(x);
    if (c.penalty > 0) {
      for (size_t k = 0; k < boundary_.size(); ++k) {
        e += c.penalty * (x[boundary_[k]] - target_[k]).squaredNorm();
      }
    }
    return e;
  }

  // Minimiser of the SLIM proxy sum_t area |W_t (J_t - R_t)|^2 (+ boundary penalty). OK, or
  // FAILED_PRECONDITION when the system is numerically not positive definite (the penalty
  // outgrew the factorization), RESOURCE_EXHAUSTED when memory ran out.
  // Per triangle the proxy is a |W (J - R)|^2 with J = X G (X: the corners' positions as 2 x 3
  // columns, G: the frame's 3 x 2 gradient), so its 6 x 6 block over (dimension, corner) is the
  // Kronecker product a (W^T W) (x) (G G^T), and its linear term a W^T W R G^T; G G^T is fixed
  // per triangle (TriangleFrame::gram). The matrix's upper triangle is accumulated straight into
  // its compressed values through slots computed once per constraint set (Pattern), so an
  // iteration allocates nothing of the matrix's size.
  absl::Status ProxySolve(const Points& x, const Constraints& c, Points* out) const {
    const int nf = c.free_count;
    Pattern* pattern = PatternFor(c);
    Eigen::SparseMatrix<double>& h = pattern->matrix;
    double* values = h.valuePtr();
    std::fill(values, values + h.nonZeros(), 0.0);
    Eigen::MatrixXd& rhs = pattern->rhs;
    rhs.setZero();
    for (size_t t = 0; t < triangles_.size(); ++t) {
      const Eigen::Matrix2d j = Jacobian(t, x);
      Eigen::Matrix2d m, rotation;
      ProxyWeights(j, &m, &rotation);
      const TriangleFrame& frame = frames_[t];
      m *= frame.area;
      // a W^T W R G^T: the linear term, 2 x 3 over (dimension, corner).
      const Eigen::Matrix<double, 2, 3> linear = m * rotation * frame.grad.transpose();
      const int* slot = pattern->slots.data() + kPairs * t;
      for (int p = 0; p < 6; ++p) {
        const int vp = triangles_[t][p % 3];
        if (c.free_index[vp] < 0) continue;
        double value = linear(p / 3, p % 3);
        for (int q = 0; q < 6; ++q) {
          const double entry = m(p / 3, q / 3) * frame.gram(p % 3, q % 3);
          const int vq = triangles_[t][q % 3];
          if (c.free_index[vq] < 0) {
            value -= entry * c.fixed_at[vq](q / 3);
          } else if (q >= p) {
            values[slot[Pair(p, q)]] += entry;
          }
        }
        rhs((p / 3) * nf + c.free_index[vp], 0) += value;
      }
    }
    if (c.penalty > 0) {
      for (size_t k = 0; k < boundary_.size(); ++k) {
        const int fi = c.free_index[boundary_[k]];
        if (fi < 0) continue;
        for (int sdim = 0; sdim < 2; ++sdim) {
          values[pattern->diagonal[sdim * nf + fi]] += c.penalty;
          rhs(sdim * nf + fi, 0) += c.penalty * target_[k](sdim);
        }
      }
    }
    // The pattern depends only on which vertices are free: analysed once per constraint set (the
    // ordering is most of a small factorization's cost), the numbers refactored each iteration.
    SparseCholesky& solver = pattern->solver;
    if (!pattern->analyzed) {
      if (absl::Status s = solver.Analyze(h); !s.ok()) return SolveError(s, h);
      pattern->analyzed = true;
    }
    if (absl::Status s = solver.Factorize(h); !s.ok()) return SolveError(s, h);
    if (absl::Status s = solver.SolveInPlace(&rhs); !s.ok()) return SolveError(s, h);
    if (!rhs.allFinite()) return absl::FailedPreconditionError("map: the proxy solve diverged");
    *out = x;
    for (size_t v = 0; v < x.size(); ++v) {
      const int fi = c.free_index[v];
      (*out)[v] = fi < 0 ? c.fixed_at[v] : Point(rhs(fi, 0), rhs(nf + fi, 0));
    }
    return absl::OkStatus();
  }

  // Largest alpha such that x + a * d keeps every triangle positive for all a in [0, alpha).
  double MaxStep(const Points& x, const Points& d) const {
    double best = kInf;
    for (const Triangle& t : triangles_) {
      const Point e1 = x[t[1]] - x[t[0]], e2 = x[t[2]] - x[t[0]];
      const Point f1 = d[t[1]] - d[t[0]], f2 = d[t[2]] - d[t[0]];
      const double c0 = Cross(e1, e2), c1 = Cross(e1, f2) + Cross(f1, e2), c2 = Cross(f1, f2);
      double root = kInf;
      if (std::abs(c2) <= 1e-14 * std::abs(c0)) {
        if (c1 < 0) root = -c0 / c1;
      } else {
        const double disc = c1 * c1 - 4 * c2 * c0;
        if (disc >= 0) {
          const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
          for (double r : {q / c2, q != 0 ? c0 / q : kInf}) {
            if (r > 0) root = std::min(root, r);
          }
        }
      }
      best = std::min(best, root);
    }
    return best;
  }

  // One iteration: proxy solve, flip-free backtracking line search on the true energy. Returns
  // the relative energy decrease (0 when no progress), or -1 if the solve failed numerically;
  // RESOURCE_EXHAUSTED when memory ran out.
  absl::StatusOr<double> Iterate(Points* x, const Constraints& c) const {
    Points proxy;
    if (absl::Status s = ProxySolve(*x, c, &proxy); !s.ok()) {
      if (absl::IsResourceExhausted(s)) return s;
      return -1.0;
    }
    Points d(x->size());
    for (size_t v = 0; v < x->size(); ++v) d[v] = proxy[v] - (*x)[v];
    double alpha = std::min(1.0, 0.9 * MaxStep(*x, d));
    const double e0 = Energy(*x, c);
    for (int tries = 0; tries < 40; ++tries, alpha *= 0.5) {
      Points trial(x->size());
      for (size_t v = 0; v < x->size(); ++v) trial[v] = (*x)[v] + alpha * d[v];
      const double e1 = Energy(trial, c);
      if (e1 < e0) {
        *x = std::move(trial);
        return (e0 - e1) / e0;
      }
    }
    return 0.0;
  }

  double MaxBoundaryDistance(const Points& x) const {
    double m = 0.0;
    for (size_t k = 0; k < boundary_.size(); ++k) {
      m = std::max(m, (x[boundary_[k]] - target_[k]).norm());
    }
    return m;
  }

 private:
  // A triangle's 6 x 6 block over (dimension, corner) is symmetric: its 21 entries (p, q), p <= q,
  // are numbered row by row.
  static constexpr int kPairs = 21;
  static constexpr int Pair(int p, int q) { return p * 6 - p * (p - 1) / 2 + (q - p); }

  // The proxy system's upper triangle for one constraint set (which vertices are free): its
  // compressed pattern, where each triangle's entries land in its values (slots: kPairs per
  // triangle, the upper-triangle entry of the two unknowns' pair; unused at a fixed vertex), each
  // unknown's diagonal entry, the right-hand side's storage and the analysed factorization.
  struct Pattern {
    Eigen::SparseMatrix<double> matrix;
    std::vector<int> slots, diagonal;
    Eigen::MatrixXd rhs;
    SparseCholesky solver{SparseCholesky::Method::kSupernodal};
    bool analyzed = false;
  };

  Pattern* PatternFor(const Constraints& c) const {
    std::unique_ptr<Pattern>& cached = patterns_[&c];
    const int size = 2 * c.free_count;
    if (cached != nullptr && cached->matrix.rows() == size) return cached.get();
    cached = std::make_unique<Pattern>();
    Pattern& p = *cached;
    // The unknowns of the triangle's (dimension, corner) pairs, -1 at a fixed vertex.
    auto unknowns = [&](const Triangle& t, int* out) {
      for (int q = 0; q < 6; ++q) {
        const int fi = c.free_index[t[q % 3]];
        out[q] = fi < 0 ? -1 : (q / 3) * c.free_count + fi;
      }
    };
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(triangles_.size() * kPairs + size);
    for (int i = 0; i < size; ++i) entries.emplace_back(i, i, 0.0);
    int u[6];
    for (const Triangle& t : triangles_) {
      unknowns(t, u);
      for (int a = 0; a < 6; ++a) {
        for (int b = a; b < 6; ++b) {
          if (u[a] >= 0 && u[b] >= 0) {
            entries.emplace_back(std::min(u[a], u[b]), std::max(u[a], u[b]), 0.0);
          }
        }
      }
    }
    p.matrix.resize(size, size);
    p.matrix.setFromTriplets(entries.begin(), entries.end());
    p.matrix.makeCompressed();
    auto position = [&](int row, int col) {
      const int* begin = p.matrix.innerIndexPtr() + p.matrix.outerIndexPtr()[col];
      const int* end = p.matrix.innerIndexPtr() + p.matrix.outerIndexPtr()[col + 1];
      return static_cast<int>(std::lower_bound(begin, end, row) - p.matrix.innerIndexPtr());
    };
    p.slots.assign(kPairs * triangles_.size(), -1);
    for (size_t t = 0; t < triangles_.size(); ++t) {
      unknowns(triangles_[t], u);
      for (int a = 0; a < 6; ++a) {
        for (int b = a; b < 6; ++b) {
          if (u[a] >= 0 && u[b] >= 0) {
            p.slots[kPairs * t + Pair(a, b)] = position(std::min(u[a], u[b]), std::max(u[a], u[b]));
          }
        }
      }
    }
    p.diagonal.resize(size);
    for (int i = 0; i < size; ++i) p.diagonal[i] = position(i, i);
    p.rhs.resize(size, 1);
    return cached.get();
  }

  mutable std::map<const Constraints*, std::unique_ptr<Pattern>> patterns_;
  const std::vector<Triangle>& triangles_;
  const std::vector<int>& boundary_;
  const Points& target_;
  std::vector<TriangleFrame> frames_;
  double total_area_ = 0.0;

  // Out of memory names the system; anything else is a numerical failure of the solve.
  static absl::Status SolveError(const absl::Status& s, const Eigen::SparseMatrix<double>& h) {
    if (absl::IsResourceExhausted(s)) {
      return absl::ResourceExhaustedError(
          absl::StrCat("map: out of memory factorizing the ", h.rows(), " x ", h.cols(),
                       " SLIM proxy system (", h.nonZeros(), " nonzeros): ", s.message()));
    }
    return absl::FailedPreconditionError(absl::StrCat("map: linear solve failed: ", s.message()));
  }
};

// Mean-value Tutte embedding with the boundary pinned to `target`. The weights are not symmetric
// (w_ij != w_ji), so the system is solved by LU. OK, FAILED_PRECONDITION when the system is
// singular or the solution not finite, RESOURCE_EXHAUSTED when memory ran out.
absl::Status TutteEmbedding(const Points& source, const std::vector<Triangle>& triangles,
                            const std::vector<int>& boundary, const Points& target, Points* out) {
  const int n = static_cast<int>(source.size());
  std::vector<int> interior(n, -1);
  std::vector<bool> pinned(n, false);
  for (int b : boundary) pinned[b] = true;
  int ni = 0;
  for (int v = 0; v < n; ++v) {
    if (!pinned[v]) interior[v] = ni++;
  }
  *out = source;
  for (size_t k = 0; k < boundary.size(); ++k) (*out)[boundary[k]] = target[k];
  if (ni == 0) return absl::OkStatus();
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(ni, 2);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3], l = t[(k + 2) % 3];
      if (interior[i] < 0) continue;
      const Point a = source[j] - source[i], b = source[l] - source[i];
      const double half_tan = std::tan(0.5 * std::atan2(std::abs(Cross(a, b)), a.dot(b)));
      for (const auto& [other, len] : {std::pair<int, double>{j, a.norm()}, {l, b.norm()}}) {
        const double w = half_tan / len;
        entries.emplace_back(interior[i], interior[i], w);
        if (interior[other] >= 0) {
          entries.emplace_back(interior[i], interior[other], -w);
        } else {
          rhs.row(interior[i]) += w * (*out)[other].transpose();
        }
      }
    }
  }
  Eigen::SparseMatrix<double> m(ni, ni);
  m.setFromTriplets(entries.begin(), entries.end());
  absl::StatusOr<Eigen::MatrixXd> sol = SparseLuSolve(m, rhs);
  if (!sol.ok()) {
    if (absl::IsResourceExhausted(sol.status())) {
      return absl::ResourceExhaustedError(absl::StrCat("map: out of memory factorizing the ", ni,
                                                       " x ", ni,
                                                       " Tutte system: ", sol.status().message()));
    }
    return absl::FailedPreconditionError(
        absl::StrCat("map: Tutte embedding failed: ", sol.status().message()));
  }
  if (!sol->allFinite()) return absl::FailedPreconditionError("map: Tutte embedding not finite");
  for (int v = 0; v < n; ++v) {
    if (interior[v] >= 0) (*out)[v] = sol->row(interior[v]).transpose();
  }
  return absl::OkStatus();
}

// The least-squares affine map of the source boundary onto the target boundary, applied to every
// vertex: when the target is (close to) an affine image of the source, a start that is already
// (close to) done (FitAffine). False when there is no such map (FitAffine) or it folds a triangle.
bool AffineStart(const Points& source, const std::vector<Triangle>& triangles,
                 const std::vector<int>& boundary, const Points& target_boundary, Points* out) {
  Affine map;
  if (!FitAffine(
          static_cast<int>(boundary.size()), [&](int k) { return source[boundary[k]]; },
          [&](int k) { return target_boundary[k]; }, &map)) {
    return false;
  }
  out->resize(source.size());
  for (size_t v = 0; v < source.size(); ++v) (*out)[v] = map(source[v]);
  return CountInverted(triangles, *out) == 0;
}

// The arguments' contract (map_to_boundary.h), checked before any work: sizes, boundary indices,
// a finite target and a source without inverted triangles.
absl::Status CheckMapInputs(const Points& source, const std::vector<Triangle>& triangles,
                            const std::vector<int>& boundary, const Points& target_boundary) {
  const int n = static_cast<int>(source.size());
  if (boundary.size() != target_boundary.size() || boundary.size() < 3) {
    return absl::InvalidArgumentError(absl::StrCat("map: ", boundary.size(),
                                                   " boundary vertices but ",
                                                   target_boundary.size(), " target positions"));
  }
  for (int b : boundary) {
    if (b < 0 || b >= n) return absl::InvalidArgumentError("map: boundary index out of range");
  }
  for (const Point& p : target_boundary) {
    if (!p.allFinite()) return absl::InvalidArgumentError("map: target is not finite");
  }
  if (CountInverted(triangles, source) > 0) {
    return absl::InvalidArgumentError("map: the source mesh has inverted triangles");
  }
  return absl::OkStatus();
}

// Every boundary vertex fixed at its target, the interior free: the constraints of the exact
// placement and of the polish.
Constraints PinnedBoundary(const Points& source, const std::vector<int>& boundary,
                           const Points& target_boundary) {
  const int n = static_cast<int>(source.size());
  Constraints fixed;
  fixed.free_index.assign(n, 0);
  fixed.fixed_at = source;
  for (size_t k = 0; k < boundary.size(); ++k) {
    fixed.free_index[boundary[k]] = -1;
    fixed.fixed_at[boundary[k]] = target_boundary[k];
  }
  for (int v = 0; v < n; ++v) {
    if (fixed.free_index[v] >= 0) fixed.free_index[v] = fixed.free_count++;
  }
  return fixed;
}

// One MapToBoundary call on checked arguments. The phases share the Mapper (whose factorization
// patterns are cached per Constraints object, so `fixed_` lives as long as the mapper) and the
// report, hence a class; Run calls them in order: a sound Tutte embedding, else the progressive
// pull and the exact placement of the boundary; then the polish with the boundary pinned.
class BoundaryMap {
 public:
  BoundaryMap(const Points& source, const std::vector<Triangle>& triangles,
              const std::vector<int>& boundary, const Points& target_boundary,
              const MapToBoundaryOptions& options, const CancelToken* cancel,
              MapToBoundaryReport* report)
      : source_(source),
        triangles_(triangles),
        boundary_(boundary),
        target_(target_boundary),
        options_(options),
        cancel_(cancel),
        rep_(*report),
        n_(static_cast<int>(source.size())),
        mapper_(source, triangles, boundary, target_boundary),
        fixed_(PinnedBoundary(source, boundary, target_boundary)) {}

  absl::StatusOr<Points> Run() {
    Points x;
    absl::StatusOr<bool> placed = TutteStart(&x);
    if (!placed.ok()) return placed.status();
    rep_.tutte = *placed;
    if (!*placed) {
      if (absl::Status s = CheckStart(); !s.ok()) return s;
      x = PullStart();
      if (absl::Status s = PullBoundary(&x); !s.ok()) return s;
      if (absl::Status s = PlaceExactly(&x); !s.ok()) return s;
    }
    for (size_t k = 0; k < boundary_.size(); ++k) x[boundary_[k]] = target_[k];
    if (CountInverted(triangles_, x) > 0) {
      return absl::FailedPreconditionError("the exactly placed boundary folds a triangle");
    }
    if (absl::Status s = Polish(&x); !s.ok()) return s;
    for (size_t k = 0; k < boundary_.size(); ++k) x[boundary_[k]] = target_[k];
    if (const int inverted = CountInverted(triangles_, x); inverted > 0) {
      return absl::FailedPreconditionError(absl::StrCat(inverted, " triangles fold"));
    }
    rep_.energy = mapper_.Distortion(x) / mapper_.total_area();
    return x;
  }

 private:
  // The Tutte embedding into *x, tried for a convex target (or always, per the options), and
  // whether it is the map: true when it folds nothing and, for a non-convex target, leaves no
  // triangle nearly flat relative to its source area, so the polish's barrier starts from a
  // sound map. Only RESOURCE_EXHAUSTED is an error: any other failure leaves the pull to try.
  absl::StatusOr<bool> TutteStart(Points* x) const {
    const bool convex = IsConvexPositive(target_);
    absl::Status tutte = absl::FailedPreconditionError("not tried");
    if ((options_.tutte_when_convex && convex) || options_.tutte_first_always) {
      tutte = TutteEmbedding(source_, triangles_, boundary_, target_, x);
      if (absl::IsResourceExhausted(tutte)) return tutte;
    }
    if (!tutte.ok()) return false;
    bool sound = CountInverted(triangles_, *x) == 0;
    for (size_t t = 0; sound && !convex && t < triangles_.size(); ++t) {
      sound = SignedArea2(triangles_[t], *x) > 1e-6 * SignedArea2(triangles_[t], source_);
    }
    return sound;
  }

  // options.start's contract (one point per vertex, nothing folded), checked only when the pull
  // is going to start from it.
  absl::Status CheckStart() const {
    if (options_.start == nullptr) return absl::OkStatus();
    if (options_.start->size() != source_.size()) {
      return absl::InvalidArgumentError(absl::StrCat("start has ", options_.start->size(),
                                                     " points, the mesh has ", source_.size()));
    }
    if (CountInverted(triangles_, *options_.start) != 0) {
      return absl::InvalidArgumentError("start folds a triangle");
    }
    return absl::OkStatus();
  }

  // Where the pull starts: the given start, else the best-fitting affine image of the source
  // (exact for a rotated, scaled or sheared copy), else the identity.
  Points PullStart() const {
    if (options_.start != nullptr) return *options_.start;
    Points affine;
    if (AffineStart(source_, triangles_, boundary_, target_, &affine)) return affine;
    return source_;
  }

  // The progressive boundary pull: stages of SLIM iterations with every vertex free and a
  // boundary penalty ten times the last stage's, until the boundary is within tolerance of the
  // target (relative to its bounding-box diagonal) or the iterations, stages or penalty run out.
  // FAILED_PRECONDITION (StuckError) when it does not get there.
  absl::Status PullBoundary(Points* x) {
    Constraints pull;
    pull.free_index.resize(n_);
    for (int v = 0; v < n_; ++v) pull.free_index[v] = v;
    pull.free_count = n_;
    Point lo = target_[0], hi = lo;
    for (const Point& p : target_) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double scale = (hi - lo).norm();
    const double tolerance = options_.boundary_tolerance * scale;
    pull.penalty = mapper_.total_area() / (boundary_.size() * scale * scale);
    while (mapper_.MaxBoundaryDistance(*x) > tolerance &&
           rep_.iterations < options_.max_iterations) {
      ++rep_.stages;
      pull.penalty *= 10;
      for (int it = 0;
           it < options_.iterations_per_stage && rep_.iterations < options_.max_iterations; ++it) {
        if (Cancelled(cancel_)) return absl::CancelledError("map: cancelled");
        ++rep_.iterations;
        const absl::StatusOr<double> iterated = mapper_.Iterate(x, pull);
        if (!iterated.ok()) return iterated.status();
        const double progress = *iterated;
        if (progress < 0) break;  // the penalty outgrew the factorization: the pull is stuck
        if (progress < options_.stage_progress) break;
      }
      if (rep_.stages > 40 || !(pull.penalty < 1e20)) break;
    }
    const double distance = mapper_.MaxBoundaryDistance(*x);
    if (distance > tolerance) return StuckError(*x, distance);
    return absl::OkStatus();
  }

  // The pull's failure, named by the boundary vertex furthest from its target (where the map is
  // stuck), in the target's and the reference drawing's coordinates, for the user to find it.
  absl::Status StuckError(const Points& x, double distance) const {
    size_t worst = 0;
    for (size_t k = 0; k < boundary_.size(); ++k) {
      if ((x[boundary_[k]] - target_[k]).norm() > (x[boundary_[worst]] - target_[worst]).norm()) {
        worst = k;
      }
    }
    return absl::FailedPreconditionError(absl::StrCat(
        "the boundary could not be pulled onto the target without folding triangles (the "
        "boundary point that belongs at (",
        target_[worst].x(), ", ", target_[worst].y(), ") stays ", distance, " away, near (",
        source_[boundary_[worst]].x(), ", ", source_[boundary_[worst]].y(),
        ") of the reference drawing, after ", rep_.iterations, " iterations)"));
  }

  // Exact placement: the proxy step with the boundary pinned, else the boundary's move alone;
  // whichever is taken must not fold anything (MaxStep beyond the full step).
  absl::Status PlaceExactly(Points* x) const {
    Points proxy;
    if (absl::Status s = mapper_.ProxySolve(*x, fixed_, &proxy); !s.ok()) return s;
    Points d(n_);
    for (int v = 0; v < n_; ++v) d[v] = proxy[v] - (*x)[v];
    if (!(mapper_.MaxStep(*x, d) > 1.0)) {
      for (int v = 0; v < n_; ++v) {
        d[v] = fixed_.free_index[v] < 0 ? proxy[v] - (*x)[v] : Point(0, 0);
      }
      if (!(mapper_.MaxStep(*x, d) > 1.0)) {
        return absl::FailedPreconditionError(
            "placing the boundary exactly on the target would fold a triangle");
      }
    }
    for (int v = 0; v < n_; ++v) (*x)[v] += d[v];
    return absl::OkStatus();
  }

  // Interior-only SLIM iterations with the boundary on target (quality polish), until
  // options.polish_iterations or an iteration gaining less than 1e-6.
  absl::Status Polish(Points* x) {
    for (int it = 0; it < options_.polish_iterations; ++it) {
      if (Cancelled(cancel_)) return absl::CancelledError("map: cancelled");
      ++rep_.iterations;
      const absl::StatusOr<double> progress = mapper_.Iterate(x, fixed_);
      if (!progress.ok()) return progress.status();
      if (*progress < 1e-6) break;
    }
    return absl::OkStatus();
  }

  const Points& source_;
  const std::vector<Triangle>& triangles_;
  const std::vector<int>& boundary_;
  const Points& target_;
  const MapToBoundaryOptions& options_;
  const CancelToken* cancel_;
  MapToBoundaryReport& rep_;
  const int n_;
  const Mapper mapper_;
  const Constraints fixed_;
};

absl::StatusOr<Points> MapToBoundaryImpl(const Points& source,
                                         const std::vector<Triangle>& triangles,
                                         const std::vector<int>& boundary,
                                         const Points& target_boundary,
                                         const MapToBoundaryOptions& options,
                                         const CancelToken* cancel, MapToBoundaryReport* report) {
  if (absl::Status s = CheckMapInputs(source, triangles, boundary, target_boundary); !s.ok()) {
    return s;
  }
  // The report is reset only once the arguments are accepted.
  MapToBoundaryReport local_report;
  MapToBoundaryReport& rep = report ? *report : local_report;
  rep = MapToBoundaryReport();
  return BoundaryMap(source, triangles, boundary, target_boundary, options, cancel, &rep).Run();
}

}  // namespace

absl::StatusOr<Points> MapToBoundary(const Points& source, const std::vector<Triangle>& triangles,
                                     const std::vector<int>& boundary,
                                     const Points& target_boundary,
                                     const MapToBoundaryOptions& options, const CancelToken* cancel,
                                     MapToBoundaryReport* report) {
  // The sparse solvers report their own allocation failures; what is left to throw are the
  // vectors and freshly constructed Eigen objects of the iterations (exception-safe: they are
  // never half-resized), so a failed allocation ends the map here, not the process.
  try {
    return MapToBoundaryImpl(source, triangles, boundary, target_boundary, options, cancel, report);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "map: out of memory (", source.size(), " vertices, ", triangles.size(), " triangles)"));
  }
}

}  // namespace inbetween::solver
