// Benchmark (S-Table 4): pentagon -> five-pointed star, hard1..hard6, ~1683 vertices. The star's
// inner radius goes from 0.8 (hard1, nearly the pentagon: the paper notes similar shapes take
// longest) to 0.3 (hard6) of its outer radius; both polygons are generated here and meshed with
// BuildMultimesh. Prints our row beside the paper's; --json FILE.
//
//   comesh_difficulty [common options: comesh_bench_common.h]
#include <cstdio>
#include <numbers>
#include <string>

#include "tests/bench/comesh_bench_common.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace {

namespace sv = inbetween::solver;

// S-Table 4: vertices before/after, inner, outer, seconds.
struct PaperRow {
  int before, after, inner, outer;
  double seconds;
};
constexpr PaperRow kPaper[] = {{1683, 1516, 3149, 96, 82.906}, {1683, 1546, 1391, 53, 40.188},
                               {1683, 1556, 479, 13, 14.508},  {1683, 1574, 484, 22, 14.347},
                               {1683, 1539, 205, 9, 6.444},    {1683, 1376, 233, 9, 9.46}};
constexpr double kInnerRatio[] = {0.8, 0.7, 0.6, 0.5, 0.4, 0.3};

}  // namespace

int main(int argc, char** argv) {
  inbetween::bench::ComeshBenchArgs args =
      inbetween::bench::ParseComeshBenchArgs(argc, argv, /*with_max_vertices=*/false);
  sv::ComeshOptions& options = args.options;
  const sv::ProgressFn progress = inbetween::bench::VerboseProgress(args.verbose);
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-7s %6s %13s %11s %11s %11s %9s %9s %7s %7s %7s\n", "case", "inner", "ver ours",
              "ver paper", "inner o/p", "outer o/p", "seconds", "paper_s", "ratio", "map", "mesh");
  const double pentagon_area = 2.5 * std::sin(2 * std::numbers::pi / 5);  // radius 1
  for (int h = 0; h < 6; ++h) {
    const PaperRow& paper = kPaper[h];
    const sv::Point c(0, 0);
    const std::vector<sv::Drawing> drawings = {
        sv::testing::RegularPolygon(5, 1.0, c, -std::numbers::pi / 2),
        sv::testing::Star(1.0, kInnerRatio[h], c)};
    const auto size = sv::testing::SizeFor(paper.before, 5 * 2 * std::sin(std::numbers::pi / 5),
                                           2.0, pentagon_area);
    absl::StatusOr<sv::Multimesh> mesh = inbetween::bench::BuildSized(drawings, size);
    const std::string name = "hard" + std::to_string(h + 1);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), mesh.status().ToString().c_str());
      return 1;
    }
    sv::ComeshReport r;
    absl::StatusOr<sv::Multimesh> out =
        inbetween::bench::TimedOptimize(*mesh, options, progress, args.repeat, &r);
    if (!out.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), out.status().ToString().c_str());
      return 1;
    }
    std::printf("%-7s %6.2f %6d/%-6d %5d/%-5d %5d/%-5d %5d/%-5d %9.3f %9.3f %7.1f %7.4f %7.4f\n",
                name.c_str(), kInnerRatio[h], r.vertices_before, r.vertices_after, paper.before,
                paper.after, r.inner, paper.inner, r.outer, paper.outer, r.seconds, paper.seconds,
                paper.seconds / r.seconds, r.map_energy, r.mesh_energy);
    std::fflush(stdout);
    rows.push_back(inbetween::bench::ComeshRow("pentagon-star-" + name, r, paper.seconds));
  }
  inbetween::bench::WriteRows(args.json_path, rows);
  return 0;
}
