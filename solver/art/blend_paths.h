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

// `path` (closed) restarted and, when needed, reversed so that it runs along `reference` (closed,
// in the same space): the same direction (the sign of the enclosed area), and the start at the
// arc-length offset whose uniform samples lie closest to the reference's (least squares over 64
// samples, every offset tried on the sample grid, then refined between its neighbours). The
// polyline is the same point set: a new first vertex is inserted at that offset unless it falls
// on a vertex. Returned as is when either path has fewer than 3 points or no length.
Points AlignClosedPath(const Points& reference, const Points& path);

// Mean squared distance between 64 uniform arc-length samples of two closed paths, sample i of
// one against sample i of the other (so: after AlignClosedPath). Infinity when either has no
// length or fewer than 3 points.
double MeanSquaredDistance(const Points& a, const Points& b);

// sum_k weights[k] paths[k](u) / sum_k weights[k], sampled at the union of every path's own
// vertex parameters (those within `merge_fraction` of a kept one merged into it), so that each
// path is represented exactly, corners included. Every path must have at least one point and
// the weights a non-zero sum. One path: returned as is.
Points BlendPaths(const std::vector<Points>& paths, bool closed, const std::vector<double>& weights,
                  double merge_fraction);

}  // namespace inbetween::solver
