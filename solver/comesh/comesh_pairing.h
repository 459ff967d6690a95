// Keeps comesh optimization from undoing the boundary correspondence the multimesh was built with.
//
// The build pairs the drawings' outlines by their features (boundary_parameterization.h): corner
// with corner, bend with bend, and between them by arc length. The optimizer's boundary sliders
// then minimize the map energy (MIPS, a conformal measure), which is blind to how much one side
// is stretched against another: left free, they slide the pairing back toward even spacing or
// toward a conformal but area-distorting one (a part stretched in one drawing, the material of a
// squashed droplet), and the inbetweens' isometric distortion grows far beyond what the built
// pairing gives ("Boundary correspondence against a known truth" in docs/benchmarks.md). So every
// boundary slider may move only within a window around where the input's pairing puts it: in
// shape 0 around where the run found it, in every other shape around the image, under the
// input's correspondence, of the vertex's current place in shape 0. The window is measured from
// the pairing, not from the run's start, so the windows of successive runs (topology passes in
// between) do not add up to a long drift; sliding still evens the mesh out locally.
//
// The correspondence is the input's: point k of loop l of Multimesh::boundary_loops is one vertex
// in every shape, and between two such points it is linear in arc length.
#pragma once

#include <optional>
#include <vector>

#include "solver/comesh/comesh_outline.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

class BoundaryPairing {
 public:
  // `window`: the half-width of the window in boundary edge lengths (the mean of the vertex's two
  // boundary edges in its shape when the run starts); > 0.
  BoundaryPairing(const Multimesh& input, double window);

  struct Window {
    int loop = -1;
    double u = 0.0;            // where the vertex is: arc length on its shape's input outline
    double lo = 0.0, hi = 0.0;  // the range it may take, in u's frame (lo <= u <= hi)
  };
  // The window of boundary vertex v of shape s at positions `shapes` (the run's start), whose
  // boundary neighbours are prev and next; nothing if v is not on the input outlines (unbounded).
  // A vertex already outside its window (a corner swap moved it) may stay or move toward it.
  std::optional<Window> WindowOf(const std::vector<Points>& shapes, int s, int v, int prev,
                                 int next) const;

  // Shape s's input outline: the frame WindowOf measures arc lengths in.
  const ShapeOutline& outline(int s) const { return outlines_[s]; }

 private:
  // The arc length on shape `to`'s loop paired with arc length u on shape `from`'s.
  double Map(int from, int to, int loop, double u) const;

  double window_;
  std::vector<ShapeOutline> outlines_;           // per shape, the input's loops
  std::vector<std::vector<std::vector<double>>> arc_;  // [shape][loop][k]: arc length to point k
  std::vector<double> tolerance_;                // per shape: how far off its outline a vertex may be
};

}  // namespace inbetween::solver
