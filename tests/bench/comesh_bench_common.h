// Shared by the comesh benchmarks (S-Tables 1, 2, 4): command line, the JSON row of one run and
// building a multimesh sized for a vertex count.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "solver/comesh/comesh_optimizer.h"
#include "solver/core/retain_memory.h"
#include "solver/mesh/build_multimesh.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"

namespace inbetween::bench {

struct ComeshBenchArgs {
  int max_vertices = 40000;
  int min_vertices = 0;   // rows below it are skipped (e.g. to run the 311k row alone)
  std::string cache_dir;  // comesh-scaling: built multimeshes kept here and reused (--cache DIR)
  // comesh-scaling: use a cached multimesh in its stored numbering instead of renumbering it along
  // the Hilbert curve as BuildMultimesh does now (--cache-order; for comparing the two).
  bool cache_order = false;
  std::string json_path;
  bool verbose = false;
  int repeat = 5;  // runs under a second are repeated (TimedOptimize); the median is reported
  bool malloc_defaults = false;  // --malloc-defaults: glibc's own thresholds (the CLI's are not)
  int cancel_trials = 0;  // comesh-scaling: cancellation latency trials per row (--cancel-trials)
  solver::ComeshOptions options;
};

// Parses --threads T, --json FILE, --max-outer K, --weight W, --blend B, --no-cure,
// --no-corner-swaps, --no-boundary-splits (TopologyOptions::corner_swaps, boundary_splits off),
// --no-outline-sliding (ComeshOptions::slide_outline off), --outline-corner DEGREES,
// --min-quality Q (ComeshOptions::min_quality; 0: no sliver removal),
// --double-substitutions (ComeshOptions::float_substitutions off), --mips-damping D
// (ComeshOptions::mips_damping; 0: the plain projected Hessian),
// --cure-keep C, --step-fraction F, --scale-by-inverse, --history M, --tolerance R, --laplacian
// (BCQN's H0), --refresh K, --relax F (0: no local relaxation), --relax-over-mean M,
// --relax-max K, --relax-steps S, --outer-inner K, --repeat N, --verbose, --malloc-defaults and
// (when `with_max_vertices`) --max-vertices N, --min-vertices N, --cache DIR and
// --cancel-trials N;
// exits 2 with a usage line otherwise.
// Unless --malloc-defaults, keeps freed memory in the process as the CLI does
// (solver/core/retain_memory.h), so the optimizer is timed as the animator's tool runs it.
inline ComeshBenchArgs ParseComeshBenchArgs(int argc, char** argv, bool with_max_vertices) {
  ComeshBenchArgs args;
  auto usage = [&] {
    std::fprintf(stderr,
                 "usage: %s %s[--threads T] [--max-outer K] [--weight W] [--blend B] [--no-cure] "
                 "[--no-corner-swaps] [--no-boundary-splits] [--no-outline-sliding] "
                 "[--slide-window W] [--outline-corner DEGREES] [--min-quality Q] "
                 "[--cure-keep C] [--double-substitutions] [--mips-damping D] [--step-fraction F] "
                 "[--outer-inner K] "
                 "[--scale-by-inverse] [--history M] [--tolerance R] [--laplacian] [--refresh K] "
                 "[--relax F] "
                 "[--relax-over-mean M] [--relax-max K] [--relax-steps S] [--repeat N] "
                 "[--verbose] [--malloc-defaults] [--json FILE]\n",
                 argv[0],
                 with_max_vertices
                     ? "[--max-vertices N] [--min-vertices N] [--cache DIR] [--cache-order] "
                       "[--cancel-trials N] "
                     : "");
    std::exit(2);
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : (usage(), ""); };
    if (a == "--max-vertices" && with_max_vertices) {
      args.max_vertices = std::atoi(next());
    } else if (a == "--min-vertices" && with_max_vertices) {
      args.min_vertices = std::atoi(next());
    } else if (a == "--cancel-trials" && with_max_vertices) {
      args.cancel_trials = std::max(0, std::atoi(next()));
    } else if (a == "--cache" && with_max_vertices) {
      args.cache_dir = next();
    } else if (a == "--cache-order" && with_max_vertices) {
      args.cache_order = true;
    } else if (a == "--json") {
      args.json_path = next();
    } else if (a == "--threads") {
      args.options.threads = std::atoi(next());
    } else if (a == "--min-quality") {
      args.options.min_quality = std::atof(next());
    } else if (a == "--max-outer") {
      args.options.max_outer = std::atoi(next());
    } else if (a == "--weight") {
      args.options.map_weight = std::atof(next());
    } else if (a == "--blend") {
      args.options.blend = std::atof(next());
    } else if (a == "--scale-by-inverse") {
      args.options.scaling_by_inverse = true;
    } else if (a == "--relax") {
      args.options.relax_fraction = std::atof(next());
    } else if (a == "--relax-over-mean") {
      args.options.relax_over_mean = std::atof(next());
    } else if (a == "--relax-max") {
      args.options.relax_max_vertices = std::atoi(next());
    } else if (a == "--relax-steps") {
      args.options.relax_steps = std::atoi(next());
    } else if (a == "--history") {
      args.options.history = std::atoi(next());
    } else if (a == "--outer-inner") {
      args.options.outer_inner_iterations = std::atoi(next());
    } else if (a == "--laplacian") {
      args.options.hessian_preconditioner = false;
    } else if (a == "--refresh") {
      args.options.hessian_refresh = std::atoi(next());
    } else if (a == "--double-substitutions") {
      args.options.float_substitutions = false;
    } else if (a == "--mips-damping") {
      args.options.mips_damping = std::atof(next());
    } else if (a == "--no-corner-swaps") {
      args.options.topology.corner_swaps = false;
    } else if (a == "--no-outline-sliding") {
      args.options.slide_outline = false;
    } else if (a == "--slide-window") {
      args.options.slide_window = std::atof(next());
    } else if (a == "--outline-corner") {
      args.options.outline_corner_degrees = std::atof(next());
    } else if (a == "--no-boundary-splits") {
      args.options.topology.boundary_splits = false;
    } else if (a == "--no-cure") {
      args.options.cure = false;
    } else if (a == "--cure-keep") {
      args.options.cure_keep = std::atof(next());
    } else if (a == "--step-fraction") {
      args.options.max_step_fraction = std::atof(next());
    } else if (a == "--tolerance") {
      args.options.relative_decrease_tolerance = std::atof(next());
    } else if (a == "--repeat") {
      args.repeat = std::max(1, std::atoi(next()));
    } else if (a == "--verbose") {
      args.verbose = true;
    } else if (a == "--malloc-defaults") {
      args.malloc_defaults = true;
    } else {
      usage();
    }
  }
  if (!args.malloc_defaults) solver::RetainFreedMemory();
  return args;
}

