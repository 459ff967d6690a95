// The comesh inner loop (see comesh_inner_loop.h).
#include "solver/comesh/comesh_inner_loop.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "solver/comesh/comesh_cure.h"
#include "solver/comesh/comesh_layout.h"
#include "solver/comesh/comesh_lbfgs.h"
#include "solver/comesh/comesh_relax.h"
#include "solver/comesh/comesh_step_bound.h"

namespace inbetween::solver {
namespace {

using Eigen::VectorXd;

// The vars (indices into layout.vars()) that local relaxation moves after a short step: those
// holding at least relax_fraction of |g|^2 and relax_over_mean times an even share of it, largest
// first (ties by index), at most relax_max_vertices of them. An outline slider's move changes the
// areas the (area-invariant) normalizers follow, which the relaxer holds fixed: it moves with the
// global steps only.
std::vector<int> PickRelaxVars(const ComeshLayout& layout, const VectorXd& g,
                               const ComeshOptions& options) {
  const double total = g.squaredNorm();
  const std::vector<ComeshLayout::Var>& vars = layout.vars();
  const double threshold =
      total * std::max(options.relax_fraction, options.relax_over_mean / vars.size());
  std::vector<std::pair<double, int>> picked;
  for (int i = 0; i < static_cast<int>(vars.size()); ++i) {
    if (vars[i].outline >= 0) continue;
    const double part = vars[i].slider ? g[vars[i].offset] * g[vars[i].offset]
                                       : g.segment<2>(vars[i].offset).squaredNorm();
    if (part >= threshold) picked.emplace_back(part, i);
  }
  std::sort(picked.begin(), picked.end(), [](const auto& x, const auto& y) {
    return x.first != y.first ? x.first > y.first : x.second < y.second;
  });
  picked.resize(std::min<size_t>(picked.size(), std::max(0, options.relax_max_vertices)));
  std::vector<int> indices;
  indices.reserve(picked.size());
  for (const auto& [part, i] : picked) indices.push_back(i);
  return indices;
}

// One inner run. Run() calls the phases below in order; each returns true to go on, or false
// once the run ends, with its status in result_ (OK with stats_->stop_reason set, Cancelled, or
// an error).
class InnerLoop {
 public:
  InnerLoop(Multimesh* mesh, const ComeshOptions& options, const InnerRunContext& context,
            ComeshInnerStats* stats)
      : mesh_(mesh),
        options_(options),
        context_(context),
        cancel_(context.cancel),
        stats_(stats),
        lbfgs_({.history = options.history,
                .scaling_by_inverse = options.scaling_by_inverse,
                .blend = options.blend}) {}
  InnerLoop(const InnerLoop&) = delete;  // the preconditioner and relaxer point into it
  InnerLoop& operator=(const InnerLoop&) = delete;

  absl::Status Run() {
    if (SetUp()) {
      for (iter_ = 0; Iterate(); ++iter_) {
      }
    }
    return result_;
  }

 private:
  // The objective, layout, initial Hessian, relaxer and outline guard; the first iterate.
  bool SetUp();
  void SetUpGuard();
  // One iteration: the stopping tests on the current iterate, then its phases.
  bool Iterate() {
    if (!Checkpoint()) return false;
    if (g_.norm() <= options_.gradient_tolerance * g0_) return Finish("gradient");
    if (iter_ >= options_.max_iterations) return Finish("max_iterations");
    return RefreshPreconditioner() && ComputeDirection() && Cure() && BoundStep() && SearchLine() &&
           UpdateCurvature() && Relax() && Accept();
  }
  bool RefreshPreconditioner();
  bool ComputeDirection();
  bool Cure();
  bool BoundStep();
  bool HoldOutlineSliders();
  bool SearchLine();
  bool UpdateCurvature();
  bool Relax();
  bool Accept();
  void ReportIteration() const;

