// S-eq.8/9 non-overlap check with bounding volume hierarchies (see overlap.h).
#include "solver/interp/overlap.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <utility>

#include "solver/geometry/primitives.h"

namespace inbetween::solver {

// Median-split AABB tree. The topology is built once (from the first positions seen: a continuous
// deformation keeps neighbouring primitives near each other) and only the boxes are refit for
// new positions, O(n) instead of the O(n log n) rebuild; a query's answer does not depend on the
// topology, only its cost does.
class OverlapChecker::Bvh {
 public:
  explicit Bvh(std::vector<Box> boxes) : boxes_(std::move(boxes)) {
    order_.resize(boxes_.size());
    std::iota(order_.begin(), order_.end(), 0);
    nodes_.reserve(2 * boxes_.size() / kLeaf + 2);
    if (!boxes_.empty()) Build(0, static_cast<int>(boxes_.size()));
  }

  // New boxes for the same primitives: children follow their parent in nodes_, so one backward
  // sweep refits every node.
  void Refit(std::vector<Box> boxes) {
    boxes_ = std::move(boxes);
    for (int id = static_cast<int>(nodes_.size()) - 1; id >= 0; --id) {
      Node& node = nodes_[id];
      Box box;
      if (node.left < 0) {
        for (int k = node.begin; k < node.end; ++k) box.extend(boxes_[order_[k]]);
      } else {
        box = nodes_[node.left].box.merged(nodes_[node.right].box);
      }
      node.box = box;
    }
  }

  const Box& box(int k) const { return boxes_[k]; }

  template <class F>
  void Query(const Box& q, F&& f) const {
    if (nodes_.empty()) return;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!node.box.intersects(q)) continue;
      if (node.left < 0) {
        for (int k = node.begin; k < node.end; ++k) {
          if (boxes_[order_[k]].intersects(q)) f(order_[k]);
        }
      } else {
        stack[top++] = node.left;
        stack[top++] = node.right;
      }
    }
  }

 private:
  static constexpr int kLeaf = 4;
  struct Node {
    Box box;
    int begin = 0, end = 0, left = -1, right = -1;
  };

  int Build(int begin, int end) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Box box;
    for (int k = begin; k < end; ++k) box.extend(boxes_[order_[k]]);
    nodes_[id].box = box;
    nodes_[id].begin = begin;
    nodes_[id].end = end;
    if (end - begin <= kLeaf) return id;
    const int axis = box.sizes().x() >= box.sizes().y() ? 0 : 1;
    const int mid = (begin + end) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](int a, int b) {
                       const double ca = boxes_[a].min()(axis) + boxes_[a].max()(axis);
                       const double cb = boxes_[b].min()(axis) + boxes_[b].max()(axis);
                       return ca < cb || (ca == cb && a < b);
                     });
    const int left = Build(begin, mid);
    const int right = Build(mid, end);
    nodes_[id].left = left;
    nodes_[id].right = right;
    return id;
  }

  std::vector<Box> boxes_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
};

namespace {

Eigen::Vector2d P(const Coords& x, int v) { return x.row(v).transpose(); }

// Strictly inside: every barycentric coordinate above `margin` (relative).
bool StrictlyInside(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    const Eigen::Vector2d& c, double margin) {
  const double area = Cross(b - a, c - a);
  if (!(area > 0.0)) return false;  // inverted triangles are counted elsewhere
  const double l0 = Cross(b - p, c - p) / area;
  const double l1 = Cross(c - p, a - p) / area;
  const double l2 = Cross(a - p, b - p) / area;
  return l0 > margin && l1 > margin && l2 > margin;
}

bool ProperlyCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

constexpr double kMargin = 1e-9;

Eigen::Vector2d ClosestOnSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                 const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double u = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
  return a + u * d;
}

}  // namespace

