// Stage driver: drawings -> compatible multimesh (correspondence, mesh of shape 1, mapping).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

struct MultimeshOptions {
  // Target number of boundary vertices per shape; 0 = choose from the shapes' size (about 64).
  int boundary_vertices = 0;
  // Max triangle edge length relative to the bounding-box diagonal of the meshed drawing
  // (0 = automatic: about the boundary spacing).
  double max_edge_relative = 0.0;
  // CGAL Delaunay_mesh_size_criteria_2 shape bound B (0.125 is a minimum angle of ~20.7 deg).
  double shape_bound = 0.125;
  // Correspondence marks: marks[m][d] is mark m's point in drawing d (one point per drawing).
  // Each pins a boundary point across drawings; between marks, boundaries are reparameterized
  // with equal vertex counts (solver/geometry/boundary_correspondence.h). Empty = the drawings'
  // own marks (Drawing::marks, matched by id), and automatic when they have none.
  std::vector<std::vector<Point>> marks;
  // Boundary vertices turning by more than this many degrees are kept as mesh vertices.
  double corner_angle_degrees = 30.0;
  // Without marks, boundaries are matched by arc length from an automatic alignment. Corner
  // matching (BoundaryCorrespondenceOptions::match_corners: loops with as many corners in every
  // drawing matched corner to corner, arc length between them) is the second attempt when that
  // correspondence cannot be built or mapped (INVALID_ARGUMENT or FAILED_PRECONDITION, e.g. a
  // sheared copy of a concave polygon, whose corners arc length puts onto straight sides), made
  // only if some loop's corners do match; if it fails too, the first attempt's error is
  // returned. Not the first choice: the optimizer slides boundary vertices along straight
  // stretches, so a corner paired with a straight point keeps a freedom that corner pairs lose
  // (principles_secondary_action at ~800 vertices: map energy 2.0018 by arc length, 2.0161 with
  // the corners matched).
  enum class CornerMatching { kNever, kWhenArcLengthFails, kAlways };
  CornerMatching corner_matching = CornerMatching::kWhenArcLengthFails;
  // How loops without marks are paired (BoundaryCorrespondenceOptions::alignment): kFeatures,
  // the default, by the feature alignment of solver/geometry/loop_alignment.h (corner onto
  // corner, stretching penalized: a bar bent into a half ring bends instead of sliding its
  // material round the corners, docs/benchmarks.md "correspondence"); kArcLength by arc length
  // from the automatic start, as before. Marks and corner matching (above) win over both.
  enum class Correspondence { kArcLength, kFeatures };
  Correspondence correspondence = Correspondence::kFeatures;
  // Outline tolerance (BoundaryCorrespondenceOptions::tolerance), relative to each drawing's
  // bounding-box diagonal: every key's boundary lies within it of its drawing's outline (0.1% by
  // default). 0: the even sampling alone. A fixed boundary_vertices wins over it.
  double boundary_tolerance = 1e-3;
  // Bound on the vertices of the initial mesh (TriangulateOptions::max_vertices); above it the
  // build is RESOURCE_EXHAUSTED instead of refining (practically) forever.
  int max_mesh_vertices = 2'000'000;
  // SLIM iterations allowed to each map into another drawing (MapToBoundaryOptions::
  // max_iterations); when they run out the build is FAILED_PRECONDITION. mesh_fuzz lowers it so
  // that an input whose pull never converges does not cost the time of thousands of others.
  int max_map_iterations = 2000;
  // When no drawing's mesh maps into some drawing (every attempt above FAILED_PRECONDITION), a
  // last attempt overlays the first drawing's mesh with a triangulation of each drawing it cannot
  // be mapped into (overlay_mesh.h): a common refinement that maps into both without folding,
  // for any component bounded by one loop that is a simple polygon in that drawing. Its thin
  // triangles are left to comesh optimization. Its vertices count against max_mesh_vertices (an
  // overlay above it is not made). false: such inputs stay FAILED_PRECONDITION.
  bool overlay = true;
  // With the overlay on, a map whose worst triangle quality (4 sqrt(3) area / sum of squared
  // edges, validate.h's WorstTriangleQuality) is below this does not count as found: the
  // boundary pull can end with a triangle nearly flat (1e-16 on random star-shaped pairs) where
  // the overlay gives ~1e-4. Such a map is still used when the overlay does not build either.
  double min_map_quality = 1e-8;
};

struct MultimeshReport {
  int vertices = 0;
  int triangles = 0;
  double seconds = 0.0;
  // Per drawing: its equivalence class after cuts and openings, e.g. "1 component, 1 hole".
  std::vector<std::string> equivalence;
  int boundary_loops = 0;
  int cohesive_edges = 0;
  // Boundary loops (groups of corresponding loops) whose correspondence matched corners to
  // corners (MultimeshOptions::corner_matching); 0 when arc length (or marks) gave it.
  int corner_matched_loops = 0;
  // Boundary vertices of each loop (Multimesh::boundary_loops), and the farthest any drawing's
  // outline strays from its loops, relative to the drawing's bounding-box diagonal
  // (MultimeshOptions::boundary_tolerance is the bound asked for).
  std::vector<int> loop_vertices;
  double achieved_tolerance = 0.0;
  // Drawings (components) reached by the overlay of MultimeshOptions::overlay; 0 when every map
  // was found directly.
  int overlays = 0;
  // Of `seconds`: embedding the drawings' art in the mesh (Multimesh::art).
  double art_seconds = 0.0;
};

// Builds one compatible mesh across all drawings (>= 2): S-Alg.1 boundaries of each drawing
// (outlines, cuts, openings), loop matching and compatible reparameterization, CGAL mesh of one
// drawing (the one with the most closed cut/opening sides, else drawing 1; holes, several
// components, cut sides duplicated into cohesive edge pairs), boundary Steiner points mirrored
// across every cohesive zone, fans widened where a boundary angle must open up to 2*pi
// (refine_boundary_fans.h), then an injective map of each component into every other drawing.
// When that drawing's mesh cannot be mapped (FAILED_PRECONDITION, after both correspondences
// below), the next drawings in the same order are meshed instead, up to 3 in all (random
// star-shaped pairs: refusals 86 -> 57, 27 -> 6, 5 -> 1 of ~190 each, docs/hardening.md); the
// error is then the first drawing's, naming the others tried, unless the overlay below builds.
// Last (MultimeshOptions::overlay), the first drawing's mesh again, refined by overlay with a
// triangulation of each drawing it cannot be mapped into.
// Drawings are named 1-based in messages ("drawing 2"). Errors: INVALID_ARGUMENT naming the drawing
// and what is wrong (including drawings of different equivalence class), FAILED_PRECONDITION when a
// shape cannot be reached, CANCELLED.
absl::StatusOr<Multimesh> BuildMultimesh(const std::vector<Drawing>& drawings,
                                         const MultimeshOptions& options,
                                         const CancelToken* cancel = nullptr,
                                         const ProgressFn& progress = nullptr,
                                         MultimeshReport* report = nullptr);

}  // namespace inbetween::solver
