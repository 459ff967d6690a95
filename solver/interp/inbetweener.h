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
  double tau = 0.1;      // separation threshold (S-eq.6)
  double alpha = 0.5;    // shear vs stretch weight (S-eq.7)
  double epsilon = 0.0;  // dynamics compliance (S-eq.28); 0 = no dynamics
  double rho = 1.0;      // density (S-eq.28)
  double h = 1.0 / 24;   // timestep, seconds (S-eq.28)
  int max_iterations = 20;
  // Added by the first inbetweening slice:
  // Per-triangle material stiffness kappa (S-eq.3); empty = 1 everywhere, else one positive
  // value per triangle of the multimesh.
  std::vector<double> stiffness;
  // kZhu17 stops when an iteration lowers the energy by less than this fraction.
  double convergence_tolerance = 1e-10;
  // A weight vector e_i returns shape i bit-exactly. The energy's unique minimizer up to rigid
  // motion is then X_i itself and the centroid gauge fixes the translation, so this only removes
  // rounding (tests turn it off to check that the solve lands within 1e-9 of X_i anyway).
  bool exact_keys = true;
  // kZhu17 starts from the kAlexa solution at the same weights. With warm_start it starts from
  // `previous` (re-centred) instead when one is given. Off by default: for examples that differ
  // by a rigid turn every rotated copy has zero energy, so a warm start freezes the turn and the
  // shape snaps at the next key; the Alexa start turns smoothly and is continuous in the weights.
  bool warm_start = false;
};

// Blend weights of the examples at one frame; they sum to 1.
using ExampleWeights = std::vector<double>;

struct Frame {
  Points vertices;
};

struct FrameReport {
  int iterations = 0;
  double energy = 0.0;
  double seconds = 0.0;
  int inverted = 0;
};

class Inbetweener {
 public:
  static absl::StatusOr<Inbetweener> Create(const Multimesh& mesh, InbetweenOptions options);
  Inbetweener(Inbetweener&&) noexcept;
  Inbetweener& operator=(Inbetweener&&) noexcept;
  ~Inbetweener();

  // One frame at the given example weights; `previous` (may be empty) warm-starts the solve and
  // keeps rotations continuous. A weight vector that is 1 for example i returns shape i exactly.
  // (In this slice rotations are continuous in the weights by construction, example_rotations.h;
  // `previous` is validated, and used as the kZhu17 start only with options.warm_start.)
  absl::StatusOr<Frame> Solve(const ExampleWeights& weights, const Frame& previous,
                              const CancelToken* cancel = nullptr, FrameReport* report = nullptr);

 private:
  struct Impl;
  explicit Inbetweener(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inbetween::solver
