// Frame timing: which example weights each output frame uses, and where the keys land.
// Weights always blend the two neighbouring keys linearly, w = (1 - s) e_i + s e_{i+1}, so they
// stay non-negative (kZhu17's energy is a convex combination); the timing curve shapes the
// progress u(f) = i + s through the keys as a function of the frame f: per segment a cubic
// Hermite u with u = i at key i's frame, whose end slopes are set by the curve (TimingOptions).
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

// How progress moves through the keys.
enum class TimingCurve {
  // Constant speed between neighbouring keys (the speed jumps at a key whose neighbours are at
  // different distances in time): exactly MakeSchedule above.
  kPiecewiseLinear,
  // Catmull-Rom through the points (key frame, key index): the speed is continuous through every
  // interior key (slope 2 / (frame_{i+1} - frame_{i-1})), ends at constant speed. Monotone (each
  // normalized end slope is < 2 <= 3, Fritsch-Carlson), so progress never goes backwards. With
  // evenly spaced keys it equals kPiecewiseLinear.
  kCatmullRom,
};

// Per segment (between key i and key i+1) easing on top of the curve: kEaseIn starts the segment
// at rest (slope 0 at key i), kEaseOut arrives at rest, kEaseInOut both (smoothstep when the
// curve is piecewise linear); kNone keeps the curve's slopes.
enum class Easing { kNone, kEaseIn, kEaseOut, kEaseInOut };

struct TimingOptions {
  TimingCurve curve = TimingCurve::kPiecewiseLinear;
  // Empty = kNone everywhere, else one per segment (num_examples - 1 values).
  std::vector<Easing> easing;
  // How much of the easing to apply, per segment in [0, 1]: the speed at an eased end is the
  // curve's speed times (1 - amount), so 1 = at rest and 0 = no easing. Empty = 1 everywhere,
  // else one per segment. Progress stays monotone for every amount (end slopes only shrink).
  std::vector<double> ease_amount;
};

// MakeSchedule with a timing curve; keys are hit exactly (weights e_i at frame keys[i]) for every
// curve. TimingOptions{} gives bit-identical results to MakeSchedule above.
absl::StatusOr<Schedule> MakeSchedule(int num_examples, int num_frames,
                                      const std::vector<double>& key_times,
                                      const TimingOptions& timing);

// Progress at `frame` in [key_frames.front(), key_frames.back()] for strictly increasing
// `key_frames` (frame numbers of the keys, may be fractional): a value in [0, n - 1], i exactly at
// key_frames[i]. Exposed for tests and for UIs that plot the curve.
double TimingProgress(const std::vector<double>& key_frames, const TimingOptions& timing,
                      double frame);

}  // namespace inbetween::solver
