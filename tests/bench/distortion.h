// The benchmarks' isometric distortion measure, shared so that every table reports the same one.
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <limits>

#include "solver/mesh/multimesh.h"

namespace inbetween::bench {

// max over triangles of max(sigma_1, 1 / sigma_2) of the affine map rest -> x (1 = every triangle
// moved rigidly; infinity when a triangle is inverted or flat).
inline double MaxDistortion(const solver::Multimesh& mesh, const solver::Points& rest,
                            const solver::Points& x) {
  double worst = 1.0;
  for (const solver::Triangle& t : mesh.triangles) {
    Eigen::Matrix2d d, e;
    d << rest[t[1]] - rest[t[0]], rest[t[2]] - rest[t[0]];
    e << x[t[1]] - x[t[0]], x[t[2]] - x[t[0]];
    const Eigen::Matrix2d j = e * d.inverse();
    if (!(j.determinant() > 0.0)) return std::numeric_limits<double>::infinity();
    const Eigen::Vector2d s = Eigen::JacobiSVD<Eigen::Matrix2d>(j).singularValues();
    worst = std::max({worst, s(0), 1.0 / s(1)});
  }
  return worst;
}

}  // namespace inbetween::bench
