// Benchmark: square -> hexagon map energy against mesh resolution, at the objective's weight
// (--weight W, default 0.5). S-Table 1 reports the map energy (2.056) at 467 vertices only and
// S-Table 2 reports none; this sweep measures where the optimized map energy crosses a line
// (--line E, default 2.06, the issue's target) between the 98 and 278 rows of S-Table 2.
//
// Meshes: the uniform meshes the other tables use (SizeFor), for each requested vertex count
// with three boundary densities (the perimeter's share of the vertices: SizeFor's perimeter
// argument 3, 4 and 5 for the square's 4), so that a row is not one lucky mesh. Each mesh is
// optimized with the common options (comesh_bench_common.h). Prints one row per mesh and the
// crossing: the largest optimized mesh above the line and the smallest at or below it.
// --json FILE writes the rows ("square-hexagon-res120-b27" and so on; the row fields plus
// "boundary_vertices" and "weight").
//
//   comesh_resolution [--line E] [common options: comesh_bench_common.h]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "tests/bench/comesh_bench_common.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace sv = inbetween::solver;

int main(int argc, char** argv) {
  // --line is ours; the rest are the common options.
  double line = 2.06;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--line") == 0 && i + 1 < argc) {
      line = std::atof(argv[++i]);
    } else {
      rest.push_back(argv[i]);
    }
  }
  const inbetween::bench::ComeshBenchArgs args = inbetween::bench::ParseComeshBenchArgs(
      static_cast<int>(rest.size()), rest.data(), /*with_max_vertices=*/false);
  const sv::ComeshOptions& options = args.options;
  const std::vector<sv::Drawing> drawings = inbetween::bench::SquareHexagon();
  std::printf("weight %.4f, line %.4f\n", options.map_weight, line);
  std::printf("%-30s %9s %11s %9s %8s %8s\n", "case", "boundary", "vertices", "seconds", "map",
              "mesh");
  nlohmann::json rows = nlohmann::json::array();
  int largest_above = 0, smallest_below = 0;  // by vertices after
  for (int target : {80, 98, 120, 140, 160, 180, 200, 230, 260, 300}) {
    for (double perimeter : {3.0, 4.0, 5.0}) {
      const auto size = sv::testing::SizeFor(target, perimeter, std::sqrt(2.0), 1.0);
      const absl::StatusOr<sv::Multimesh> mesh = inbetween::bench::BuildSized(drawings, size);
      if (!mesh.ok()) {
        std::fprintf(stderr, "%d vertices: %s\n", target, mesh.status().ToString().c_str());
        return 1;
      }
      sv::ComeshReport r;
      const absl::StatusOr<sv::Multimesh> out =
          inbetween::bench::TimedOptimize(*mesh, options, nullptr, args.repeat, &r);
      if (!out.ok()) {
        std::fprintf(stderr, "%d vertices: %s\n", target, out.status().ToString().c_str());
        return 1;
      }
      const std::string name = "square-hexagon-res" + std::to_string(target) + "-b" +
                               std::to_string(size.boundary_vertices);
      std::printf("%-30s %9d %5d/%-5d %9.3f %8.4f %8.4f\n", name.c_str(), size.boundary_vertices,
                  r.vertices_before, r.vertices_after, r.seconds, r.map_energy, r.mesh_energy);
      nlohmann::json row = inbetween::bench::ComeshRow(name, r, /*paper_seconds=*/0.0);
      row.erase("paper_seconds");  // no paper row at these counts
      row["boundary_vertices"] = size.boundary_vertices;
      row["weight"] = options.map_weight;
      rows.push_back(std::move(row));
      if (r.map_energy > line) {
        largest_above = std::max(largest_above, r.vertices_after);
      } else if (smallest_below == 0 || r.vertices_after < smallest_below) {
        smallest_below = r.vertices_after;
      }
    }
  }
  std::printf("map energy above %.4f up to %d vertices (after); at or below it from %d vertices\n",
              line, largest_above, smallest_below);
  inbetween::bench::WriteRows(args.json_path, rows);
  return 0;
}
