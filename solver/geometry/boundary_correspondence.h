// S-Sec.1 "Boundary Tool": boundaries of all drawings matched loop to loop (components, then
// their holes), pinned by user marks or aligned automatically, and compatibly reparameterized so
// that every boundary segment between breakpoints has the same vertex count in every drawing.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/types.h"
#include "solver/geometry/graph_flow.h"

namespace inbetween::solver {

struct BoundaryCorrespondenceOptions {
  // Boundary vertices per drawing (all loops); 0 = automatic (64, more with many corners).
  int vertices = 0;
  // Vertices turning by more than this (degrees) are corners: kept as vertices.
  double corner_angle_degrees = 30.0;
  // marks[m][d]: where correspondence mark m sits in drawing d (one point per drawing). Each mark
  // pins the nearest boundary point of drawing 1 to the nearest point of the matching loop in
  // every other drawing; marks on a loop must keep their cyclic order in every drawing. A mark
  // also pairs the loops it sits on (the nearest loop of each drawing) and their components: the
  // loop matching below keeps every such pair, so one mark says which part or hole of drawing 1
  // becomes which of another. A mark on an outline in one drawing and on a hole in another, or two
  // marks that pair one loop (or component) with two, give INVALID_ARGUMENT naming the marks.
  std::vector<std::vector<Point>> marks;
  // Without marks on a loop: when every drawing has as many corners on it as drawing 1, they are
  // matched in cyclic order (each pair turning the same way, convex or reflex; of such shifts,
  // the one closest in the pairs' turn angles and, far less, to the automatic alignment) and the
  // loop is reparameterized by arc length between them. Corners here: first every vertex
  // turning by more than 1 degree (so a polygon and its affine copy match vertex to vertex); if
  // their counts differ, every vertex off its neighbours' line (a shear can take a turn across 1
  // degree, but an affine map keeps collinear points collinear); else those above
  // corner_angle_degrees. So corners go onto corners, and an affine image of a polygon gets the
  // affine correspondence (plain arc length put a sheared arrowhead's corners onto straight
  // sides, and its map folded). Otherwise, and with false (the default), arc length from the
  // aligned start. BuildMultimesh turns it on when the arc-length correspondence cannot be built
  // or mapped (MultimeshOptions::corner_matching).
  bool match_corners = false;
  // How a loop without marks (and without matched corners, above) is paired with drawing 1's:
  // kArcLength: arc length from the automatic start; kFeatures: the feature alignment of
  // loop_alignment.h (corner onto corner, turning onto turning, stretching penalized), drawing
  // 1's loop carried into the other drawing's frame as for the start.
  enum class Alignment { kArcLength, kFeatures };
  Alignment alignment = Alignment::kArcLength;
  // Outline tolerance, relative to each drawing's bounding-box diagonal: an interval between
  // breakpoints whose even vertices (`vertices` or the automatic budget) leave some drawing's
  // outline farther than this from a chord is sampled again, every drawing at once, greedily to
  // the tolerance (no piece longer than the even spacing), so that in every drawing the polyline
  // lies within the tolerance of the drawing's outline (Hausdorff, both ways: the outline between
  // two vertices strays at most this far from their chord). A rounded tip drawn with many small
  // turns, which no single turn marks as a corner, keeps its shape. The vertices are common
  // parameters, so the correspondence between drawings is the one chosen above; an interval gets
  // what the drawing that needs most needs. Corners closer than the tolerance share one
  // breakpoint. 0, or a fixed `vertices`: no refinement. Intervals on a cut or opening stay
  // evenly spaced (each side repeats its twin's vertices), their class's count raised until
  // every drawing is within the tolerance.
  double tolerance = 0.0;
};

// Loops are matched as follows (documented default; pairs set by marks are kept, and the rest
// matched around them): each drawing is normalised by its bounding box (centre, diagonal);
// components are matched to drawing 1's by the assignment of least total squared distance
// between normalised area centroids (components with a different hole count never match; exact:
// brute force up to 8, the Hungarian method beyond). Where three or more components spread
// across drawing 1, that placement is also turned about drawing 1's centre by 24 steps and
// refitted to the matched centroids (affine), and the candidate whose carried outlines lie
// nearest their matches wins, so a turned or sheared drawing pairs each part with its image.
// Holes within matched components likewise, but drawing 1's hole centroids are first carried by
// the least-squares affine map of the component's outline onto its match (sampled by arc length
// from the aligned starts), so that a sheared, rotated copy matches hole to hole where the
// bounding boxes would pair neighbours (bootstrap-icons' flower1, 13 holes); where the holes'
// centroids spread across, that map is also refitted to them from 24 turns of it (a round
// outline does not fix the turn: browser-safari's ticks). Of the turned candidates (components
// or holes) that score within 1.5 times the best (plus a small floor), the one turning least
// from the start wins: a symmetric layout (four equal dots) fits a quarter turn as well as the
// right map. Without marks, each loop gets the cyclic shift that best matches drawing
// 1's loop in normalised turning angle and position over arc length, its component's map (if
// any) carrying drawing 1's loop first (orientation is fixed: the drawing is on the left of
// every loop); with Alignment::kFeatures, loops are then paired by the feature alignment
// (loop_alignment.h), that start one of the starts it tries. In a component with holes the
// outline is aligned as carried by the component's map where that map leaves it more than 2% of
// its length off (a bend) and the aligned outline carries every hole onto its match; each hole
// then follows: carried through the outline's correspondence (mean value coordinates) and
// aligned as carried. Otherwise the component's loops keep arc length from the carried starts.
// Last, where an affine map (fitted to that pairing, refined by point-to-line ICP on the outline
// and its holes) carries drawing 1's outline within 0.2% of its match's length, the outline, and
// each hole of the component that the map carries as closely, pair through the map: drawing 1's
// vertices carried onto the nearest points of the match. Loops along a cut or an opening keep the
// pairing above.
struct BoundaryCorrespondence {
  // Loop g's vertices are the global indices loop_start[g] .. loop_start[g + 1] - 1; edge e joins
  // vertex e to the next vertex of its loop.
  std::vector<int> loop_start;
  std::vector<bool> loop_outer;
  std::vector<int> loop_component;          // component index (drawing 1's numbering)
  std::vector<std::vector<Points>> shapes;  // shapes[d][g]: loop g in drawing d
  // edge_twin[d][e]: the edge collocated with e and walked the other way in drawing d (the two
  // sides of a cut or opening of drawing d), or -1.
  std::vector<std::vector<int>> edge_twin;
  // The global vertex of each correspondence mark (ascending, each once; marks that fell onto
  // the same breakpoint share it).
  std::vector<int> mark_vertices;
  // Loops parameterized by matched corners (BoundaryCorrespondenceOptions::match_corners).
  int corner_matched_loops = 0;
  // The farthest any drawing's outline strays from its loops' chords, relative to the drawing's
  // bounding-box diagonal (the tolerance achieved).
  double achieved_tolerance = 0.0;
  // Boundary vertices before the refinement to the tolerance (the even sampling's budget): the
  // spacing that sizes the interior mesh, so that a few refined tips do not refine it all.
  int base_vertices = 0;
  int num_loops() const { return static_cast<int>(loop_start.size()) - 1; }
  int num_vertices() const { return loop_start.back(); }
};

// All graphs must have the same equivalence class (else INVALID_ARGUMENT naming each drawing's
// class). Marks that cannot be used give INVALID_ARGUMENT naming the mark and the drawing.
absl::StatusOr<BoundaryCorrespondence> ComputeBoundaryCorrespondence(
    const std::vector<BoundaryGraph>& graphs, const BoundaryCorrespondenceOptions& options = {});

// "drawing 1: 1 component, 0 holes; drawing 2: 1 component, 1 hole" and a hint, or OK.
absl::Status CheckSameEquivalence(const std::vector<BoundaryGraph>& graphs);

}  // namespace inbetween::solver
