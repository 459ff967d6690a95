// Inbetweening of a multimesh at given example weights w (the sum_i w_i W_D(X_i, x) part of the
// per-frame objective in DESIGN.md; cohesion S-eq.4-16, non-overlap S-eq.8/9 and dynamics
// S-eq.28/29 come with later issues).
//  - kLinear: x = sum_i w_i X_i.
//  - kAlexa (Alexa, Cohen-Or, Levin 2000): per triangle A_i = R(theta_i) S_i from example 0 to i
//    (example_rotations.h); target J*_t = R(sum_i w_i theta_it) sum_i w_i S_it; one least-squares
//    solve min sum_t kappa_t A_0t ||J_t(x) - J*_t||^2 whose matrix (the Laplacian K_0 of example
//    0) is factored once in Create.
//  - kZhu17: local-global minimization of sum_i w_i W_D(X_i, x) (S-eq.3, arap_energy.h), started
//    from the kAlexa solution. The global matrix sum_i w_i K_i changes with w but its pattern
//    does not: CHOLMOD analyzes it once in Create and refactors numerically once per distinct
//    weight vector (every iteration of a frame reuses it).
// Translation gauge (all methods): W_D is invariant to translating each connected component, so
// the lowest-index vertex of each component is pinned during the solve (making the reduced
// matrices positive definite) and the component is then shifted so that its mass-weighted
// centroid c(x) = sum_v m_v x_v / sum_v m_v equals sum_i w_i c(X_i). The vertex masses m_v (a
// third of the adjacent triangles' areas, averaged over the examples) are the same for all shapes,
// so c is linear and the key shapes keep their own centroids.
#include "solver/interp/inbetweener.h"

#include <chrono>
#include <cmath>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/core/sparse_cholesky.h"
#include "solver/interp/arap_energy.h"
#include "solver/interp/example_rotations.h"
#include "solver/interp/polar.h"

namespace inbetween::solver {
namespace {

// Signed area <= 0 in raw coordinates (see types.h for the orientation convention).
int CountInverted(const std::vector<Triangle>& triangles, const Coords& x) {
  int inverted = 0;
  for (const Triangle& t : triangles) {
    const Eigen::Vector2d e1 = x.row(t[1]) - x.row(t[0]);
    const Eigen::Vector2d e2 = x.row(t[2]) - x.row(t[0]);
    if (!(e1.x() * e2.y() - e1.y() * e2.x() > 0.0)) ++inverted;
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

}  // namespace

struct Inbetweener::Impl {
  InbetweenOptions options;
  std::vector<Triangle> triangles;
  std::vector<Coords> shapes;
  std::vector<ArapEnergy> energies;  // W_D(X_i, .) per example
  ExampleRotations rotations;        // Alexa split, unwrapped

  // Gauge.
  std::vector<int> component;  // per vertex
  int num_components = 0;
  std::vector<double> mass;                             // m_v
  std::vector<double> component_mass;                   // sum of m_v per component
  std::vector<std::vector<Eigen::Vector2d>> centroids;  // [example][component]
  std::vector<int> free_index;                          // reduced index, -1 for pinned vertices
  int num_free = 0;

  // Reduced (pinned rows/columns removed) Laplacians: one pattern, values per example.
  Eigen::SparseMatrix<double> reduced;
  std::vector<Eigen::VectorXd> reduced_values;
  SparseCholesky alexa_solver;  // K_0, factored in Create
  SparseCholesky zhu_solver;    // sum_i w_i K_i, analyzed in Create
  ExampleWeights zhu_factored_weights;

  int num_vertices() const { return static_cast<int>(free_index.size()); }

  absl::Status Setup(const Multimesh& mesh);
  void ApplyGauge(const ExampleWeights& w, Coords* x) const;
  absl::StatusOr<Coords> SolveReduced(const SparseCholesky& solver, const Coords& b,
                                      const ExampleWeights& w) const;
  double BlendedEnergy(const ExampleWeights& w, const Coords& x) const;
  absl::StatusOr<Coords> Alexa(const ExampleWeights& w) const;
  absl::StatusOr<Coords> Zhu17(const ExampleWeights& w, const Frame& previous,
                               const CancelToken* cancel, FrameReport* report);
};

absl::Status Inbetweener::Impl::Setup(const Multimesh& mesh) {
  triangles = mesh.triangles;
  const int n = mesh.num_vertices();
  const int num_shapes = mesh.num_shapes();
  for (int i = 0; i < num_shapes; ++i) {
    absl::StatusOr<ArapEnergy> e = ArapEnergy::Create(triangles, mesh.shapes[i], options.stiffness);
    if (!e.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("shape ", i, ": ", e.status().message()));
    }
    energies.push_back(*std::move(e));
    shapes.push_back(ToCoords(mesh.shapes[i]));
  }
  rotations = ComputeExampleRotations(triangles, mesh.shapes);

  // Connected components by shared vertices (union-find, roots = lowest index).
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::vector<char> used(n, 0);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      used[t[k]] = 1;
      const int a = find(t[k]);
      const int b = find(t[(k + 1) % 3]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  for (int v = 0; v < n; ++v) {
    if (!used[v]) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", v, " is in no triangle"));
    }
  }
  component.assign(n, -1);
  free_index.assign(n, -1);
  std::vector<int> root_component(n, -1);
  for (int v = 0; v < n; ++v) {
    const int r = find(v);
    if (root_component[r] < 0) {
      root_component[r] = num_components++;  // v == r: the pinned vertex
    } else {
      free_index[v] = num_free++;
    }
    component[v] = root_component[r];
  }

  mass.assign(n, 0.0);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    double area = 0.0;
    for (const ArapEnergy& e : energies) area += e.rest_area(t);
    area /= static_cast<double>(num_shapes);
    for (int k = 0; k < 3; ++k) mass[triangles[t][k]] += area / 3.0;
  }
  component_mass.assign(num_components, 0.0);
  for (int v = 0; v < n; ++v) component_mass[component[v]] += mass[v];
  centroids.assign(num_shapes,
                   std::vector<Eigen::Vector2d>(num_components, Eigen::Vector2d::Zero()));
  for (int i = 0; i < num_shapes; ++i) {
    for (int v = 0; v < n; ++v) {
      centroids[i][component[v]] += mass[v] * shapes[i].row(v).transpose();
    }
    for (int c = 0; c < num_components; ++c) centroids[i][c] /= component_mass[c];
  }

