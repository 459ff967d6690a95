// Multimesh construction benchmark: a square with an N x N grid of square holes (N = 10, 20, 30 by
// default) built by BuildMultimesh (default options) against its affine copy (the icon corpus's
// transform, matrix(1.2 0.35 -0.25 1.1 30 -4): sheared, turned, scaled, moved), and, as the
// baseline measured in the same run, against itself (the same meshing and loop matching, a map
// with nothing to pull). Prints both times, their ratio, the vertex count and the overlays. The
// copy's loops pair through the affine map fitted to them, so its map costs about what the map
// onto the drawing itself costs (docs/benchmarks.md, "Multimesh construction").
// Usage: multimesh [--max-holes N (grids up to N x N)] [--json FILE] (one JSON row per case:
// {"case", "vertices", "seconds", "seconds_itself", "ratio", "overlays"}).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "solver/mesh/build_multimesh.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program

// A square of side 10 n + 5 with n x n square holes of side 5, 10 apart (holes clockwise).
Drawing HoleGrid(int n) {
  const double side = 10.0 * n + 5.0;
  Drawing d;
  d.outlines.push_back(Outline{{{0, 0}, {side, 0}, {side, side}, {0, side}}});
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = 5.0 + 10.0 * i, y = 5.0 + 10.0 * j;
      d.outlines.push_back(Outline{{{x, y}, {x, y + 5}, {x + 5, y + 5}, {x + 5, y}}});
    }
  }
  return d;
}

Drawing AffineCopy(const Drawing& d) {
  Drawing copy = d;
  for (Outline& o : copy.outlines) {
    for (Point& p : o.points)
      p = Point(1.2 * p.x() - 0.25 * p.y() + 30, 0.35 * p.x() + 1.1 * p.y() - 4);
  }
  return copy;
}

struct Run {
  double seconds = 0.0;
  MultimeshReport report;
  bool ok = false;
};

Run Build(const std::vector<Drawing>& drawings) {
  Run run;
  const auto start = std::chrono::steady_clock::now();
  const absl::StatusOr<Multimesh> mesh =
      BuildMultimesh(drawings, MultimeshOptions(), nullptr, nullptr, &run.report);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.ok = mesh.ok();
  if (!mesh.ok()) std::fprintf(stderr, "build: %s\n", mesh.status().ToString().c_str());
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  int max_holes = 30;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--max-holes" && i + 1 < argc) {
      max_holes = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--max-holes N] [--json FILE]\n", argv[0]);
      return 2;
    }
  }
  std::vector<nlohmann::json> rows;
  std::printf("%-16s %9s %10s %12s %7s %8s\n", "case", "vertices", "seconds", "itself (s)", "ratio",
              "overlays");
  for (int n : {10, 20, 30}) {
    if (n > max_holes) break;
    const Drawing grid = HoleGrid(n);
    const Run itself = Build({grid, grid});
    const Run copy = Build({grid, AffineCopy(grid)});
    if (!itself.ok || !copy.ok) return 1;
    const std::string name = "holes_" + std::to_string(n) + "x" + std::to_string(n);
    const double ratio = copy.seconds / itself.seconds;
    std::printf("%-16s %9d %10.2f %12.2f %7.2f %8d\n", name.c_str(), copy.report.vertices,
                copy.seconds, itself.seconds, ratio, copy.report.overlays);
    std::fflush(stdout);
    rows.push_back({{"case", name},
                    {"vertices", copy.report.vertices},
                    {"seconds", copy.seconds},
                    {"seconds_itself", itself.seconds},
                    {"ratio", ratio},
                    {"overlays", copy.report.overlays}});
  }
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    for (const nlohmann::json& row : rows) out << row.dump() << "\n";
  }
  return 0;
}
