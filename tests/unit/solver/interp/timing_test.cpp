// MakeSchedule: piecewise-linear weights, keys hit exactly, errors name the bad parameter; timing
// curves (Catmull-Rom progress, per-segment easing) keep every property and add smoothness.
#include "solver/interp/timing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace inbetween::solver {
namespace {

void ExpectValid(const Schedule& s, int num_examples, int num_frames) {
  ASSERT_EQ(static_cast<int>(s.frames.size()), num_frames);
  ASSERT_EQ(static_cast<int>(s.keys.size()), num_examples);
  EXPECT_EQ(s.keys.front(), 0);
  EXPECT_EQ(s.keys.back(), num_frames - 1);
  for (int f = 0; f < num_frames; ++f) {
    const FrameTiming& frame = s.frames[f];
    EXPECT_DOUBLE_EQ(frame.time, static_cast<double>(f) / (num_frames - 1));
    ASSERT_EQ(static_cast<int>(frame.weights.size()), num_examples);
    double sum = 0.0;
    int nonzero = 0;
    for (double w : frame.weights) {
      EXPECT_GE(w, 0.0);
      EXPECT_LE(w, 1.0);
      sum += w;
      nonzero += w != 0.0;
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_LE(nonzero, 2);  // only neighbouring keys blend
  }
  for (int i = 0; i < num_examples; ++i) {
    const ExampleWeights& w = s.frames[s.keys[i]].weights;
    for (int j = 0; j < num_examples; ++j) EXPECT_EQ(w[j], i == j ? 1.0 : 0.0);
    if (i > 0) EXPECT_GT(s.keys[i], s.keys[i - 1]);
  }
}

TEST(ScheduleTest, EvenlySpacedKeys) {
  for (int examples : {2, 3, 5}) {
    for (int frames : {examples, examples + 1, 24, 97}) {
      absl::StatusOr<Schedule> s = MakeSchedule(examples, frames);
      ASSERT_TRUE(s.ok()) << s.status();
      ExpectValid(*s, examples, frames);
    }
  }
  absl::StatusOr<Schedule> s = MakeSchedule(2, 5);
  ASSERT_TRUE(s.ok());
  EXPECT_DOUBLE_EQ(s->frames[1].weights[1], 0.25);
  EXPECT_DOUBLE_EQ(s->frames[2].weights[0], 0.5);
}

TEST(ScheduleTest, WeightsAreLinearBetweenKeys) {
  absl::StatusOr<Schedule> s = MakeSchedule(3, 11, {0.0, 0.2, 1.0});
  ASSERT_TRUE(s.ok()) << s.status();
  ExpectValid(*s, 3, 11);
  EXPECT_EQ(s->keys, (std::vector<int>{0, 2, 10}));
  EXPECT_DOUBLE_EQ(s->frames[1].weights[0], 0.5);
  EXPECT_DOUBLE_EQ(s->frames[1].weights[1], 0.5);
  EXPECT_DOUBLE_EQ(s->frames[6].weights[1], 0.5);
  EXPECT_DOUBLE_EQ(s->frames[6].weights[2], 0.5);
  // Second differences vanish inside each segment.
  for (int f = 3; f < 10; ++f) {
    const double d2 =
        s->frames[f - 1].weights[2] - 2 * s->frames[f].weights[2] + s->frames[f + 1].weights[2];
    EXPECT_NEAR(d2, 0.0, 1e-15);
  }
}

TEST(ScheduleTest, RejectsBadCounts) {
  absl::StatusOr<Schedule> s = MakeSchedule(1, 10);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find("num_examples"), std::string::npos);
  EXPECT_NE(s.status().message().find("1"), std::string::npos);
  s = MakeSchedule(4, 3);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find("num_frames"), std::string::npos);
  EXPECT_NE(s.status().message().find("3"), std::string::npos);
  EXPECT_FALSE(MakeSchedule(2, -1).ok());
}

TEST(ScheduleTest, RejectsBadKeyTimes) {
  EXPECT_EQ(MakeSchedule(3, 10, {0.0, 1.0}).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_FALSE(MakeSchedule(3, 10, {0.1, 0.5, 1.0}).ok());
  EXPECT_FALSE(MakeSchedule(3, 10, {0.0, 0.5, 0.9}).ok());
  EXPECT_FALSE(MakeSchedule(3, 10, {0.0, 0.7, 0.5}).ok());
  // 0.5 and 0.52 both snap to frame 2 of 5.
  absl::StatusOr<Schedule> s = MakeSchedule(4, 5, {0.0, 0.5, 0.52, 1.0});
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find("same frame"), std::string::npos) << s.status();
}