  // Reduced Laplacians. Every K_i has the same pattern (triangle list only), and the reduction
  // keeps it, so one analysis serves every weighted sum.
  for (int i = 0; i < num_shapes; ++i) {
    const Eigen::SparseMatrix<double>& k = energies[i].Laplacian();
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
    if (i == 0) {
      reduced = r;
    } else if (r.nonZeros() != reduced.nonZeros() ||
               !std::equal(r.innerIndexPtr(), r.innerIndexPtr() + r.nonZeros(),
                           reduced.innerIndexPtr())) {
      return absl::InternalError("example Laplacians do not share one sparsity pattern");
    }
    reduced_values.push_back(Eigen::Map<const Eigen::VectorXd>(r.valuePtr(), r.nonZeros()));
  }
  if (absl::Status s = alexa_solver.Compute(reduced); !s.ok()) {
    return absl::InternalError(absl::StrCat("factoring example 0's ARAP matrix: ", s.message()));
  }
  if (absl::Status s = zhu_solver.Analyze(reduced); !s.ok()) return s;
  return absl::OkStatus();
}

void Inbetweener::Impl::ApplyGauge(const ExampleWeights& w, Coords* x) const {
  std::vector<Eigen::Vector2d> shift(num_components, Eigen::Vector2d::Zero());
  for (int v = 0; v < num_vertices(); ++v) {
    shift[component[v]] -= mass[v] * x->row(v).transpose();
  }
  for (int c = 0; c < num_components; ++c) {
    shift[c] /= component_mass[c];
    for (size_t i = 0; i < w.size(); ++i) shift[c] += w[i] * centroids[i][c];
  }
  for (int v = 0; v < num_vertices(); ++v) x->row(v) += shift[component[v]].transpose();
}

absl::StatusOr<Coords> Inbetweener::Impl::SolveReduced(const SparseCholesky& solver,
                                                       const Coords& b,
                                                       const ExampleWeights& w) const {
  Eigen::MatrixXd rhs(num_free, 2);
  for (int v = 0; v < num_vertices(); ++v) {
    if (free_index[v] >= 0) rhs.row(free_index[v]) = b.row(v);
  }
  absl::StatusOr<Eigen::MatrixXd> sol = solver.Solve(rhs);
  if (!sol.ok()) return sol.status();
  Coords x = Coords::Zero(num_vertices(), 2);  // pinned vertices at 0, moved by the gauge
  for (int v = 0; v < num_vertices(); ++v) {
    if (free_index[v] >= 0) x.row(v) = sol->row(free_index[v]);
  }
  ApplyGauge(w, &x);
  return x;
}

double Inbetweener::Impl::BlendedEnergy(const ExampleWeights& w, const Coords& x) const {
  double e = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    if (w[i] != 0.0) e += w[i] * energies[i].Value(x);
  }
  return e;
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
  energies[0].AddRhs(targets, 1.0, &b);
  return SolveReduced(alexa_solver, b, w);
}

