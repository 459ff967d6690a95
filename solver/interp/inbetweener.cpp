// Inbetweening of a multimesh at given example weights w: the per-frame objective of DESIGN.md,
//   sum_i w_i [W_D(X_i, x) + W_C(C_i, x)] + W_O(x)  (+ the dynamics term of S-eq.28/29).
//  - kLinear: x = sum_i w_i X_i.
//  - kAlexa (Alexa, Cohen-Or, Levin 2000): per triangle A_i = R(theta_i) S_i from example 0 to i
//    (example_rotations.h); target J*_t = R(sum_i w_i theta_it) sum_i w_i S_it; one least-squares
//    solve min sum_t kappa_t A_0t ||J_t(x) - J*_t||^2 with example 0's Laplacian, factored once.
//  - kZhu17: local-global minimization of
//      E(x) = Wbar(w, x) + W_C(w, x)                       (blended_arap.h, cohesive_energy.h)
//    Wbar is S-eq.3 per example measured in one fixed reference per triangle, so the global
//    matrix Kbar + Hbar (cohesive) does not depend on w: CHOLMOD factors it ONCE in Create, and
//    every iteration of every frame is a local step plus one back-substitution with 2 right-hand
//    sides. W_C's weight-dependent, capped and anisotropic parts enter only the right-hand side
//    (majorize-minimize, cohesive_energy.h). No iteration raises E: Anderson steps that would are
//    replaced by the plain step, and a plain step that would (W_C's lagged direction for
//    alpha != 1/2) ends the frame. The start is the lower-energy of (a) the Alexa targets solved
//    with the same matrix and (b) the previous frame translated into this frame's gauge (the
//    rotation gauge is applied once, after the iterations); (a) is skipped in sequential playback
//    when warm_start_trust_radius > 0. The back-substitutions are our own over CHOLMOD's factor
//    (sparse_cholesky.h), the overlap hierarchies are refit, not rebuilt, per frame, and with
//    options.threads > 1 the local step, right-hand side and x/y solves run in fixed chunks
//    (bit-identical frames for every thread count).
//    Non-overlap W_O (S-eq.8/9) is checked on every frame (overlap.h) and, when violated, enforced
//    by pushing the offending boundary vertices out to the boundary with a stiff spring term
//    (a second matrix with the spring on every boundary vertex, factored on first use).
//  - Dynamics (S-eq.28/29, DESIGN.md's reading), kZhu17 with epsilon > 0: Phi = the frame above;
//    x = argmin beta ||x - x_pred||_M^2 + Wbar(Phi, x) + W_C, x_pred = 2 x(s-1) - x(s-2) moved
//    into Phi's gauge, beta = xi rho / (2 h^2) = epsilon kappa / (2 (delta + 1)),
//    delta = Wbar(Phi, x(s-1)) (S-eq.29), kappa the area-weighted mean stiffness. The matrix holds
//    beta_max M, beta_max = epsilon kappa / 2 >= beta (factored once; the difference is
//    majorized like W_C). Key frames stay exact.
// Gauge (rigid motions leave E unchanged): per gauge group (vertices connected by triangles or
// cohesive pairs) the mass-weighted centroid is sum_i w_i c_i (example centroids), and for kZhu17
// the area-weighted mean rotation angle relative to example 0 is that of the Alexa angles
// sum_i w_i theta_it (blended_arap.h AngleOffset). The translation is fixed by pinning one vertex
// per group in the solve and shifting afterwards; the vertex masses m_v (a third of the adjacent
// triangles' areas, averaged over the examples) are the same for all shapes, so keys keep their
// own centroids.
#include "solver/interp/inbetweener.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/geometry/primitives.h"
#include "solver/interp/arap_energy.h"
#include "solver/interp/blended_arap.h"
#include "solver/interp/cohesive_energy.h"
#include "solver/interp/example_rotations.h"
#include "solver/interp/overlap.h"
#include "solver/interp/polar.h"

namespace inbetween::solver {
namespace {

// Twice the signed area of triangle t in the coordinates x (one row per vertex).
double DoubleArea(const Triangle& t, const Coords& x) {
  return SignedArea2(x.row(t[0]).transpose(), x.row(t[1]).transpose(), x.row(t[2]).transpose());
}

// Signed area <= 0 in raw coordinates (see types.h for the orientation convention).
int CountInverted(const std::vector<Triangle>& triangles, const Coords& x) {
  int inverted = 0;
  for (const Triangle& t : triangles) {
    if (!(DoubleArea(t, x) > 0.0)) ++inverted;
  }
  return inverted;
}

absl::Status CheckMesh(const Multimesh& mesh) {
  if (mesh.num_shapes() < 1) return absl::InvalidArgumentError("multimesh has no shapes");
  if (mesh.triangles.empty()) return absl::InvalidArgumentError("multimesh has no triangles");
  const int n = mesh.num_vertices();
  for (int i = 0; i < mesh.num_shapes(); ++i) {
    if (static_cast<int>(mesh.shapes[i].size()) != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("shape ", i, " has ", mesh.shapes[i].size(), " vertices, shape 0 has ", n));
    }
    for (int v = 0; v < n; ++v) {
      if (!mesh.shapes[i][v].allFinite()) {
        return absl::InvalidArgumentError(
            absl::StrCat("shape ", i, ", vertex ", v, " has a non-finite coordinate"));
      }
    }
  }
  return absl::OkStatus();
}

// Anderson acceleration (type II, Walker & Ni 2011) of x -> G(x) with a sliding window; the Gram
// matrix of the residual differences is updated incrementally.
class Anderson {
 public:
  explicit Anderson(int history) : m_(history) {}

  void Reset() {
    dg_.clear();
    df_.clear();
    gram_.clear();
    has_previous_ = false;
  }

