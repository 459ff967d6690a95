// The least-squares affine map between two point lists: the loop matching carries drawing 1's
// loops by it (boundary_loop_matching.cpp), and the map into another drawing starts from it
// when it folds nothing (map_to_boundary.cpp).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <utility>
#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// An affine map p -> m p + t.
struct Affine {
  Eigen::Matrix2d m = Eigen::Matrix2d::Identity();
  Point t = Point::Zero();
  Point operator()(const Point& p) const { return m * p + t; }
};

// The least-squares affine map taking a(k) to b(k) for k in [0, n). False when the a(k) do not
// spread in two directions (the determinant of their scatter at most 1e-12 of its squared norm:
// nearly collinear points leave the map across them to noise), or the map is not finite or
// reverses orientation; `fit` is then unspecified.
template <typename A, typename B>
bool FitAffine(int n, A&& a, B&& b, Affine* fit) {
  if (n <= 0) return false;
  Point ca = Point::Zero(), cb = Point::Zero();
  for (int k = 0; k < n; ++k) ca += a(k), cb += b(k);
  ca /= static_cast<double>(n);
  cb /= static_cast<double>(n);
  Eigen::Matrix2d aa = Eigen::Matrix2d::Zero(), ba = Eigen::Matrix2d::Zero();
  for (int k = 0; k < n; ++k) {
    const Point da = a(k) - ca;
    aa += da * da.transpose();
    ba += (b(k) - cb) * da.transpose();
  }
  if (!(std::abs(aa.determinant()) > 1e-12 * aa.squaredNorm())) return false;
  fit->m = ba * aa.inverse();
  fit->t = cb - fit->m * ca;
  return fit->m.allFinite() && fit->t.allFinite() && fit->m.determinant() > 0.0;
}

// The same for pairs (first -> second).
inline bool FitAffine(const std::vector<std::pair<Point, Point>>& pairs, Affine* fit) {
  return FitAffine(
      static_cast<int>(pairs.size()), [&](int k) { return pairs[k].first; },
      [&](int k) { return pairs[k].second; }, fit);
}

}  // namespace inbetween::solver