// Progress of each frame: segment index + the later key's weight.
std::vector<double> Progress(const Schedule& s) {
  std::vector<double> u;
  for (const FrameTiming& f : s.frames) {
    int i = 0;
    while (i + 1 < static_cast<int>(f.weights.size()) && f.weights[i] == 0.0) ++i;
    u.push_back(i + (i + 1 < static_cast<int>(f.weights.size()) ? f.weights[i + 1] : 0.0));
  }
  return u;
}

std::vector<TimingOptions> AllTimings(int segments) {
  std::vector<TimingOptions> all;
  for (TimingCurve curve : {TimingCurve::kPiecewiseLinear, TimingCurve::kCatmullRom}) {
    for (Easing e : {Easing::kNone, Easing::kEaseIn, Easing::kEaseOut, Easing::kEaseInOut}) {
      TimingOptions t;
      t.curve = curve;
      if (e != Easing::kNone) t.easing.assign(segments, e);
      all.push_back(t);
    }
    TimingOptions mixed;  // alternate easings per segment
    mixed.curve = curve;
    for (int i = 0; i < segments; ++i) mixed.easing.push_back(static_cast<Easing>(i % 4));
    all.push_back(mixed);
  }
  return all;
}

TEST(TimingCurveTest, EveryCurveKeepsKeysExactWeightsValidAndProgressMonotone) {
  const std::vector<std::vector<double>> key_sets = {
      {}, {0.0, 0.1, 0.7, 1.0}, {0.0, 0.45, 0.5, 0.55, 1.0}, {0.0, 0.9, 1.0}};
  for (const std::vector<double>& keys : key_sets) {
    const int examples = keys.empty() ? 4 : static_cast<int>(keys.size());
    for (const TimingOptions& t : AllTimings(examples - 1)) {
      for (int frames : {examples, 31, 120}) {
        absl::StatusOr<Schedule> s = MakeSchedule(examples, frames, keys, t);
        if (!s.ok()) continue;  // keys too close for few frames, tested elsewhere
        ExpectValid(*s, examples, frames);
        const std::vector<double> u = Progress(*s);
        for (int f = 1; f < frames; ++f) EXPECT_GE(u[f], u[f - 1]) << f;
        for (int i = 0; i < examples; ++i) EXPECT_EQ(u[s->keys[i]], i);
      }
    }
  }
}

TEST(TimingCurveTest, DefaultOptionsEqualTheLinearSchedule) {
  absl::StatusOr<Schedule> a = MakeSchedule(4, 50, {0.0, 0.2, 0.3, 1.0});
  absl::StatusOr<Schedule> b = MakeSchedule(4, 50, {0.0, 0.2, 0.3, 1.0}, TimingOptions{});
  ASSERT_TRUE(a.ok() && b.ok());
  for (size_t f = 0; f < a->frames.size(); ++f) {
    EXPECT_EQ(a->frames[f].weights, b->frames[f].weights);  // bit-identical
  }
}

TEST(TimingCurveTest, CatmullRomEqualsLinearForEvenKeysAndSmoothsUnevenOnes) {
  TimingOptions cr;
  cr.curve = TimingCurve::kCatmullRom;
  absl::StatusOr<Schedule> even_linear = MakeSchedule(3, 41);
  absl::StatusOr<Schedule> even_cr = MakeSchedule(3, 41, {}, cr);
  ASSERT_TRUE(even_linear.ok() && even_cr.ok());
  for (size_t f = 0; f < 41; ++f) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(even_linear->frames[f].weights[i], even_cr->frames[f].weights[i], 1e-12);
    }
  }
  // Uneven keys: the linear speed jumps at the middle key (1/8 vs 1/32 per frame); Catmull-Rom's
  // one-frame speeds on both sides of the key nearly agree (continuous speed).
  const std::vector<double> keys = {0.0, 0.2, 1.0};
  absl::StatusOr<Schedule> linear = MakeSchedule(3, 41, keys);
  absl::StatusOr<Schedule> smooth = MakeSchedule(3, 41, keys, cr);
  ASSERT_TRUE(linear.ok() && smooth.ok());
  const int k = linear->keys[1];
  ASSERT_EQ(k, 8);
  const std::vector<double> ul = Progress(*linear), us = Progress(*smooth);
  const double jump_linear = std::abs((ul[k + 1] - ul[k]) - (ul[k] - ul[k - 1]));
  const double jump_smooth = std::abs((us[k + 1] - us[k]) - (us[k] - us[k - 1]));
  EXPECT_NEAR(jump_linear, 1.0 / 8 - 1.0 / 32, 1e-12);
  EXPECT_LT(jump_smooth, 0.3 * jump_linear);
  // The continuous slope at the key is 2 / (40 - 0) frames.
  EXPECT_NEAR(TimingProgress({0.0, 8.0, 40.0}, cr, 8.0 + 1e-6) - 1.0, 2.0 / 40 * 1e-6, 1e-9);
  EXPECT_NEAR(1.0 - TimingProgress({0.0, 8.0, 40.0}, cr, 8.0 - 1e-6), 2.0 / 40 * 1e-6, 1e-9);
}

