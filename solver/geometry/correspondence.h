// Boundary correspondence for single-outline drawings: every outline is resampled by arc length
// to the same vertex count, and drawings 1..n-1 are cyclically shifted to best match drawing 0.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/geometry/resample_outline.h"

namespace inbetween::solver {

struct CorrespondenceOptions {
  // Boundary vertices per drawing; 0 = automatic (64, or more when the outlines have many
  // corners).
  int vertices = 0;
  ResampleOptions resample;
};

struct Correspondence {
  // boundaries[i][k] corresponds to boundaries[0][k]; every boundary is positive and simple.
  std::vector<Points> boundaries;
  // shifts[i]: boundaries[i][k] is the (k + shifts[i])-th vertex of drawing i's resampling.
  std::vector<int> shifts;
};

// Drawings are numbered from 0 in messages ("drawing 1"). Errors:
//  INVALID_ARGUMENT: a drawing without outline, non-finite coordinates, fewer than 3 distinct
//    points, zero area, a self-intersecting outline (with the location).
//  UNIMPLEMENTED: a drawing with several outlines (components/holes need cuts and openings).
absl::StatusOr<Correspondence> ComputeCorrespondence(const std::vector<Drawing>& drawings,
                                                     const CorrespondenceOptions& options = {});

// Checks that `polygon` is usable as a boundary: finite, >= 3 distinct points, non-zero area,
// simple. `what` starts the error message (e.g. "drawing 2").
absl::Status CheckSimplePolygon(const Points& polygon, const std::string& what);

}  // namespace inbetween::solver
