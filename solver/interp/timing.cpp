// Frame timing (see timing.h): example weights linear between neighbouring keys in the progress
// u(f), which is piecewise linear or a per-segment cubic Hermite (Catmull-Rom slopes, easing).
// The weights are linear in the frame index between the *snapped* key frames, so that the key
// frame of example i has weights exactly e_i (1.0 and 0.0, no rounding) and the solver returns
// that example exactly.
#include "solver/interp/timing.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {

absl::StatusOr<Schedule> MakeSchedule(int num_examples, int num_frames,
                                      const std::vector<double>& key_times) {
  return MakeSchedule(num_examples, num_frames, key_times, TimingOptions{});
}

namespace {

// Slopes (d progress / d frame) at the ends of segment i, before easing.
std::pair<double, double> CurveSlopes(const std::vector<double>& k, TimingCurve curve, int i) {
  const double linear = 1.0 / (k[i + 1] - k[i]);
  if (curve == TimingCurve::kPiecewiseLinear) return {linear, linear};
  const int last = static_cast<int>(k.size()) - 1;
  const double m0 = i > 0 ? 2.0 / (k[i + 1] - k[i - 1]) : linear;
  const double m1 = i + 1 < last ? 2.0 / (k[i + 2] - k[i]) : linear;
  return {m0, m1};
}

}  // namespace

double TimingProgress(const std::vector<double>& key_frames, const TimingOptions& timing,
                      double frame) {
  const int n = static_cast<int>(key_frames.size());
  if (n < 2) return 0.0;
  if (frame <= key_frames.front()) return 0.0;
  if (frame >= key_frames.back()) return n - 1.0;
  int i = 0;
  while (i + 2 < n && frame >= key_frames[i + 1]) ++i;
  const double length = key_frames[i + 1] - key_frames[i];
  const double s = (frame - key_frames[i]) / length;
  auto [m0, m1] = CurveSlopes(key_frames, timing.curve, i);
  const Easing easing = timing.easing.empty() ? Easing::kNone : timing.easing[i];
  const double keep = timing.ease_amount.empty() ? 0.0 : 1.0 - timing.ease_amount[i];
  if (easing == Easing::kEaseIn || easing == Easing::kEaseInOut) m0 *= keep;
  if (easing == Easing::kEaseOut || easing == Easing::kEaseInOut) m1 *= keep;
  if (timing.curve == TimingCurve::kPiecewiseLinear && easing == Easing::kNone) return i + s;
  // Cubic Hermite from (0, 0) to (1, 1) with slopes m0, m1 in segment units.
  const double a = m0 * length, b = m1 * length;
  const double s2 = s * s, s3 = s2 * s;
  const double h = (s3 - 2.0 * s2 + s) * a + (3.0 * s2 - 2.0 * s3) + (s3 - s2) * b;
  return i + std::clamp(h, 0.0, 1.0);
}

absl::StatusOr<Schedule> MakeSchedule(int num_examples, int num_frames,
                                      const std::vector<double>& key_times,
                                      const TimingOptions& timing) {
  if (!timing.easing.empty() && static_cast<int>(timing.easing.size()) != num_examples - 1) {
    return absl::InvalidArgumentError(absl::StrCat("timing.easing has ", timing.easing.size(),
                                                   " values, expected one per segment (",
                                                   num_examples - 1, ") or none"));
  }
  if (!timing.ease_amount.empty() &&
      static_cast<int>(timing.ease_amount.size()) != num_examples - 1) {
    return absl::InvalidArgumentError(absl::StrCat("timing.ease_amount has ",
                                                   timing.ease_amount.size(),
                                                   " values, expected one per segment (",
                                                   num_examples - 1, ") or none"));
  }
  for (size_t i = 0; i < timing.ease_amount.size(); ++i) {
    const double a = timing.ease_amount[i];
    if (!(a >= 0.0 && a <= 1.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("timing.ease_amount[", i, "] = ", a, " is not in [0, 1]"));
    }
  }
  if (num_examples < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("num_examples must be at least 2, got ", num_examples));
  }
  if (num_frames < num_examples) {
    return absl::InvalidArgumentError(absl::StrCat("num_frames must be at least num_examples (",
                                                   num_examples, "), got ", num_frames));
  }
  std::vector<double> times = key_times;
  if (times.empty()) {
    times.resize(num_examples);
    for (int i = 0; i < num_examples; ++i) {
      times[i] = static_cast<double>(i) / static_cast<double>(num_examples - 1);
    }
  } else {
    if (static_cast<int>(times.size()) != num_examples) {
      return absl::InvalidArgumentError(
          absl::StrCat("key_times has ", times.size(),
                       " values, expected num_examples = ", num_examples, " (or none)"));
    }
    if (times.front() != 0.0 || times.back() != 1.0) {
      return absl::InvalidArgumentError(absl::StrCat("key_times must start at 0 and end at 1, got ",
                                                     times.front(), " ... ", times.back()));
    }
    for (int i = 1; i < num_examples; ++i) {
      if (!std::isfinite(times[i]) || !(times[i] > times[i - 1])) {
        return absl::InvalidArgumentError(
            absl::StrCat("key_times must be strictly increasing, but key_times[", i,
                         "] = ", times[i], " follows key_times[", i - 1, "] = ", times[i - 1]));
      }
    }
  }

  Schedule schedule;
  const double last = static_cast<double>(num_frames - 1);
  schedule.keys.resize(num_examples);
  for (int i = 0; i < num_examples; ++i) {
    schedule.keys[i] = static_cast<int>(std::lround(times[i] * last));
    if (i > 0 && schedule.keys[i] == schedule.keys[i - 1]) {
      return absl::InvalidArgumentError(
          absl::StrCat("key_times[", i - 1, "] = ", times[i - 1], " and key_times[", i,
                       "] = ", times[i], " both snap to the same frame ", schedule.keys[i], " of ",
                       num_frames, "; use more frames or spread the keys"));
    }
  }

  const std::vector<double> key_frames(schedule.keys.begin(), schedule.keys.end());
  schedule.frames.resize(num_frames);
  int segment = 0;  // frames in [keys[segment], keys[segment + 1]]
  for (int f = 0; f < num_frames; ++f) {
    FrameTiming& frame = schedule.frames[f];
    frame.time = static_cast<double>(f) / last;
    frame.weights.assign(num_examples, 0.0);
    while (segment + 2 < num_examples && f > schedule.keys[segment + 1]) ++segment;
    const int k0 = schedule.keys[segment];
    const int k1 = schedule.keys[segment + 1];
    if (f == k0) {
      frame.weights[segment] = 1.0;
    } else if (f == k1) {
      frame.weights[segment + 1] = 1.0;
    } else {
      double u = static_cast<double>(f - k0) / static_cast<double>(k1 - k0);
      if (timing.curve != TimingCurve::kPiecewiseLinear || !timing.easing.empty()) {
        u = TimingProgress(key_frames, timing, f) - segment;
      }
      frame.weights[segment] = 1.0 - u;
      frame.weights[segment + 1] = u;
    }
  }
  return schedule;
}

}  // namespace inbetween::solver