  // g = G(x_k), f = G(x_k) - x_k; returns x_{k+1}.
  Eigen::VectorXd Step(const Eigen::VectorXd& g, const Eigen::VectorXd& f) {
    if (has_previous_) {
      dg_.push_back(g - g_previous_);
      df_.push_back(f - f_previous_);
      std::vector<double> row(df_.size());
      for (size_t j = 0; j < df_.size(); ++j) row[j] = df_.back().dot(df_[j]);
      gram_.push_back(row);
      if (static_cast<int>(df_.size()) > m_) {
        dg_.pop_front();
        df_.pop_front();
        gram_.pop_front();
        for (auto& r : gram_) r.erase(r.begin());
      }
    }
    g_previous_ = g;
    f_previous_ = f;
    has_previous_ = true;
    const int k = static_cast<int>(df_.size());
    if (k == 0) return g;
    Eigen::MatrixXd a(k, k);
    Eigen::VectorXd rhs(k);
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j <= i; ++j) a(i, j) = a(j, i) = gram_[i][j];
      rhs(i) = df_[i].dot(f);
    }
    a.diagonal().array() += 1e-10 * a.trace() / k + 1e-300;
    const Eigen::VectorXd gamma = a.ldlt().solve(rhs);
    Eigen::VectorXd x = g;
    for (int j = 0; j < k; ++j) x -= gamma(j) * dg_[j];
    return x;
  }

 private:
  int m_;
  std::deque<Eigen::VectorXd> dg_, df_;
  std::deque<std::vector<double>> gram_;  // gram_[i][j] = df_i . df_j, j <= i
  Eigen::VectorXd g_previous_, f_previous_;
  bool has_previous_ = false;
};

}  // namespace

struct Inbetweener::Impl {
  InbetweenOptions options;
  std::vector<Triangle> triangles;
  std::vector<Coords> shapes;
  std::vector<Eigen::VectorXd> shape_area2;  // [example][triangle] doubled signed area, lazily
  std::optional<BlendedArap> arap;           // kZhu17 energy (also reported for all methods)
  std::optional<CohesiveEnergy> cohesive;    // may have no edges
  std::optional<OverlapChecker> overlap;
  std::optional<ArapEnergy> alexa_energy;  // example 0, kAlexa
  ExampleRotations rotations;              // kAlexa split, unwrapped

  // Gauge.
  std::vector<int> group;  // per vertex
  int num_groups = 0;
  std::vector<double> mass;                             // m_v
  std::vector<double> group_mass;                       // sum of m_v per group
  std::vector<std::vector<Eigen::Vector2d>> centroids;  // [example][group]
  std::vector<std::vector<int>> group_triangles;
  std::vector<int> free_index;  // reduced index, -1 for pinned vertices
  int num_free = 0;
  double size = 1.0;        // sqrt of the total reference area
  double mean_kappa = 1.0;  // area-weighted

  SparseCholesky solver;          // kAlexa: K_0; kZhu17: Kbar + Hbar (pinned)
  SparseCholesky dynamic_solver;  // Kbar + Hbar + beta_max M (not pinned), epsilon > 0
  SparseCholesky contact_solver;  // Kbar + Hbar + gamma on boundary vertices (not pinned), lazily
  bool contact_factored = false;
  double contact_stiffness = 0.0;
  Eigen::SparseMatrix<double> zhu_matrix;  // Kbar + Hbar, full

  // The two frames Solve returned last (dynamics through the two-argument Solve), and the
  // weights of the last one (warm start without the cold-start check).
  Points last_frame, frame_before_last;
  ExampleWeights last_weights;
  // What a frame is checked for: inverted triangles and overlaps (W_O).
  struct Validity {
    int inverted = 0;
    int overlaps = 0;
    bool clean() const { return inverted == 0 && overlaps == 0; }
  };
  // Set by Zhu17 when it checked the frame it returns (Solve reports it instead of checking
  // again).
  std::optional<Validity> known_validity;
  mutable Eigen::MatrixXd solve_scratch;  // right-hand sides of GlobalSolve

  // What one frame's objective is made of (see the header comment).
  struct Problem {
    const ExampleWeights* w = nullptr;
    std::vector<double> thresholds;  // cohesive tau_e l_e
    // Dynamics: rest = Jbar(Phi) per triangle, inertia beta ||x - pred||_M^2, matrix beta_max M.
    bool dynamic = false;
    std::vector<Eigen::Matrix2d> rest;
    Coords pred;
    double beta = 0.0, beta_max = 0.0;
    std::vector<Eigen::Vector2d> group_centroids;  // gauge target per group
    // Contacts: spring gamma ||x_v - target_v||^2 on boundary vertices (others: proximal).
    bool contact = false;
    std::vector<OverlapContact> contacts;
  };