  // The run's one checkpoint: polls the token and, once it is set, ends the run as Cancelled at
  // the current iteration. Every point where the run observes cancellation calls it, except
  // where a callee has seen the token itself (an empty solve, a cancelled set-up): those call
  // Cancel() directly.
  bool Checkpoint() { return !Cancelled(cancel_) || Cancel(); }
  bool Cancel() {
    return Stop(absl::CancelledError(absl::StrCat("comesh optimization cancelled at iteration ",
                                                  context_.iteration_base + iter_)));
  }
  bool Stop(absl::Status status) {
    result_ = std::move(status);
    return false;
  }
  bool Finish(const char* stop_reason) {
    stats_->stop_reason = stop_reason;
    return false;
  }

  Multimesh* mesh_;
  const ComeshOptions& options_;
  const InnerRunContext& context_;
  const CancelToken* cancel_;
  ComeshInnerStats* stats_;
  Stopwatch clock_;
  absl::Status result_;
  int iter_ = 0;

  std::optional<ComeshObjective> objective_;
  std::optional<ComeshLayout> layout_;
  std::unique_ptr<ComeshPreconditioner> preconditioner_;
  int refresh_ = 0;  // ComeshOptions::hessian_refresh if the model follows the positions, else 0
  ComeshLbfgs lbfgs_;
  std::optional<VertexRelaxer> relaxer_;
  std::optional<OutlineGuard> guard_;
  std::vector<int> guard_slot_;  // per var: its slot in the guard, or -1

  // The current iterate.
  VectorXd z_, g_;
  double f_ = 0.0;
  double g0_ = 0.0;              // ||g|| at the start of the run
  std::vector<double> history_;  // objective per iteration, for the stopping window