OverlapChecker::OverlapChecker(const std::vector<Triangle>& triangles,
                               const std::vector<std::array<int, 4>>& cohesive_edges,
                               int num_vertices)
    : triangles_(triangles), twins_(num_vertices) {
  // Per undirected edge: the triangle edges (t, k) on it.
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> sides;
  const int num_triangles = static_cast<int>(triangles.size());
  for (int t = 0; t < num_triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      sides[{std::min(a, b), std::max(a, b)}].emplace_back(t, k);
    }
  }
  neighbours_.assign(num_triangles, {-1, -1, -1});
  edge_segment_.assign(num_triangles, {-1, -1, -1});
  std::vector<char> on_boundary(num_vertices, 0);
  for (int t = 0; t < num_triangles; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      const auto& on_edge = sides[{std::min(a, b), std::max(a, b)}];
      if (on_edge.size() == 1) {
        edge_segment_[t][k] = static_cast<int>(segments_.size());
        segments_.push_back({a, b});
        on_boundary[a] = on_boundary[b] = 1;
      } else if (on_edge.size() == 2) {
        neighbours_[t][k] = on_edge[0].first == t ? on_edge[1].first : on_edge[0].first;
      }
    }
  }
  for (int v = 0; v < num_vertices; ++v) {
    if (on_boundary[v]) boundary_vertices_.push_back(v);
  }
  for (const std::array<int, 4>& e : cohesive_edges) {
    for (auto [p, q] : {std::pair{e[0], e[2]}, std::pair{e[1], e[3]}}) {
      twins_[p].push_back(q);
      twins_[q].push_back(p);
    }
  }
  // Twins of twins (a vertex where several cohesive edges meet), one level is enough for pairs.
  for (auto& list : twins_) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
}

OverlapChecker::~OverlapChecker() = default;
OverlapChecker::OverlapChecker(OverlapChecker&&) noexcept = default;
OverlapChecker& OverlapChecker::operator=(OverlapChecker&&) noexcept = default;

const OverlapChecker::Bvh& OverlapChecker::Tree(std::vector<Box> boxes,
                                                std::unique_ptr<Bvh>* tree) const {
  if (*tree == nullptr) {
    *tree = std::make_unique<Bvh>(std::move(boxes));
  } else {
    (*tree)->Refit(std::move(boxes));
  }
  return **tree;
}

bool OverlapChecker::Exempt(int v, const Triangle& t) const {
  for (int u : t) {
    if (u == v) return true;
    for (int twin : twins_[v]) {
      if (twin == u) return true;
    }
  }
  return false;
}

bool OverlapChecker::Exempt(int a, int b, int c, int d) const {
  for (int p : {a, b}) {
    for (int q : {c, d}) {
      if (p == q) return true;
      for (int twin : twins_[p]) {
        if (twin == q) return true;
      }
    }
  }
  return false;
}

std::vector<std::pair<int, int>> OverlapChecker::Inside(const Coords& x) const {
  std::vector<Box> boxes(triangles_.size());
  for (size_t t = 0; t < triangles_.size(); ++t) {
    for (int v : triangles_[t]) boxes[t].extend(P(x, v));
  }
  const Bvh& bvh = Tree(std::move(boxes), &triangle_tree_);
  std::vector<std::pair<int, int>> inside;
  for (int v : boundary_vertices_) {
    const Eigen::Vector2d p = P(x, v);
    int found = -1;
    bvh.Query(Box(p, p), [&](int t) {
      if (found >= 0 || Exempt(v, triangles_[t])) return;
      const Triangle& tri = triangles_[t];
      if (StrictlyInside(p, P(x, tri[0]), P(x, tri[1]), P(x, tri[2]), kMargin)) found = t;
    });
    if (found >= 0) inside.emplace_back(v, found);
  }
  return inside;
}