  int num_vertices() const { return static_cast<int>(free_index.size()); }
  absl::Status Setup(const Multimesh& mesh);
  absl::StatusOr<Eigen::SparseMatrix<double>> Reduce(const Eigen::SparseMatrix<double>& k) const;
  std::vector<Eigen::Vector2d> BlendedCentroids(const ExampleWeights& w) const;
  Eigen::Vector2d Centroid(const Coords& x, int g) const;
  void Translate(const std::vector<Eigen::Vector2d>& target, Coords* x) const;
  void Rotate(const ExampleWeights& w, Coords* x) const;
  absl::StatusOr<Coords> GlobalSolve(const SparseCholesky& s, bool pinned, const Coords& b,
                                     const std::vector<Eigen::Vector2d>& centroid_target) const;
  double Evaluate(const Coords& x, const Problem& p, Coords* rhs, int* separated) const;
  absl::StatusOr<Coords> Iterate(const Problem& p, Coords x, double energy, Coords rhs,
                                 const CancelToken* cancel, FrameReport* report) const;
  absl::StatusOr<Coords> Alexa(const ExampleWeights& w) const;
  // Fills report->min/max_area_ratio: each triangle's area in x over its weight-blended area in
  // the examples.
  void AreaRatios(const Coords& x, const ExampleWeights& w, FrameReport* report);
  absl::StatusOr<Coords> Zhu17(const ExampleWeights& w, const Frame& previous,
                               const Frame& before_previous, const CancelToken* cancel,
                               FrameReport* report);
  // `inside_free`: x is known to have no boundary vertex inside the shape (only crossings are
  // counted then).
  Validity Check(const Coords& x, bool inside_free = false) const {
    return {CountInverted(triangles, x), inside_free ? overlap->Crossings(x) : overlap->Count(x)};
  }
  // Moves *to back towards the clean `from` until it is clean: the largest fraction t of the
  // step found by bisection (`from` + t (*to - `from`), t in [0, 1]); returns t. *first_bad:
  // the point just past it, where the step first overlaps.
  double HoldBack(const Coords& from, Coords* to, Coords* first_bad) const;
  // Returns whether the final x was checked and has no boundary vertex inside the shape.
  // `seed`: contacts to start from (else those of *x).
  absl::StatusOr<bool> EnforceNonOverlap(Problem* p, Coords* x, const CancelToken* cancel,
                                         FrameReport* report,
                                         std::vector<OverlapContact> seed = {});
  // Zhu17's steps. The start: the cold start (Alexa targets) or the previous frame, whichever
  // has the lower energy (the cold start skipped when sequential playback trusts the warm one).
  absl::Status StartPoint(const Problem& p, const Frame& previous,
                          const std::optional<Coords>& prev, Coords* x, Coords* rhs, double* energy,
                          FrameReport* report);
  // prevent_overlap: pushes boundary vertices out of the shape, else holds the frame back where
  // the motion from a clean previous frame first meets an overlap; sets known_validity.
  absl::Status ResolveOverlaps(Problem* p, const std::optional<Coords>& prev, Coords* x,
                               const CancelToken* cancel, FrameReport* report);
  // The dynamics solve (S-eq.28/29) from Phi = x; Phi itself when the dynamics would overlap.
  absl::StatusOr<Coords> Dynamics(Problem* p, Coords x, const Coords& x1,
                                  const Frame& before_previous, const CancelToken* cancel,
                                  FrameReport* report);
  absl::Status SetupGaugeGroups(const Multimesh& mesh);
  void SetupMasses(const Multimesh& mesh);
  absl::Status FactorMatrices(const Multimesh& mesh);
  absl::StatusOr<Frame> Solve(const ExampleWeights& weights, const Frame& previous,
                              const Frame& before_previous, const CancelToken* cancel,
                              FrameReport* report);
};

absl::Status Inbetweener::Impl::Setup(const Multimesh& mesh) {
  triangles = mesh.triangles;
  const int n = mesh.num_vertices();
  const int num_shapes = mesh.num_shapes();
  for (int i = 0; i < num_shapes; ++i) shapes.push_back(ToCoords(mesh.shapes[i]));
  absl::StatusOr<BlendedArap> blended =
      BlendedArap::Create(triangles, mesh.shapes, options.stiffness);
  if (!blended.ok()) return blended.status();
  arap = *std::move(blended);
  absl::StatusOr<CohesiveEnergy> coh =
      CohesiveEnergy::Create(mesh.cohesive_edges, mesh.shapes,
                             {options.lambda, options.tau, options.alpha, options.hysteresis});
  if (!coh.ok()) return coh.status();
  cohesive = *std::move(coh);
  overlap.emplace(triangles, mesh.cohesive_edges, n);
  if (absl::Status s = SetupGaugeGroups(mesh); !s.ok()) return s;
  SetupMasses(mesh);
  return FactorMatrices(mesh);
}

// Gauge groups: connected by shared triangle vertices or cohesive pairs (union-find, roots =
// lowest index); each group's root is pinned, the other vertices are numbered free.
absl::Status Inbetweener::Impl::SetupGaugeGroups(const Multimesh& mesh) {
  const int n = mesh.num_vertices();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  auto unite = [&](int p, int q) {
    const int a = find(p), b = find(q);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  std::vector<char> used(n, 0);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      used[t[k]] = 1;
      unite(t[k], t[(k + 1) % 3]);
    }
  }
  for (int v = 0; v < n; ++v) {
    if (!used[v]) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", v, " is in no triangle"));
    }
  }
  // Cohesive pairs tie pieces together only where the cohesive term is in the matrix (zhu17 with
  // lambda > 0); alexa's matrix has no such term, so each piece needs its own pinned vertex (a
  // drawing split in two, like examples/split, would otherwise leave one piece singular).
  if (options.lambda > 0.0 && options.method == InterpMethod::kZhu17) {
    for (const auto& e : mesh.cohesive_edges) {
      unite(e[0], e[2]);
      unite(e[1], e[3]);
    }
  }
  group.assign(n, -1);
  free_index.assign(n, -1);
  std::vector<int> root_group(n, -1);
  for (int v = 0; v < n; ++v) {
    const int r = find(v);
    if (root_group[r] < 0) {
      root_group[r] = num_groups++;  // v == r: the pinned vertex
    } else {
      free_index[v] = num_free++;
    }
    group[v] = root_group[r];
  }
  group_triangles.assign(num_groups, {});
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    group_triangles[group[triangles[t][0]]].push_back(t);
  }
  return absl::OkStatus();
}

