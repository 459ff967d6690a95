// Comesh optimization (DESIGN "Comesh optimization", S-eq.1/2, S-Tables 1-4): minimise the comesh
// objective (comesh_objective.h) over every shape's vertices at once, alternating an inner
// quasi-Newton loop on a fixed topology with an outer loop of topology operations applied
// identically to every shape (comesh_topology.h).
//
// Inner loop: L-BFGS after Blended Cured Quasi-Newton (Zhu, Bridson & Kaufman 2018), with
// - initial Hessian B0 (default for two shapes, hessian_preconditioner): the objective's
//   Hessian, block diagonal by shape (the shape-shape MIPS blocks dropped), projected positive
//   definite per triangle and shape (comesh_hessian.h), in the reduced unknowns (a slider's row
//   projected on its direction); one sparse matrix and CHOLMOD factor per shape, built and
//   factored once per inner run (every hessian_refresh iterations if set); CHOLMOD goes
//   supernodal (BLAS) on large blocks (SparseCholesky::Method::kAuto). A Newton-type
//   model: inner iterations grow far more slowly with the mesh size than with BCQN's Laplacian
//   (docs/benchmarks.md).
//   Otherwise (more shapes, or hessian_preconditioner = false) BCQN's model: H0_s = A_s J_s^T
//   L^{-1} J_s / beta, L the uniform graph Laplacian of the shared topology restricted to the
//   vertices movable in every shape, factored ONCE as a scalar matrix (CHOLMOD,
//   solver/core/sparse_cholesky.h) and applied to x and y of all shapes in one multi-column solve;
//   J_s lifts a sliding boundary unknown to 2D along its line. Vertices movable only in some shapes
//   get the Jacobi value A_s / deg. Either way H0 = B0^{-1} / beta with beta = s^T y / s^T B0 s
//   from the newest pair.
// - blending: y <- (1 - theta) y + theta beta B0 s with theta = min(1, blend ||g|| / ||g_0||):
//   the model dominates far from the minimum, measured curvature near it.
// - curing: per triangle and shape, corners whose unit step would shrink the linearised area
//   below cure_keep of its current value are scaled down (CureDirection), so a few blocking
//   triangles do not shrink the step of the whole mesh; kept only if still a descent direction.
//   (Tried and measured worse on the 35k row: the exact quadratic area and repeated passes.)
// - line search: the largest step t_max before any triangle of any shape reaches zero area
//   (smallest positive root of a quadratic per triangle); start at min(1, max_step_fraction *
//   t_max) and backtrack (Armijo). Every accepted iterate is strictly positive everywhere.
// - local relaxation (comesh_relax.h, relax_* options): after a short step, the few vertices
//   that hold most of |g|^2 (those of nearly degenerate triangles, where the MIPS term acts as a
//   barrier and would otherwise set the one L-BFGS scale and the inversion bound of the whole
//   mesh) move alone by damped Newton steps on their own terms; f, g and the energies are updated
//   from the terms of their rings, without a full evaluation. Never raises the objective.
// - stops when (first that holds): ||g|| <= gradient_tolerance ||g_0||; the relative decrease
//   over the last decrease_window iterations is below relative_decrease_tolerance (over twice
//   that window if the last step was capped by the inversion bound); max_iterations
//   (per inner run) is reached; or the line search finds no decrease.
//
// Outer loop: a short inner run (outer_inner_iterations) then one topology pass (flips,
// collapses, splits; each accepted only if valid in every shape and the objective does not
// increase), repeated until a pass changes nothing, max_outer passes were made, a pass by itself
// lowered the objective by at most outer_tolerance (relative; that pass is kept), or a pass plus
// its short run lowered the objective by less than outer_tolerance (relative); then one inner run
// to convergence on the final topology. The objective is a mean quality (the ODT normalizer uses
// the current triangle count), so it is comparable across passes and never increases. Last (with
// max_outer > 0 and min_quality > 0), sliver removal (RemoveSlivers, comesh_topology.h): local
// operations on the triangles nearly flat in some shape, judged by triangle quality; it may raise
// the objective a little, and the report's energies are those of its result (objective_trace ends
// before it).
//
// Checkpoints: after every topology pass that changed the mesh, on_checkpoint (if set) receives
// a ComeshCheckpoint: the multimesh at that point plus every number the rest of the run reads
// (pass count, the objective the outer_tolerance stop compares with, the counters and trace of
// the report). Each inner run starts a fresh L-BFGS history, so nothing else carries over; a run
// resumed from a checkpoint (OptimizeComesh's `resume`) returns the same multimesh, bit for bit,
// and the same report (seconds aside) as the uninterrupted run, and numbers its iterations on.
//
// Unknowns, per shape: interior vertices move in 2D. With slide_boundary, a boundary vertex that
// lies strictly inside the straight segment between its two boundary neighbours in that shape
// slides along that line (one unknown), so the domain of every shape is preserved exactly. With
// slide_outline too, every other boundary vertex (a corner of its own polyline: on a curved
// outline, nearly all of them) slides along its shape's outline as it was in the input mesh (the
// polyline of its boundary loops, frozen for the whole run, comesh_outline.h; on by default, see
// ComeshOptions::slide_outline): its unknown is the
// arc length, its position the point of the polyline there, its gradient taken along the tangent
// where it is (updated after every step); it passes the polyline's soft corners (turns up to
// outline_corner_degrees) and stops at the hard ones, at cohesive vertices and at marks. Every
// boundary vertex thus stays on its input outline; the outline of a shape changes only by chords
// across soft corners that a vertex has left (the objective, area-invariant then, neither rewards
// nor penalizes the area that changes), each held within outline_tolerance of the drawing by the
// outline guard (a slider whose own move would break it keeps still for the iteration; a trial
// step that breaks it is shortened like one that inverts). At a polyline point, where the path bends, the gradient
// is the one-sided derivative of the side along which the objective falls. The line search's
// inversion bound follows the
// tangent (first order across a soft corner); the trial's own evaluation, infinite for any
// non-positive triangle, keeps every accepted iterate valid. Outline sliding is a second stage:
// the whole run above (passes and final inner run) first goes without it, then, from its result,
// short runs with the outlines sliding, passes (boundary splits on the outline) and a final run
// with them (ComeshCheckpoint::stage 1). Each step of that stage lowers the objective or keeps
// it, so a run with slide_outline never ends above the run without it (sliding from the start
// led the greedy passes elsewhere: up to 0.17% higher on some examples, docs/benchmarks.md). A
// shape without a soft corner (ShapeOutline::curved: polygons) keeps the straight sliders, and
// with no curved shape at all there is no second stage (the run is the one without, bit for
// bit).
// Fixed: boundary corners, every vertex of a cohesive edge, correspondence marks
// (Multimesh::pinned), vertices listed in Multimesh::boundary that are not on the topological
// boundary, and unused vertices.
//
// Threads: the objective, gradient and step bound are computed over fixed-size chunks of
// triangles, reduced in a fixed order, so the result is bit-identical for ANY thread count
// (options.threads only changes speed). threads <= 0 uses std::thread::hardware_concurrency().
//
// The boundary correspondence moves past a hard corner only by the topology pass's corner swaps
// (TopologyOptions::corner_swaps), a discrete step accepted when the objective does not rise.
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
  // run still makes progress). With the Hessian preconditioner, 1e-5 over 10 leaves the map
  // energy of the S-Table 2 rows within 1e-4 of what 1e-6 reaches (measured 1k-17k vertices).
  double relative_decrease_tolerance = 1e-5;
  int decrease_window = 10;
  int history = 8;                       // L-BFGS curvature pairs kept
  bool laplacian_preconditioner = true;  // false: H0 = identity (plain L-BFGS)
  // H0 = the shape-block Hessian (see "Inner loop" above) instead of the Laplacian model, for
  // multimeshes of at most hessian_max_shapes shapes; refactored every hessian_refresh
  // iterations of an inner run (0: once per run). The block-diagonal model drops the MIPS
  // coupling between neighbouring shapes of the cycle, which matters more the more shapes there
  // are: measured on the walking character (S-Table 3), it beats the Laplacian for 2 shapes and
  // loses from 3 on (more time, and from 4 shapes a worse mesh energy).
  bool hessian_preconditioner = true;
  // The shape-block Hessian's supernodal factors are substituted in single precision
  // (SparseCholesky::set_float_substitutions): a preconditioner needs no more, and the solves,
  // bound by reading L, were ~27% faster per iteration at 165k vertices. Small meshes get
  // simplicial factors, which stay double.
  bool float_substitutions = true;
  // In the shape-block Hessian, each triangle's MIPS blocks (its source side and its target
  // side, comesh_hessian.h) get mips_damping times their own Gershgorin bound added on the
  // diagonal before the sum is projected: a per-triangle Levenberg-Marquardt term relative to that
  // triangle's curvature. sigma* is invariant under scaling a triangle in one shape, so the block
  // has no curvature along that scaling, and without the damping the model asks triangles
  // crushed in one shape (the fans at the square's corners opened onto the hexagon's sides, S-Table
  // 2) to move many times their size; the inversion bound then cuts the step of the whole mesh,
  // iteration after iteration. Measured on S-Table 2 (docs/benchmarks.md): 1.0 against 0 cut
  // the 165k row's inner iterations 168 -> 94 and the 311k row's 260 (the cap) -> 123, the
  // smaller rows and S-Tables 1, 3 and 4 about unchanged. Both sides are damped: the target side
  // alone left S-Table 4's hard5/hard6 at 103/201 inner iterations against 62/102. 0: the plain
  // projected Hessian; finite and >= 0 (else INVALID_ARGUMENT).
  double mips_damping = 1.0;
  int hessian_max_shapes = 2;
  int hessian_refresh = 0;
  bool scaling_by_inverse = false;  // beta = y^T H0 y / s^T y (else s^T y / s^T B0 s)
  double blend = 1.0;               // blending strength (0 = plain L-BFGS pairs), see above
  bool cure = true;                 // BCQN curing of the direction
  double cure_keep = 0.5;           // curing keeps at least this fraction of each linearised area
  bool slide_boundary = true;       // boundary vertices on straight runs slide (see above)
  // With slide_boundary: the other boundary vertices (the corners of their own polyline, as on
  // every curved outline) slide by arc length along their shape's input outline, across its soft
  // corners, stopping at turns above outline_corner_degrees and at cohesive vertices and marks
  // (comesh_outline.h; see "Unknowns" above). The objective is then area-invariant (its
  // normalizers follow the current areas, comesh_objective.h), so cutting a soft corner to
  // shrink a shape gains nothing. A second stage after the run without it (see "Unknowns"
  // above): never ends higher than that run; on curved pairs whose initial boundary
  // correspondence is poor it lowers the map energy far (bird 4.18 -> 3.13, docs/benchmarks.md).
  // On by default (off: every boundary vertex off a straight stretch stays where it is).
  bool slide_outline = true;
  double outline_corner_degrees = 25.0;
  // The outline guard (OutlineGuard, comesh_outline.h): with slide_outline, no accepted step
  // takes a chord at an outline slider farther than outline_tolerance times the drawing's
  // bounding-box diagonal from the drawing's outline (the distance of the outline points the
  // chord spans from it), so a rounded tip the build kept within MultimeshOptions'
  // boundary_tolerance is not cut off again; a slider whose own move would do so waits. A chord
  // beyond the bound at the start (a build with a fixed vertex count) keeps its own deviation as
  // its bound. 0: off (the outline then strays by the chords across whatever soft corners the
  // sliders leave; keys up to 0.5% of the diagonal off on rounded icons, docs/benchmarks.md).
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
  // triangles around them. relax_fraction <= 0: off. Measured (docs/benchmarks.md): ~30% fewer
  // inner iterations and ~20% less time on the 8k-73k rows of S-Table 2, better map energies at
  // 165k and 311k. The over-mean condition and the short-step gate keep it off small meshes,
  // whose gradient is spread out and whose steps are mostly full: there it cost more than it
  // saved.
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
  // that meet, an interior vertex onto a boundary edge), which the objective barely resists:
  // S-Table 2's rows from 4k vertices on ended with 1-6 triangles of quality 3.6e-8 to 8e-4
  // (twenty-first session). 0: off.
  double min_quality = 0.02;
  // Called after every accepted inner iterate (numbered globally from 1) with all shapes'
  // positions (of the current topology); for tests, traces and visualisation.
  std::function<void(int iteration, const std::vector<Points>& shapes)> on_iterate;
  // Called after every topology pass that changed the mesh (see "Checkpoints" above).
  std::function<void(const ComeshCheckpoint& checkpoint)> on_checkpoint;
};

