// Frame timing: which example weights each output frame uses, and where the keys land.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/interp/inbetweener.h"

namespace inbetween::solver {

struct FrameTiming {
  double time = 0.0;       // normalized time in [0, 1]
  ExampleWeights weights;  // one per example, sum 1
};

struct Schedule {
  std::vector<FrameTiming> frames;
  std::vector<int> keys;  // frame index at which each example is hit exactly, in input order
};

// `num_frames` frames over `num_examples` examples. `key_times` (optional, strictly increasing,
// first 0 and last 1) places the examples in normalized time; empty = evenly spaced. Weights
// are piecewise linear between neighbouring keys; each key time is snapped to its nearest frame.
absl::StatusOr<Schedule> MakeSchedule(int num_examples, int num_frames,
                                      const std::vector<double>& key_times = {});

}  // namespace inbetween::solver