// Lumped vertex masses (a third of each triangle's mean area over the shapes), the mesh's size
// and mean stiffness, each group's mass and its centroid in every shape.
void Inbetweener::Impl::SetupMasses(const Multimesh& mesh) {
  const int n = mesh.num_vertices();
  const int num_shapes = mesh.num_shapes();
  mass.assign(n, 0.0);
  double total_area = 0.0, kappa_area = 0.0;
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    double area = 0.0;
    for (int i = 0; i < num_shapes; ++i) {
      area += 0.5 * SignedArea2(triangles[t], mesh.shapes[i]);
    }
    area /= static_cast<double>(num_shapes);
    for (int k = 0; k < 3; ++k) mass[triangles[t][k]] += area / 3.0;
    total_area += arap->reference_area(t);
    kappa_area += arap->stiffness(t) * arap->reference_area(t);
  }
  size = std::sqrt(total_area);
  mean_kappa = kappa_area / total_area;
  group_mass.assign(num_groups, 0.0);
  for (int v = 0; v < n; ++v) group_mass[group[v]] += mass[v];
  centroids.assign(num_shapes, std::vector<Eigen::Vector2d>(num_groups, Eigen::Vector2d::Zero()));
  for (int i = 0; i < num_shapes; ++i) {
    for (int v = 0; v < n; ++v) centroids[i][group[v]] += mass[v] * shapes[i].row(v).transpose();
    for (int g = 0; g < num_groups; ++g) centroids[i][g] /= group_mass[g];
  }
}

