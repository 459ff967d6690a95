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
  double lambda = 1.0;  // cohesive stiffness (S-eq.6)
  double tau = 0.1;     // separation threshold (S-eq.6)
  double alpha = 0.5;   // shear vs stretch weight (S-eq.7)
  double epsilon = 0.0; // dynamics compliance (S-eq.28); 0 = no dynamics
  double rho = 1.0;     // density (S-eq.28)
  double h = 1.0 / 24;  // timestep, seconds (S-eq.28)
  int max_iterations = 20;
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
  absl::StatusOr<Frame> Solve(const ExampleWeights& weights, const Frame& previous,
                              const CancelToken* cancel = nullptr,
                              FrameReport* report = nullptr);

 private:
  struct Impl;
  explicit Inbetweener(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace inbetween::solver