absl::StatusOr<Coords> Inbetweener::Impl::Zhu17(const ExampleWeights& w, const Frame& previous,
                                                const CancelToken* cancel, FrameReport* report) {
  Coords x;
  if (options.warm_start && !previous.vertices.empty()) {
    x = ToCoords(previous.vertices);
    ApplyGauge(w, &x);
  } else {
    absl::StatusOr<Coords> start = Alexa(w);
    if (!start.ok()) return start.status();
    x = *std::move(start);
  }
  if (w != zhu_factored_weights) {
    Eigen::SparseMatrix<double> k = reduced;
    Eigen::Map<Eigen::VectorXd> values(k.valuePtr(), k.nonZeros());
    values.setZero();
    for (size_t i = 0; i < w.size(); ++i) {
      if (w[i] != 0.0) values += w[i] * reduced_values[i];
    }
    zhu_factored_weights.clear();
    if (absl::Status s = zhu_solver.Factorize(k); !s.ok()) return s;
    zhu_factored_weights = w;
  }

  // Energy of J = 0 everywhere: a scale for "the energy is zero up to rounding".
  double scale = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
      scale += w[i] * 2.0 * energies[i].rest_area(t) *
               (options.stiffness.empty() ? 1.0 : options.stiffness[t]);
    }
  }
  std::vector<std::vector<Eigen::Matrix2d>> fitted(w.size());
  double energy = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    if (w[i] == 0.0) continue;
    fitted[i] = energies[i].FitRotations(x);
    energy += w[i] * energies[i].Value(x, fitted[i]);
  }
  int iterations = 0;
  while (iterations < options.max_iterations && energy > 1e-24 * scale) {
    if (cancel != nullptr && cancel->IsCancelled()) {
      return absl::CancelledError("inbetweening cancelled");
    }
    Coords b = Coords::Zero(num_vertices(), 2);
    for (size_t i = 0; i < w.size(); ++i) {
      if (w[i] != 0.0) energies[i].AddRhs(fitted[i], w[i], &b);
    }
    absl::StatusOr<Coords> next = SolveReduced(zhu_solver, b, w);
    if (!next.ok()) return next.status();
    x = *std::move(next);
    ++iterations;
    const double previous_energy = energy;
    energy = 0.0;
    for (size_t i = 0; i < w.size(); ++i) {
      if (w[i] == 0.0) continue;
      fitted[i] = energies[i].FitRotations(x);
      energy += w[i] * energies[i].Value(x, fitted[i]);
    }
    if (previous_energy - energy <= options.convergence_tolerance * previous_energy) break;
  }
  if (report != nullptr) {
    report->iterations = iterations;
    report->energy = energy;
  }
  return x;
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
  auto impl = std::make_unique<Impl>();
  impl->options = std::move(options);
  if (absl::Status s = impl->Setup(mesh); !s.ok()) return s;
  return Inbetweener(std::move(impl));
}

absl::StatusOr<Frame> Inbetweener::Solve(const ExampleWeights& weights, const Frame& previous,
                                         const CancelToken* cancel, FrameReport* report) {
  const auto start = std::chrono::steady_clock::now();
  Impl& m = *impl_;
  const int num_shapes = static_cast<int>(m.shapes.size());
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
    if (m.options.method == InterpMethod::kZhu17 && weights[i] < 0.0) {
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
  if (!previous.vertices.empty() &&
      static_cast<int>(previous.vertices.size()) != m.num_vertices()) {
    return absl::InvalidArgumentError(absl::StrCat("previous frame has ", previous.vertices.size(),
                                                   " vertices, the multimesh has ",
                                                   m.num_vertices()));
  }
  if (cancel != nullptr && cancel->IsCancelled()) {
    return absl::CancelledError("inbetweening cancelled");
  }

  FrameReport local_report;
  Coords x;
  if (unit >= 0 && m.options.exact_keys) {
    x = m.shapes[unit];
  } else if (m.options.method == InterpMethod::kLinear) {
    x = Coords::Zero(m.num_vertices(), 2);
    for (int i = 0; i < num_shapes; ++i) x += weights[i] * m.shapes[i];
  } else if (m.options.method == InterpMethod::kAlexa) {
    absl::StatusOr<Coords> r = m.Alexa(weights);
    if (!r.ok()) return r.status();
    x = *std::move(r);
  } else {
    absl::StatusOr<Coords> r = m.Zhu17(weights, previous, cancel, &local_report);
    if (!r.ok()) return r.status();
    x = *std::move(r);
  }
  if (m.options.method != InterpMethod::kZhu17 || (unit >= 0 && m.options.exact_keys)) {
    local_report.energy = m.BlendedEnergy(weights, x);
  }
  local_report.inverted = CountInverted(m.triangles, x);
  local_report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report != nullptr) *report = local_report;
  return Frame{ToPoints(x)};
}

}  // namespace inbetween::solver