// The factorizations the method solves with: alexa's ARAP matrix of example 0; zhu17's blended
// ARAP plus cohesive matrix, and with dynamics (epsilon > 0) that matrix plus the largest mass
// term.
absl::Status Inbetweener::Impl::FactorMatrices(const Multimesh& mesh) {
  const int n = mesh.num_vertices();
  if (options.method == InterpMethod::kAlexa) {
    absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(triangles, mesh.shapes[0], options.stiffness);
    if (!e.ok()) return e.status();
    alexa_energy = *std::move(e);
    rotations = ComputeExampleRotations(triangles, mesh.shapes);
    absl::StatusOr<Eigen::SparseMatrix<double>> k = Reduce(alexa_energy->Laplacian());
    if (!k.ok()) return k.status();
    if (absl::Status s = solver.Compute(*k); !s.ok()) {
      return absl::InternalError(absl::StrCat("factoring example 0's ARAP matrix: ", s.message()));
    }
  } else if (options.method == InterpMethod::kZhu17) {
    std::vector<Eigen::Triplet<double>> triplets;
    cohesive->AddMatrix(&triplets);
    Eigen::SparseMatrix<double> h(n, n);
    h.setFromTriplets(triplets.begin(), triplets.end());
    zhu_matrix = arap->Laplacian() + h;
    zhu_matrix.makeCompressed();
    absl::StatusOr<Eigen::SparseMatrix<double>> k = Reduce(zhu_matrix);
    if (!k.ok()) return k.status();
    if (absl::Status s = solver.Compute(*k); !s.ok()) {
      return absl::InternalError(absl::StrCat("factoring the inbetweening matrix: ", s.message()));
    }
    if (options.epsilon > 0.0) {
      Eigen::SparseMatrix<double> m = zhu_matrix;
      const double beta_max = 0.5 * options.epsilon * mean_kappa;
      for (int v = 0; v < n; ++v) m.coeffRef(v, v) += beta_max * mass[v];
      m.makeCompressed();
      if (absl::Status s = dynamic_solver.Compute(m); !s.ok()) {
        return absl::InternalError(absl::StrCat("factoring the dynamics matrix: ", s.message()));
      }
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<Eigen::SparseMatrix<double>> Inbetweener::Impl::Reduce(
    const Eigen::SparseMatrix<double>& k) const {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(k.nonZeros()));
  for (int col = 0; col < k.outerSize(); ++col) {
    if (free_index[col] < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      if (free_index[it.row()] < 0) continue;
      triplets.emplace_back(free_index[it.row()], free_index[col], it.value());
    }
  }
  Eigen::SparseMatrix<double> r(num_free, num_free);
  r.setFromTriplets(triplets.begin(), triplets.end());
  r.makeCompressed();
  return r;
}

std::vector<Eigen::Vector2d> Inbetweener::Impl::BlendedCentroids(const ExampleWeights& w) const {
  std::vector<Eigen::Vector2d> c(num_groups, Eigen::Vector2d::Zero());
  for (int g = 0; g < num_groups; ++g) {
    for (size_t i = 0; i < w.size(); ++i) c[g] += w[i] * centroids[i][g];
  }
  return c;
}

Eigen::Vector2d Inbetweener::Impl::Centroid(const Coords& x, int g) const {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int v = 0; v < num_vertices(); ++v) {
    if (group[v] == g) c += mass[v] * x.row(v).transpose();
  }
  return c / group_mass[g];
}

void Inbetweener::Impl::Translate(const std::vector<Eigen::Vector2d>& target, Coords* x) const {
  std::vector<Eigen::Vector2d> shift(num_groups, Eigen::Vector2d::Zero());
  for (int v = 0; v < num_vertices(); ++v) shift[group[v]] -= mass[v] * x->row(v).transpose();
  for (int g = 0; g < num_groups; ++g) shift[g] = shift[g] / group_mass[g] + target[g];
  for (int v = 0; v < num_vertices(); ++v) x->row(v) += shift[group[v]].transpose();
}

void Inbetweener::Impl::Rotate(const ExampleWeights& w, Coords* x) const {
  for (int g = 0; g < num_groups; ++g) {
    const double offset = arap->AngleOffset(*x, w, group_triangles[g]);
    if (offset == 0.0) continue;
    const Eigen::Vector2d c = Centroid(*x, g);
    const Eigen::Matrix2d r = RotationMatrix(-offset);
    for (int v = 0; v < num_vertices(); ++v) {
      if (group[v] == g) x->row(v) = (c + r * (x->row(v).transpose() - c)).transpose();
    }
  }
}

absl::StatusOr<Coords> Inbetweener::Impl::GlobalSolve(
    const SparseCholesky& s, bool pinned, const Coords& b,
    const std::vector<Eigen::Vector2d>& centroid_target) const {
  Coords x(num_vertices(), 2);
  Eigen::MatrixXd& rhs = solve_scratch;
  if (pinned) {
    rhs.resize(num_free, 2);
    for (int v = 0; v < num_vertices(); ++v) {
      if (free_index[v] >= 0) rhs.row(free_index[v]) = b.row(v);
    }
    if (absl::Status st = s.SolveInPlace(&rhs, options.threads); !st.ok()) return st;
    for (int v = 0; v < num_vertices(); ++v) {
      // Pinned vertices at 0, moved by the gauge.
      if (free_index[v] >= 0) {
        x.row(v) = rhs.row(free_index[v]);
      } else {
        x.row(v).setZero();
      }
    }
  } else {
    rhs = b;
    if (absl::Status st = s.SolveInPlace(&rhs, options.threads); !st.ok()) return st;
    x = rhs;
  }
  if (!centroid_target.empty()) Translate(centroid_target, &x);
  return x;
}

double Inbetweener::Impl::Evaluate(const Coords& x, const Problem& p, Coords* rhs,
                                   int* separated) const {
  static thread_local std::vector<Eigen::Matrix2d> targets;
  rhs->setZero(num_vertices(), 2);
  double energy = p.dynamic ? arap->LocalStepToRest(x, p.rest, &targets)
                            : arap->LocalStep(x, *p.w, &targets, options.threads);
  arap->AddRhs(targets, rhs, options.threads);
  if (cohesive->num_edges() > 0) {
    std::vector<char> open;
    energy += cohesive->LocalStep(x, *p.w, p.thresholds, rhs, &open);
    if (separated != nullptr)
      *separated = static_cast<int>(std::count(open.begin(), open.end(), 1));
  }
  if (p.dynamic) {
    // beta ||x - pred||_M^2 majorized by beta_max ||x - pred||^2 - (beta_max - beta) (linearized
    // at x): right-hand side M (beta pred + (beta_max - beta) x).
    for (int v = 0; v < num_vertices(); ++v) {
      const Eigen::RowVector2d d = x.row(v) - p.pred.row(v);
      energy += p.beta * mass[v] * d.squaredNorm();
      rhs->row(v) += mass[v] * (p.beta * p.pred.row(v) + (p.beta_max - p.beta) * x.row(v));
    }
  }
  if (p.contact) {
    // Non-overlap as one-sided springs gamma min(0, n.(x_v - q))^2 (zero once x_v is past the
    // contact's line), majorized at x by gamma ||x_v - x_v^k||^2 plus the gradient: the matrix
    // holds gamma on every boundary vertex (a proximal term, zero at x, for the vertices without
    // a contact) and the right-hand side gamma (x_v - n min(0, n.(x_v - q))). The vertex can
    // slide along the line; the majorizer keeps the energy from rising.
    for (int v : overlap->boundary_vertices()) rhs->row(v) += contact_stiffness * x.row(v);
    for (const OverlapContact& c : p.contacts) {
      const double s = c.normal.dot(x.row(c.vertex).transpose() - c.target);
      if (s >= 0.0) continue;
      energy += contact_stiffness * s * s;
      rhs->row(c.vertex) -= contact_stiffness * s * c.normal.transpose();
    }
  }
  return energy;
}

absl::StatusOr<Coords> Inbetweener::Impl::Iterate(const Problem& p, Coords x, double energy,
                                                  Coords rhs, const CancelToken* cancel,
                                                  FrameReport* report) const {
  const SparseCholesky& s = p.contact ? contact_solver : p.dynamic ? dynamic_solver : solver;
  // The contact springs are not translation invariant: that solve pins nothing and is not moved
  // into the gauge afterwards (the springs on every boundary vertex make its matrix definite).
  const bool pinned = !p.dynamic && !p.contact;
  static const std::vector<Eigen::Vector2d> kNoGauge;
  const std::vector<Eigen::Vector2d>& gauge = p.contact ? kNoGauge : p.group_centroids;
  Anderson anderson(std::max(1, options.anderson_history));
  const double displacement_limit = options.displacement_tolerance * size;
  int iterations = 0;
  int separated = 0;
  Coords next_rhs(num_vertices(), 2);
  while (iterations < options.max_iterations && energy > 0.0) {
    if (Cancelled(cancel)) {
      return absl::CancelledError("inbetweening cancelled");
    }
    absl::StatusOr<Coords> g = GlobalSolve(s, pinned, rhs, gauge);
    if (!g.ok()) return g.status();
    ++iterations;
    const double step = (*g - x).cwiseAbs().maxCoeff();
    const double previous_energy = energy;
    bool accepted = false;
    if (options.anderson) {
      const Eigen::Map<const Eigen::VectorXd> gv(g->data(), g->size());
      const Eigen::VectorXd f = gv - Eigen::Map<const Eigen::VectorXd>(x.data(), x.size());
      const Eigen::VectorXd accelerated = anderson.Step(gv, f);
      Coords candidate = Eigen::Map<const Coords>(accelerated.data(), num_vertices(), 2);
      const double candidate_energy = Evaluate(candidate, p, &next_rhs, &separated);
      if (candidate_energy <= energy) {
        x = std::move(candidate);
        energy = candidate_energy;
        std::swap(rhs, next_rhs);
        accepted = true;
      } else {
        anderson.Reset();
      }
    }
    if (!accepted) {
      // Safeguard: the plain step minimizes a majorizer of E, so it cannot raise E except where
      // the majorizer is inexact: W_C's direction xhat (S-eq.14) lagged at x_k for alpha != 1/2,
      // and rounding near convergence. A step that would raise E is refused and the frame ends,
      // so E never increases over the iterations (tested for alpha != 1/2).
      int plain_separated = 0;
      const double plain_energy = Evaluate(*g, p, &next_rhs, &plain_separated);
      if (plain_energy > energy) break;
      x = *std::move(g);
      energy = plain_energy;
      std::swap(rhs, next_rhs);
      separated = plain_separated;
    }
    if (step <= displacement_limit ||
        previous_energy - energy <= options.convergence_tolerance * previous_energy) {
      break;
    }
  }
  if (report != nullptr) {
    report->iterations += iterations;
    report->energy = energy;
    report->separated_edges = separated;
  }
  return x;
}

void Inbetweener::Impl::AreaRatios(const Coords& x, const ExampleWeights& w, FrameReport* report) {
  const int num_triangles = static_cast<int>(triangles.size());
  if (shape_area2.empty()) {
    shape_area2.resize(shapes.size());
    for (size_t i = 0; i < shapes.size(); ++i) {
      shape_area2[i].resize(num_triangles);
      for (int t = 0; t < num_triangles; ++t)
        shape_area2[i][t] = DoubleArea(triangles[t], shapes[i]);
    }
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int t = 0; t < num_triangles; ++t) {
    double blended = 0.0;
    for (size_t i = 0; i < shapes.size(); ++i) blended += w[i] * shape_area2[i][t];
    const double ratio = DoubleArea(triangles[t], x) / blended;  // examples have positive areas
    lo = std::min(lo, ratio);
    hi = std::max(hi, ratio);
  }
  report->min_area_ratio = lo;
  report->max_area_ratio = hi;
}

absl::StatusOr<Coords> Inbetweener::Impl::Alexa(const ExampleWeights& w) const {
  const int num_t = static_cast<int>(triangles.size());
  std::vector<Eigen::Matrix2d> targets(num_t);
  for (int t = 0; t < num_t; ++t) {
    double angle = 0.0;
    Eigen::Matrix2d stretch = Eigen::Matrix2d::Zero();
    for (size_t i = 0; i < w.size(); ++i) {
      angle += w[i] * rotations.angles[i][t];
      stretch += w[i] * rotations.stretches[i][t];
    }
    targets[t] = RotationMatrix(angle) * stretch;
  }
  Coords b = Coords::Zero(num_vertices(), 2);
  alexa_energy->AddRhs(targets, 1.0, &b);
  return GlobalSolve(solver, true, b, BlendedCentroids(w));
}

absl::StatusOr<bool> Inbetweener::Impl::EnforceNonOverlap(Problem* p, Coords* x,
                                                          const CancelToken* cancel,
                                                          FrameReport* report,
                                                          std::vector<OverlapContact> contacts) {
  if (contacts.empty()) contacts = overlap->Contacts(*x);
  if (contacts.empty()) return true;
  if (!contact_factored) {
    // Springs an order of magnitude stiffer than the material around a boundary vertex.
    double max_diagonal = 0.0;
    for (int v : overlap->boundary_vertices()) {
      max_diagonal = std::max(max_diagonal, zhu_matrix.coeff(v, v));
    }
    contact_stiffness = 10.0 * max_diagonal;
    Eigen::SparseMatrix<double> m = zhu_matrix;
    for (int v : overlap->boundary_vertices()) m.coeffRef(v, v) += contact_stiffness;
    m.makeCompressed();
    if (absl::Status s = contact_solver.Compute(m); !s.ok()) return s;
    contact_factored = true;
  }
  p->contact = true;
  // The active set only grows within a frame: a vertex pushed out in one round keeps its
  // half-plane in the next ones (else it springs back in and the rounds flip-flop), while a
  // vertex still inside gets a new way out.
  std::map<int, OverlapContact> active;
  for (int round = 0; round < 10 && !contacts.empty(); ++round) {
    for (const OverlapContact& c : contacts) active[c.vertex] = c;
    p->contacts.clear();
    for (const auto& [v, c] : active) p->contacts.push_back(c);
    Coords rhs;
    const double energy = Evaluate(*x, *p, &rhs, nullptr);
    absl::StatusOr<Coords> next = Iterate(*p, *x, energy, std::move(rhs), cancel, report);
    if (!next.ok()) return next.status();
    *x = *std::move(next);
    contacts = overlap->Contacts(*x);
  }
  p->contact = false;
  const bool inside_free = contacts.empty();
  p->contacts.clear();
  return inside_free;
}

double Inbetweener::Impl::HoldBack(const Coords& from, Coords* to, Coords* first_bad) const {
  const Coords step = *to - from;
  double good = 0.0, bad = 1.0;
  for (int k = 0; k < 12; ++k) {  // 1/4096 of the step
    const double t = 0.5 * (good + bad);
    if (Check(from + t * step).clean()) {
      good = t;
    } else {
      bad = t;
    }
  }
  *first_bad = from + bad * step;
  *to = from + good * step;
  return good;
}

absl::Status Inbetweener::Impl::StartPoint(const Problem& p, const Frame& previous,
                                           const std::optional<Coords>& prev, Coords* x,
                                           Coords* rhs, double* energy, FrameReport* report) {
  const ExampleWeights& w = *p.w;
  // Sequential playback: `previous` is the frame returned last and the weights moved little, so
  // the warm start is the continuation of the last solve and the cold-start check is skipped.
  bool trusted = false;
  if (options.warm_start && options.warm_start_trust_radius > 0.0 && prev &&
      last_weights.size() == w.size() && previous.vertices == last_frame) {
    double moved = 0.0;
    for (size_t i = 0; i < w.size(); ++i) moved += std::abs(w[i] - last_weights[i]);
    trusted = 0.5 * moved <= options.warm_start_trust_radius;
  }
  *energy = std::numeric_limits<double>::infinity();
  // Start (a): the Alexa targets solved with the kZhu17 matrix (cohesive jumps pulled to 0).
  auto cold_start = [&]() -> absl::Status {
    std::vector<Eigen::Matrix2d> targets;
    arap->AlexaTargets(w, &targets, options.threads);
    Coords b = Coords::Zero(num_vertices(), 2);
    arap->AddRhs(targets, &b, options.threads);
    absl::StatusOr<Coords> cold = GlobalSolve(solver, true, b, p.group_centroids);
    if (!cold.ok()) return cold.status();
    *x = *std::move(cold);
    *energy = Evaluate(*x, p, rhs, nullptr);
    return absl::OkStatus();
  };
  if (!trusted) {
    if (absl::Status s = cold_start(); !s.ok()) return s;
  }
  // Start (b): the previous frame, translated into this frame's gauge (the energy and the
  // iteration are rotation-equivariant, so the rotation gauge is applied once, at the end).
  if (options.warm_start && prev) {
    Coords warm = *prev;
    Translate(p.group_centroids, &warm);
    Coords warm_rhs;
    const double warm_energy = Evaluate(warm, p, &warm_rhs, nullptr);
    if (warm_energy <= *energy) {
      *x = std::move(warm);
      *rhs = std::move(warm_rhs);
      *energy = warm_energy;
      report->warm_started = true;
    }
  }
  if (x->rows() == 0) {  // a trusted warm start that is not finite
    if (absl::Status s = cold_start(); !s.ok()) return s;
  }
  return absl::OkStatus();
}

absl::Status Inbetweener::Impl::ResolveOverlaps(Problem* p, const std::optional<Coords>& prev,
                                                Coords* x, const CancelToken* cancel,
                                                FrameReport* report) {
  const Coords unpushed = *x;
  absl::StatusOr<bool> inside_free = EnforceNonOverlap(p, x, cancel, report);
  if (!inside_free.ok()) return inside_free.status();
  Validity checked = Check(*x, *inside_free);
  if (!checked.clean()) {
    // The push-out left an overlap (or folded a triangle to make room): the frame stops where
    // the motion from the previous frame first meets one instead, when that frame is clean.
    if (checked.inverted > 0 && CountInverted(triangles, unpushed) == 0) {
      *x = unpushed;
      checked = Check(*x);
    }
    if (prev && Check(*prev).clean()) {
      Coords first_bad;
      report->hold_back = 1.0 - HoldBack(*prev, x, &first_bad);
      checked = Validity{};  // HoldBack's point is clean, and so is a resumed push kept
      // Continue from the clean frame where the motion met the overlap, with the contacts of
      // that meeting: the push then starts on the right side of every contact instead of
      // from deep inside. Kept when it comes out clean.
      Coords resumed = *x;
      absl::StatusOr<bool> resumed_free =
          EnforceNonOverlap(p, &resumed, cancel, report, overlap->Contacts(first_bad));
      if (!resumed_free.ok()) return resumed_free.status();
      if (Check(resumed).clean()) {
        *x = std::move(resumed);
        report->hold_back = 0.0;
      }
    }
  }
  known_validity = checked;
  return absl::OkStatus();
}

absl::StatusOr<Coords> Inbetweener::Impl::Dynamics(Problem* p, Coords x, const Coords& x1,
                                                   const Frame& before_previous,
                                                   const CancelToken* cancel, FrameReport* report) {
  const ExampleWeights& w = *p->w;
  const Coords x2 = before_previous.vertices.empty() ? x1 : ToCoords(before_previous.vertices);
  p->dynamic = true;
  p->rest.resize(triangles.size());
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    p->rest[t] = arap->DeformationGradient(x, t);
  }
  std::vector<Eigen::Matrix2d> scratch;
  const double delta = arap->LocalStepToRest(x1, p->rest, &scratch);
  p->beta_max = 0.5 * options.epsilon * mean_kappa;
  p->beta = p->beta_max / (delta + 1.0);
  report->xi = options.epsilon * options.h * options.h * mean_kappa / (options.rho * (delta + 1.0));
  p->pred = 2.0 * x1 - x2;
  Rotate(w, &p->pred);
  Translate(p->group_centroids, &p->pred);
  const Coords phi = x;
  Coords rhs;
  const double energy = Evaluate(x, *p, &rhs, nullptr);
  absl::StatusOr<Coords> solved = Iterate(*p, std::move(x), energy, std::move(rhs), cancel, report);
  if (!solved.ok()) return solved.status();
  x = *std::move(solved);
  p->dynamic = false;
  if (options.prevent_overlap && overlap->Count(x) > 0) return phi;  // keep the valid Phi
  return x;
}

