// Comesh optimization: the outer loop (comesh_optimizer.h, "Outer loop"): inner runs
// (comesh_inner_loop.h) alternating with topology passes (comesh_topology.h), in two stages when
// outlines slide, then sliver removal.
#include "solver/comesh/comesh_optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "solver/comesh/comesh_inner_loop.h"
#include "solver/comesh/comesh_objective.h"
#include "solver/comesh/comesh_outline.h"
#include "solver/comesh/comesh_preconditioner.h"
#include "solver/comesh/comesh_topology.h"
#include "solver/core/parallel_chunks.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

absl::Status ValidateInput(const Multimesh& mesh) {
  if (mesh.shapes.empty()) return absl::InvalidArgumentError("multimesh has no shapes");
  const int n = mesh.num_vertices();
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    if (static_cast<int>(mesh.shapes[s].size()) != n) {
      return absl::InvalidArgumentError(
          absl::StrCat("shape ", s, " has ", mesh.shapes[s].size(), " vertices, shape 0 has ", n));
    }
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (const std::optional<int> v = IndexOutOfRange(tri, n)) {
      return absl::InvalidArgumentError(
          absl::StrCat("triangle ", t, " has vertex index ", *v, " outside [0, ", n, ")"));
    }
    for (int s = 0; s < mesh.num_shapes(); ++s) {
      const double area2 = SignedArea2(tri, mesh.shapes[s]);
      if (!(area2 > 0.0)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "triangle %d (%d, %d, %d) is inverted or degenerate in shape %d (signed area %g)", t,
            tri[0], tri[1], tri[2], s, 0.5 * area2));
      }
    }
  }
  for (int v : mesh.boundary) {
    if (v < 0 || v >= n) {
      return absl::InvalidArgumentError(absl::StrCat("boundary vertex ", v, " out of range"));
    }
  }
  for (const auto& c : mesh.cohesive_edges) {
    for (int v : c) {
      if (v < 0 || v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("cohesive edge vertex ", v, " out of range"));
      }
    }
  }
  return absl::OkStatus();
}

absl::Status ValidateCheckpoint(const ComeshCheckpoint& resume) {
  if (absl::Status st = ValidateInput(resume.mesh); !st.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("comesh checkpoint: ", st.message()));
  }
  if (resume.outer < 0 || resume.inner < 0) {
    return absl::InvalidArgumentError("comesh checkpoint: negative pass or iteration count");
  }
  if (resume.stage != 0 && resume.stage != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("comesh checkpoint: stage ", resume.stage, " (0 or 1)"));
  }
  return absl::OkStatus();
}

absl::Status ValidateOptions(const ComeshOptions& options, const Multimesh& mesh) {
  if (options.max_iterations < 0 || options.history < 0 || !(options.max_step_fraction > 0.0) ||
      !(options.max_step_fraction < 1.0) || options.max_outer < 0 ||
      !(options.cure_keep >= 0.0 && options.cure_keep < 1.0) || !(options.blend >= 0.0) ||
      !(options.mips_damping >= 0.0 && std::isfinite(options.mips_damping)) ||
      std::isnan(options.relax_fraction) || !(options.relax_over_mean >= 0.0) ||
      options.relax_max_vertices < 0 || options.relax_steps < 0 ||
      !(options.outline_corner_degrees >= 0.0 && options.outline_corner_degrees <= 180.0) ||
      !(options.outline_tolerance >= 0.0 && std::isfinite(options.outline_tolerance)) ||
      !(options.slide_window >= 0.0 && std::isfinite(options.slide_window))) {
    return absl::InvalidArgumentError(
        "comesh options: max_iterations, history, max_outer, relax_max_vertices and relax_steps "
        "must be >= 0, max_step_fraction in (0, 1), cure_keep in [0, 1), blend and "
        "relax_over_mean >= 0, mips_damping finite and >= 0, relax_fraction a number, "
        "outline_corner_degrees in [0, 180], outline_tolerance and slide_window finite and >= 0");
  }
  if (!options.outline_reference.empty() &&
      static_cast<int>(options.outline_reference.size()) != mesh.num_shapes()) {
    return absl::InvalidArgumentError(
        absl::StrCat("comesh options: outline_reference has ", options.outline_reference.size(),
                     " drawings' outlines for ", mesh.num_shapes(), " shapes"));
  }
  return absl::OkStatus();
}

