// Benchmark (S-Table 1): square -> hexagon (about 467 vertices, as in the paper) optimized with the
// map weight w swept over the paper's values, from two starting meshes:
// - "uniform": the mesh the other tables use (boundary and interior edges of one length, SizeFor);
// - "graded": the kind of start the paper describes (Triangle's conforming Delaunay triangulation
//   of the boundary samples, S §2 "Initial Meshing"): quality refinement only (no size bound), so
//   the interior grades from a dense boundary to large triangles inside, and the boundary count
//   is the one whose mesh comes closest to 467 vertices.
// Prints our rows beside the paper's; --json FILE (cases "square-hexagon-w0.50" and
// "square-hexagon-graded-w0.50" and so on).
//
//   comesh_weights [common options: comesh_bench_common.h]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "tests/bench/comesh_bench_common.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace {

namespace sv = inbetween::solver;

// S-Table 1: weight, vertices after (467 before), seconds, map, mesh.
struct PaperRow {
  double weight;
  int after;
  double seconds, map, mesh;
};
constexpr PaperRow kPaper[] = {{0.13, 358, 2.329, 2.114, 0.494}, {0.21, 331, 1.881, 2.095, 0.494},
                               {0.33, 340, 2.034, 2.065, 0.494}, {0.44, 332, 3.473, 2.054, 0.494},
                               {0.5, 345, 2.0, 2.056, 0.494},    {0.62, 337, 2.245, 2.052, 0.494},
                               {0.7, 335, 1.186, 2.055, 0.494},  {0.85, 327, 1.263, 2.050, 0.495},
                               {0.93, 360, 1.072, 2.046, 0.495}};

}  // namespace

int main(int argc, char** argv) {
  inbetween::bench::ComeshBenchArgs args =
      inbetween::bench::ParseComeshBenchArgs(argc, argv, /*with_max_vertices=*/false);
  sv::ComeshOptions& options = args.options;
  const sv::ProgressFn progress = inbetween::bench::VerboseProgress(args.verbose);
  const std::vector<sv::Drawing> drawings = inbetween::bench::SquareHexagon();
  const auto size = sv::testing::SizeFor(467, 4.0, std::sqrt(2.0), 1.0);
  absl::StatusOr<sv::Multimesh> uniform = inbetween::bench::BuildSized(drawings, size);
  if (!uniform.ok()) {
    std::fprintf(stderr, "%s\n", uniform.status().ToString().c_str());
    return 1;
  }
  // Graded start: the boundary count (even, 160..400) whose quality-only mesh is nearest 467.
  absl::StatusOr<sv::Multimesh> graded = absl::InternalError("no graded mesh built");
  for (int b = 160; b <= 400; b += 2) {
    sv::MultimeshOptions graded_options;
    graded_options.boundary_vertices = b;
    graded_options.max_edge_relative = 1.0;
    absl::StatusOr<sv::Multimesh> m = sv::BuildMultimesh(drawings, graded_options);
    if (!m.ok()) {
      std::fprintf(stderr, "graded, %d boundary vertices: %s\n", b, m.status().ToString().c_str());
      return 1;
    }
    if (!graded.ok() ||
        std::abs(m->num_vertices() - 467) < std::abs(graded->num_vertices() - 467)) {
      graded = std::move(m);
    }
    if (graded->num_vertices() >= 467) break;
  }
  nlohmann::json rows = nlohmann::json::array();
  const std::pair<const char*, const sv::Multimesh*> starts[] = {{"uniform", &*uniform},
                                                                 {"graded", &*graded}};
  for (const auto& [start, mesh] : starts) {
    std::printf("%s start (%d vertices, %zu on the boundary)\n", start, mesh->num_vertices(),
                mesh->boundary.size());
    std::printf("%-6s %13s %11s %6s %9s %9s %7s %15s %15s\n", "weight", "ver ours", "paper",
                "outer", "seconds", "paper_s", "ratio", "map ours/paper", "mesh ours/paper");
    for (const PaperRow& paper : kPaper) {
      options.map_weight = paper.weight;
      sv::ComeshReport r;
      absl::StatusOr<sv::Multimesh> out =
          inbetween::bench::TimedOptimize(*mesh, options, progress, args.repeat, &r);
      if (!out.ok()) {
        std::fprintf(stderr, "%s start, w = %g: %s\n", start, paper.weight,
                     out.status().ToString().c_str());
        return 1;
      }
      std::printf("%-6.2f %6d/%-6d %4d/%-6d %6d %9.3f %9.3f %7.1f %7.4f/%-7.3f %7.4f/%-7.3f\n",
                  paper.weight, r.vertices_before, r.vertices_after, 467, paper.after, r.outer,
                  r.seconds, paper.seconds, paper.seconds / r.seconds, r.map_energy, paper.map,
                  r.mesh_energy, paper.mesh);
      std::fflush(stdout);
      const std::string prefix =
          std::string(start) == "graded" ? "square-hexagon-graded-w" : "square-hexagon-w";
      rows.push_back(inbetween::bench::ComeshRow(prefix + std::to_string(paper.weight).substr(0, 4),
                                                 r, paper.seconds));
    }
  }
  inbetween::bench::WriteRows(args.json_path, rows);
  return 0;
}