absl::StatusOr<Coords> Inbetweener::Impl::Zhu17(const ExampleWeights& w, const Frame& previous,
                                                const Frame& before_previous,
                                                const CancelToken* cancel, FrameReport* report) {
  Problem p;
  p.w = &w;
  p.group_centroids = BlendedCentroids(w);
  std::optional<Coords> prev;
  if (!previous.vertices.empty()) prev = ToCoords(previous.vertices);
  p.thresholds = cohesive->Thresholds(prev ? &*prev : nullptr);
  Coords x, rhs;
  double energy = 0.0;
  if (absl::Status s = StartPoint(p, previous, prev, &x, &rhs, &energy, report); !s.ok()) {
    return s;
  }
  absl::StatusOr<Coords> solved = Iterate(p, std::move(x), energy, std::move(rhs), cancel, report);
  if (!solved.ok()) return solved.status();
  x = *std::move(solved);
  Rotate(w, &x);
  Translate(p.group_centroids, &x);
  if (options.prevent_overlap) {
    if (absl::Status s = ResolveOverlaps(&p, prev, &x, cancel, report); !s.ok()) return s;
  }
  if (options.epsilon <= 0.0 || !prev) return x;
  known_validity.reset();
  // Dynamics (S-eq.28/29): x is Phi.
  return Dynamics(&p, std::move(x), *prev, before_previous, cancel, report);
}

