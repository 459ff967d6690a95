// Benchmark (S-Table 2 columns): comesh optimization inner loop on square -> hexagon at
// increasing resolution. The hexagon shape is the Tutte embedding of the square grid
// (tests/unit/solver/comesh/comesh_test_meshes.h). Prints one row per size and, with
// --json FILE, writes the rows as JSON. Topology operations are not implemented yet, so
// vertices_after == vertices_before and outer == 0.
//
//   comesh_scaling [--max-vertices N] [--weight W] [--no-laplacian] [--json FILE]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "solver/comesh/comesh_optimizer.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace {

namespace sv = inbetween::solver;

// S-Table 2, (vertices before, seconds): the paper's square -> hexagon scaling rows.
struct PaperRow {
  int vertices;
  double seconds;
};
constexpr PaperRow kPaper[] = {{98, 0.065},       {278, 0.181},        {545, 0.41},
                               {1057, 2.181},     {2087, 4.691},       {4331, 12.243},
                               {8649, 58.011},    {17131, 220.362},    {35386, 838.025},
                               {73072, 3358.401}, {165107, 13650.724}, {311522, 51253.368}};

// Paper seconds at the nearest vertex count (log-linear interpolation between rows).
double PaperSecondsAt(int vertices) {
  const int n = sizeof(kPaper) / sizeof(kPaper[0]);
  if (vertices <= kPaper[0].vertices) return kPaper[0].seconds;
  for (int i = 1; i < n; ++i) {
    if (vertices <= kPaper[i].vertices) {
      const double t = std::log(double(vertices) / kPaper[i - 1].vertices) /
                       std::log(double(kPaper[i].vertices) / kPaper[i - 1].vertices);
      return std::exp((1 - t) * std::log(kPaper[i - 1].seconds) + t * std::log(kPaper[i].seconds));
    }
  }
  return kPaper[n - 1].seconds;
}

}  // namespace

int main(int argc, char** argv) {
  int max_vertices = 70000;
  std::string json_path;
  sv::ComeshOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--max-vertices" && i + 1 < argc) {
      max_vertices = std::atoi(argv[++i]);
    } else if (a == "--json" && i + 1 < argc) {
      json_path = argv[++i];
    } else if (a == "--weight" && i + 1 < argc) {
      options.map_weight = std::atof(argv[++i]);
    } else if (a == "--no-laplacian") {
      options.laplacian_preconditioner = false;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--max-vertices N] [--weight W] [--no-laplacian] [--json FILE]\n",
                   argv[0]);
      return 2;
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%9s %9s %6s %6s %10s %8s %8s %8s %8s %12s %8s %s\n", "ver", "ver_after", "inner",
              "outer", "seconds", "map0", "map", "mesh0", "mesh", "paper_s(~)", "ratio", "stop");
  // Even k: every corner cell is cut by the diagonal through the square corner, so no triangle
  // has three vertices on one hexagon side (see SquareGrid).
  for (int k = 6;; k = 2 * static_cast<int>(k * 0.71)) {
    const int vertices = (k + 1) * (k + 1);
    if (vertices > max_vertices) break;
    sv::Multimesh mesh = sv::testing::SquareGrid(k);
    mesh.shapes.push_back(sv::testing::TutteHexagon(mesh));
    sv::ComeshReport report;
    absl::StatusOr<sv::Multimesh> out =
        sv::OptimizeComesh(mesh, options, nullptr, nullptr, &report);
    if (!out.ok()) {
      std::fprintf(stderr, "k = %d: %s\n", k, out.status().ToString().c_str());
      return 1;
    }
    const double paper = PaperSecondsAt(vertices);
    std::printf("%9d %9d %6d %6d %10.4f %8.4f %8.4f %8.4f %8.4f %12.3f %8.1f %s\n",
                report.vertices_before, report.vertices_after, report.inner, report.outer,
                report.seconds, report.map_energy_before, report.map_energy,
                report.mesh_energy_before, report.mesh_energy, paper, paper / report.seconds,
                report.stop_reason.c_str());
    std::fflush(stdout);
    rows.push_back({{"case", "square-hexagon-grid-" + std::to_string(k)},
                    {"vertices_before", report.vertices_before},
                    {"vertices_after", report.vertices_after},
                    {"inner", report.inner},
                    {"outer", report.outer},
                    {"seconds", report.seconds},
                    {"map_energy", report.map_energy},
                    {"mesh_energy", report.mesh_energy},
                    {"map_energy_before", report.map_energy_before},
                    {"mesh_energy_before", report.mesh_energy_before},
                    {"stop_reason", report.stop_reason},
                    {"paper_seconds", paper}});
  }
  if (!json_path.empty()) {
    std::ofstream(json_path) << rows.dump(2) << "\n";
  }
  return 0;
}
