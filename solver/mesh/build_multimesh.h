// Stage driver: drawings -> compatible multimesh (correspondence, mesh of shape 1, mapping).
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

struct MultimeshOptions {
  // Target number of boundary vertices per shape; 0 = choose from the shapes' size (about 64).
  int boundary_vertices = 0;
  // Max triangle edge length relative to the bounding-box diagonal of shape 1 (0 = automatic).
  double max_edge_relative = 0.0;
  // CGAL Delaunay_mesh_size_criteria_2 shape bound B (0.125 is a minimum angle of ~20.7 deg).
  double shape_bound = 0.125;
};

struct MultimeshReport {
  int vertices = 0;
  int triangles = 0;
  double seconds = 0.0;
};

// Builds one compatible mesh across all drawings (>= 2). Errors: INVALID_ARGUMENT naming the
// drawing and what is wrong, FAILED_PRECONDITION when a shape cannot be reached, CANCELLED.
absl::StatusOr<Multimesh> BuildMultimesh(const std::vector<Drawing>& drawings,
                                         const MultimeshOptions& options,
                                         const CancelToken* cancel = nullptr,
                                         const ProgressFn& progress = nullptr,
                                         MultimeshReport* report = nullptr);

}  // namespace inbetween::solver
