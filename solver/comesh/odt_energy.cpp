// S-eq.1: ODT mesh energy, per-triangle closed form and gradient (see odt_energy.h).
#include "solver/comesh/odt_energy.h"

#include <cmath>
#include <limits>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {

double OdtTriangleEnergy(const Point& a, const Point& b, const Point& c,
                         std::array<Point, 3>* gradient) {
  const Point ab = b - a;
  const Point ac = c - a;
  const Point bc = c - b;
  const double area = 0.5 * Cross(ab, ac);
  if (!(area > 0.0)) return std::numeric_limits<double>::infinity();
  const double sum_sq = ab.squaredNorm() + ac.squaredNorm() + bc.squaredNorm();
  if (gradient != nullptr) {
    // d|t|/da = 0.5 * (b.y - c.y, c.x - b.x), and cyclically for b and c.
    const Point da(0.5 * (b.y() - c.y()), 0.5 * (c.x() - b.x()));
    const Point db(0.5 * (c.y() - a.y()), 0.5 * (a.x() - c.x()));
    const Point dc(0.5 * (a.y() - b.y()), 0.5 * (b.x() - a.x()));
    // d(sum_sq)/da = 2 (a - b) + 2 (a - c), etc.
    const double s = sum_sq / 12.0;
    const double k = area / 6.0;  // area / 12 * 2
    (*gradient)[0] = s * da + k * (-ab - ac);
    (*gradient)[1] = s * db + k * (ab - bc);
    (*gradient)[2] = s * dc + k * (ac + bc);
  }
  return area * sum_sq / 12.0;
}

double OdtEnergy(const std::vector<Triangle>& triangles, const Points& x, Points* gradient) {
  double total = 0.0;
  std::array<Point, 3> g;
  for (const Triangle& t : triangles) {
    const double e = OdtTriangleEnergy(x[t[0]], x[t[1]], x[t[2]], gradient ? &g : nullptr);
    if (!std::isfinite(e)) return std::numeric_limits<double>::infinity();
    total += e;
    if (gradient != nullptr) {
      for (int k = 0; k < 3; ++k) (*gradient)[t[k]] += g[k];
    }
  }
  return total;
}

double OdtNormalization(const std::vector<Triangle>& triangles, const Points& x) {
  if (triangles.empty()) return 0.0;
  double area = 0.0;
  for (const Triangle& t : triangles) area += 0.5 * std::abs(SignedArea2(t, x));
  return area * area / (std::sqrt(3.0) * static_cast<double>(triangles.size()));
}

}  // namespace inbetween::solver
