// Benchmark (S-Table 3): comesh optimization of a walking character with 2, 3, ..., 16 shapes at
// the paper's 1639 vertices. The poses are generated here: the side-view silhouette of
// examples/walk (head, torso, arm, two legs apart) at 16 phases of a stride, all of one topology,
// with correspondence marks at the crotch, the toe tips, the fingertip, the top of the head, the
// armpit and the hips (tests/unit/solver/mesh/walker_poses.h); the first n poses are meshed with
// BuildMultimesh and optimized. Prints our row beside the paper's and the ratio
// paper_seconds / seconds; a row whose multimesh cannot be built is printed as failed (exit 1).
//
//   comesh_shapes [--max-shapes N] [--pair K [--pair2 L]] [common options: comesh_bench_common.h]
//   (--pair: mesh poses 0 and K (and L) only, for investigating a failed row)
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "solver/geometry/polygon.h"
#include "tests/bench/comesh_bench_common.h"
#include "tests/unit/solver/comesh/comesh_test_meshes.h"
#include "tests/unit/solver/mesh/walker_poses.h"

namespace {

namespace sv = inbetween::solver;

// S-Table 3: shapes, vertices after (1639 before), inner, outer, seconds.
struct PaperRow {
  int shapes, after, inner, outer;
  double seconds;
};
constexpr PaperRow kPaper[] = {
    {2, 1514, 81, 6, 2.566},     {3, 1509, 419, 13, 12.548},   {4, 1482, 482, 12, 16.776},
    {5, 1483, 554, 16, 21.146},  {6, 1482, 197, 7, 9.894},     {7, 1446, 471, 16, 23.526},
    {8, 1427, 529, 12, 27.953},  {9, 1425, 825, 11, 42.558},   {10, 1380, 1273, 24, 77.621},
    {11, 1380, 818, 14, 85.71},  {12, 1357, 643, 13, 56.014},  {13, 1342, 742, 12, 94.933},
    {14, 1314, 843, 18, 82.283}, {15, 1337, 723, 11, 104.171}, {16, 1357, 883, 16, 78.754}};
constexpr int kVertices = 1639;

}  // namespace

int main(int argc, char** argv) {
  int max_shapes = 16;
  int pair = -1;  // debugging: mesh poses 0 and `pair` only
  int pair2 = -1;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--max-shapes" && i + 1 < argc) {
      max_shapes = std::atoi(argv[++i]);
    } else if (std::string(argv[i]) == "--pair" && i + 1 < argc) {
      pair = std::atoi(argv[++i]);
    } else if (std::string(argv[i]) == "--pair2" && i + 1 < argc) {
      pair2 = std::atoi(argv[++i]);
    } else {
      rest.push_back(argv[i]);
    }
  }
  inbetween::bench::ComeshBenchArgs args = inbetween::bench::ParseComeshBenchArgs(
      static_cast<int>(rest.size()), rest.data(), /*with_max_vertices=*/false);
  const sv::ProgressFn progress = inbetween::bench::VerboseProgress(args.verbose);

  std::vector<sv::Drawing> poses;
  for (int k = 0; k < 16; ++k) poses.push_back(sv::testing::WalkerPose(k, /*feature_marks=*/true));
  const sv::Points& outline = poses[0].outlines[0].points;
  double perimeter = 0.0;
  Eigen::AlignedBox2d box;
  for (size_t i = 0; i < outline.size(); ++i) {
    perimeter += (outline[(i + 1) % outline.size()] - outline[i]).norm();
    box.extend(outline[i]);
  }
  const auto size = sv::testing::SizeFor(kVertices, perimeter, box.diagonal().norm(),
                                         std::abs(sv::PolygonSignedArea(outline)));

  nlohmann::json rows = nlohmann::json::array();
  int failures = 0;
  std::printf("%-7s %13s %13s %11s %11s %6s %9s %9s %7s %7s %7s\n", "shapes", "ver ours",
              "ver paper", "inner o/p", "outer o/p", "evals", "seconds", "paper_s", "ratio", "map",
              "mesh");
  for (const PaperRow& paper : kPaper) {
    if (paper.shapes > max_shapes) break;
    std::vector<sv::Drawing> drawings(poses.begin(), poses.begin() + paper.shapes);
    if (pair >= 0) drawings = {poses[0], poses[pair]};
    if (pair2 >= 0) drawings.push_back(poses[pair2]);
    absl::StatusOr<sv::Multimesh> mesh = inbetween::bench::BuildSized(drawings, size);
    if (!mesh.ok()) {  // reported as a failed row; the other rows still run
      std::printf("%-7d multimesh failed: %s\n", paper.shapes, mesh.status().ToString().c_str());
      rows.push_back({{"case", "walk-" + std::to_string(paper.shapes) + "-shapes"},
                      {"error", mesh.status().ToString()},
                      {"paper_seconds", paper.seconds}});
      ++failures;
      continue;
    }
    sv::ComeshReport r;
    absl::StatusOr<sv::Multimesh> out =
        inbetween::bench::TimedOptimize(*mesh, args.options, progress, args.repeat, &r);
    if (!out.ok()) {
      std::fprintf(stderr, "%d shapes: %s\n", paper.shapes, out.status().ToString().c_str());
      return 1;
    }
    std::printf("%-7d %6d/%-6d %6d/%-6d %5d/%-5d %5d/%-5d %6d %9.3f %9.3f %7.1f %7.4f %7.4f\n",
                paper.shapes, r.vertices_before, r.vertices_after, kVertices, paper.after, r.inner,
                paper.inner, r.outer, paper.outer, r.energy_evaluations, r.seconds, paper.seconds,
                paper.seconds / r.seconds, r.map_energy, r.mesh_energy);
    std::fflush(stdout);
    rows.push_back(inbetween::bench::ComeshRow("walk-" + std::to_string(paper.shapes) + "-shapes",
                                               r, paper.seconds));
  }
  inbetween::bench::WriteRows(args.json_path, rows);
  return failures == 0 ? 0 : 1;
}
