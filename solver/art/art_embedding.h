// A key drawing's art in mesh coordinates: every art point written once as (triangle,
// barycentric coordinates) in that key's own shape of the multimesh, so that any frame draws the
// art from its vertex positions alone (DESIGN.md, "Art"). The art then follows the mesh's
// piecewise-affine map exactly:
//  - Segments are split where they cross triangle edges of the key's shape (the crossing points
//    are inserted), so each piece lies in one triangle and its image in a frame is the image of
//    the piece, bent with the mesh, instead of a chord cutting across triangles. Exact where
//    resampling to a fraction of the edge length would only approximate, and it adds no point
//    inside a triangle. A segment running along the boundary (on it, or a little outside, as a
//    fill whose outline is the drawing's outline) crosses no edge there; it is also split at the
//    foot of each boundary vertex it passes within a quarter of that vertex's shorter boundary
//    edge, so it follows the boundary where a frame bends it.
//  - A point inside no triangle (art a little outside the mesh: on a curved outline, outside the
//    chords between boundary vertices, or paint within the import's gap tolerance) rides the
//    nearest triangle, with its barycentric coordinates extrapolated (some negative).
//    Extrapolation, not clamping to the triangle, so that the key is reproduced exactly and an
//    affine motion of that triangle moves the point with it; clamping would pull the art onto
//    the mesh boundary.
//  - A point on a cohesive edge (a cut or an opening, closed in this key) rides whichever side's
//    triangle point location finds; a segment across a cut that opens in a frame stretches over
//    the gap.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/art.h"
#include "solver/core/types.h"
#include "solver/core/embedded_art.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

struct ArtEmbeddingOptions {
  // Split segments where they cross triangle edges (see above). false: only the drawn points are
  // embedded, and a segment spanning several triangles becomes a straight chord in every frame.
  bool split_at_edges = true;
  // A crossing within this fraction of the segment's length from the segment's ends or from
  // another crossing is not inserted (it would add a point indistinguishable from one there).
  double min_split_fraction = 1e-9;
  // A point counts as inside a triangle when every barycentric coordinate is >= -this (points
  // on an edge belong to both sides; rounding must not send them to the nearest-triangle path).
  double inside_tolerance = 1e-12;
  // Spatial index resolution: about this many triangles per grid cell (triangle_grid.h).
  double triangles_per_cell = 2.0;
};

struct ArtEmbeddingReport {
  int points = 0;            // embedded points, inserted ones included
  int inserted = 0;          // crossing points inserted by split_at_edges
  int outside = 0;           // points inside no triangle (extrapolated from the nearest)
  double max_outside = 0.0;  // the largest distance of such a point to its triangle
  double seconds = 0.0;
};

// Embeds `art` (key `key`'s layers, in that drawing's coordinates) in shape `key` of `mesh`.
// Errors: INVALID_ARGUMENT for a key out of range, a mesh without triangles, or a non-finite art
// point (naming the layer and path).
absl::StatusOr<EmbeddedArt> EmbedArt(const Multimesh& mesh, int key,
                                     const std::vector<ArtLayer>& art,
                                     const ArtEmbeddingOptions& options = {},
                                     ArtEmbeddingReport* report = nullptr);

// Every drawing's art embedded in its own shape: drawings[k].art in shape k, one EmbeddedArt per
// drawing; empty when no drawing has art (Multimesh::art). Errors: INVALID_ARGUMENT when the
// mesh has fewer shapes than drawings, or EmbedArt's, naming the drawing ("drawing 2: ...").
absl::StatusOr<std::vector<EmbeddedArt>> EmbedDrawingsArt(const Multimesh& mesh,
                                                          const std::vector<Drawing>& drawings,
                                                          const ArtEmbeddingOptions& options = {});

// Positions of one embedded path's points in a geometry `vertices` of the multimesh:
// sum_i b_i vertices[corner_i]. Expects vertices.size() == the art's num_vertices.
Points PlacePath(const EmbeddedPath& path, const Points& vertices);

// The art in geometry `vertices` (a frame, or a key's shape): paint as embedded, every path
// placed by PlacePath. In the key's own shape this returns the drawn points (to rounding, about
// 1e-16 of the coordinates), with the inserted crossings on the drawn segments. INVALID_ARGUMENT
// when vertices.size() != art.num_vertices.
absl::StatusOr<std::vector<ArtLayer>> PlaceArt(const EmbeddedArt& art, const Points& vertices);

}  // namespace inbetween::solver
