// Parameters: ranges name the field, request values override session values, defaults apply.
#include "server/parameters.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace inbetween::server {
namespace {

using ::testing::HasSubstr;
namespace v1 = ::inbetween::v1;

TEST(ParametersTest, DefaultsArePlanned) {
  absl::StatusOr<InbetweenPlan> plan = ToInbetweenPlan(v1::InbetweenParameters(), "parameters");
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->frames, 24);
  EXPECT_EQ(plan->options.method, solver::InterpMethod::kZhu17);
  EXPECT_DOUBLE_EQ(plan->options.tau, 0.1);
  EXPECT_DOUBLE_EQ(plan->options.h, 1.0 / 24);
  EXPECT_EQ(plan->options.max_iterations, 20);
}

TEST(ParametersTest, RequestOverridesSession) {
  v1::InbetweenParameters session;
  session.set_frames(10);
  session.set_method(v1::METHOD_LINEAR);
  session.set_tau(0.5);
  v1::InbetweenParameters request;
  request.set_frames(30);
  request.set_tau(0.0);  // explicitly set to zero: presence counts, not the value
  absl::StatusOr<InbetweenPlan> plan =
      ToInbetweenPlan(MergeInbetween(session, request), "parameters");
  ASSERT_TRUE(plan.ok()) << plan.status();
  EXPECT_EQ(plan->frames, 30);
  EXPECT_EQ(plan->options.method, solver::InterpMethod::kLinear);
  EXPECT_DOUBLE_EQ(plan->options.tau, 0.0);
}

TEST(ParametersTest, OutOfRangeNamesTheField) {
  v1::InbetweenParameters p;
  p.set_alpha(1.5);
  absl::Status s = ValidateInbetween(p, "parameters");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("parameters.alpha"));

  p.Clear();
  p.set_rho(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ValidateInbetween(p, "parameters").code(), absl::StatusCode::kInvalidArgument);

  p.Clear();
  p.set_frames(kMaxFrames + 1);
  s = ValidateInbetween(p, "parameters");
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(std::string(s.message()), HasSubstr("parameters.frames"));

  v1::MeshingParameters m;
  m.set_boundary_vertices(3);
  EXPECT_THAT(std::string(ValidateMeshing(m, "meshing").message()),
              HasSubstr("meshing.boundary_vertices"));
}

TEST(ParametersTest, CornerMatchingIsCheckedAndReachesTheBuilder) {
  using CornerMatching = solver::MultimeshOptions::CornerMatching;
  v1::MeshingParameters m;
  EXPECT_TRUE(ValidateMeshing(m, "meshing").ok());
  EXPECT_EQ(ToMultimeshOptions(m).corner_matching, CornerMatching::kWhenArcLengthFails);
  m.set_corner_matching(v1::CORNER_MATCHING_WHEN_ARC_LENGTH_FAILS);
  EXPECT_EQ(ToMultimeshOptions(m).corner_matching, CornerMatching::kWhenArcLengthFails);
  m.set_corner_matching(v1::CORNER_MATCHING_NEVER);
  EXPECT_TRUE(ValidateMeshing(m, "meshing").ok());
  EXPECT_EQ(ToMultimeshOptions(m).corner_matching, CornerMatching::kNever);
  m.set_corner_matching(v1::CORNER_MATCHING_ALWAYS);
  EXPECT_EQ(ToMultimeshOptions(m).corner_matching, CornerMatching::kAlways);
  // An enum value this server does not know (a newer client's) is refused, naming the field.
  m.set_corner_matching(static_cast<v1::CornerMatching>(17));
  const absl::Status s = ValidateMeshing(m, "meshing");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("meshing.corner_matching = 17"));
}

TEST(ParametersTest, BoundaryToleranceAndAlignmentAreCheckedAndReachTheBuilder) {
  using Correspondence = solver::MultimeshOptions::Correspondence;
  v1::MeshingParameters m;
  // Unset: the solver's defaults (0.1% of the diagonal, the feature alignment).
  EXPECT_DOUBLE_EQ(ToMultimeshOptions(m).boundary_tolerance,
                   solver::MultimeshOptions().boundary_tolerance);
  EXPECT_EQ(ToMultimeshOptions(m).correspondence, Correspondence::kFeatures);
  m.set_boundary_tolerance(0.0);  // the even sampling alone
  ASSERT_TRUE(ValidateMeshing(m, "meshing").ok());
  EXPECT_DOUBLE_EQ(ToMultimeshOptions(m).boundary_tolerance, 0.0);
  m.set_boundary_tolerance(5e-4);
  ASSERT_TRUE(ValidateMeshing(m, "meshing").ok());
  EXPECT_DOUBLE_EQ(ToMultimeshOptions(m).boundary_tolerance, 5e-4);
  m.set_boundary_tolerance(0.5);
  EXPECT_THAT(std::string(ValidateMeshing(m, "meshing").message()),
              HasSubstr("meshing.boundary_tolerance"));
  m.set_boundary_tolerance(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ValidateMeshing(m, "meshing").code(), absl::StatusCode::kInvalidArgument);
  m.clear_boundary_tolerance();
  m.set_boundary_alignment(v1::BOUNDARY_ALIGNMENT_ARC_LENGTH);
  ASSERT_TRUE(ValidateMeshing(m, "meshing").ok());
  EXPECT_EQ(ToMultimeshOptions(m).correspondence, Correspondence::kArcLength);
  m.set_boundary_alignment(v1::BOUNDARY_ALIGNMENT_FEATURES);
  EXPECT_EQ(ToMultimeshOptions(m).correspondence, Correspondence::kFeatures);
  m.set_boundary_alignment(static_cast<v1::BoundaryAlignment>(9));
  EXPECT_THAT(std::string(ValidateMeshing(m, "meshing").message()),
              HasSubstr("meshing.boundary_alignment = 9"));
}

