// Comesh optimization (the paper's supplement: S-eq.1/2, S-Tables 1-4; docs/design.md):
// minimises the comesh objective (comesh_objective.h: ODT mesh quality plus the MIPS distortion
// between consecutive shapes) over every shape's vertices at once and, with max_outer > 0, over
// the shared topology too. Paper: Zhu, Popović, Bridson & Kaufman, "Planar Interpolation with
// Extreme Deformation, Topology Change and Dynamics", SIGGRAPH Asia 2017; the inner loop follows
// Blended Cured Quasi-Newton (Zhu, Bridson & Kaufman 2018).
//
// Inner loop (comesh_inner_loop.h): L-BFGS on a fixed topology, with each shape's projected
// Hessian as initial Hessian for up to two shapes and BCQN's Laplacian model from three on
// (comesh_preconditioner.h), curing and an inversion-free line search: every accepted iterate is
// strictly positive in every shape. It stops at the first of: ||g|| <= gradient_tolerance
// ||g_0||; a relative decrease below relative_decrease_tolerance over decrease_window iterations
// (twice that window after a step capped by the inversion bound); max_iterations; no decrease.
//
// Outer loop: a short inner run (outer_inner_iterations), then one topology pass (flips,
// collapses, splits, corner swaps: comesh_topology.h; each valid in every shape and accepted only
// if the objective does not rise), until a pass changes nothing, max_outer passes were made, or
// a pass (or a pass and its short run) gains less than outer_tolerance (relative); then one inner
// run to convergence. The objective is a mean quality, comparable across passes, and never
// increases (ComeshReport::objective_trace). Last, sliver removal (min_quality), which may raise
// it a little.
//
// Unknowns: interior vertices move in 2D. With slide_boundary, a boundary vertex on a straight
// stretch slides along it, so every shape's domain is kept exactly. With slide_outline too, the
// other boundary vertices slide by arc length along their shape's input outline, past its soft
// corners only, in a second stage that continues from the converged run without sliding (so it
// never ends above that run); the outline guard keeps the keys within outline_tolerance of the
// drawings. Fixed: boundary corners, cohesive vertices, correspondence marks (Multimesh::pinned),
// vertices listed in Multimesh::boundary that are not on the topological boundary, unused
// vertices. The correspondence moves past a hard corner only by corner swaps.
//
// Determinism: the result is bit-identical for any thread count (options.threads changes speed
// only), and a run resumed from a ComeshCheckpoint returns what the uninterrupted run returns.
//
// Where the choices are measured (docs/benchmarks.md): "Comesh optimization: S-Table 2" (scaling,
// and its "Cancellation latency"), "Comesh optimization: S-Table 1", "... S-Table 3", "...
// S-Table 4", "Comesh optimization: outline sliding", and "Decisions and what they rest on" (its
// parts "The comesh inner loop" and "Outline sliding and mesh quality").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/comesh/comesh_topology.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

struct ComeshCheckpoint;