TEST(TimingCurveTest, EasingStartsAndEndsAtRestOnlyWhereAsked) {
  const std::vector<double> k = {0.0, 10.0, 20.0};
  TimingOptions in_out;
  in_out.easing = {Easing::kEaseInOut, Easing::kNone};
  const double d = 1e-4;
  // Eased segment: zero speed at both of its ends (second-order small steps).
  EXPECT_LT(TimingProgress(k, in_out, d), 1e-6);
  EXPECT_LT(1.0 - TimingProgress(k, in_out, 10.0 - d), 1e-6);
  EXPECT_NEAR(TimingProgress(k, in_out, 5.0), 0.5, 1e-15);  // smoothstep is symmetric
  // The plain segment keeps its constant speed.
  EXPECT_NEAR(TimingProgress(k, in_out, 10.0 + d) - 1.0, d / 10.0, 1e-12);
  TimingOptions in;
  in.easing = {Easing::kEaseIn, Easing::kEaseIn};
  EXPECT_LT(TimingProgress(k, in, 10.0 + d) - 1.0, 1e-6);          // starts at rest
  EXPECT_GT(1.0 - TimingProgress(k, in, 10.0 - d), 0.5 * d / 10);  // arrives moving
  TimingOptions out;
  out.easing = {Easing::kEaseOut, Easing::kEaseOut};
  EXPECT_GT(TimingProgress(k, out, d), 0.5 * d / 10);  // leaves moving
  EXPECT_LT(2.0 - TimingProgress(k, out, 20.0 - d), 1e-6);
}

TEST(TimingCurveTest, RejectsAnEasingListOfTheWrongLength) {
  TimingOptions t;
  t.easing = {Easing::kEaseIn};
  absl::StatusOr<Schedule> s = MakeSchedule(3, 10, {}, t);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find("easing"), std::string::npos) << s.status();
}

TEST(TimingCurveTest, EaseAmountScalesTheSpeedAtEasedEnds) {
  const std::vector<double> k = {0.0, 10.0, 20.0};
  const double d = 1e-5;
  TimingOptions half;
  half.easing = {Easing::kEaseInOut, Easing::kEaseInOut};
  half.ease_amount = {0.5, 0.0};
  // Segment 1 leaves and arrives at half the linear speed 1/10; segment 2 is not eased at all.
  EXPECT_NEAR(TimingProgress(k, half, d) / d, 0.05, 1e-4);
  EXPECT_NEAR((1.0 - TimingProgress(k, half, 10.0 - d)) / d, 0.05, 1e-4);
  for (double f : {11.0, 13.0, 17.5}) {
    EXPECT_NEAR(TimingProgress(k, half, f), 1.0 + (f - 10.0) / 10.0, 1e-12) << f;
  }
  // Full amount equals the default (at rest); progress stays monotone for every amount.
  TimingOptions rest;
  rest.easing = half.easing;
  for (double a : {0.0, 0.3, 0.7, 1.0}) {
    TimingOptions t = half;
    t.ease_amount = {a, a};
    double previous = -1.0;
    for (double f = 0.0; f <= 20.0; f += 0.25) {
      const double u = TimingProgress(k, t, f);
      EXPECT_GE(u, previous) << "amount " << a << " frame " << f;
      previous = u;
      if (a == 1.0) EXPECT_EQ(u, TimingProgress(k, rest, f));
    }
  }
  absl::StatusOr<Schedule> s = MakeSchedule(3, 21, {}, half);
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->keys, (std::vector<int>{0, 10, 20}));
}

TEST(TimingCurveTest, RejectsEaseAmountsOutOfRangeOrOfTheWrongLength) {
  TimingOptions t;
  t.ease_amount = {0.5};
  EXPECT_EQ(MakeSchedule(3, 10, {}, t).status().code(), absl::StatusCode::kInvalidArgument);
  t.ease_amount = {0.5, 1.5};
  absl::StatusOr<Schedule> s = MakeSchedule(3, 10, {}, t);
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.status().message().find("ease_amount[1] = 1.5"), std::string::npos) << s.status();
}

}  // namespace
}  // namespace inbetween::solver
