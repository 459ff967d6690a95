// Comesh objective: (1 - w) * normalized ODT (S-eq.1) + w * normalized cyclic MIPS (S-eq.2).
#include "solver/comesh/comesh_objective.h"

#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "solver/comesh/mips_energy.h"
#include "solver/comesh/odt_energy.h"

namespace inbetween::solver {

absl::StatusOr<ComeshObjective> ComeshObjective::Create(const std::vector<Triangle>& triangles,
                                                        const std::vector<Points>& rest,
                                                        double map_weight) {
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
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("triangle ", t, " has vertex index ", tri[k], " outside [0, ", n, ")"));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      return absl::InvalidArgumentError(absl::StrCat("triangle ", t, " repeats a vertex"));
    }
  }
  ComeshObjective o;
  o.triangles_ = triangles;
  o.num_vertices_ = n;
  o.map_weight_ = map_weight;
  for (size_t s = 0; s < rest.size(); ++s) {
    double area = 0.0;
    for (const Triangle& t : triangles) {
      const Point ab = rest[s][t[1]] - rest[s][t[0]];
      const Point ac = rest[s][t[2]] - rest[s][t[0]];
      area += 0.5 * std::abs(ab.x() * ac.y() - ab.y() * ac.x());
    }
    if (!(area > 0.0) || !std::isfinite(area)) {
      return absl::InvalidArgumentError(absl::StrCat("shape ", s, " has zero or invalid area"));
    }
    o.areas_.push_back(area);
    o.odt_normalizer_.push_back(OdtNormalization(triangles, rest[s]));
  }
  return o;
}

double ComeshObjective::Evaluate(const std::vector<Points>& shapes, std::vector<Points>* gradient,
                                 ComeshEnergies* energies) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int n = num_shapes();
  const double w = map_weight_;
  if (gradient != nullptr) {
    gradient->assign(n, Points(num_vertices_, Point::Zero()));
  }
  Points gi, gj;
  double mesh_sum = 0.0;
  double map_sum = 0.0;
  for (int i = 0; i < n; ++i) {
    // Mesh term of shape i.
    if (gradient != nullptr) gi.assign(num_vertices_, Point::Zero());
    const double d = OdtEnergy(triangles_, shapes[i], gradient ? &gi : nullptr);
    if (!std::isfinite(d)) return kInf;
    mesh_sum += d / odt_normalizer_[i];
    if (gradient != nullptr && w < 1.0) {
      const double scale = (1.0 - w) / odt_normalizer_[i];
      for (int v = 0; v < num_vertices_; ++v) (*gradient)[i][v] += scale * gi[v];
    }
    // Map term from shape i to shape j = i + 1 (mod n).
    const int j = (i + 1) % n;
    if (gradient != nullptr) {
      gi.assign(num_vertices_, Point::Zero());
      gj.assign(num_vertices_, Point::Zero());
    }
    Points* gj_ptr = (j == i) ? &gi : &gj;  // one shape: both derivatives land on X_i
    const double c = MipsEnergy(triangles_, shapes[i], shapes[j], gradient ? &gi : nullptr,
                                gradient ? gj_ptr : nullptr);
    if (!std::isfinite(c)) return kInf;
    map_sum += c / areas_[i];
    if (gradient != nullptr && w > 0.0) {
      const double scale = w / areas_[i];
      for (int v = 0; v < num_vertices_; ++v) (*gradient)[i][v] += scale * gi[v];
      if (j != i) {
        for (int v = 0; v < num_vertices_; ++v) (*gradient)[j][v] += scale * gj[v];
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
