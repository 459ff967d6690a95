// Frame timing (see timing.h): piecewise-linear example weights between neighbouring keys.
// The weights are linear in the frame index between the *snapped* key frames, so that the key
// frame of example i has weights exactly e_i (1.0 and 0.0, no rounding) and the solver returns
// that example exactly.
#include "solver/interp/timing.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {

absl::StatusOr<Schedule> MakeSchedule(int num_examples, int num_frames,
                                      const std::vector<double>& key_times) {
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
      const double u = static_cast<double>(f - k0) / static_cast<double>(k1 - k0);
      frame.weights[segment] = 1.0 - u;
      frame.weights[segment + 1] = u;
    }
  }
  return schedule;
}

}  // namespace inbetween::solver
