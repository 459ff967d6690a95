// Arc-length morph of corresponding polylines (see blend_paths.h).
#include "solver/art/blend_paths.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/geometry/primitives.h"

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

namespace {

constexpr int kAlignSamples = 64;

// Samples of the closed `path` at arc-length offsets (i / kAlignSamples + shift) mod 1.
Points UniformSamples(const Points& path, const std::vector<double>& params, double shift) {
  Points out;
  out.reserve(kAlignSamples);
  for (int i = 0; i < kAlignSamples; ++i) {
    double u = static_cast<double>(i) / kAlignSamples + shift;
    u -= std::floor(u);
    out.push_back(PointAtParameter(path, true, params, u));
  }
  return out;
}

double SquaredDistances(const Points& a, const Points& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).squaredNorm();
  return sum;
}

// `path` started at arc-length offset u in [0, 1) (params from ArcLengthParameters).
Points RestartAt(const Points& path, const std::vector<double>& params, double u) {
  const size_t n = path.size();
  const size_t a = std::upper_bound(params.begin(), params.end(), u) - params.begin() - 1;
  const Point start = PointAtParameter(path, true, params, u);
  Points out;
  out.reserve(n + 1);
  out.push_back(start);
  for (size_t k = 1; k <= n; ++k) {
    const Point& p = path[(a + k) % n];
    if (k == n && p == start) break;  // the offset fell on vertex a
    if (k == 1 && p == start) continue;  // or on vertex a + 1
    out.push_back(p);
  }
  return out;
}

}  // namespace

Points AlignClosedPath(const Points& reference, const Points& path) {
  if (reference.size() < 3 || path.size() < 3) return path;
  Points p = path;
  if (PolygonSignedArea2(reference) * PolygonSignedArea2(p) < 0.0) {
    std::reverse(p.begin() + 1, p.end());  // the other direction, from the same first point
  }
  const std::vector<double> ref_params = ArcLengthParameters(reference, true);
  const std::vector<double> params = ArcLengthParameters(p, true);
  if (ref_params.back() == 0.0 || params.back() == 0.0) return p;
  const Points ref = UniformSamples(reference, ref_params, 0.0);
  const Points grid = UniformSamples(p, params, 0.0);
  // Every offset of the sample grid: sample i of the reference against sample i + k of the path.
  int best = 0;
  double best_cost = 0.0;
  for (int k = 0; k < kAlignSamples; ++k) {
    double cost = 0.0;
    for (int i = 0; i < kAlignSamples; ++i) {
      cost += (ref[i] - grid[(i + k) % kAlignSamples]).squaredNorm();
    }
    if (k == 0 || cost < best_cost) best = k, best_cost = cost;
  }
  // Refined between the neighbouring grid offsets (golden-section search on the sampled cost).
  const auto cost_at = [&](double shift) {
    return SquaredDistances(ref, UniformSamples(p, params, shift));
  };
  const double step = 1.0 / kAlignSamples, ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = (best - 1) * step, hi = (best + 1) * step;
  double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
  double f1 = cost_at(x1), f2 = cost_at(x2);
  for (int it = 0; it < 40; ++it) {
    if (f1 <= f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - ratio * (hi - lo), f1 = cost_at(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + ratio * (hi - lo), f2 = cost_at(x2);
    }
  }
  double shift = f1 <= f2 ? x1 : x2;
  if (std::min(f1, f2) >= cost_at(0.0)) return p;  // the drawn start is as good
  shift -= std::floor(shift);
  // An offset within a hair of a vertex is that vertex (no near-duplicate first point).
  for (double v : params) {
    if (std::abs(v - shift) < 1e-9) shift = v;
  }
  if (shift >= 1.0 - 1e-9 || shift == 0.0) return p;
  return RestartAt(p, params, shift);
}

double MeanSquaredDistance(const Points& a, const Points& b) {
  if (a.size() < 3 || b.size() < 3) return std::numeric_limits<double>::infinity();
  const std::vector<double> pa = ArcLengthParameters(a, true), pb = ArcLengthParameters(b, true);
  if (pa.back() == 0.0 || pb.back() == 0.0) return std::numeric_limits<double>::infinity();
  return SquaredDistances(UniformSamples(a, pa, 0.0), UniformSamples(b, pb, 0.0)) / kAlignSamples;
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
