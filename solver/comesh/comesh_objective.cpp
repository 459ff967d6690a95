// Comesh objective: (1 - w) * normalized ODT (S-eq.1) + w * normalized cyclic MIPS (S-eq.2).
#include "solver/comesh/comesh_objective.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/comesh/comesh_topology.h"
#include "solver/comesh/mips_energy.h"
#include "solver/comesh/odt_energy.h"
#include "solver/core/parallel_chunks.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {

absl::StatusOr<ComeshObjective> ComeshObjective::Create(const std::vector<Triangle>& triangles,
                                                        const std::vector<Points>& rest,
                                                        double map_weight, int threads,
                                                        bool area_invariant) {
  if (rest.empty()) return absl::InvalidArgumentError("comesh objective needs at least one shape");
  if (!(map_weight >= 0.0 && map_weight <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("map weight ", map_weight, " must lie in [0, 1]"));
  }
  const int n = static_cast<int>(rest[0].size());
  for (size_t s = 1; s < rest.size(); ++s) {
    if (static_cast<int>(rest[s].size()) != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("shape ", s, " has ", rest[s].size(), " vertices, shape 0 has ", n));
    }
  }
  for (size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    if (const std::optional<int> v = IndexOutOfRange(tri, n)) {
      return absl::InvalidArgumentError(
          absl::StrCat("triangle ", t, " has vertex index ", *v, " outside [0, ", n, ")"));
    }
    if (RepeatsVertex(tri)) {
      return absl::InvalidArgumentError(absl::StrCat("triangle ", t, " repeats a vertex"));
    }
  }
  ComeshObjective o;
  o.triangles_ = triangles;
  o.num_vertices_ = n;
  o.map_weight_ = map_weight;
  for (size_t s = 0; s < rest.size(); ++s) {
    double area = 0.0;
    for (const Triangle& t : triangles) area += 0.5 * std::abs(SignedArea2(t, rest[s]));
    if (!(area > 0.0) || !std::isfinite(area)) {
      return absl::InvalidArgumentError(absl::StrCat("shape ", s, " has zero or invalid area"));
    }
    o.areas_.push_back(area);
    o.odt_normalizer_.push_back(OdtNormalization(triangles, rest[s]));
  }
  o.threads_ = ResolveThreads(threads);
  o.mesh_scale_ = o.odt_normalizer_;
  o.map_scale_ = o.areas_;
  o.area_invariant_ = area_invariant;
  if (area_invariant) {
    // Edges used by one triangle (EdgeUses: sorted), in that triangle's orientation, in
    // triangle order.
    const std::vector<std::pair<std::pair<int, int>, int>> uses =
        EdgeUses(triangles, std::vector<char>(triangles.size(), 1));
    auto boundary = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto it =
          std::lower_bound(uses.begin(), uses.end(), key,
                           [](const auto& use, const auto& k) { return use.first < k; });
      return it != uses.end() && it->first == key && it->second == 1;
    };
    for (const Triangle& t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const int a = t[k], b = t[(k + 1) % 3];
        if (boundary(a, b)) o.boundary_edges_.push_back({a, b});
      }
    }
  }
  o.corner_begin_.assign(n + 1, 0);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) ++o.corner_begin_[t[k] + 1];
  }
  for (int v = 0; v < n; ++v) o.corner_begin_[v + 1] += o.corner_begin_[v];
  o.corners_.resize(3 * triangles.size());
  std::vector<int> fill(o.corner_begin_.begin(), o.corner_begin_.end() - 1);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) o.corners_[fill[triangles[t][k]]++] = static_cast<int>(3 * t + k);
  }
  return o;
}

void ComeshObjective::TriangleTerms(const Triangle& t, const std::vector<Points>& shapes,
                                    double* odt, double* mips) const {
  *odt = 0.0;
  *mips = 0.0;
  if (!AccumulateTriangle(t, shapes, odt, mips)) {
    *odt = *mips = std::numeric_limits<double>::infinity();
  }
}

double ComeshObjective::TriangleTerm(const Triangle& t, const std::vector<Points>& shapes) const {
  double odt, mips;
  TriangleTerms(t, shapes, &odt, &mips);
  return (1.0 - map_weight_) * odt + map_weight_ * mips;
}

bool ComeshObjective::AccumulateTriangle(const Triangle& tri, const std::vector<Points>& shapes,
                                         double* mesh_sum, double* map_sum,
                                         Point* corner_gradient, double* shape_sums) const {
  const int n = num_shapes();
  const double w = map_weight_;
  Point* cg = corner_gradient;
  std::array<Point, 3> g_odt, g_i, g_j;
  if (cg != nullptr) {
    for (int k = 0; k < 3 * n; ++k) cg[k].setZero();
  }
  for (int i = 0; i < n; ++i) {
    const Points& xi = shapes[i];
    const int j = (i + 1) % n;
    const Points& xj = shapes[j];
    const std::array<Point, 3> ci = {xi[tri[0]], xi[tri[1]], xi[tri[2]]};
    const std::array<Point, 3> cj = {xj[tri[0]], xj[tri[1]], xj[tri[2]]};
    const double d = OdtTriangleEnergy(ci[0], ci[1], ci[2], cg != nullptr ? &g_odt : nullptr);
    const double c =
        MipsTriangleEnergy(ci, cj, cg != nullptr ? &g_i : nullptr, cg != nullptr ? &g_j : nullptr);
    if (!std::isfinite(d) || !std::isfinite(c)) return false;
    *mesh_sum += d / mesh_scale_[i];
    *map_sum += c / map_scale_[i];
    if (shape_sums != nullptr) {
      shape_sums[i] += d / mesh_scale_[i];
      shape_sums[n + i] += c / map_scale_[i];
    }
    if (cg != nullptr) {
      const double sd = (1.0 - w) / mesh_scale_[i];
      const double sc = w / map_scale_[i];
      for (int k = 0; k < 3; ++k) {
        cg[k * n + i] += sd * g_odt[k] + sc * g_i[k];
        cg[k * n + j] += sc * g_j[k];
      }
    }
  }
  return true;
}

