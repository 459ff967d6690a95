// Boundary loop extraction (see boundary_loops.h).
//
// Each directed edge a->b of a triangle is a half-edge. In a consistently oriented mesh an
// interior edge appears once in each direction and a boundary edge once in total. Walking a loop,
// the boundary half-edge entering vertex b is continued by rotating through the triangle fan
// around b (half-edge b->c of the current triangle, then its twin c->b and the next triangle)
// until a boundary half-edge leaves b: that keeps loops apart where components touch at b.
#include "client/render/boundary_loops.h"

#include <cstdint>
#include <unordered_map>

#include "absl/strings/str_cat.h"

namespace inbetween::render {
namespace {

uint64_t Key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

struct HalfEdge {
  int from;
  int to;
  int triangle;
};

}  // namespace

absl::StatusOr<std::vector<Loop>> BoundaryLoops(const std::vector<std::array<int, 3>>& triangles) {
  std::unordered_map<uint64_t, int> half_edge;   // directed edge -> triangle
  std::unordered_map<uint64_t, int> edge_count;  // undirected edge -> number of triangles
  half_edge.reserve(3 * triangles.size());
  edge_count.reserve(3 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      return absl::InvalidArgumentError(absl::StrCat("triangles[", t, "] repeats a vertex: [",
                                                     tri[0], ", ", tri[1], ", ", tri[2], "]"));
    }
    for (int i = 0; i < 3; ++i) {
      const int a = tri[i], b = tri[(i + 1) % 3];
      auto [it, inserted] = half_edge.emplace(Key(a, b), static_cast<int>(t));
      if (!inserted) {
        return absl::InvalidArgumentError(absl::StrCat(
            "triangles[", it->second, "] and triangles[", t, "] both have edge ", a, "->", b,
            " in the same direction (inconsistent orientation or a non-manifold edge)"));
      }
      ++edge_count[Key(std::min(a, b), std::max(a, b))];
    }
  }
  const auto is_boundary = [&](int a, int b) {
    return edge_count.at(Key(std::min(a, b), std::max(a, b))) == 1;
  };

  std::vector<HalfEdge> boundary;                     // in triangle order: deterministic
  std::unordered_map<uint64_t, int> boundary_index;   // directed edge -> index in `boundary`
  std::unordered_map<int, std::vector<int>> leaving;  // vertex -> boundary half-edges from it
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int i = 0; i < 3; ++i) {
      const int a = triangles[t][i], b = triangles[t][(i + 1) % 3];
      if (!is_boundary(a, b)) continue;
      boundary_index[Key(a, b)] = static_cast<int>(boundary.size());
      leaving[a].push_back(static_cast<int>(boundary.size()));
      boundary.push_back({a, b, static_cast<int>(t)});
    }
  }

  // The vertex that follows `v` in triangle `t`.
  const auto next_in = [&](int t, int v) {
    const auto& tri = triangles[t];
    return tri[0] == v ? tri[1] : tri[1] == v ? tri[2] : tri[0];
  };
  // The boundary half-edge that leaves `e`'s end vertex in the same fan of triangles, or -1.
  const auto fan_successor = [&](int e) {
    const int b = boundary[e].to;
    int t = boundary[e].triangle;
    for (size_t step = 0; step <= triangles.size(); ++step) {
      const int c = next_in(t, b);
      if (is_boundary(b, c)) return boundary_index.at(Key(b, c));
      auto twin = half_edge.find(Key(c, b));
      if (twin == half_edge.end()) return -1;
      t = twin->second;
    }
    return -1;
  };

  std::vector<bool> used(boundary.size(), false);
  std::vector<Loop> loops;
  for (size_t start = 0; start < boundary.size(); ++start) {
    if (used[start]) continue;
    Loop loop;
    int e = static_cast<int>(start);
    while (true) {
      used[e] = true;
      loop.push_back(boundary[e].from);
      int next = fan_successor(e);
      if (next == static_cast<int>(start)) break;
      if (next < 0 || used[next]) {
        // Not reached for an oriented mesh; any unused edge leaving the vertex keeps going.
        next = -1;
        for (int candidate : leaving[boundary[e].to]) {
          if (!used[candidate]) {
            next = candidate;
            break;
          }
        }
        if (next < 0) break;
      }
      e = next;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

double LoopSignedArea(const Loop& loop, const std::vector<Vertex>& vertices) {
  double twice = 0.0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const Vertex& p = vertices[loop[i]];
    const Vertex& q = vertices[loop[(i + 1) % loop.size()]];
    twice += p[0] * q[1] - p[1] * q[0];
  }
  return 0.5 * twice;
}

}  // namespace inbetween::render
