// libFuzzer: boundary construction by directed graph flow (solver/geometry/graph_flow.cpp,
// S-Alg.1) on random planar drawings: outlines, cuts and openings on a coarse grid (touching,
// collinear and duplicate points are common) with occasional tiny nudges. Checks: no crash or
// sanitizer report; errors are INVALID_ARGUMENT; a result has at least one loop per component,
// every loop closed with >= 2 points, twins that point back at each other.
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "solver/geometry/graph_flow.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

inbetween::solver::Points Polyline(inbetween::fuzz::FuzzInput& in, int min_points, int max_points) {
  inbetween::solver::Points p;
  const int n = in.Int(min_points, max_points);
  for (int i = 0; i < n; ++i) {
    const double x = in.Coordinate();
    p.emplace_back(x, in.Coordinate());
  }
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace inbetween::solver;
  inbetween::fuzz::FuzzInput in(data, size);
  Drawing d;
  const int outlines = in.Int(1, 3), cuts = in.Int(0, 3), openings = in.Int(0, 2);
  for (int i = 0; i < outlines; ++i) d.outlines.push_back({Polyline(in, 3, 10)});
  for (int i = 0; i < cuts; ++i) d.cuts.push_back(Polyline(in, 2, 4));
  for (int i = 0; i < openings; ++i) d.openings.push_back(Polyline(in, 2, 4));
  absl::StatusOr<BoundaryGraph> g = BuildBoundaries(d, 1);
  if (!g.ok()) {
    if (g.status().code() != absl::StatusCode::kInvalidArgument) {
      std::fprintf(stderr, "unexpected status: %s\n", g.status().ToString().c_str());
      std::abort();
    }
    return 0;
  }
  if (g->loops.empty() || g->equivalence.components < 1) std::abort();
  for (size_t l = 0; l < g->loops.size(); ++l) {
    const BoundaryLoop& loop = g->loops[l];
    if (loop.points.size() < 2 || loop.twin.size() != loop.points.size()) std::abort();
    for (size_t k = 0; k < loop.twin.size(); ++k) {
      const auto [tl, tk] = loop.twin[k];
      if (tl < 0) continue;
      if (tl >= static_cast<int>(g->loops.size()) ||
          tk >= static_cast<int>(g->loops[tl].twin.size()) ||
          g->loops[tl].twin[tk] != std::pair<int, int>(static_cast<int>(l), static_cast<int>(k))) {
        std::fprintf(stderr, "twin of loop %zu edge %zu is not mutual\n", l, k);
        std::abort();
      }
    }
  }
  return 0;
}
