// The unknowns of the comesh inner loop (comesh_optimizer.h, "Unknowns"): which vertex of which
// shape moves, and how, and the maps between the stacked unknown vector z and the shapes'
// positions and gradients. Internal to the comesh optimizer.
//
// Per shape: interior vertices move freely in 2D. With slide_boundary, a boundary vertex that
// lies strictly between its two boundary neighbours on a straight line (in that shape) moves
// along that line (one unknown). With `outlines` (one per shape, may be null), in a shape whose
// outline has a soft corner (ShapeOutline::curved) any other boundary vertex that lies on the
// reference outline away from a hard point moves by arc length along it (comesh_outline.h). Every
// other vertex is fixed: cohesive vertices, correspondence marks (Multimesh::pinned), vertices
// listed in Multimesh::boundary that are not on the topological boundary, unused vertices.
//
// Unknowns are numbered shape by shape, vertex by vertex, so each shape's unknowns are one
// contiguous range of z (the Hessian preconditioner's blocks rely on it).
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "solver/comesh/comesh_outline.h"
#include "solver/comesh/comesh_pairing.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

class ComeshLayout {
 public:
  // With a `cancel` token (may be null) the edge list polls it (~0.1 s at 311k vertices); if it
  // was set, cancelled() is true and the layout is empty.
  // With `pairing` (may be null), every boundary slider stays within its window
  // (BoundaryPairing::WindowOf).
  ComeshLayout(const Multimesh& mesh, bool slide_boundary,
               const std::vector<ShapeOutline>* outlines, const BoundaryPairing* pairing = nullptr,
               const CancelToken* cancel = nullptr);

  struct Var {
    int shape;
    int vertex;
    int offset;       // into z
    bool slider;      // one unknown (position = base + z * direction) instead of two
    Point direction;  // unit, sliders only; for outline sliders the tangent where the run began
    Point base;       // position at the start, sliders only
    // Outline sliders: the loop of the shape's outline, the arc length where the run began (the
    // unknown is the arc length itself) and the stretch between hard points it stays in (within
    // its pairing window). Straight sliders: lo <= z <= hi, the pairing window (else infinite).
    int outline = -1;
    double u0 = 0.0, lo = 0.0, hi = 0.0;
    int prev = -1, next = -1;  // outline sliders: the two boundary neighbours
  };

  bool cancelled() const { return cancelled_; }
  int size() const { return size_; }
  int num_shapes() const { return num_shapes_; }
  int num_vertices() const { return num_vertices_; }
  const std::vector<Var>& vars() const { return vars_; }
  int index(int shape, int v) const { return index_[shape][v]; }  // var of (shape, v), or -1

  // z of the positions `shapes`.
  Eigen::VectorXd Gather(const std::vector<Points>& shapes) const;
  // The gradient in the unknowns; a slider's is the 2D gradient along its current tangent (see
  // Track). An outline slider at a polyline point, where the path bends, takes the one-sided
  // derivative of the side along which the objective falls (0 if it rises both ways), and its
  // tangent (for Displacements) becomes that side's.
  Eigen::VectorXd GatherGradient(const std::vector<Points>& gradient);
  // Writes the positions of z into *shapes (fixed vertices untouched).
  void Scatter(const Eigen::VectorXd& z, std::vector<Points>* shapes) const;
  // Every vertex's displacement in every shape for the step z -> z + d (zero where fixed), to
  // first order: a slider moves along its current tangent.
  void Displacements(const Eigen::VectorXd& d, std::vector<Points>* out) const;
  // Where outline slider `var` (var.outline >= 0) is at unknown value u.
  Point OutlinePoint(const Var& var, double u) const;
  // Moves the outline sliders' current tangents to the arc lengths in z (after an accepted step;
  // a straight slider's tangent is its direction throughout).
  void Track(const Eigen::VectorXd& z);

 private:
  // Adds shape s's unknowns (`outline`: its reference outline if it slides along it, else null).
  void AddShape(int s, const std::vector<Points>& shapes, const std::vector<char>& movable,
                const std::vector<std::vector<int>>& boundary_nbrs, bool slide_boundary,
                const ShapeOutline* outline, const BoundaryPairing* pairing);
  // Outline slider i's tangent and sides at arc length u of its loop of `outline`.
  void UpdateTangents(const ShapeOutline& outline, size_t i, double u);

  int num_shapes_ = 0;
  int num_vertices_ = 0;
  int size_ = 0;
  int num_outline_ = 0;
  bool cancelled_ = false;
  std::vector<Var> vars_;
  std::vector<Point> tangent_;  // per var: a slider's current unit tangent
  // Per var: an outline slider's tangents just before and after where it is (equal inside a
  // segment; a straight slider's direction twice).
  std::vector<std::pair<Point, Point>> sides_;
  const std::vector<ShapeOutline>* outlines_ = nullptr;
  std::vector<std::vector<int>> index_;  // [shape][vertex] -> var or -1
};

}  // namespace inbetween::solver
