#include "solver/mesh/collapse_vertices.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/validate.h"
#include "solver/mesh/vertex_star.h"

namespace inbetween::solver {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

class Collapser {
 public:
  Collapser(const std::vector<Triangle>& triangles, const std::vector<Points>& shapes)
      : triangles_(triangles), shapes_(shapes), alive_(triangles.size(), true) {
    const int n = shapes.empty() ? 0 : static_cast<int>(shapes[0].size());
    star_.resize(n);
    removed_.assign(n, false);
    for (size_t t = 0; t < triangles_.size(); ++t) {
      for (int v : triangles_[t]) star_[v].push_back(static_cast<int>(t));
    }
  }

  // The thinnest of v's triangles over every shape.
  double StarQuality(int v) const {
    double worst = kInf;
    for (int t : star_[v]) worst = std::min(worst, Quality(triangles_[t]));
    return worst;
  }

  // Merges v into its best neighbour if one qualifies (header); true if it did.
  bool TryCollapse(int v, double quality_floor) {
    if (removed_[v] || !Interior(v)) return false;
    const double before = StarQuality(v);
    const double bar = quality_floor > 0 ? std::min(before, quality_floor) : before;
    int best_u = -1;
    double best = -kInf;
    const std::vector<int> nv = Neighbours(v);
    for (int u : nv) {
      if (!LinkCondition(v, nv, u)) continue;
      double after = kInf;
      for (int t : star_[v]) {
        Triangle tri = triangles_[t];
        if (Holds(tri, u)) continue;
        for (int& x : tri) x = x == v ? u : x;
        after = std::min(after, Quality(tri));
        if (after < bar || after <= best) break;
      }
      if (after >= bar && after > 0.0 && after > best) best = after, best_u = u;
    }
    if (best_u < 0) return false;
    Apply(v, best_u);
    return true;
  }

  CollapseResult Result() const {
    CollapseResult r;
    const int n = static_cast<int>(removed_.size());
    r.old_to_new.assign(n, -1);
    int next = 0;
    for (int v = 0; v < n; ++v) {
      if (!removed_[v]) r.old_to_new[v] = next++;
    }
    r.removed = n - next;
    for (const Points& s : shapes_) {
      Points kept(next);
      for (int v = 0; v < n; ++v) {
        if (r.old_to_new[v] >= 0) kept[r.old_to_new[v]] = s[v];
      }
      r.shapes.push_back(std::move(kept));
    }
    for (size_t t = 0; t < triangles_.size(); ++t) {
      if (!alive_[t]) continue;
      Triangle tri = triangles_[t];
      for (int& x : tri) x = r.old_to_new[x];
      r.triangles.push_back(tri);
    }
    return r;
  }

 private:
  static bool Holds(const Triangle& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

  double Quality(const Triangle& t) const {
    double worst = kInf;
    for (const Points& s : shapes_)
      worst = std::min(worst, TriangleQuality(s[t[0]], s[t[1]], s[t[2]]));
    return worst;
  }

  std::vector<int> Neighbours(int v) const { return StarNeighbours(triangles_, star_[v], v); }

  // Every edge at v borders two triangles: each neighbour appears in exactly two of its triangles.
  bool Interior(int v) const {
    if (star_[v].size() < 3) return false;
    std::vector<int> seen;
    for (int t : star_[v]) {
      for (int x : triangles_[t]) {
        if (x != v) seen.push_back(x);
      }
    }
    std::sort(seen.begin(), seen.end());
    for (size_t i = 0; i < seen.size(); i += 2) {
      if (i + 1 >= seen.size() || seen[i] != seen[i + 1]) return false;
      if (i + 2 < seen.size() && seen[i + 2] == seen[i]) return false;
    }
    return true;
  }

  // u and v (whose neighbours are nv) share exactly the two neighbours opposite their edge.
  bool LinkCondition(int v, const std::vector<int>& nv, int u) const {
    const std::vector<int> nu = Neighbours(u);
    std::vector<int> common;
    std::set_intersection(nv.begin(), nv.end(), nu.begin(), nu.end(), std::back_inserter(common));
    int across = 0;
    for (int t : star_[v]) across += Holds(triangles_[t], u);
    return across == 2 && common.size() == 2;
  }

  void Apply(int v, int u) {
    for (int t : star_[v]) {
      Triangle& tri = triangles_[t];
      if (Holds(tri, u)) {
        alive_[t] = false;
        for (int x : tri) {
          if (x == v) continue;
          auto& s = star_[x];
          s.erase(std::remove(s.begin(), s.end(), t), s.end());
        }
      } else {
        for (int& x : tri) x = x == v ? u : x;
        star_[u].push_back(t);
      }
    }
    star_[v].clear();
    removed_[v] = true;
  }

  std::vector<Triangle> triangles_;
  const std::vector<Points>& shapes_;
  std::vector<bool> alive_;
  std::vector<std::vector<int>> star_;
  std::vector<bool> removed_;
};

}  // namespace

absl::StatusOr<CollapseResult> CollapseVertices(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& shapes,
                                                int first_removable, const CollapseOptions& options,
                                                const CancelToken* cancel) {
  if (shapes.empty()) return absl::InvalidArgumentError("collapse: no shapes");
  const int n = static_cast<int>(shapes[0].size());
  for (size_t s = 0; s < shapes.size(); ++s) {
    if (static_cast<int>(shapes[s].size()) != n) {
      return absl::InvalidArgumentError(absl::StrCat("collapse: shape ", s + 1, " has ",
                                                     shapes[s].size(), " points, shape 1 ", n));
    }
  }
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (const std::optional<int> v = IndexOutOfRange(triangles[t], n)) {
      return absl::InvalidArgumentError(
          absl::StrCat("collapse: triangle ", t + 1, " has vertex ", *v, " of ", n));
    }
  }
  Collapser collapser(triangles, shapes);
  std::vector<std::pair<double, int>> order;
  for (int pass = 0; pass < options.max_passes; ++pass) {
    if (Cancelled(cancel)) return absl::CancelledError("collapse cancelled");
    order.clear();
    for (int v = std::max(0, first_removable); v < n; ++v) {
      order.emplace_back(collapser.StarQuality(v), v);
    }
    std::sort(order.begin(), order.end());
    int collapsed = 0;
    for (size_t i = 0; i < order.size(); ++i) {
      if ((i & 4095) == 0 && Cancelled(cancel)) return absl::CancelledError("collapse cancelled");
      collapsed += collapser.TryCollapse(order[i].second, options.quality_floor);
    }
    if (collapsed == 0) break;
  }
  return collapser.Result();
}

}  // namespace inbetween::solver