// Prints every inner iterate's progress line when verbose.
inline solver::ProgressFn VerboseProgress(bool verbose) {
  if (!verbose) return nullptr;
  return [](const std::string&, double, const std::string& detail) {
    std::printf("  %s\n", detail.c_str());
  };
}

// With --verbose: where the (first) run's time went.
inline void PrintPhases(const solver::ComeshReport& r) {
  const solver::ComeshPhaseSeconds& p = r.phase_seconds;
  std::printf(
      "  phases (s): hessian %.3f, direction %.3f, step bound %.3f, line search %.3f, "
      "relax %.3f, topology %.3f\n",
      p.hessian, p.direction, p.step_bound, p.line_search, p.relax, p.topology);
  std::printf("  slivers: %d below min_quality, %d operations, worst quality %.4f\n", r.slivers,
              r.sliver_operations, r.worst_quality);
}

// OptimizeComesh, timed: a run shorter than a second is repeated until `repeat` runs and at
// least kMinTimedSeconds in all were made (at most kMaxRuns; the optimizer is deterministic, so
// every run reports the same numbers) and report->seconds is the median, because a few
// milliseconds on a shared machine are mostly noise (the 98-vertex row of S-Table 2, ~5 ms: the
// median of 5 runs ranged over 5.0-6.8 ms from one start of the benchmark to the next, of ~100
// runs 5.0-5.1 ms). Progress is only
// shown for the first run (and, with it, where that run's time went). Each run gets a live
// cancellation token that is never set, as the service's OptimizeComesh does, so the polled
// paths are the ones timed.
inline absl::StatusOr<solver::Multimesh> TimedOptimize(const solver::Multimesh& mesh,
                                                       const solver::ComeshOptions& options,
                                                       const solver::ProgressFn& progress,
                                                       int repeat, solver::ComeshReport* report) {
  const solver::CancelToken never;
  absl::StatusOr<solver::Multimesh> out =
      solver::OptimizeComesh(mesh, options, &never, progress, report);
  if (out.ok() && progress) PrintPhases(*report);
  if (!out.ok() || report->seconds >= 1.0 || repeat <= 1) return out;
  constexpr double kMinTimedSeconds = 0.5;
  constexpr int kMaxRuns = 101;
  std::vector<double> seconds = {report->seconds};
  double total = report->seconds;
  while (static_cast<int>(seconds.size()) < repeat ||
         (total < kMinTimedSeconds && seconds.size() < kMaxRuns)) {
    solver::ComeshReport again;
    if (!solver::OptimizeComesh(mesh, options, &never, nullptr, &again).ok()) break;
    seconds.push_back(again.seconds);
    total += again.seconds;
  }
  std::sort(seconds.begin(), seconds.end());
  report->seconds = seconds[seconds.size() / 2];
  return out;
}

