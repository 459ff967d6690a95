// The boundary pairing comesh sliders keep to (comesh_pairing.h).
#include "solver/comesh/comesh_pairing.h"

#include <algorithm>
#include <cmath>

namespace inbetween::solver {

BoundaryPairing::BoundaryPairing(const Multimesh& input, double window) : window_(window) {
  const std::vector<std::vector<int>> loops =
      input.boundary_loops.empty() ? std::vector<std::vector<int>>{input.boundary}
                                   : input.boundary_loops;
  for (int s = 0; s < input.num_shapes(); ++s) {
    // No hard points: the outline is only a frame to measure arc length in.
    outlines_.emplace_back(input, s, 180.0, std::vector<char>{});
    // Loops of fewer than three points are left out, as ShapeOutline leaves them out.
    std::vector<std::vector<double>>& arcs = arc_.emplace_back();
    const Points& x = input.shapes[s];
    for (const std::vector<int>& ids : loops) {
      const int m = static_cast<int>(ids.size());
      if (m < 3) continue;
      std::vector<double>& arc = arcs.emplace_back(1, 0.0);
      for (int k = 0; k < m; ++k) arc.push_back(arc.back() + (x[ids[(k + 1) % m]] - x[ids[k]]).norm());
    }
    tolerance_.push_back(1e-7 * outlines_.back().diagonal());
  }
}

double BoundaryPairing::Map(int from, int to, int loop, double u) const {
  const std::vector<double>& a = arc_[from][loop];
  const std::vector<double>& b = arc_[to][loop];
  const int m = static_cast<int>(a.size()) - 1;
  const int k = std::clamp(
      static_cast<int>(std::upper_bound(a.begin(), a.end(), u) - a.begin()) - 1, 0, m - 1);
  const double span = a[k + 1] - a[k];
  const double t = span > 0.0 ? std::clamp((u - a[k]) / span, 0.0, 1.0) : 0.0;
  return b[k] + t * (b[k + 1] - b[k]);
}

std::optional<BoundaryPairing::Window> BoundaryPairing::WindowOf(const std::vector<Points>& shapes,
                                                                 int s, int v, int prev,
                                                                 int next) const {
  const std::optional<ShapeOutline::Location> at = outlines_[s].Locate(shapes[s][v], tolerance_[s]);
  if (!at) return std::nullopt;
  // Where the vertex is in every shape, pulled back to shape 0's outline and averaged (unwrapped
  // next to the first).
  const int num_shapes = static_cast<int>(outlines_.size());
  const double length0 = outlines_[0].length(at->loop);
  double first = 0.0, sum = 0.0;
  for (int q = 0; q < num_shapes; ++q) {
    const std::optional<ShapeOutline::Location> here =
        q == s ? at : outlines_[q].Locate(shapes[q][v], tolerance_[q]);
    if (!here || here->loop != at->loop) return std::nullopt;
    const double t = q == 0 ? here->u : Map(q, 0, at->loop, here->u);
    if (q == 0) first = t;
    sum += first + std::remainder(t - first, length0);
  }
  double mean = std::fmod(sum / num_shapes, length0);
  if (mean < 0.0) mean += length0;
  const double paired = s == 0 ? mean : Map(0, s, at->loop, mean);
  // The paired place, unwrapped next to u.
  const double centre = at->u - std::remainder(at->u - paired, outlines_[s].length(at->loop));
  const Points& x = shapes[s];
  const double r = window_ * 0.5 * ((x[prev] - x[v]).norm() + (x[next] - x[v]).norm());
  return Window{at->loop, at->u, std::min(at->u, centre - r), std::max(at->u, centre + r)};
}

}  // namespace inbetween::solver
