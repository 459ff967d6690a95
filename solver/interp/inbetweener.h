// Inbetweening: per-frame interpolation of a multimesh's shapes. Expensive set-up once
// (Create), cheap calls per frame (Solve).
#pragma once

#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::solver {

enum class InterpMethod { kLinear, kAlexa, kZhu17 };

struct InbetweenOptions {
  InterpMethod method = InterpMethod::kZhu17;
  double lambda = 1.0;   // cohesive stiffness (S-eq.6)
  double tau = 0.1;      // separation threshold (S-eq.6): energy per unit edge length
  double alpha = 0.5;    // shear vs stretch weight (S-eq.7)
  double epsilon = 0.0;  // dynamics compliance (S-eq.28); 0 = no dynamics
  double rho = 1.0;      // density (S-eq.28)
  double h = 1.0 / 24;   // timestep, seconds (S-eq.28)
  int max_iterations = 20;
  // Added by the first inbetweening slice:
  // Per-triangle material stiffness kappa (S-eq.3); empty = 1 everywhere, else one positive
  // value per triangle of the multimesh.
  std::vector<double> stiffness;
  // kZhu17 stops when an iteration lowers the energy by less than this fraction...
  double convergence_tolerance = 1e-10;
  // A weight vector e_i returns shape i bit-exactly. The energy's unique minimizer up to rigid
  // motion is then X_i itself and the gauge fixes the rigid motion, so this only removes
  // rounding (tests turn it off to check that the solve lands within 1e-9 of X_i anyway).
  bool exact_keys = true;
  // kZhu17 starts from the better (lower energy) of the Alexa-target solve at the same weights
  // and `previous` moved into the frame's gauge (centroid and mean rotation, see
  // inbetweener.cpp), when one is given. The rotation gauge is what makes the warm start safe
  // for examples that differ by a rigid turn (the energy alone cannot tell rotated copies apart).
  bool warm_start = true;
  // ... or when no vertex moved by more than this times the reference size sqrt(total area) in
  // the last plain local-global step (whichever comes first).
  double displacement_tolerance = 1e-4;
  // Anderson acceleration of the local-global fixed point (Peng et al. 2018), with `history`
  // previous steps; a step that would raise the energy is replaced by the plain step, so the
  // energy still never increases.
  bool anderson = true;
  int anderson_history = 5;
  // Cohesive zones (S-eq.6): an edge that was separated in `previous` separates at
  // (1 - hysteresis) tau, a bonded one at (1 + hysteresis) tau, so edges near tau do not flicker.
  double hysteresis = 0.1;
  // Non-overlap W_O (S-eq.8/9) enforced as a constraint in kZhu17 (overlap.h).
  bool prevent_overlap = true;
  // Warm start without the cold-start check: when `previous` is the frame this object returned
  // last and the weights moved by at most this much since (half their L1 distance, 0..1), the
  // solve continues from `previous` alone; the Alexa start is computed only otherwise (first
  // frame, scrubbing, a caller-made `previous`). 0 = always compare both starts: the default,
  // because on smooth bends the Alexa start is within the tolerance after one iteration while the
  // previous frame needs ~10 (bench_inbetween --trust 0.5: 2.7x slower frames on the bar).
  double warm_start_trust_radius = 0.0;
  // Threads for the local step, the right-hand side and the x/y back-substitutions (<= 0: all
  // cores). Work is cut into fixed chunks reduced in a fixed order, so frames are bit-identical
  // for every thread count; small meshes (< 8192 triangles / rows) stay on the caller's thread.
  int threads = 1;
};

// Blend weights of the examples at one frame; they sum to 1.
using ExampleWeights = std::vector<double>;

struct Frame {
  Points vertices;
};

struct FrameReport {
  int iterations = 0;
  double energy = 0.0;  // the kZhu17 objective at the frame (blended_arap.h + cohesive + inertia)
  double seconds = 0.0;
  int inverted = 0;
  int overlaps = 0;           // boundary vertices inside the shape + crossing boundary segments
  int separated_edges = 0;    // cohesive edge pairs whose zone is open (S-eq.6 capped)
  bool warm_started = false;  // kZhu17 started from `previous`
  double xi = 0.0;            // dynamics blend weight xi(s) (S-eq.28); 0 without dynamics
  // Smallest and largest ratio of a triangle's signed area to its area blended over the examples
  // with the frame's weights (1 = area kept; <= 0 = inverted).
  double min_area_ratio = 1.0;
  double max_area_ratio = 1.0;
  // Non-overlap: above 0 when pushing the boundary out of the shape (W_O)
  // could not make the frame clean, so it stopped short of its solution: the fraction of the way
  // from the previous frame to the solution it was held back (the frame is the furthest point on
  // that way with no overlap and no inverted triangle; 1 = it did not move).
  double hold_back = 0.0;
};

class Inbetweener {
 public:
  static absl::StatusOr<Inbetweener> Create(const Multimesh& mesh, InbetweenOptions options);
  Inbetweener(Inbetweener&&) noexcept;
  Inbetweener& operator=(Inbetweener&&) noexcept;
  ~Inbetweener();

  // One frame at the given example weights; `previous` (may be empty) warm-starts the solve, sets
  // the cohesive hysteresis and, with dynamics (epsilon > 0), is x(s-1). A weight vector that is 1
  // for example i returns shape i exactly. With dynamics, x(s-2) is the frame this object returned
  // before `previous` when `previous` is the frame it returned last (sequential calls), else
  // `previous` itself (motion starts at rest); the overload below and FrameSequence pass it
  // explicitly.
  absl::StatusOr<Frame> Solve(const ExampleWeights& weights, const Frame& previous,
                              const CancelToken* cancel = nullptr, FrameReport* report = nullptr);

  // Dynamics (S-eq.28/29): `previous` = x(s-1), `before_previous` = x(s-2) (either may be empty).
  // With epsilon = 0 this is exactly Solve(weights, previous, ...).
  absl::StatusOr<Frame> Solve(const ExampleWeights& weights, const Frame& previous,
                              const Frame& before_previous, const CancelToken* cancel = nullptr,
                              FrameReport* report = nullptr);

 private:
  struct Impl;
  explicit Inbetweener(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Frames in order, owning the two previous frames that warm starts and dynamics need.
class FrameSequence {
 public:
  explicit FrameSequence(Inbetweener* inbetweener) : inbetweener_(inbetweener) {}
  absl::StatusOr<Frame> Next(const ExampleWeights& weights, const CancelToken* cancel = nullptr,
                             FrameReport* report = nullptr);
  void Reset() { previous_ = before_previous_ = Frame{}; }

 private:
  Inbetweener* inbetweener_;
  Frame previous_;
  Frame before_previous_;
};

}  // namespace inbetween::solver