// The outlines the boundary slides along (slide_outline): each shape's outline in `mesh`, with
// its cohesive vertices and marks as hard points. Empty when no shape has a soft corner (polygons
// only): the straight sliders then do all outline sliding would, and the run is the one without
// it, bit for bit.
std::vector<ShapeOutline> SlidingOutlines(const Multimesh& mesh, const ComeshOptions& options) {
  std::vector<ShapeOutline> outlines;
  if (!(options.slide_boundary && options.slide_outline)) return outlines;
  std::vector<char> fixed(mesh.num_vertices(), 0);
  for (const auto& c : mesh.cohesive_edges) {
    for (int v : c) fixed[v] = 1;
  }
  for (int v : mesh.pinned) fixed[v] = 1;
  bool curved = false;
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    outlines.emplace_back(mesh, s, options.outline_corner_degrees, fixed);
    curved |= outlines.back().curved();
  }
  if (!curved) outlines.clear();
  return outlines;
}

// One optimization past validation: the multimesh and every number the outer loop carries
// across inner runs and topology passes (what a ComeshCheckpoint records).
class OuterLoop {
 public:
  OuterLoop(const Multimesh& input, const ComeshOptions& options, int threads,
            const CancelToken* cancel, const ProgressFn& progress, ComeshReport* rep)
      : input_(input),
        options_(options),
        threads_(threads),
        cancel_(cancel),
        progress_(progress),
        rep_(*rep) {}

  // Runs both stages (or continues `resume`), then sliver removal; the report's counters and
  // energies are then filled in (seconds aside).
  absl::StatusOr<Multimesh> Run(const ComeshCheckpoint* resume);

 private:
  void Resume(const ComeshCheckpoint& resume);
  void SetUpOutlines();
  absl::Status RunStage(int stage, bool resumed_in_stage);
  absl::Status InnerRun(int max_iterations, const std::vector<ShapeOutline>* stage_outlines);
  // One topology pass (index `outer`): false (and the mesh unchanged) if it changed nothing,
  // false too if it settled the topology (see below), else true.
  absl::StatusOr<bool> TopologyPass(int outer, int stage,
                                    const std::vector<ShapeOutline>* stage_outlines);
  absl::Status RemoveSliversAtEnd();
  void FillReport();

  const Multimesh& input_;
  const ComeshOptions& options_;
  const int threads_;
  const CancelToken* cancel_;
  const ProgressFn& progress_;
  ComeshReport& rep_;

  Multimesh current_;
  ComeshInnerStats stats_;
  // The objective the outer_tolerance stop of the next pass compares with.
  double pass_start_objective_ = 0.0;
  int first_outer_ = 0;  // the first pass index of the stage
  // The reference outlines are the input's (also when resuming), so every inner run slides the
  // boundary along the drawn outlines, not along the chords of earlier runs.
  std::vector<ShapeOutline> outlines_;
  std::vector<ShapeOutline> drawn_;  // ComeshOptions::outline_reference, as outlines
  std::optional<OutlineGuardBounds> bounds_;
  std::optional<BoundaryPairing> pairing_;  // ComeshOptions::slide_window, from the input
  // What every inner run takes (its max_iterations aside); the drawings' outlines are in
  // bounds_, so the runs' copies leave them out.
  ComeshOptions per_run_;
  SharedFactors factors_;
};

absl::StatusOr<Multimesh> OuterLoop::Run(const ComeshCheckpoint* resume) {
  current_ = resume != nullptr ? resume->mesh : input_;
  current_.art.clear();  // embedded in the input's triangles; the caller re-embeds (multimesh.h)
  pass_start_objective_ = rep_.objective_before;
  if (resume != nullptr) Resume(*resume);
  SetUpOutlines();
  if (options_.slide_boundary && options_.slide_window > 0.0) {
    pairing_.emplace(input_, options_.slide_window);
  }
  per_run_ = options_;
  per_run_.outline_reference.clear();
  // Stage 0 is the run without outline sliding, to convergence; stage 1 (curved outlines with
  // slide_outline only) continues from its result with the boundary sliding along the outlines:
  // short runs and topology passes again, then a final run. Every step of stage 1 lowers the
  // objective or keeps it, so outline sliding never ends above the run without it (a run that
  // slid from the start took other topology passes and ended up to 0.17% higher on some
  // examples: "Comesh optimization: outline sliding" in docs/benchmarks.md).
  const int last_stage = outlines_.empty() ? 0 : 1;
  for (int stage = resume != nullptr ? std::min(resume->stage, last_stage) : 0; stage <= last_stage;
       ++stage) {
    const bool resumed_in_stage = resume != nullptr && resume->stage == stage;
    if (absl::Status st = RunStage(stage, resumed_in_stage); !st.ok()) return st;
  }
  if (absl::Status st = RemoveSliversAtEnd(); !st.ok()) return st;
  FillReport();
  return std::move(current_);
}