struct ComeshOptions {
  double map_weight = 0.5;           // w of the objective (S-Table 1 default)
  int max_iterations = 200;          // per inner run (the service default too)
  double gradient_tolerance = 1e-6;  // relative to the inner run's initial gradient
  // Stop when the objective fell by less than relative_decrease_tolerance * |f| over the last
  // decrease_window iterations (a window, not one iteration: single steps can be tiny while the
  // run still makes progress). 1e-5 over 10 leaves S-Table 2's map energies within 1e-4 of what
  // 1e-6 reaches ("Decisions and what they rest on": the stop rule).
  double relative_decrease_tolerance = 1e-5;
  int decrease_window = 10;
  int history = 8;                       // L-BFGS curvature pairs kept
  bool laplacian_preconditioner = true;  // false: H0 = identity (plain L-BFGS)
  // H0 = the shape-block Hessian (comesh_hessian_preconditioner.h) instead of the Laplacian
  // model, for multimeshes of at most hessian_max_shapes shapes; refactored every
  // hessian_refresh iterations of an inner run (0: once per run). The block-diagonal model drops
  // the MIPS coupling between neighbouring shapes, which matters more the more shapes there are:
  // it beats the Laplacian for 2 shapes and loses from 3 on (S-Table 3; "Decisions").
  bool hessian_preconditioner = true;
  // The shape-block Hessian's supernodal factors are substituted in single precision
  // (SparseCholesky::set_float_substitutions): a preconditioner needs no more, and the solves are
  // bound by reading the factor ("Decisions"). Small meshes get simplicial factors, which stay
  // double.
  bool float_substitutions = true;
  // In the shape-block Hessian, each triangle's MIPS blocks (its source and its target side,
  // comesh_hessian.h) get mips_damping times their own Gershgorin bound added on the diagonal
  // before the sum is projected: a per-triangle Levenberg-Marquardt term. sigma* is invariant
  // under scaling a triangle in one shape, so without it the model asks triangles crushed in one
  // shape to move many times their size, and the inversion bound then cuts the step of the whole
  // mesh, iteration after iteration (the large rows of S-Table 2; "Decisions"). 0: the plain
  // projected Hessian; finite and >= 0 (else INVALID_ARGUMENT).
  double mips_damping = 1.0;
  int hessian_max_shapes = 2;
  int hessian_refresh = 0;
  bool scaling_by_inverse = false;  // beta = y^T H0 y / s^T y (else s^T y / s^T B0 s)
  double blend = 1.0;               // blending strength (0 = plain L-BFGS pairs), comesh_lbfgs.h
  bool cure = true;                 // BCQN curing of the direction (comesh_cure.h)
  double cure_keep = 0.5;           // curing keeps at least this fraction of each linearised area
  bool slide_boundary = true;       // boundary vertices on straight runs slide (see above)
  // With slide_boundary: the other boundary vertices (the corners of their own polyline, as on
  // every curved outline) slide by arc length along their shape's input outline, across its soft
  // corners, stopping at turns above outline_corner_degrees and at cohesive vertices and marks
  // (comesh_outline.h; see "Unknowns" above). The objective is then area-invariant (its
  // normalizers follow the current areas, comesh_objective.h), so cutting a soft corner to
  // shrink a shape gains nothing. On curved pairs whose initial boundary correspondence is poor
  // it lowers the map energy far ("Comesh optimization: outline sliding"). Off: every boundary
  // vertex off a straight stretch stays where it is.
  bool slide_outline = true;
  double outline_corner_degrees = 25.0;
  // With slide_boundary and > 0: every boundary slider stays within slide_window boundary edge
  // lengths (the mean of its two, in its shape, when the inner run starts) of where the input's
  // boundary correspondence pairs it (comesh_pairing.h): sliding evens the mesh out locally but
  // cannot undo the built pairing, which the map energy alone slides toward a conformal but
  // area-distorting one. 0 (the default): unbounded. The trade, measured
  // (docs/benchmarks.md, "Boundary correspondence against a known truth"): 0.15 brings three more
  // of the 49 known-truth cases within 10% of the true pairing's middle-frame distortion, but
  // ends 20 of the 31 examples of "outline sliding" more than 1% above the unbounded objective
  // (8% on average, a star-to-pentagon pair 70%), where the paper's objective is the measure.
  double slide_window = 0.0;
  // The outline guard (OutlineGuard, comesh_outline.h): with slide_outline, no accepted step
  // takes a chord at an outline slider farther than outline_tolerance times the drawing's
  // bounding-box diagonal from the drawing's outline (the distance of the outline points the
  // chord spans from it), so a rounded tip the build kept within MultimeshOptions'
  // boundary_tolerance is not cut off again; a slider whose own move would do so waits. A chord
  // beyond the bound at the start (a build with a fixed vertex count) keeps its own deviation as
  // its bound. 0: off (the outline then strays by the chords across whatever soft corners the
  // sliders leave).
  double outline_tolerance = 1e-3;
  // The drawings' outlines the guard measures against, one entry per shape (its closed loops, as
  // Drawing::outlines): the outlines the multimesh was built from. Empty: the input mesh's own
  // outline, which the build placed within its tolerance of the drawing, so the keys may then
  // stray up to the build's deviation plus outline_tolerance.
  std::vector<std::vector<Points>> outline_reference;
  // Local relaxation (comesh_relax.h): after each accepted step shorter than the unit step (one
  // that backtracked or met the inversion bound), every vertex (of one shape) whose gradient holds
  // at least relax_fraction of |g|^2 and relax_over_mean times an even share of it, at most
  // relax_max_vertices of them (largest first), takes up to relax_steps damped Newton steps alone
  // on the terms that depend on it; f, g and the energies follow through the terms of the
  // triangles around them. relax_fraction <= 0: off. It saves inner iterations and time on the
  // large rows of S-Table 2; the over-mean condition and the short-step gate keep it off small
  // meshes, whose gradient is spread out and whose steps are mostly full ("Decisions").
  double relax_fraction = 1e-3;
  double relax_over_mean = 100.0;
  int relax_max_vertices = 256;
  int relax_steps = 3;
  double max_step_fraction = 0.8;  // line search starts at this fraction of the inversion bound
  double armijo = 1e-4;            // sufficient decrease constant c1
  int max_backtracks = 50;
  int threads = 0;  // <= 0: hardware concurrency; results do not depend on it
  // Hessian blocks of at least this many unknowns are analysed (AMD + CHOLMOD's symbolic
  // analysis, single library calls of up to ~1 s at 311k vertices) on a helper thread that a
  // cancel leaves to finish on its own (RunCancellable); <= 0: always on the calling thread.
  // Results do not depend on it.
  int background_analysis_unknowns = 65536;
  // Outer topology loop: 0 = inner loop only (topology and vertex count unchanged).
  int max_outer = 30;
  double outer_tolerance = 1e-4;    // stop when a pass (or pass + short run) gains less
  int outer_inner_iterations = 10;  // inner iterations between topology passes
  TopologyOptions topology;
  // With max_outer > 0, the last step: sliver removal (RemoveSlivers, comesh_topology.h) on the
  // triangles whose quality (TriangleQuality: 1 equilateral, 0 flat) is below min_quality in
  // some shape. Inner runs can press a triangle flat in every shape alike (two boundary sliders
  // that meet, an interior vertex onto a boundary edge), which the objective barely resists
  // ("Decisions": sliver removal). 0: off.
  double min_quality = 0.02;
  // Called after every accepted inner iterate (numbered globally from 1) with all shapes'
  // positions (of the current topology); for tests, traces and visualisation.
  std::function<void(int iteration, const std::vector<Points>& shapes)> on_iterate;
  // Called after every topology pass that changed the mesh (see ComeshCheckpoint).
  std::function<void(const ComeshCheckpoint& checkpoint)> on_checkpoint;
};