TEST(ParametersTest, OutlineCornerDegreesIsCheckedAndReachesTheOptimizer) {
  v1::ComeshParameters c;
  EXPECT_TRUE(ToComeshOptions(c).slide_outline);  // unset: the solver's default, 25 degrees
  EXPECT_DOUBLE_EQ(ToComeshOptions(c).outline_corner_degrees, 25.0);
  c.set_outline_corner_degrees(0.0);  // off: straight stretches only
  ASSERT_TRUE(ValidateComesh(c, "comesh").ok());
  EXPECT_FALSE(ToComeshOptions(c).slide_outline);
  c.set_outline_corner_degrees(30.0);
  ASSERT_TRUE(ValidateComesh(c, "comesh").ok());
  EXPECT_TRUE(ToComeshOptions(c).slide_outline);
  EXPECT_DOUBLE_EQ(ToComeshOptions(c).outline_corner_degrees, 30.0);
  c.set_outline_corner_degrees(181.0);
  const absl::Status s = ValidateComesh(c, "comesh");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("comesh.outline_corner_degrees = 181"));
  c.set_outline_corner_degrees(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ValidateComesh(c, "comesh").code(), absl::StatusCode::kInvalidArgument);
}

TEST(ParametersTest, SlideWindowIsCheckedAndReachesTheOptimizer) {
  v1::ComeshParameters c;
  EXPECT_EQ(ToComeshOptions(c).slide_window, 0.0);  // unset: unbounded
  c.set_slide_window(0.15);
  ASSERT_TRUE(ValidateComesh(c, "comesh").ok());
  EXPECT_DOUBLE_EQ(ToComeshOptions(c).slide_window, 0.15);
  c.set_slide_window(-1.0);
  const absl::Status s = ValidateComesh(c, "comesh");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("comesh.slide_window = -1"));
  c.set_slide_window(std::numeric_limits<double>::infinity());
  EXPECT_EQ(ValidateComesh(c, "comesh").code(), absl::StatusCode::kInvalidArgument);
}

TEST(ParametersTest, MinQualityIsCheckedAndReachesTheOptimizer) {
  v1::ComeshParameters c;
  EXPECT_DOUBLE_EQ(ToComeshOptions(c).min_quality, 0.02);  // unset: the solver's default
  c.set_min_quality(0.0);                                    // off
  ASSERT_TRUE(ValidateComesh(c, "comesh").ok());
  EXPECT_EQ(ToComeshOptions(c).min_quality, 0.0);
  c.set_min_quality(0.1);
  ASSERT_TRUE(ValidateComesh(c, "comesh").ok());
  EXPECT_DOUBLE_EQ(ToComeshOptions(c).min_quality, 0.1);
  for (double bad : {1.0, -0.1, std::numeric_limits<double>::quiet_NaN()}) {
    c.set_min_quality(bad);
    const absl::Status s = ValidateComesh(c, "comesh");
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_THAT(std::string(s.message()), HasSubstr("comesh.min_quality = ")) << bad;
  }
}

TEST(ParametersTest, TimingCurvesMapOntoTheSolver) {
  v1::InbetweenParameters p;
  absl::StatusOr<solver::TimingOptions> t = ToTimingOptions(p, 3, "parameters");
  ASSERT_TRUE(t.ok()) << t.status();
  EXPECT_EQ(t->curve, solver::TimingCurve::kPiecewiseLinear);
  EXPECT_TRUE(t->easing.empty());

  p.set_timing(v1::TIMING_CURVE_CATMULL_ROM);
  p.add_ease(0.5);  // ignored by curves other than EASE_IN_OUT
  t = ToTimingOptions(p, 3, "parameters");
  ASSERT_TRUE(t.ok()) << t.status();
  EXPECT_EQ(t->curve, solver::TimingCurve::kCatmullRom);
  EXPECT_TRUE(t->easing.empty());

  p.set_timing(v1::TIMING_CURVE_EASE_IN_OUT);
  p.add_ease(0.25);
  t = ToTimingOptions(p, 3, "parameters");
  ASSERT_TRUE(t.ok()) << t.status();
  EXPECT_EQ(t->easing, (std::vector<solver::Easing>(2, solver::Easing::kEaseInOut)));
  EXPECT_EQ(t->ease_amount, (std::vector<double>{0.5, 0.25}));

  absl::StatusOr<solver::TimingOptions> wrong = ToTimingOptions(p, 4, "parameters");
  EXPECT_EQ(wrong.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(wrong.status().message()), HasSubstr("parameters.ease has 2 values"));
}

