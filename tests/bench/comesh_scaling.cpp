// Benchmark (S-Table 2): comesh optimization of square -> hexagon at the paper's vertex counts.
// Inputs are real multimeshes: generated polygons (unit square, regular hexagon) through
// BuildMultimesh, sized by MultimeshOptions for each Table 2 row's vertex count. Prints our row
// beside the paper's and the ratio paper_seconds / seconds; --json FILE writes the rows.
//
//   comesh_scaling [--max-vertices N] [--threads T] [--max-outer K] [--weight W] [--blend B]
//                  [--cure] [--json FILE] [--verbose]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "solver/comesh/comesh_optimizer.h"
#include "solver/mesh/build_multimesh.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace {

namespace sv = inbetween::solver;

// S-Table 2: vertices before/after, inner, outer, seconds.
struct PaperRow {
  int before, after, inner, outer;
  double seconds;
};
constexpr PaperRow kPaper[] = {{98, 98, 59, 5, 0.065},
                               {278, 277, 50, 7, 0.181},
                               {545, 544, 50, 8, 0.41},
                               {1057, 1046, 131, 13, 2.181},
                               {2087, 2074, 127, 13, 4.691},
                               {4331, 4296, 117, 10, 12.243},
                               {8649, 8611, 209, 17, 58.011},
                               {17131, 16963, 361, 18, 220.362},
                               {35386, 35114, 311, 21, 838.025},
                               {73072, 71870, 382, 26, 3358.401},
                               {165107, 164638, 447, 33, 13650.724},
                               {311522, 311183, 495, 34, 51253.368}};

}  // namespace

int main(int argc, char** argv) {
  int max_vertices = 40000;
  std::string json_path;
  bool verbose = false;
  sv::ComeshOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return i + 1 < argc ? argv[++i] : (std::exit(2), ""); };
    if (a == "--max-vertices") {
      max_vertices = std::atoi(next());
    } else if (a == "--json") {
      json_path = next();
    } else if (a == "--threads") {
      options.threads = std::atoi(next());
    } else if (a == "--max-outer") {
      options.max_outer = std::atoi(next());
    } else if (a == "--weight") {
      options.map_weight = std::atof(next());
    } else if (a == "--blend") {
      options.blend = std::atof(next());
    } else if (a == "--cure") {
      options.cure = true;
    } else if (a == "--verbose") {
      verbose = true;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--max-vertices N] [--threads T] [--max-outer K] [--weight W] "
                   "[--blend B] [--cure] [--json FILE] [--verbose]\n",
                   argv[0]);
      return 2;
    }
  }
  sv::ProgressFn progress;
  if (verbose) {
    progress = [](const std::string&, double, const std::string& detail) {
      std::printf("  %s\n", detail.c_str());
    };
  }
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-22s %13s %13s %11s %11s %9s %9s %7s %7s %7s\n", "case", "ver ours", "ver paper",
              "inner o/p", "outer o/p", "seconds", "paper_s", "ratio", "map", "mesh");
  const std::vector<sv::Drawing> drawings = {
      sv::testing::UnitSquare(), sv::testing::RegularPolygon(6, 0.6, sv::Point(0.5, 0.5))};
  for (const PaperRow& paper : kPaper) {
    if (paper.before > max_vertices) break;
    const auto size = sv::testing::SizeFor(paper.before, 4.0, std::sqrt(2.0), 1.0);
    sv::MultimeshOptions mesh_options;
    mesh_options.boundary_vertices = size.boundary_vertices;
    mesh_options.max_edge_relative = size.max_edge_relative;
    absl::StatusOr<sv::Multimesh> mesh = sv::BuildMultimesh(drawings, mesh_options);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%d vertices: %s\n", paper.before, mesh.status().ToString().c_str());
      return 1;
    }
    sv::ComeshReport r;
    absl::StatusOr<sv::Multimesh> out = sv::OptimizeComesh(*mesh, options, nullptr, progress, &r);
    if (!out.ok()) {
      std::fprintf(stderr, "%d vertices: %s\n", paper.before, out.status().ToString().c_str());
      return 1;
    }
    const std::string name = "square-hexagon-" + std::to_string(paper.before);
    std::printf("%-22s %6d/%-6d %6d/%-6d %5d/%-5d %5d/%-5d %9.3f %9.3f %7.1f %7.4f %7.4f\n",
                name.c_str(), r.vertices_before, r.vertices_after, paper.before, paper.after,
                r.inner, paper.inner, r.outer, paper.outer, r.seconds, paper.seconds,
                paper.seconds / r.seconds, r.map_energy, r.mesh_energy);
    std::fflush(stdout);
    rows.push_back({{"case", name},
                    {"vertices_before", r.vertices_before},
                    {"vertices_after", r.vertices_after},
                    {"inner", r.inner},
                    {"outer", r.outer},
                    {"seconds", r.seconds},
                    {"map_energy", r.map_energy},
                    {"mesh_energy", r.mesh_energy},
                    {"paper_seconds", paper.seconds}});
  }
  if (!json_path.empty()) std::ofstream(json_path) << rows.dump(2) << "\n";
  return 0;
}