absl::StatusOr<Frame> Inbetweener::Impl::Solve(const ExampleWeights& weights, const Frame& previous,
                                               const Frame& before_previous,
                                               const CancelToken* cancel, FrameReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const int num_shapes = static_cast<int>(shapes.size());
  if (static_cast<int>(weights.size()) != num_shapes) {
    return absl::InvalidArgumentError(absl::StrCat(
        "weights has ", weights.size(), " values, the multimesh has ", num_shapes, " shapes"));
  }
  double sum = 0.0;
  int unit = -1;  // the example hit exactly, if weights == e_unit
  for (int i = 0; i < num_shapes; ++i) {
    if (!std::isfinite(weights[i])) {
      return absl::InvalidArgumentError(absl::StrCat("weights[", i, "] is not finite"));
    }
    if (options.method == InterpMethod::kZhu17 && weights[i] < 0.0) {
      return absl::InvalidArgumentError(absl::StrCat("weights[", i, "] = ", weights[i],
                                                     " is negative; kZhu17 needs weights >= 0"));
    }
    sum += weights[i];
    if (weights[i] == 1.0) unit = i;
  }
  if (std::abs(sum - 1.0) > 1e-9) {
    return absl::InvalidArgumentError(absl::StrCat("weights sum to ", sum, ", not 1"));
  }
  if (unit >= 0) {
    for (int i = 0; i < num_shapes; ++i) {
      if (i != unit && weights[i] != 0.0) unit = -1;
    }
  }
  for (const Frame* f : {&previous, &before_previous}) {
    if (!f->vertices.empty() && static_cast<int>(f->vertices.size()) != num_vertices()) {
      return absl::InvalidArgumentError(absl::StrCat("previous frame has ", f->vertices.size(),
                                                     " vertices, the multimesh has ",
                                                     num_vertices()));
    }
  }
  if (Cancelled(cancel)) {
    return absl::CancelledError("inbetweening cancelled");
  }

  FrameReport local;
  Coords x;
  known_validity.reset();
  if (unit >= 0 && options.exact_keys) {
    x = shapes[unit];
  } else if (options.method == InterpMethod::kLinear) {
    x = Coords::Zero(num_vertices(), 2);
    for (int i = 0; i < num_shapes; ++i) x += weights[i] * shapes[i];
  } else if (options.method == InterpMethod::kAlexa) {
    absl::StatusOr<Coords> r = Alexa(weights);
    if (!r.ok()) return r.status();
    x = *std::move(r);
  } else {
    absl::StatusOr<Coords> r = Zhu17(weights, previous, before_previous, cancel, &local);
    if (!r.ok()) return r.status();
    x = *std::move(r);
  }
  if (options.method != InterpMethod::kZhu17 || (unit >= 0 && options.exact_keys)) {
    local.energy = arap->Value(x, weights);
  }
  const Validity validity = known_validity ? *known_validity : Check(x);
  local.inverted = validity.inverted;
  local.overlaps = validity.overlaps;
  AreaRatios(x, weights, &local);
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report != nullptr) *report = local;
  Frame frame{ToPoints(x)};
  frame_before_last = std::move(last_frame);
  last_frame = frame.vertices;
  last_weights = weights;
  return frame;
}