// Everything the loop reads across passes (see ComeshCheckpoint).
void OuterLoop::Resume(const ComeshCheckpoint& resume) {
  first_outer_ = resume.outer;
  stats_.iterations = resume.inner;
  stats_.evaluations = resume.energy_evaluations;
  pass_start_objective_ = resume.pass_start_objective;
  rep_.outer = resume.outer;
  rep_.flips = resume.flips;
  rep_.collapses = resume.collapses;
  rep_.splits = resume.splits;
  rep_.objective_trace = resume.objective_trace;
}

// The sliding outlines and the outline guard's bounds: against each drawing's outline when
// given, else the input's.
void OuterLoop::SetUpOutlines() {
  outlines_ = SlidingOutlines(input_, options_);
  if (outlines_.empty() || !(options_.outline_tolerance > 0.0)) return;
  bounds_.emplace();
  for (const std::vector<Points>& loops : options_.outline_reference) {
    drawn_.emplace_back(loops, options_.outline_corner_degrees);
  }
  for (int s = 0; s < input_.num_shapes(); ++s) {
    const ShapeOutline* reference = drawn_.empty() ? &outlines_[s] : &drawn_[s];
    bounds_->reference.push_back(reference);
    bounds_->tolerance.push_back(options_.outline_tolerance * reference->diagonal());
  }
}

// Topology passes, each after a short inner run (positions only need to be roughly relaxed for
// the operations' decisions), then one inner run to convergence on the final topology.
absl::Status OuterLoop::RunStage(int stage, bool resumed_in_stage) {
  const std::vector<ShapeOutline>* stage_outlines = stage == 1 ? &outlines_ : nullptr;
  if (stage == 1 && !resumed_in_stage) {
    // The first short run is judged against stage 0's result, like a pass's run against the
    // pass before.
    first_outer_ = rep_.outer;
    pass_start_objective_ = stats_.objective;
    if (progress_) progress_("comesh", 1.0, "outline sliding");
  }
  for (int outer = first_outer_; outer < options_.max_outer; ++outer) {
    if (absl::Status st = InnerRun(
            std::min(options_.max_iterations, options_.outer_inner_iterations), stage_outlines);
        !st.ok()) {
      return st;
    }
    if ((outer > 0 || stage > 0) && pass_start_objective_ - stats_.objective <=
                                        options_.outer_tolerance * std::abs(stats_.objective)) {
      break;
    }
    pass_start_objective_ = stats_.objective;
    absl::StatusOr<bool> go_on = TopologyPass(outer, stage, stage_outlines);
    if (!go_on.ok()) return go_on.status();
    if (!*go_on) break;
  }
  return InnerRun(options_.max_iterations, stage_outlines);
}

absl::Status OuterLoop::InnerRun(int max_iterations,
                                 const std::vector<ShapeOutline>* stage_outlines) {
  ComeshOptions run = per_run_;
  run.max_iterations = max_iterations;
  const InnerRunContext context{.threads = threads_,
                                .outlines = stage_outlines,
                                .bounds = bounds_ ? &*bounds_ : nullptr,
                                .pairing = pairing_ ? &*pairing_ : nullptr,
                                .cancel = cancel_,
                                .progress = &progress_,
                                .iteration_base = stats_.iterations,
                                .factors = &factors_};
  absl::Status st = RunComeshInnerLoop(&current_, run, context, &stats_);
  if (st.ok()) rep_.objective_trace.push_back(stats_.objective);
  return st;
}

absl::StatusOr<bool> OuterLoop::TopologyPass(int outer, int stage,
                                             const std::vector<ShapeOutline>* stage_outlines) {
  if (Cancelled(cancel_)) {
    return absl::CancelledError(absl::StrCat("comesh optimization cancelled at outer ", outer));
  }
  TopologyReport topo;
  Stopwatch topology_clock;
  absl::StatusOr<Multimesh> improved = ImproveTopology(
      current_, options_.map_weight, options_.topology, &topo, cancel_, stage_outlines);
  stats_.phases.topology += topology_clock.Lap();
  if (absl::IsCancelled(improved.status())) {
    return absl::CancelledError(absl::StrCat("comesh optimization cancelled at outer ", outer));
  }
  if (!improved.ok()) return improved.status();
  if (topo.flips + topo.collapses + topo.splits == 0) return false;
  rep_.flips += topo.flips;
  rep_.collapses += topo.collapses;
  rep_.splits += topo.splits;
  ++rep_.outer;
  current_ = *std::move(improved);
  rep_.objective_trace.push_back(topo.objective_after);
  // The pass itself (not the short run after it) gained little: the topology has settled, and
  // further passes would only interleave restarts with the inner run (on large meshes the short
  // runs keep gaining, so the pass + run test alone keeps the loop going far too long).
  const bool settled = topo.objective_before - topo.objective_after <=
                       options_.outer_tolerance * std::abs(topo.objective_after);
  // The server reads the pass count after "outer" (server/comesh_progress.cpp).
  if (progress_) {
    progress_("comesh", 1.0,
              absl::StrFormat("outer %d: %d flips, %d collapses (%d corner swaps), %d splits, "
                              "vertices %d",
                              rep_.outer, topo.flips, topo.collapses, topo.corner_swaps,
                              topo.splits, current_.num_vertices()));
  }
  if (options_.on_checkpoint) {
    options_.on_checkpoint(ComeshCheckpoint{.mesh = current_,
                                            .outer = rep_.outer,
                                            .inner = stats_.iterations,
                                            .energy_evaluations = stats_.evaluations,
                                            .flips = rep_.flips,
                                            .collapses = rep_.collapses,
                                            .splits = rep_.splits,
                                            .pass_start_objective = pass_start_objective_,
                                            .objective_trace = rep_.objective_trace,
                                            .stage = stage});
  }
  return !settled;
}