TEST(ParametersTest, KeyTimesAreRangeCheckedAndMerged) {
  v1::InbetweenParameters p;
  p.add_key_times(0.0);
  p.add_key_times(1.5);
  absl::Status s = ValidateInbetween(p, "parameters");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr("parameters.key_times[1]"));

  v1::InbetweenParameters session;
  session.add_key_times(0.0);
  session.add_key_times(1.0);
  v1::InbetweenParameters request;
  EXPECT_EQ(MergeInbetween(session, request).key_times_size(), 2);
  request.add_key_times(0.0);
  request.add_key_times(0.3);
  request.add_key_times(1.0);
  EXPECT_EQ(MergeInbetween(session, request).key_times_size(), 3);
}

// A session of `n` drawings, with key_time on the first `timed` of them (times i / (n - 1)).
v1::Session SessionOfDrawings(int n, int timed) {
  v1::Session session;
  for (int i = 0; i < n; ++i) {
    v1::Drawing* drawing = session.add_drawings();
    if (i < timed) drawing->set_key_time(static_cast<double>(i) / (n - 1));
  }
  return session;
}

TEST(ParametersTest, FramesAreScheduledFromTheKeyTimesTheRequestOrTheDrawingsGive) {
  v1::InbetweenParameters p;
  // Evenly spaced: 3 drawings over 9 frames hit frames 0, 4 and 8.
  absl::StatusOr<solver::Schedule> even = ScheduleFrames(p, SessionOfDrawings(3, 0), 9, 0, 100);
  ASSERT_TRUE(even.ok()) << even.status();
  EXPECT_EQ(even->keys, (std::vector<int>{0, 4, 8}));
  EXPECT_EQ(even->frames.size(), 9u);
  // The drawings' key times when every drawing has one.
  v1::Session session = SessionOfDrawings(3, 3);
  session.mutable_drawings(1)->set_key_time(0.25);
  absl::StatusOr<solver::Schedule> drawn = ScheduleFrames(p, session, 9, 0, 100);
  ASSERT_TRUE(drawn.ok()) << drawn.status();
  EXPECT_EQ(drawn->keys, (std::vector<int>{0, 2, 8}));
  // The request's key times over the drawings'.
  p.add_key_times(0.0);
  p.add_key_times(0.75);
  p.add_key_times(1.0);
  absl::StatusOr<solver::Schedule> asked = ScheduleFrames(p, session, 9, 0, 100);
  ASSERT_TRUE(asked.ok()) << asked.status();
  EXPECT_EQ(asked->keys, (std::vector<int>{0, 6, 8}));
}

TEST(ParametersTest, FrameSchedulesThatCannotBeMadeNameTheReason) {
  const v1::InbetweenParameters p;
  auto error = [](const absl::StatusOr<solver::Schedule>& s) {
    return std::make_pair(s.status().code(), std::string(s.status().message()));
  };
  auto [code, message] = error(ScheduleFrames(p, SessionOfDrawings(3, 0), 101, 0, 100));
  EXPECT_EQ(code, absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(message, HasSubstr("--max-frames"));
  std::tie(code, message) = error(ScheduleFrames(p, SessionOfDrawings(3, 0), 2, 0, 100));
  EXPECT_EQ(code, absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(message, HasSubstr("fewer than the 3 drawings"));
  std::tie(code, message) = error(ScheduleFrames(p, SessionOfDrawings(3, 0), 9, 9, 100));
  EXPECT_EQ(code, absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(message, HasSubstr("start_frame = 9"));
  std::tie(code, message) = error(ScheduleFrames(p, SessionOfDrawings(3, 2), 9, 0, 100));
  EXPECT_EQ(code, absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(message, HasSubstr("key_time is set on 2 of 3 drawings"));
  v1::Session session = SessionOfDrawings(3, 3);
  session.mutable_drawings(1)->set_key_time(0.01);  // snaps onto the first key's frame
  std::tie(code, message) = error(ScheduleFrames(p, session, 4, 0, 100));
  EXPECT_NE(code, absl::StatusCode::kOk);
  EXPECT_THAT(message, HasSubstr("drawings' key_time: "));
}

}  // namespace
}  // namespace inbetween::server