// A run between two topology passes (see "Checkpoints" above). Valid only for the input
// multimesh and options of the run that reported it.
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
// some shape (the message names shape and triangle); Cancelled if `cancel` fires: polled
// between every phase of an iteration, inside the direction's solves and the line search,
// inside the set-up's loops and factorizations and before every topology operation; the symbolic
// analysis of a large Hessian block runs on a helper thread that a cancel leaves behind
// (RunCancellable); large dense supernodes are factored in polled panels; energy evaluations
// poll per chunk of triangles; the two-loop recursion, the Hessian product and curing poll in
// spans; a fresh factor's values are allocated and touched in polled spans. Measured from the
// cancel to the return: at most 69 ms up to 165k vertices; at 311k (eleventh session, on a
// machine where that row took 150-177 s) p50 30.5-34.5 ms, max 53.8 ms in 14 cancelled trials
// (docs/benchmarks.md). `progress` (may be empty) is called once per iteration; `report` may be
// null. The result passes ValidateMultimesh; Multimesh::boundary and cohesive_edges are
// remapped to the compacted vertex numbering. `resume` (may be null): continue from a checkpoint
// that a run on the same `mesh` with the same options reported (InvalidArgument if its multimesh is
// not valid); the result and report equal that run's.
absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report,
                                         const ComeshCheckpoint* resume = nullptr);

}  // namespace inbetween::solver
