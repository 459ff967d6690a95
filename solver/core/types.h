// Value types shared by every solver stage: points, polylines, drawings, triangles.
#pragma once

#include <array>
#include <vector>

#include "solver/core/art.h"
#include "solver/core/point.h"

namespace inbetween::solver {

// Orientation convention, used everywhere: "positive" means positive signed area by the usual
// formula 0.5 * sum(x_i * y_{i+1} - x_{i+1} * y_i) in the drawing's own coordinates (SVG user
// units, y pointing down, so positive looks clockwise on screen). Every triangle of every shape
// is positive; outer outlines are positive, holes negative.
using Triangle = std::array<int, 3>;  // vertex indices

// A closed oriented polyline (the last point connects back to the first; it is not repeated).
struct Outline {
  Points points;
};

// A correspondence mark (S-Sec.1 "Boundary Tool"): marks with the same id in several drawings
// pin corresponding boundary points (the boundary point nearest to `point` in each drawing).
struct CorrespondenceMark {
  int id = 0;
  Point point = Point::Zero();
};

// One key drawing: its outlines in the drawing's user units (SVG y-down coordinates as given).
struct Drawing {
  std::vector<Outline> outlines;
  // Open polylines (S-Sec.1, "topo operations"): their segments become bi-directed edges of the
  // planar straight-line graph. A cut is meant to separate (boundary to boundary), an opening to
  // open a hole or a slit; both become cohesive edge pairs (solver/geometry/graph_flow.h).
  std::vector<Points> cuts;
  std::vector<Points> openings;
  // Correspondence marks drawn with the drawing (e.g. SVG data-corr="N" elements), in document
  // order. Used by BuildMultimesh when MultimeshOptions::marks is empty.
  std::vector<CorrespondenceMark> marks;
  // The drawing's painted layers in paint order (SVG sources; empty for polylines). The outlines
  // are the boundary of their union, or of the class="outline" elements (svg_import.h).
  std::vector<ArtLayer> art;
};

}  // namespace inbetween::solver