// The last step: sliver removal. It may raise the objective a little (it judges by quality), so
// the report's energies are evaluated afresh after it; the trace ends before it. Skipped where no
// triangle is below min_quality (with 4 slivers the step took ~0.1 s at 165k vertices; its
// topology editor is set up over every triangle).
absl::Status OuterLoop::RemoveSliversAtEnd() {
  rep_.worst_quality = WorstQuality(current_);
  if (!(options_.max_outer > 0 && options_.min_quality > 0.0 &&
        rep_.worst_quality < options_.min_quality)) {
    return absl::OkStatus();
  }
  SliverReport slivers;
  Stopwatch topology_clock;
  absl::StatusOr<Multimesh> cleaned =
      RemoveSlivers(current_, options_.map_weight, options_.min_quality, &slivers, cancel_,
                    outlines_.empty() ? nullptr : &outlines_, &input_);
  if (absl::IsCancelled(cleaned.status())) {
    return absl::CancelledError("comesh optimization cancelled at sliver removal");
  }
  if (!cleaned.ok()) return cleaned.status();
  rep_.slivers = slivers.slivers_before;
  rep_.sliver_operations = slivers.operations;
  if (slivers.operations > 0) {
    current_ = *std::move(cleaned);
    absl::StatusOr<ComeshObjective> final_objective =
        ComeshObjective::Create(current_.triangles, current_.shapes, options_.map_weight, threads_);
    if (!final_objective.ok()) return final_objective.status();
    stats_.objective = final_objective->Evaluate(current_.shapes, nullptr, &stats_.energies);
    ++stats_.evaluations;
  }
  rep_.worst_quality = slivers.worst_quality_after;
  stats_.phases.topology += topology_clock.Lap();
  return absl::OkStatus();
}

void OuterLoop::FillReport() {
  rep_.inner = stats_.iterations;
  rep_.energy_evaluations = stats_.evaluations + 1;  // + the report's own "before"
  rep_.phase_seconds = stats_.phases;
  rep_.stop_reason = stats_.stop_reason;
  rep_.objective_after = stats_.objective;
  rep_.map_energy = stats_.energies.map;
  rep_.mesh_energy = stats_.energies.mesh;
  rep_.vertices_after = current_.num_vertices();
}

}  // namespace

absl::StatusOr<Multimesh> OptimizeComesh(const Multimesh& mesh, const ComeshOptions& options,
                                         const CancelToken* cancel, const ProgressFn& progress,
                                         ComeshReport* report, const ComeshCheckpoint* resume) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status st = ValidateInput(mesh); !st.ok()) return st;
  if (resume != nullptr) {
    if (absl::Status st = ValidateCheckpoint(*resume); !st.ok()) return st;
  }
  if (absl::Status st = ValidateOptions(options, mesh); !st.ok()) return st;
  const int threads = ResolveThreads(options.threads);
  const absl::Status not_started = absl::CancelledError("comesh optimization cancelled at start");
  if (Cancelled(cancel)) return not_started;
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh.triangles, mesh.shapes, options.map_weight, threads);
  if (!objective.ok()) return objective.status();
  if (Cancelled(cancel)) return not_started;

  ComeshReport rep;
  rep.vertices_before = rep.vertices_after = mesh.num_vertices();
  ComeshEnergies energies;
  rep.objective_before = objective->Evaluate(mesh.shapes, nullptr, &energies);
  rep.map_energy_before = energies.map;
  rep.mesh_energy_before = energies.mesh;

  absl::StatusOr<Multimesh> result =
      OuterLoop(mesh, options, threads, cancel, progress, &rep).Run(resume);
  if (!result.ok()) return result.status();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report != nullptr) *report = rep;
  return result;
}

}  // namespace inbetween::solver
