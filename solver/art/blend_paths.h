// Morph of corresponding polylines: resample to one point count by arc length, then blend.
#pragma once

#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

// Normalized arc-length parameter of every vertex of `path` (0 at the first, 1 at the last of an
// open path; a closed path's closing segment counts, so its last vertex is < 1). All 0 for a path
// of zero length.
std::vector<double> ArcLengthParameters(const Points& path, bool closed);

// The point at normalized arc length u in [0, 1] of `path` (`params` from ArcLengthParameters);
// the first point for a path of zero length.
Point PointAtParameter(const Points& path, bool closed, const std::vector<double>& params,
                       double u);

// sum_k weights[k] paths[k](u) / sum_k weights[k], sampled at the union of every path's own
// vertex parameters (those within `merge_fraction` of a kept one merged into it), so that each
// path is represented exactly, corners included. Every path must have at least one point and
// the weights a non-zero sum. One path: returned as is.
Points BlendPaths(const std::vector<Points>& paths, bool closed, const std::vector<double>& weights,
                  double merge_fraction);

}  // namespace inbetween::solver
