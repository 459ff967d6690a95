// Alexa et al. 2000 rotation/stretch split with spatial and sequential angle unwrapping
// (see example_rotations.h).
#include "solver/interp/example_rotations.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <queue>
#include <utility>

#include "solver/interp/polar.h"

namespace inbetween::solver {

std::vector<std::vector<int>> TriangleAdjacency(const std::vector<Triangle>& triangles) {
  // (edge as (min, max), triangle), sorted: equal edges end up next to each other.
  std::vector<std::pair<std::pair<int, int>, int>> edges;
  edges.reserve(3 * triangles.size());
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t][k];
      const int b = triangles[t][(k + 1) % 3];
      edges.push_back({{std::min(a, b), std::max(a, b)}, t});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> adjacency(triangles.size());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    for (size_t p = i; p < j; ++p) {
      for (size_t q = i; q < j; ++q) {
        if (p != q) adjacency[edges[p].second].push_back(edges[q].second);
      }
    }
    i = j;
  }
  for (auto& list : adjacency) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return adjacency;
}

ExampleRotations ComputeExampleRotations(const std::vector<Triangle>& triangles,
                                         const std::vector<Points>& shapes) {
  const int num_t = static_cast<int>(triangles.size());
  const int num_shapes = static_cast<int>(shapes.size());
  ExampleRotations out;
  out.angles.assign(num_shapes, std::vector<double>(num_t, 0.0));
  out.stretches.assign(num_shapes, std::vector<Eigen::Matrix2d>(num_t));

  auto edge_matrix = [&](const Points& x, int t) {
    Eigen::Matrix2d d;
    d.col(0) = x[triangles[t][1]] - x[triangles[t][0]];
    d.col(1) = x[triangles[t][2]] - x[triangles[t][0]];
    return d;
  };
  std::vector<double> principal(num_t);  // principal angle of the current example
  const std::vector<std::vector<int>> adjacency = TriangleAdjacency(triangles);
  for (int i = 0; i < num_shapes; ++i) {
    for (int t = 0; t < num_t; ++t) {
      const Eigen::Matrix2d a = edge_matrix(shapes[i], t) * edge_matrix(shapes[0], t).inverse();
      const PolarDecomposition p = Polar(a);
      principal[t] = p.angle;
      // Example 0 maps to itself: exactly the identity, so key 0 is reproduced exactly.
      out.stretches[i][t] = i == 0 ? Eigen::Matrix2d::Identity() : p.stretch;
    }
    std::vector<char> visited(num_t, 0);
    for (int seed = 0; seed < num_t; ++seed) {
      if (visited[seed]) continue;
      // Example 0 is the reference (theta = 0); later examples continue from the previous one.
      out.angles[i][seed] = i == 0 ? 0.0 : UnwrapAngle(principal[seed], out.angles[i - 1][seed]);
      visited[seed] = 1;
      std::queue<int> queue;
      queue.push(seed);
      while (!queue.empty()) {
        const int t = queue.front();
        queue.pop();
        for (int u : adjacency[t]) {
          if (visited[u]) continue;
          visited[u] = 1;
          out.angles[i][u] = i == 0 ? 0.0 : UnwrapAngle(principal[u], out.angles[i][t]);
          queue.push(u);
        }
      }
    }
  }
  return out;
}

}  // namespace inbetween::solver
