// Injective mapping benchmark: a CGAL mesh of a 4 x 1 bar (~1.7k vertices)
// mapped by MapToBoundary onto the same bar bent into a half circle about its centre line (a
// half annulus of mid radius 4 / pi). LIM (Schueller et al. 2013) reports ~285 ms for this
// case; the target is < 100 ms. Prints the median and minimum over several runs, the vertex
// count, iterations and inverted triangles; --json FILE writes
// {"case", "vertices", "ms_median", "ms_min", "inverted"}.
// Usage: mapping [--runs N] [--pull (progressive pull only, no Tutte start)] [--json FILE]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "solver/geometry/polygon.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program

constexpr double kLength = 4.0;
constexpr double kWidth = 1.0;
constexpr double kSpacing = 0.08;  // boundary spacing and max edge: ~1.7k vertices

// The bar's boundary, positive, sampled every kSpacing.
Points BarBoundary() {
  Points p;
  const int nx = static_cast<int>(std::lround(kLength / kSpacing));
  const int ny = static_cast<int>(std::lround(kWidth / kSpacing));
  for (int i = 0; i < nx; ++i) p.emplace_back(i * kLength / nx, 0.0);
  for (int j = 0; j < ny; ++j) p.emplace_back(kLength, j * kWidth / ny);
  for (int i = nx; i > 0; --i) p.emplace_back(i * kLength / nx, kWidth);
  for (int j = ny; j > 0; --j) p.emplace_back(0.0, j * kWidth / ny);
  return p;
}

// Bends the bar about its centre line y = 1/2 into a half circle (x -> angle, y -> radius).
Point Bend(const Point& p) {
  const double radius = kLength / std::numbers::pi;
  const double angle = std::numbers::pi * p.x() / kLength;
  const double r = radius + (kWidth / 2 - p.y());
  return {-r * std::cos(angle), -r * std::sin(angle)};
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 7;
  bool pull_only = false;  // --pull: skip the Tutte attempt (the progressive pull alone)
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--pull") {
      pull_only = true;
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--runs N] [--pull] [--json FILE]\n", argv[0]);
      return 2;
    }
  }
  const Points bar = BarBoundary();
  TriangulateOptions options;
  options.max_edge = kSpacing;
  absl::StatusOr<PolygonTriangulation> mesh = CgalTriangulate(bar, options);
  if (!mesh.ok()) {
    std::fprintf(stderr, "triangulate: %s\n", mesh.status().ToString().c_str());
    return 1;
  }
  Points vertices = mesh->vertices;
  std::vector<Triangle> triangles = mesh->triangles;
  // Boundary in order: the polygon points with the mesher's boundary Steiner points between.
  std::vector<int> boundary;
  for (size_t k = 0, s = 0; k < bar.size(); ++k) {
    boundary.push_back(static_cast<int>(k));
    for (; s < mesh->boundary_steiner.size() && mesh->boundary_steiner[s].segment == int(k); ++s)
      boundary.push_back(mesh->boundary_steiner[s].vertex);
  }
  std::vector<bool> is_boundary(vertices.size(), false);
  for (int b : boundary) is_boundary[b] = true;
  SplitBoundaryChords(&vertices, &triangles, &is_boundary);
  Points target;
  for (int b : boundary) target.push_back(Bend(vertices[b]));
  if (PolygonSignedArea(target) <= 0) {
    std::fprintf(stderr, "bent boundary is not positive\n");
    return 1;
  }

  std::vector<double> ms;
  int inverted = -1;
  MapToBoundaryReport report;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    MapToBoundaryOptions map_options;
    map_options.tutte_first_always = !pull_only;
    absl::StatusOr<Points> mapped =
        MapToBoundary(vertices, triangles, boundary, target, map_options, nullptr, &report);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
    if (!mapped.ok()) {
      std::fprintf(stderr, "map: %s\n", mapped.status().ToString().c_str());
      return 1;
    }
    inverted = CountInverted(triangles, *mapped);
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::printf("%-16s %9s %9s %9s %6s %6s %7s %9s\n", "case", "vertices", "ms_median", "ms_min",
              "iters", "stages", "energy", "inverted");
  std::printf("%-16s %9zu %9.1f %9.1f %6d %6d %7.3f %9d  (%s)\n", "bar_half_circle",
              vertices.size(), median, sorted.front(), report.iterations, report.stages,
              report.energy, inverted, report.tutte ? "Tutte start" : "progressive pull");
  std::printf("(LIM: ~285 ms; target < 100 ms)\n");
  if (!json_path.empty()) {
    nlohmann::json row = {{"case", "bar_half_circle"},
                          {"vertices", vertices.size()},
                          {"ms_median", median},
                          {"ms_min", sorted.front()},
                          {"inverted", inverted}};
    std::ofstream(json_path) << row.dump(2) << "\n";
  }
  return inverted == 0 ? 0 : 1;
}
