// Validators for meshes and multimeshes: orientation of every triangle in every shape.
#include "solver/mesh/validate.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {

double SignedArea2(const Triangle& t, const Points& x) {
  const Point e1 = x[t[1]] - x[t[0]];
  const Point e2 = x[t[2]] - x[t[0]];
  return e1.x() * e2.y() - e1.y() * e2.x();
}

int CountInverted(const std::vector<Triangle>& triangles, const Points& x, double min_area2) {
  int count = 0;
  for (const Triangle& t : triangles) {
    const double a = SignedArea2(t, x);
    if (!(a > min_area2)) ++count;  // NaN counts as inverted
  }
  return count;
}

absl::Status ValidateMultimesh(const Multimesh& mesh) {
  if (mesh.shapes.empty()) return absl::InvalidArgumentError("multimesh has no shapes");
  const int n = mesh.num_vertices();
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    if (static_cast<int>(mesh.shapes[s].size()) != n) {
      return absl::InvalidArgumentError(absl::StrCat(
          "multimesh shape ", s, " has ", mesh.shapes[s].size(), " vertices, shape 0 has ", n));
    }
    for (int v = 0; v < n; ++v) {
      if (!mesh.shapes[s][v].allFinite()) {
        return absl::InvalidArgumentError(
            absl::StrCat("multimesh shape ", s, " vertex ", v, " is not finite"));
      }
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= n) {
        return absl::InvalidArgumentError(absl::StrCat(
            "multimesh triangle ", t, " has vertex index ", tri[k], " out of range [0, ", n, ")"));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh triangle ", t, " repeats a vertex"));
    }
  }
  for (int v : mesh.boundary) {
    if (v < 0 || v >= n) {
      return absl::InvalidArgumentError(
          absl::StrCat("multimesh boundary vertex ", v, " out of range [0, ", n, ")"));
    }
  }
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const double a = SignedArea2(mesh.triangles[t], mesh.shapes[s]);
      if (!(a > 0)) {
        return absl::InvalidArgumentError(absl::StrCat("multimesh shape ", s, " triangle ", t,
                                                       a == 0 ? " is degenerate" : " is inverted",
                                                       " (signed area ", 0.5 * a, ")"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace inbetween::solver
