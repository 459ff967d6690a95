// MakeSchedule: piecewise-linear weights, keys hit exactly, errors name the bad parameter.
#include "solver/interp/timing.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace inbetween::solver