// The state between two topology passes: the multimesh after the pass plus every number the rest
// of the run reads (each inner run starts a fresh L-BFGS history, so nothing else carries over).
// OptimizeComesh's `resume` continues from it and returns the same multimesh, bit for bit, and
// the same report (seconds aside) as the uninterrupted run, numbering iterations on. Valid only
// for the input multimesh and options of the run that reported it.
struct ComeshCheckpoint {
  Multimesh mesh;  // after `outer` passes
  int outer = 0;   // topology passes made (each changed the mesh); the next pass has this index
  int inner = 0;   // accepted inner iterations so far; the next one is numbered inner + 1
  int energy_evaluations = 0;
  int flips = 0;
  int collapses = 0;
  int splits = 0;
  // The objective after the last pass's short inner run: the outer_tolerance stop of the next
  // pass compares with it.
  double pass_start_objective = 0.0;
  std::vector<double> objective_trace;  // ComeshReport::objective_trace so far
  // 0: a pass of the run without outline sliding; 1: of the run that continues from its result
  // with it (slide_outline on curved outlines; see "Unknowns" above).
  int stage = 0;
};

// Where a run's time went (seconds, summed over inner runs and passes; for benchmarks).
struct ComeshPhaseSeconds {
  double hessian = 0.0;      // H0: objective set-up, pattern, ordering, factorization (per run)
  double direction = 0.0;    // L-BFGS two-loop recursion with H0 solves, curvature pairs
  double step_bound = 0.0;   // curing and the largest non-inverting step
  double line_search = 0.0;  // objective + gradient evaluations of the line search
  double relax = 0.0;        // local relaxation after short steps (comesh_relax.h)
  double topology = 0.0;     // topology passes
};

struct ComeshReport {
  int vertices_before = 0;
  int vertices_after = 0;
  int inner = 0;  // accepted L-BFGS iterations, summed over inner runs
  int outer = 0;  // topology passes that changed the mesh
  double seconds = 0.0;
  double map_energy = 0.0;   // after; mean area-weighted sigma*, 2 = conformal
  double mesh_energy = 0.0;  // after; normalized ODT, 1 = equal equilateral triangles
  double map_energy_before = 0.0;
  double mesh_energy_before = 0.0;
  double objective_before = 0.0;
  double objective_after = 0.0;
  // Objective after each inner run and each topology pass, in order (non-increasing).
  std::vector<double> objective_trace;
  int flips = 0;
  int collapses = 0;
  int splits = 0;
  int energy_evaluations = 0;
  ComeshPhaseSeconds phase_seconds;
  std::string stop_reason;  // last inner run: "gradient", "decrease", "max_iterations",
                            // "line_search", "no_free", "outline" (every slider that would
                            // descend is held by the outline guard)
  // Sliver removal (ComeshOptions::min_quality): triangles below min_quality before it, the
  // operations it made, and the worst triangle quality of the result over every shape.
  int slivers = 0;
  int sliver_operations = 0;
  double worst_quality = 0.0;
};

// Optimizes every shape of `mesh` (positions, and with max_outer > 0 the shared topology).
// InvalidArgument if the multimesh is inconsistent or a triangle is inverted or degenerate in
// some shape (the message names shape and triangle), or if an option is out of range.
// Cancelled if `cancel` fires: every step of a run polls it (the set-up's loops and
// factorizations, the direction's solves, curing, every energy evaluation, the line search and
// every topology operation), so the call returns within tens of milliseconds even at 311k
// vertices ("Cancellation latency" in docs/benchmarks.md); the symbolic analysis of a large
// Hessian block runs on a helper thread that a cancel leaves behind (RunCancellable).
// `progress` (may be empty) is called once per inner iteration, once per topology pass and when
// outline sliding starts; `report` may be null. The result passes ValidateMultimesh;
// Multimesh::boundary and cohesive_edges are remapped to the compacted vertex numbering. `resume`
// (may be null): continue from a checkpoint that a run on the same `mesh` with the same options
// reported (InvalidArgument if its multimesh is not valid); the result and report equal that run's.
absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report,
                                         const ComeshCheckpoint* resume = nullptr);

}  // namespace inbetween::solver
