// libFuzzer: the meshing pipeline (solver/mesh/build_multimesh.cpp: boundary correspondence,
// CGAL mesh, map to the other drawing) on random simple polygons, near-degenerate ones included
// (grid coordinates: collinear runs, sliver spikes; tiny nudges). The second drawing is an affine
// image of the first (rotated, scaled, sheared, so the same class). Checks: a built multimesh is
// valid (ValidateMultimesh: no inverted or degenerate triangle in any shape: never a folded
// mesh); a refusal is INVALID_ARGUMENT or FAILED_PRECONDITION, never INTERNAL.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "solver/geometry/polygon.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace inbetween::solver;
  inbetween::fuzz::FuzzInput in(data, size);
  const int n = in.Int(3, 16);
  Points a;
  for (int i = 0; i < n; ++i) {
    const double x = in.Coordinate();
    a.emplace_back(x, in.Coordinate());
  }
  const double angle = in.Int(0, 63) * 0.1, scale = 0.5 + in.Int(0, 15) * 0.1;
  const double shear = (in.Int(0, 10) - 5) * 0.1;
  // Small meshes: degenerate geometry shows at any size, and a fuzzer must run millions of
  // inputs (the automatic count, ~64, is left to the unit tests).
  const int boundary_vertices = 8 + in.Int(0, 3) * 4;
  // The pipeline receives what the server would pass on: the server refuses non-simple or
  // zero-area outlines before meshing (server/drawing_import.cpp).
  if (FindSelfIntersection(a) || !(std::abs(PolygonSignedArea(a)) > 0)) return 0;
  if (PolygonSignedArea(a) < 0) std::reverse(a.begin(), a.end());
  Points b;
  for (const Point& p : a) {
    const Point s(scale * (p.x() + shear * p.y()), scale * p.y());
    b.emplace_back(std::cos(angle) * s.x() - std::sin(angle) * s.y() + 5,
                   std::sin(angle) * s.x() + std::cos(angle) * s.y() - 3);
  }
  Drawing da, db;
  da.outlines = {{a}};
  db.outlines = {{b}};
  MultimeshOptions options;
  options.boundary_vertices = boundary_vertices;
  // A thin feature is refused quickly, not refined for hours; and the map of a mesh this size
  // (2000 iterations at most, each one factorization) stays well inside the hang timeout under
  // ASan (20000 vertices took 40 s). 300 rather than 3000 for throughput.
  options.max_mesh_vertices = 300;
  // A spike whose boundary pull never converges ran the whole 2,000-iteration budget (9.6 s
  // here) before its FAILED_PRECONDITION; 200 still run three stages of the pull (60 iterations
  // each) and end in the same refusal.
  options.max_map_iterations = 200;
  absl::StatusOr<Multimesh> m = BuildMultimesh({da, db}, options);
  if (!m.ok()) {
    const absl::StatusCode code = m.status().code();
    if (code != absl::StatusCode::kInvalidArgument &&
        code != absl::StatusCode::kFailedPrecondition &&
        code != absl::StatusCode::kResourceExhausted) {
      std::fprintf(stderr, "unexpected status: %s\n", m.status().ToString().c_str());
      std::abort();
    }
    return 0;
  }
  if (absl::Status s = ValidateMultimesh(*m); !s.ok()) {
    std::fprintf(stderr, "folded or invalid multimesh accepted: %s\n", s.ToString().c_str());
    std::abort();
  }
  return 0;
}
