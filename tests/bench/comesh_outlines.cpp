// Benchmark: comesh optimization with and without sliding along curved outlines
// (ComeshOptions::slide_outline, comesh_outline.h), on two generated curved pairs (a circle to a
// 0.9 x 0.3 ellipse and to a half-disk, 96- and 33-point outlines, 48 boundary vertices) and on
// every example under examples/ (default meshing). The paper has no such table: each case is
// its own baseline, outline sliding off, run in the same process. Prints vertices, inner
// iterations, seconds, the final objective and the map / mesh energies of both runs, and the
// largest relative change of a shape's area with outline sliding (the shapes keep their areas
// exactly without it); --json FILE writes the issue's
// rows (cases NAME-outline-off / NAME-outline-on, paper_seconds null).
//
//   comesh_outlines [--only NAME] [--boundary-vertices N] [--max-edge-relative E]
//                   [common options: comesh_bench_common.h]
// (--boundary-vertices / --max-edge-relative: every case meshed finer, e.g. 600 and 0.008 for
// ~16k vertices on principles_squash_stretch.)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "tests/bench/comesh_bench_common.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace {

namespace sv = inbetween::solver;

sv::Drawing Ellipse(double a, double b, int points) {
  sv::Drawing d;
  sv::Points outline;
  for (int k = 0; k < points; ++k) {
    const double t = 2.0 * std::numbers::pi * k / points;
    outline.push_back(sv::Point(0.5 + a * std::cos(t), 0.5 + b * std::sin(t)));
  }
  d.outlines.push_back({outline});
  return d;
}

sv::Drawing HalfDisk() {
  sv::Drawing d;
  sv::Points outline;
  for (int k = 0; k <= 32; ++k) {
    const double t = std::numbers::pi * k / 32.0;
    outline.push_back(sv::Point(0.5 + 0.5 * std::cos(t), 0.3 + 0.5 * std::sin(t)));
  }
  d.outlines.push_back({outline});
  return d;
}

double Area(const sv::Multimesh& m, int s) {
  double area = 0.0;
  for (const sv::Triangle& t : m.triangles) {
    const sv::Point e1 = m.shapes[s][t[1]] - m.shapes[s][t[0]];
    const sv::Point e2 = m.shapes[s][t[2]] - m.shapes[s][t[0]];
    area += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  return area;
}

struct Case {
  std::string name;
  std::vector<sv::Drawing> drawings;
  sv::MultimeshOptions options;
};

}  // namespace

int main(int argc, char** argv) {
  std::string only;
  int boundary_vertices = 0;
  double max_edge_relative = 0.0;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (std::string(argv[i]) == "--boundary-vertices" && i + 1 < argc) {
      boundary_vertices = std::atoi(argv[++i]);
    } else if (std::string(argv[i]) == "--max-edge-relative" && i + 1 < argc) {
      max_edge_relative = std::atof(argv[++i]);
    } else {
      rest.push_back(argv[i]);
    }
  }
  inbetween::bench::ComeshBenchArgs args = inbetween::bench::ParseComeshBenchArgs(
      static_cast<int>(rest.size()), rest.data(), /*with_max_vertices=*/false);
  const sv::ProgressFn progress = inbetween::bench::VerboseProgress(args.verbose);

  std::vector<Case> cases;
  sv::MultimeshOptions generated;
  generated.boundary_vertices = 48;
  cases.push_back({"circle-ellipse", {Ellipse(0.5, 0.5, 96), Ellipse(0.9, 0.3, 96)}, generated});
  cases.push_back({"circle-half-disk", {Ellipse(0.5, 0.5, 96), HalfDisk()}, generated});
  for (const std::string& name : sv::example_projects::List()) {
    absl::StatusOr<sv::example_projects::Example> example = sv::example_projects::Load(name);
    if (!example.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), example.status().ToString().c_str());
      return 1;
    }
    cases.push_back({name, example->drawings, example->options});
  }

  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-38s %6s %11s %11s %9s %9s %9s %15s %15s %17s %8s\n", "case", "shapes",
              "ver off", "ver on", "inner", "s off", "s on", "map before/off", "map on (mesh)",
              "objective off/on", "area on");
  for (const Case& c : cases) {
    if (!only.empty() && c.name != only) continue;
    sv::MultimeshOptions mesh_options = c.options;
    if (boundary_vertices > 0) mesh_options.boundary_vertices = boundary_vertices;
    if (max_edge_relative > 0.0) mesh_options.max_edge_relative = max_edge_relative;
    absl::StatusOr<sv::Multimesh> mesh = sv::BuildMultimesh(c.drawings, mesh_options);
    if (!mesh.ok()) {
      std::fprintf(stderr, "%s: %s\n", c.name.c_str(), mesh.status().ToString().c_str());
      return 1;
    }
    sv::ComeshReport report[2];
    double area_change = 0.0;
    for (int on = 0; on < 2; ++on) {
      sv::ComeshOptions options = args.options;
      options.slide_outline = on == 1;
      absl::StatusOr<sv::Multimesh> out =
          inbetween::bench::TimedOptimize(*mesh, options, progress, args.repeat, &report[on]);
      if (!out.ok()) {
        std::fprintf(stderr, "%s (outline sliding %s): %s\n", c.name.c_str(), on ? "on" : "off",
                     out.status().ToString().c_str());
        return 1;
      }
      if (on == 1) {
        for (int shape = 0; shape < mesh->num_shapes(); ++shape) {
          const double change = Area(*out, shape) / Area(*mesh, shape) - 1.0;
          if (std::abs(change) > std::abs(area_change)) area_change = change;
        }
      }
      std::string name = c.name;
      for (char& ch : name) {
        if (ch == '/') ch = '-';
      }
      rows.push_back(inbetween::bench::ComeshRow(name + (on ? "-outline-on" : "-outline-off"),
                                                 report[on],
                                                 std::numeric_limits<double>::quiet_NaN()));
    }
    const sv::ComeshReport& off = report[0];
    const sv::ComeshReport& on = report[1];
    std::printf(
        "%-38s %6d %5d/%-5d %5d/%-5d %4d/%-4d %9.3f %9.3f %7.4f/%-7.4f %7.4f (%.4f) %8.4f/%-8.4f "
        "%+7.3f%%\n",
        c.name.c_str(), mesh->num_shapes(), off.vertices_before, off.vertices_after,
        on.vertices_before, on.vertices_after, off.inner, on.inner, off.seconds, on.seconds,
        off.map_energy_before, off.map_energy, on.map_energy, on.mesh_energy, off.objective_after,
        on.objective_after, 100.0 * area_change);
    std::fflush(stdout);
  }
  inbetween::bench::WriteRows(args.json_path, rows);
  return 0;
}
