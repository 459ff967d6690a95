// Arc-length resampling of a closed outline to a fixed vertex count, keeping its corners.
#include "solver/geometry/resample_outline.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {

std::vector<int> FindCorners(const Points& outline, double corner_angle_degrees) {
  const int n = static_cast<int>(outline.size());
  const double threshold = corner_angle_degrees * M_PI / 180.0;
  std::vector<int> corners;
  for (int i = 0; i < n; ++i) {
    const Point a = outline[i] - outline[(i + n - 1) % n];
    const Point b = outline[(i + 1) % n] - outline[i];
    const double turn = std::atan2(Cross(a, b), a.dot(b));
    if (std::abs(turn) > threshold) corners.push_back(i);
  }
  return corners;
}

Points ResampleOutline(const Points& outline, int count, const ResampleOptions& options) {
  const std::vector<double> cum = CumulativeLength(outline);
  const double total = cum.back();
  std::vector<int> corners = FindCorners(outline, options.corner_angle_degrees);
  Points out;
  out.reserve(count);
  if (corners.empty() || static_cast<int>(corners.size()) > count) {
    for (int k = 0; k < count; ++k) {
      out.push_back(PointAtArcLength(outline, cum, total * k / count, SegmentEnds::kInterpolate));
    }
    return out;
  }
  // Arcs between consecutive corners get the remaining vertices in proportion to their length
  // (largest remainder, ties to the earlier arc, so the result is deterministic).
  const int k_corners = static_cast<int>(corners.size());
  const int spare = count - k_corners;
  std::vector<double> length(k_corners);
  for (int j = 0; j < k_corners; ++j) {
    const double start = cum[corners[j]];
    const double end = j + 1 < k_corners ? cum[corners[j + 1]] : cum[corners[0]] + total;
    length[j] = end - start;
  }
  std::vector<int> extra(k_corners);
  std::vector<double> remainder(k_corners);
  int assigned = 0;
  for (int j = 0; j < k_corners; ++j) {
    const double ideal = spare * length[j] / total;
    extra[j] = static_cast<int>(std::floor(ideal));
    remainder[j] = ideal - extra[j];
    assigned += extra[j];
  }
  std::vector<int> order(k_corners);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return remainder[a] > remainder[b]; });
  for (int r = 0; assigned < spare; ++r, ++assigned) ++extra[order[r % k_corners]];
  for (int j = 0; j < k_corners; ++j) {
    out.push_back(outline[corners[j]]);
    for (int k = 1; k <= extra[j]; ++k) {
      const double u = cum[corners[j]] + length[j] * k / (extra[j] + 1);
      out.push_back(PointAtArcLength(outline, cum, u, SegmentEnds::kInterpolate));
    }
  }
  return out;
}

}  // namespace inbetween::solver