Inbetweener::Inbetweener(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Inbetweener::Inbetweener(Inbetweener&&) noexcept = default;
Inbetweener& Inbetweener::operator=(Inbetweener&&) noexcept = default;
Inbetweener::~Inbetweener() = default;

absl::StatusOr<Inbetweener> Inbetweener::Create(const Multimesh& mesh, InbetweenOptions options) {
  if (absl::Status s = CheckMesh(mesh); !s.ok()) return s;
  if (options.max_iterations < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_iterations must be >= 0, got ", options.max_iterations));
  }
  if (!(options.convergence_tolerance >= 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("convergence_tolerance must be >= 0, got ", options.convergence_tolerance));
  }
  if (!(options.displacement_tolerance >= 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("displacement_tolerance must be >= 0, got ", options.displacement_tolerance));
  }
  if (!(options.epsilon >= 0.0) || !std::isfinite(options.epsilon)) {
    return absl::InvalidArgumentError(absl::StrCat("epsilon must be >= 0, got ", options.epsilon));
  }
  if (!(options.rho > 0.0) || !(options.h > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rho and h must be > 0, got rho = ", options.rho, ", h = ", options.h));
  }
  auto impl = std::make_unique<Impl>();
  impl->options = std::move(options);
  if (absl::Status s = impl->Setup(mesh); !s.ok()) return s;
  return Inbetweener(std::move(impl));
}

absl::StatusOr<Frame> Inbetweener::Solve(const ExampleWeights& weights, const Frame& previous,
                                         const CancelToken* cancel, FrameReport* report) {
  Impl& m = *impl_;
  Frame before;
  if (m.options.epsilon > 0.0 && !previous.vertices.empty() && previous.vertices == m.last_frame) {
    before.vertices = m.frame_before_last;
  }
  return m.Solve(weights, previous, before, cancel, report);
}

absl::StatusOr<Frame> Inbetweener::Solve(const ExampleWeights& weights, const Frame& previous,
                                         const Frame& before_previous, const CancelToken* cancel,
                                         FrameReport* report) {
  return impl_->Solve(weights, previous, before_previous, cancel, report);
}

absl::StatusOr<Frame> FrameSequence::Next(const ExampleWeights& weights, const CancelToken* cancel,
                                          FrameReport* report) {
  absl::StatusOr<Frame> f =
      inbetweener_->Solve(weights, previous_, before_previous_, cancel, report);
  if (!f.ok()) return f.status();
  before_previous_ = std::move(previous_);
  previous_ = *f;
  return f;
}

}  // namespace inbetween::solver