// The JSON row, plus energy evaluations (line-search trials included).
inline nlohmann::json ComeshRow(const std::string& name, const solver::ComeshReport& r,
                                double paper_seconds) {
  return {{"case", name},
          {"vertices_before", r.vertices_before},
          {"vertices_after", r.vertices_after},
          {"inner", r.inner},
          {"outer", r.outer},
          {"evaluations", r.energy_evaluations},
          {"seconds", r.seconds},
          {"map_energy", r.map_energy},
          {"mesh_energy", r.mesh_energy},
          {"worst_quality", r.worst_quality},
          {"slivers", r.slivers},
          {"paper_seconds", paper_seconds},
          {"phase_seconds",
           {{"hessian", r.phase_seconds.hessian},
            {"direction", r.phase_seconds.direction},
            {"step_bound", r.phase_seconds.step_bound},
            {"line_search", r.phase_seconds.line_search},
            {"relax", r.phase_seconds.relax},
            {"topology", r.phase_seconds.topology}}}};
}

// S-Tables 1 and 2's drawings: the unit square and a regular hexagon inside it.
inline std::vector<solver::Drawing> SquareHexagon() {
  return {solver::testing::UnitSquare(),
          solver::testing::RegularPolygon(6, 0.6, solver::Point(0.5, 0.5))};
}

// BuildMultimesh of `drawings` at the boundary count and edge bound SizeFor gave (other options
// default): the uniform meshes of the comesh tables.
inline absl::StatusOr<solver::Multimesh> BuildSized(const std::vector<solver::Drawing>& drawings,
                                                    const solver::testing::SizedMeshOptions& size) {
  solver::MultimeshOptions options;
  options.boundary_vertices = size.boundary_vertices;
  options.max_edge_relative = size.max_edge_relative;
  return solver::BuildMultimesh(drawings, options);
}

inline void WriteRows(const std::string& path, const nlohmann::json& rows) {
  if (!path.empty()) std::ofstream(path) << rows.dump(2) << "\n";
}

}  // namespace inbetween::bench
