// Reference outlines along which comesh boundary vertices slide (comesh_outline.h).
#include "solver/comesh/comesh_outline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {

ShapeOutline::ShapeOutline(const Multimesh& mesh, int shape, double corner_degrees,
                           const std::vector<char>& fixed) {
  const Points& x = mesh.shapes[shape];
  const std::vector<std::vector<int>> loops =
      mesh.boundary_loops.empty() ? std::vector<std::vector<int>>{mesh.boundary}
                                  : mesh.boundary_loops;
  std::vector<Points> points;
  std::vector<std::vector<char>> fixed_points;
  for (const std::vector<int>& ids : loops) {
    Points& p = points.emplace_back();
    std::vector<char>& f = fixed_points.emplace_back();
    for (int v : ids) {
      p.push_back(x[v]);
      f.push_back(v < static_cast<int>(fixed.size()) && fixed[v]);
    }
  }
  Init(points, fixed_points, corner_degrees);
}

ShapeOutline::ShapeOutline(const std::vector<Points>& loops, double corner_degrees) {
  std::vector<std::vector<char>> fixed;
  for (const Points& loop : loops) fixed.emplace_back(loop.size(), 0);
  Init(loops, fixed, corner_degrees);
}

void ShapeOutline::Init(const std::vector<Points>& loops,
                        const std::vector<std::vector<char>>& fixed, double corner_degrees) {
  const double cos_corner = std::cos(corner_degrees * std::numbers::pi / 180.0);
  Point lo = Point::Constant(std::numeric_limits<double>::infinity());
  Point hi = -lo;
  double total = 0.0;
  int segments = 0;
  for (size_t i = 0; i < loops.size(); ++i) {
    const Points& x = loops[i];
    const int m = static_cast<int>(x.size());
    if (m < 3) continue;
    Loop loop;
    loop.arc.push_back(0.0);
    for (int k = 0; k < m; ++k) {
      const Point& p = x[k];
      loop.points.push_back(p);
      loop.arc.push_back(loop.arc.back() + (x[(k + 1) % m] - p).norm());
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (int k = 0; k < m; ++k) {
      const Point in = x[k] - x[(k + m - 1) % m];
      const Point out = x[(k + 1) % m] - x[k];
      const double norms = in.norm() * out.norm();
      // A turn above corner_degrees means cos(turn) below cos(corner_degrees).
      if (fixed[i][k] || !(norms > 0.0) || in.dot(out) < cos_corner * norms) {
        loop.hard.push_back(loop.arc[k]);
      } else if (std::abs(Cross(in, out)) > 1e-9 * norms) {
        curved_ = true;  // a soft corner (StrictlyInsideSegment's straightness tolerance)
      }
    }
    total += loop.arc.back();
    segments += m;
    loops_.push_back(std::move(loop));
  }
  if (segments == 0) return;
  origin_ = lo;
  diagonal_ = (hi - lo).norm();
  cell_ = std::max(total / segments, 1e-9 * std::max(diagonal_, 1e-300));
  for (int l = 0; l < num_loops(); ++l) {
    const Loop& loop = loops_[l];
    const int m = static_cast<int>(loop.points.size());
    for (int k = 0; k < m; ++k) {
      const Point& a = loop.points[k];
      const Point& b = loop.points[(k + 1) % m];
      const Point c0 = (a.cwiseMin(b) - origin_) / cell_, c1 = (a.cwiseMax(b) - origin_) / cell_;
      for (int64_t ix = static_cast<int64_t>(std::floor(c0.x()));
           ix <= static_cast<int64_t>(std::floor(c1.x())); ++ix) {
        for (int64_t iy = static_cast<int64_t>(std::floor(c0.y()));
             iy <= static_cast<int64_t>(std::floor(c1.y())); ++iy) {
          grid_[CellKey(ix, iy)].emplace_back(l, k);
        }
      }
    }
  }
}

std::optional<ShapeOutline::Location> ShapeOutline::Locate(const Point& p,
                                                           double tolerance) const {
  std::optional<Location> best;
  double best_distance = tolerance;
  const Point c0 = (p - origin_).array() - tolerance, c1 = (p - origin_).array() + tolerance;
  for (int64_t ix = static_cast<int64_t>(std::floor(c0.x() / cell_));
       ix <= static_cast<int64_t>(std::floor(c1.x() / cell_)); ++ix) {
    for (int64_t iy = static_cast<int64_t>(std::floor(c0.y() / cell_));
         iy <= static_cast<int64_t>(std::floor(c1.y() / cell_)); ++iy) {
      const auto it = grid_.find(CellKey(ix, iy));
      if (it == grid_.end()) continue;
      for (const auto& [l, k] : it->second) {
        const Loop& loop = loops_[l];
        const Point& a = loop.points[k];
        const Point& b = loop.points[(k + 1) % loop.points.size()];
        const Point ab = b - a;
        const double t = ab.squaredNorm() > 0.0 ? SegmentParameter(p, a, b) : 0.0;
        const double distance = (p - (a + t * ab)).norm();
        // Ties (a polyline point is on two segments) go to the first segment found in this
        // fixed cell order, so the result is deterministic.
        if (distance < best_distance || (!best && distance <= best_distance)) {
          best_distance = distance;
          const double u = loop.arc[k] + t * (loop.arc[k + 1] - loop.arc[k]);
          best = Location{l, Wrap(loop, u)};
        }
      }
    }
  }
  return best;
}

double ShapeOutline::Wrap(const Loop& loop, double u) const {
  const double length = loop.arc.back();
  double w = std::fmod(u, length);
  if (w < 0.0) w += length;
  if (w >= length) w = 0.0;
  return w;
}

int ShapeOutline::SegmentAt(const Loop& loop, double w) const {
  const int m = static_cast<int>(loop.points.size());
  const int k = static_cast<int>(std::upper_bound(loop.arc.begin(), loop.arc.end(), w) -
                                 loop.arc.begin()) -
                1;
  return std::clamp(k, 0, m - 1);
}

Point ShapeOutline::At(int l, double u) const {
  const Loop& loop = loops_[l];
  const double w = Wrap(loop, u);
  const int k = SegmentAt(loop, w);
  const double len = loop.arc[k + 1] - loop.arc[k];
  const double t = len > 0.0 ? (w - loop.arc[k]) / len : 0.0;
  const Point& a = loop.points[k];
  const Point& b = loop.points[(k + 1) % loop.points.size()];
  return a + t * (b - a);
}

Point ShapeOutline::Direction(const Loop& loop, int j) const {
  const int m = static_cast<int>(loop.points.size());
  j = (j % m + m) % m;
  const Point d = loop.points[(j + 1) % m] - loop.points[j];
  const double n = d.norm();
  return n > 0.0 ? Point(d / n) : Point(Point::Zero());
}

Point ShapeOutline::Tangent(int l, double u) const {
  const Loop& loop = loops_[l];
  const double w = Wrap(loop, u);
  const int k = SegmentAt(loop, w);
  const double eps = 1e-12 * loop.arc.back();
  const Point here = Direction(loop, k);
  Point t = here;
  if (w - loop.arc[k] <= eps) {
    t = Direction(loop, k - 1) + here;
  } else if (loop.arc[k + 1] - w <= eps) {
    t = here + Direction(loop, k + 1);
  }
  const double n = t.norm();
  return n > 1e-12 ? Point(t / n) : here;
}

std::pair<Point, Point> ShapeOutline::Tangents(int l, double u) const {
  const Loop& loop = loops_[l];
  const double w = Wrap(loop, u);
  const int k = SegmentAt(loop, w);
  const double eps = 1e-12 * loop.arc.back();
  if (w - loop.arc[k] <= eps) return {Direction(loop, k - 1), Direction(loop, k)};
  if (loop.arc[k + 1] - w <= eps) return {Direction(loop, k), Direction(loop, k + 1)};
  return {Direction(loop, k), Direction(loop, k)};
}

bool ShapeOutline::AtHardPoint(int l, double u, double tolerance) const {
  const Loop& loop = loops_[l];
  const double w = Wrap(loop, u), length = loop.arc.back();
  for (double h : loop.hard) {
    const double d = std::abs(w - h);
    if (std::min(d, length - d) <= tolerance) return true;
  }
  return false;
}

std::pair<double, double> ShapeOutline::Stretch(int l, double u) const {
  const Loop& loop = loops_[l];
  if (loop.hard.empty()) {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  const double length = loop.arc.back();
  const double w = Wrap(loop, u);
  const double base = u - w;
  const auto after = std::upper_bound(loop.hard.begin(), loop.hard.end(), w);
  const double lo = after == loop.hard.begin() ? loop.hard.back() - length : *(after - 1);
  const auto at_or_after = std::lower_bound(loop.hard.begin(), loop.hard.end(), w);
  const double hi = at_or_after == loop.hard.end() ? loop.hard.front() + length : *at_or_after;
  return {base + lo, base + hi};
}

double ShapeOutline::tolerance() const {
  double longest = 0.0;
  for (const Loop& loop : loops_) longest = std::max(longest, loop.arc.back());
  return 1e-9 * longest;
}

std::optional<Point> ShapeOutline::SplitPoint(const Point& a, const Point& b,
                                              double tolerance) const {
  const Point chord = 0.5 * (a + b);
  if (Locate(chord, tolerance)) return chord;
  const std::optional<Location> la = Locate(a, tolerance), lb = Locate(b, tolerance);
  if (!la || !lb || la->loop != lb->loop) return std::nullopt;
  const Loop& loop = loops_[la->loop];
  const double length = loop.arc.back();
  // The shorter arc from a, forwards (d > 0) or backwards (d < 0).
  double d = Wrap(loop, lb->u - la->u);
  if (d > 0.5 * length) d -= length;
  const double from = std::min(la->u, la->u + d), to = std::max(la->u, la->u + d);
  for (double h : loop.hard) {
    for (double shifted : {h - length, h, h + length}) {
      if (shifted > from + tolerance && shifted < to - tolerance) return std::nullopt;
    }
  }
  return At(la->loop, la->u + 0.5 * d);
}

double ShapeOutline::ChordDeviation(const Point& a, const Point& b,
                                    double locate_tolerance) const {
  const std::optional<Location> la = Locate(a, locate_tolerance),
                                lb = Locate(b, locate_tolerance);
  if (!la || !lb || la->loop != lb->loop) return 0.0;
  const Loop& loop = loops_[la->loop];
  const int m = static_cast<int>(loop.points.size());
  const double length = loop.arc.back();
  // The shorter arc, walked forwards from its start.
  double from = la->u, span = Wrap(loop, lb->u - la->u);
  if (span > 0.5 * length) {
    from = lb->u;
    span = length - span;
  }
  double worst = 0.0;
  // Points strictly inside the arc: from the first point after `from` while within the span.
  int k = SegmentAt(loop, from) + 1;
  for (int steps = 0; steps < m; ++steps, ++k) {
    const int j = k % m;
    const double along = (k >= m ? length : 0.0) + loop.arc[j] - from;
    if (!(along < span)) break;
    worst = std::max(worst, DistanceToSegment(loop.points[j], a, b));
  }
  return worst;
}

OutlineGuard::OutlineGuard(std::vector<const ShapeOutline*> reference,
                           std::vector<double> tolerance)
    : reference_(std::move(reference)), tolerance_(std::move(tolerance)) {}

double OutlineGuard::Deviation(int s, const Point& a, const Point& b) const {
  // Vertices sit on the input outline, which is within the tolerance of the reference (a build
  // that met it); twice the bound finds them on the reference with room to spare.
  return reference_[s]->ChordDeviation(a, b, 2.0 * tolerance_[s] + reference_[s]->tolerance());
}

int OutlineGuard::Add(int s, int v, int prev, int next, const Points& x) {
  // A chord already beyond the bound keeps its own deviation as its bound (plus rounding).
  auto allowed = [&](int a, int b) {
    return std::max(tolerance_[s], Deviation(s, x[a], x[b]) * (1.0 + 1e-9));
  };
  slots_.push_back({s, v, prev, next, allowed(prev, v), allowed(v, next)});
  return static_cast<int>(slots_.size()) - 1;
}

bool OutlineGuard::HoldsAt(int i, const Point& p, const Points& x) const {
  const Slot& slot = slots_[i];
  return Deviation(slot.shape, x[slot.prev], p) <= slot.allowed_prev &&
         Deviation(slot.shape, p, x[slot.next]) <= slot.allowed_next;
}

bool OutlineGuard::Holds(const std::vector<Points>& shapes) const {
  for (size_t i = 0; i < slots_.size(); ++i) {
    const Points& x = shapes[slots_[i].shape];
    if (!HoldsAt(static_cast<int>(i), x[slots_[i].vertex], x)) return false;
  }
  return true;
}

}  // namespace inbetween::solver
