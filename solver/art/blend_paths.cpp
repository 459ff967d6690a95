// Arc-length morph of corresponding polylines (see blend_paths.h).
#include "solver/art/blend_paths.h"

#include <algorithm>

namespace inbetween::solver {

std::vector<double> ArcLengthParameters(const Points& path, bool closed) {
  const size_t n = path.size();
  std::vector<double> params(n, 0.0);
  for (size_t i = 1; i < n; ++i) params[i] = params[i - 1] + (path[i] - path[i - 1]).norm();
  const double total =
      n == 0 ? 0.0 : params[n - 1] + (closed ? (path[0] - path[n - 1]).norm() : 0.0);
  if (!(total > 0.0)) return std::vector<double>(n, 0.0);
  for (double& p : params) p /= total;
  if (!closed) params[n - 1] = 1.0;  // exactly, whatever the rounding of the sum
  return params;
}

Point PointAtParameter(const Points& path, bool closed, const std::vector<double>& params,
                       double u) {
  const size_t n = path.size();
  if (n == 1 || params.back() == 0.0) return path[0];
  const size_t i = std::upper_bound(params.begin(), params.end(), u) - params.begin();
  const size_t a = i == 0 ? 0 : i - 1;
  if (a + 1 == n && !closed) return path[n - 1];
  const size_t b = (a + 1) % n;
  const double end = a + 1 == n ? 1.0 : params[b];
  const double span = end - params[a];
  const double t = span > 0.0 ? std::clamp((u - params[a]) / span, 0.0, 1.0) : 0.0;
  return t == 0.0 ? path[a] : path[a] + t * (path[b] - path[a]);
}

Points BlendPaths(const std::vector<Points>& paths, bool closed, const std::vector<double>& weights,
                  double merge_fraction) {
  if (paths.size() == 1) return paths[0];
  std::vector<std::vector<double>> params;
  std::vector<double> all;
  double total_weight = 0.0;
  for (size_t k = 0; k < paths.size(); ++k) {
    params.push_back(ArcLengthParameters(paths[k], closed));
    all.insert(all.end(), params.back().begin(), params.back().end());
    total_weight += weights[k];
  }
  std::sort(all.begin(), all.end());
  std::vector<double> samples;
  for (double u : all) {
    if (samples.empty() || u - samples.back() > merge_fraction) samples.push_back(u);
  }
  if (!closed) samples.back() = 1.0;  // the ends stay the ends, whatever was merged into them
  Points out;
  out.reserve(samples.size());
  for (double u : samples) {
    Point p = Point::Zero();
    for (size_t k = 0; k < paths.size(); ++k) {
      p += weights[k] * PointAtParameter(paths[k], closed, params[k], u);
    }
    out.push_back(p / total_weight);
  }
  return out;
}

}  // namespace inbetween::solver