double ComeshObjective::Evaluate(const std::vector<Points>& shapes, std::vector<Points>* gradient,
                                 ComeshEnergies* energies, const CancelToken* cancel) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr int kChunk = 2048;  // triangles per chunk (fixed: results independent of threads)
  const int n = num_shapes();
  const int num_triangles = static_cast<int>(triangles_.size());
  const double w = map_weight_;
  const bool want_gradient = gradient != nullptr;
  if (want_gradient) corner_gradient_.resize(static_cast<size_t>(3) * num_triangles * n);
  const int chunks = NumChunks(num_triangles, kChunk);
  // Area-invariant mode: the current areas (from the boundary edges) set the normalizers.
  std::vector<double> area(n, 0.0);
  if (area_invariant_) {
    for (int i = 0; i < n; ++i) {
      const Points& x = shapes[i];
      for (const auto& [a, b] : boundary_edges_) {
        area[i] += 0.5 * Cross(x[a], x[b]);
      }
      if (!(area[i] > 0.0) || !std::isfinite(area[i])) return kInf;
      const double r = area[i] / areas_[i];
      mesh_scale_[i] = odt_normalizer_[i] * r * r;
      map_scale_[i] = area[i];
    }
  }
  // Per chunk: sum of D_t / N_i and of C_t / A_i over its triangles and shapes; NaN if invalid.
  // Area-invariant mode: also per shape (2 n per chunk, for the gradient's area term).
  std::vector<double> mesh_part(chunks, 0.0), map_part(chunks, 0.0);
  std::vector<double> shape_part(area_invariant_ ? static_cast<size_t>(chunks) * 2 * n : 0, 0.0);
  ParallelChunks(num_triangles, kChunk, threads_, [&](int chunk, int begin, int end) {
    if (Cancelled(cancel)) return;  // the result is NaN below
    double mesh_sum = 0.0, map_sum = 0.0;
    double* shape_sums =
        area_invariant_ ? &shape_part[static_cast<size_t>(chunk) * 2 * n] : nullptr;
    for (int t = begin; t < end; ++t) {
      const Triangle& tri = triangles_[t];
      Point* cg = want_gradient ? &corner_gradient_[static_cast<size_t>(3) * t * n] : nullptr;
      if (!AccumulateTriangle(tri, shapes, &mesh_sum, &map_sum, cg, shape_sums)) {
        mesh_part[chunk] = map_part[chunk] = kInf;
        return;
      }
    }
    mesh_part[chunk] = mesh_sum;
    map_part[chunk] = map_sum;
  });
  double mesh_sum = 0.0, map_sum = 0.0;
  // Chunks skipped after a cancel left zeros: the sums mean nothing then.
  if (Cancelled(cancel)) return std::numeric_limits<double>::quiet_NaN();
  for (int c = 0; c < chunks; ++c) {
    mesh_sum += mesh_part[c];
    map_sum += map_part[c];
  }
  if (!std::isfinite(mesh_sum) || !std::isfinite(map_sum)) return kInf;
  if (want_gradient) {
    gradient->resize(n);
    for (Points& g : *gradient) g.resize(num_vertices_);
    ParallelChunks(num_vertices_, 4096, threads_, [&](int, int begin, int end) {
      for (int v = begin; v < end; ++v) {
        for (int i = 0; i < n; ++i) {
          Point sum = Point::Zero();
          for (int c = corner_begin_[v]; c < corner_begin_[v + 1]; ++c) {
            sum += corner_gradient_[static_cast<size_t>(corners_[c]) * n + i];
          }
          (*gradient)[i][v] = sum;
        }
      }
    });
    if (area_invariant_) {
      // dE/dX_i += -(2 E_i^mesh + E_i^map) / A_i(X) dA_i/dX_i, A_i = 1/2 sum over the boundary
      // edges (a, b) of cross(x_a, x_b). Serial, in a fixed order.
      for (int i = 0; i < n; ++i) {
        double mesh_i = 0.0, map_i = 0.0;
        for (int c = 0; c < chunks; ++c) {
          mesh_i += shape_part[static_cast<size_t>(c) * 2 * n + i];
          map_i += shape_part[static_cast<size_t>(c) * 2 * n + n + i];
        }
        const double coef = -(2.0 * (1.0 - w) * mesh_i + w * map_i) / area[i];
        const Points& x = shapes[i];
        Points& g = (*gradient)[i];
        for (const auto& [a, b] : boundary_edges_) {
          g[a] += 0.5 * coef * Point(x[b].y(), -x[b].x());
          g[b] += 0.5 * coef * Point(-x[a].y(), x[a].x());
        }
      }
    }
  }
  const double objective = (1.0 - w) * mesh_sum + w * map_sum;
  if (energies != nullptr) {
    energies->objective = objective;
    energies->mesh = mesh_sum / n;
    energies->map = map_sum / n;
  }
  return objective;
}

}  // namespace inbetween::solver