  // This iteration's direction, step and trial.
  VectorXd d_;
  double slope_ = 0.0;
  std::vector<Points> disp_;  // the direction as per-vertex displacements (step bound, curing)
  bool disp_is_d_ = false;    // disp_ holds d_'s displacements
  double max_step_ = 0.0;     // the inversion bound
  double step_ = 0.0;
  VectorXd z_new_, g_new_;
  double f_new_ = 0.0;
  std::vector<Points> trial_;
  std::vector<Points> trial_grad_;
  ComeshEnergies trial_energies_;
};

bool InnerLoop::SetUp() {
  // The set-up's steps each poll the token.
  absl::StatusOr<ComeshObjective> objective =
      ComeshObjective::Create(mesh_->triangles, mesh_->shapes, options_.map_weight,
                              context_.threads, /*area_invariant=*/context_.outlines != nullptr);
  if (!objective.ok()) return Stop(objective.status());
  objective_.emplace(*std::move(objective));
  if (!Checkpoint()) return false;
  layout_.emplace(*mesh_, options_.slide_boundary, context_.outlines, context_.pairing, cancel_);
  if (layout_->cancelled()) return Cancel();
  if (!Checkpoint()) return false;
  std::vector<Points> grad_shapes;
  ComeshEnergies energies;
  f_ = objective_->Evaluate(mesh_->shapes, &grad_shapes, &energies, cancel_);
  if (!Checkpoint()) return false;  // f is NaN then
  ++stats_->evaluations;
  stats_->energies = energies;
  stats_->objective = f_;
  if (layout_->size() == 0) return Finish("no_free");
  if (!Checkpoint()) return false;
  absl::StatusOr<std::unique_ptr<ComeshPreconditioner>> preconditioner = CreateComeshPreconditioner(
      mesh_->triangles, *layout_, *objective_, mesh_->shapes, options_, cancel_, context_.factors);
  if (absl::IsCancelled(preconditioner.status())) return Cancel();
  if (!preconditioner.ok()) return Stop(preconditioner.status());
  preconditioner_ = *std::move(preconditioner);
  refresh_ = preconditioner_->follows_positions() ? options_.hessian_refresh : 0;
  if (options_.relax_fraction > 0.0) relaxer_.emplace(*objective_);
  SetUpGuard();
  stats_->phases.hessian += clock_.Lap();

  z_ = layout_->Gather(mesh_->shapes);
  g_ = layout_->GatherGradient(grad_shapes);
  g0_ = g_.norm();
  history_ = {f_};
  trial_ = mesh_->shapes;
  return true;
}

void InnerLoop::SetUpGuard() {
  guard_slot_.assign(layout_->vars().size(), -1);
  if (context_.outlines == nullptr || context_.bounds == nullptr) return;
  for (size_t i = 0; i < layout_->vars().size(); ++i) {
    const ComeshLayout::Var& var = layout_->vars()[i];
    if (var.outline < 0) continue;
    if (!guard_) guard_.emplace(context_.bounds->reference, context_.bounds->tolerance);
    guard_slot_[i] =
        guard_->Add(var.shape, var.vertex, var.prev, var.next, mesh_->shapes[var.shape]);
  }
}

bool InnerLoop::RefreshPreconditioner() {
  if (!(refresh_ > 0 && iter_ > 0 && iter_ % refresh_ == 0)) return true;
  if (absl::Status st = preconditioner_->Update(mesh_->shapes, cancel_); !st.ok()) {
    return absl::IsCancelled(st) ? Cancel() : Stop(std::move(st));
  }
  stats_->phases.hessian += clock_.Lap();
  return true;
}

// Besides the top of the loop and the line search's trials, the token is polled inside the
// direction's solves and after each phase below: at 165k vertices the direction, curing, step
// bound and first trial took up to ~150 ms between two polls.
bool InnerLoop::ComputeDirection() {
  d_ = lbfgs_.Direction(g_, *preconditioner_, cancel_);
  if (d_.size() == 0) return Cancel();
  slope_ = g_.dot(d_);
  if (!(slope_ < 0.0)) {  // lost descent (non-convexity): restart from the preconditioned gradient
    lbfgs_.Clear();
    d_ = lbfgs_.Direction(g_, *preconditioner_, cancel_);
    if (d_.size() == 0) return Cancel();
    slope_ = g_.dot(d_);
    if (!(slope_ < 0.0)) {
      d_ = -g_;
      slope_ = -g_.squaredNorm();
    }
  }
  stats_->phases.direction += clock_.Lap();
  return Checkpoint();
}

// The cured direction is kept only if it still descends.
bool InnerLoop::Cure() {
  disp_is_d_ = false;
  if (options_.cure) {
    VectorXd cured = d_;
    disp_is_d_ = true;  // CureDirection leaves the uncured d's displacements in disp_
    const int scaled = CureDirection(mesh_->triangles, mesh_->shapes, *layout_, options_.cure_keep,
                                     objective_->threads(), cancel_, &disp_, &cured);
    if (scaled < 0) return Cancel();
    if (scaled > 0) {
      const double cured_slope = g_.dot(cured);
      if (cured_slope < 0.0) {
        d_ = std::move(cured);
        slope_ = cured_slope;
        disp_is_d_ = false;
      }
    }
  }
  return Checkpoint();
}

// The line search's first step: min(1, max_step_fraction * the inversion bound).
bool InnerLoop::BoundStep() {
  if (!disp_is_d_) layout_->Displacements(d_, &disp_);
  if (!Checkpoint()) return false;
  max_step_ = MaxNonInvertingStep(mesh_->triangles, mesh_->shapes, disp_, objective_->threads());
  step_ = std::min(1.0, options_.max_step_fraction * max_step_);
  if (guard_ && !HoldOutlineSliders()) return false;
  stats_->phases.step_bound += clock_.Lap();
  return true;
}

// An outline slider whose own move (its neighbours where they are) would take a chord beyond the
// bound stays put for this iteration, so the others still move; the line search holds the chords
// between two moving sliders.
bool InnerLoop::HoldOutlineSliders() {
  const ComeshLayout& layout = *layout_;
  bool held = false;
  for (size_t i = 0; i < guard_slot_.size(); ++i) {
    const ComeshLayout::Var& var = layout.vars()[i];
    if (guard_slot_[i] < 0 || d_[var.offset] == 0.0) continue;
    const Point p = layout.OutlinePoint(var, z_[var.offset] + step_ * d_[var.offset]);
    if (!guard_->HoldsAt(guard_slot_[i], p, mesh_->shapes[var.shape])) {
      d_[var.offset] = 0.0;
      held = true;
    }
  }
  if (!held) return true;
  slope_ = g_.dot(d_);
  if (!(slope_ < 0.0)) {  // what is left does not descend: the free part of -g
    const VectorXd kept = d_;
    d_ = -g_;
    for (size_t i = 0; i < guard_slot_.size(); ++i) {
      const int offset = layout.vars()[i].offset;
      if (guard_slot_[i] >= 0 && kept[offset] == 0.0) d_[offset] = 0.0;
    }
    slope_ = g_.dot(d_);
    if (!(slope_ < 0.0)) return Finish("outline");
  }
  layout.Displacements(d_, &disp_);
  max_step_ = MaxNonInvertingStep(mesh_->triangles, mesh_->shapes, disp_, objective_->threads());
  step_ = std::min(1.0, options_.max_step_fraction * max_step_);
  return true;
}

// Backtracking (Armijo) from step_; then the accepted trial's gradient in the unknowns.
bool InnerLoop::SearchLine() {
  bool accepted = false;
  f_new_ = f_;
  for (int b = 0; b <= options_.max_backtracks; ++b) {
    // Every trial is an energy evaluation (15 ms at 73k vertices): poll before each.
    if (!Checkpoint()) return false;
    z_new_ = z_ + step_ * d_;
    layout_->Scatter(z_new_, &trial_);
    if (!Checkpoint()) return false;
    if (guard_ && !guard_->Holds(trial_)) {
      step_ *= 0.5;  // a chord strays beyond the bound: shorter, like a non-finite trial
      continue;
    }
    f_new_ = objective_->Evaluate(trial_, &trial_grad_, &trial_energies_, cancel_);
    ++stats_->evaluations;
    // And after it (f_new_ is NaN if it was cancelled inside): at 311k vertices an evaluation
    // takes ~0.1 s, and an accepted trial followed by the curvature pair's update would otherwise
    // be the longest stretch without a poll.
    if (!Checkpoint()) return false;
    if (std::isfinite(f_new_) && f_new_ <= f_ + options_.armijo * step_ * slope_) {
      accepted = true;
      break;
    }
    // Next trial: the minimizer of the quadratic through f, slope and f_new, kept within
    // [0.1, 0.5] of the failed step (plain halving when f_new is not finite).
    double next = 0.5 * step_;
    if (std::isfinite(f_new_)) {
      const double curvature = f_new_ - f_ - slope_ * step_;
      if (curvature > 0.0) next = -slope_ * step_ * step_ / (2.0 * curvature);
      next = std::clamp(next, 0.1 * step_, 0.5 * step_);
    }
    step_ = next;
  }
  stats_->phases.line_search += clock_.Lap();
  if (!accepted) return Finish("line_search");

  layout_->Track(z_new_);
  g_new_ = layout_->GatherGradient(trial_grad_);
  return Checkpoint();
}

// ComeshLbfgs::Update polls between its vector operations (see SearchLine for why).
bool InnerLoop::UpdateCurvature() {
  if (!lbfgs_.Update(z_, z_new_, g_, g_new_, g0_, *preconditioner_, cancel_)) return Cancel();
  stats_->phases.direction += clock_.Lap();
  return true;
}

// Local relaxation (ComeshOptions::relax_fraction) after a step shorter than the unit step.
bool InnerLoop::Relax() {
  if (!(relaxer_ && step_ < 1.0 && g_new_.squaredNorm() > 0.0)) return true;
  const std::vector<ComeshLayout::Var>& vars = layout_->vars();
  const std::vector<int> picked = PickRelaxVars(*layout_, g_new_, options_);
  std::vector<RelaxTarget> targets;
  for (int i : picked) {
    const ComeshLayout::Var& var = vars[i];
    targets.push_back({var.shape, var.vertex, var.slider, var.direction, var.base, var.lo, var.hi});
  }
  if (relaxer_->Relax(targets, options_.relax_steps, &trial_, &trial_grad_, &trial_energies_) > 0) {
    if (!Checkpoint()) return false;
    // Only the picked vertices moved (a full Gather would re-round every slider's unknown).
    for (int i : picked) {
      const ComeshLayout::Var& var = vars[i];
      const Point& x = trial_[var.shape][var.vertex];
      if (var.slider) {
        z_new_[var.offset] = (x - var.base).dot(var.direction);
      } else {
        z_new_.segment<2>(var.offset) = x;
      }
    }
    if (objective_->area_invariant()) {
      // The moves kept every area, but the gradient's area term on the boundary follows every
      // shape's energy: evaluate afresh.
      f_new_ = objective_->Evaluate(trial_, &trial_grad_, &trial_energies_, cancel_);
      ++stats_->evaluations;
      if (!Checkpoint()) return false;
    }
    g_new_ = layout_->GatherGradient(trial_grad_);
    f_new_ = trial_energies_.objective;
  }
  stats_->phases.relax += clock_.Lap();
  return true;
}

// Takes the trial as the new iterate; stops when the objective has stalled.
bool InnerLoop::Accept() {
  history_.push_back(f_new_);
  const int window = std::max(1, options_.decrease_window);
  // A step capped by the inversion bound is "blocked": slow progress there may be one blocking
  // triangle rather than convergence, so it only counts as a stall over twice the window.
  const bool blocked = options_.max_step_fraction * max_step_ < 1.0;
  auto small_decrease = [&](int over) {
    return static_cast<int>(history_.size()) > over &&
           history_[history_.size() - 1 - over] - f_new_ <=
               options_.relative_decrease_tolerance * std::max(std::abs(f_new_), 1e-300);
  };
  const bool stalled = (!blocked && small_decrease(window)) || small_decrease(2 * window);
  z_ = z_new_;
  g_ = g_new_;
  f_ = f_new_;
  std::swap(mesh_->shapes, trial_);
  ++stats_->iterations;
  stats_->objective = f_;
  stats_->energies = trial_energies_;
  ReportIteration();
  if (stalled) return Finish("decrease");
  return true;
}

// on_iterate and the progress callback, once per accepted iteration. The server reads the numbers
// after "objective", "map" and "mesh" out of this line (server/comesh_progress.cpp).
void InnerLoop::ReportIteration() const {
  const int global_iteration = context_.iteration_base + iter_ + 1;
  if (options_.on_iterate) options_.on_iterate(global_iteration, mesh_->shapes);
  if (context_.progress == nullptr || !*context_.progress) return;
  (*context_.progress)(
      "comesh",
      options_.max_iterations > 0
          ? std::min(1.0, static_cast<double>(iter_ + 1) / options_.max_iterations)
          : 1.0,
      absl::StrFormat("iteration %d: objective %.6g, map %.5f, mesh %.5f, vertices %d, "
                      "step %.3g of %.3g",
                      global_iteration, f_, trial_energies_.map, trial_energies_.mesh,
                      mesh_->num_vertices(), step_, max_step_));
}

}  // namespace

absl::Status RunComeshInnerLoop(Multimesh* mesh, const ComeshOptions& options,
                                const InnerRunContext& context, ComeshInnerStats* stats) {
  return InnerLoop(mesh, options, context, stats).Run();
}

}  // namespace inbetween::solver