std::vector<std::pair<int, int>> OverlapChecker::CrossingPairs(const Coords& x) const {
  std::vector<Box> boxes(segments_.size());
  for (size_t s = 0; s < segments_.size(); ++s) {
    boxes[s].extend(P(x, segments_[s][0]));
    boxes[s].extend(P(x, segments_[s][1]));
  }
  const Bvh& bvh = Tree(std::move(boxes), &segment_tree_);
  std::vector<std::pair<int, int>> pairs;
  for (int s = 0; s < static_cast<int>(segments_.size()); ++s) {
    // Not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
    const int a = segments_[s][0], b = segments_[s][1];
    bvh.Query(bvh.box(s), [&](int r) {
      if (r <= s) return;
      const auto [c, d] = segments_[r];
      if (Exempt(a, b, c, d)) return;
      if (ProperlyCross(P(x, a), P(x, b), P(x, c), P(x, d))) pairs.emplace_back(s, r);
    });
  }
  return pairs;
}

int OverlapChecker::Crossings(const Coords& x) const {
  return static_cast<int>(CrossingPairs(x).size());
}

int OverlapChecker::Count(const Coords& x) const {
  return static_cast<int>(Inside(x).size()) + Crossings(x);
}

std::vector<OverlapContact> OverlapChecker::Contacts(const Coords& x) const {
  std::vector<OverlapContact> contacts;
  const std::vector<std::pair<int, int>> inside = Inside(x);
  if (inside.empty()) return contacts;
  // Best-first walk over triangles from the one holding p, in order of their distance to p,
  // never entering a triangle incident to v; the closest boundary segment (not incident to v)
  // on a visited triangle wins once no unvisited triangle is nearer than it.
  std::vector<int> seen(triangles_.size(), -1);
  for (auto [v, start] : inside) {
    const Eigen::Vector2d p = P(x, v);
    double best = std::numeric_limits<double>::infinity();
    int best_segment = -1;
    Eigen::Vector2d best_point = p;
    using Entry = std::pair<double, int>;  // (distance from p, triangle)
    std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
    queue.emplace(0.0, start);
    seen[start] = v;
    while (!queue.empty() && queue.top().first < best) {
      const int t = queue.top().second;
      queue.pop();
      for (int k = 0; k < 3; ++k) {
        const int a = triangles_[t][k], b = triangles_[t][(k + 1) % 3];
        const Eigen::Vector2d q = ClosestOnSegment(p, P(x, a), P(x, b));
        const double distance = (q - p).norm();
        if (const int s = edge_segment_[t][k]; s >= 0) {
          if (a != v && b != v && distance < best)
            best = distance, best_segment = s, best_point = q;
          continue;
        }
        const int u = neighbours_[t][k];
        if (u < 0 || seen[u] == v) continue;
        seen[u] = v;
        const Triangle& tu = triangles_[u];
        if (tu[0] == v || tu[1] == v || tu[2] == v) continue;
        queue.emplace(distance, u);  // the shared edge is the nearest u can be reached through
      }
    }
    if (best_segment < 0) {
      // Every boundary edge the walk can reach is incident to v: the closest segment that is not
      // (so every vertex inside has a contact, and no contact means none inside).
      for (int s = 0; s < static_cast<int>(segments_.size()); ++s) {
        const auto [a, b] = segments_[s];
        if (a == v || b == v) continue;
        const Eigen::Vector2d q = ClosestOnSegment(p, P(x, a), P(x, b));
        if ((q - p).norm() < best) best = (q - p).norm(), best_segment = s, best_point = q;
      }
      if (best_segment < 0) continue;  // no boundary but its own: not reachable in a valid mesh
    }
    const auto [a, b] = segments_[best_segment];
    const Eigen::Vector2d d = P(x, b) - P(x, a);
    // Triangles are positive, so the interior is on the segment's left.
    const Eigen::Vector2d normal = Eigen::Vector2d(d.y(), -d.x()).normalized();
    contacts.push_back({v, best_point + 1e-2 * d.norm() * normal, normal});
  }
  return contacts;
}

}  // namespace inbetween::solver
