// Tests ApplyInbetweenOverrides (client/commands.cpp): command-line inbetween parameters land in
// InbetweenParameters, win over the project file, and bad values are refused naming the flag;
// likewise the import flags ResolveProject applies.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <utility>

#include "client/commands.h"

namespace inbetween::client {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

Project ThreeDrawings() {
  Project p;
  for (const char* f : {"a.svg", "b.svg", "c.svg"}) p.drawings.push_back({.file = f});
  return p;
}

TEST(InbetweenOverridesTest, EveryFlagReachesTheParameters) {
  Project p = ThreeDrawings();
  InbetweenOverrides o;
  o.frames = 30;
  o.method = "alexa";
  o.timing = "catmull-rom";
  o.lambda = 2, o.tau = 0.25, o.alpha = 0.75, o.epsilon = 0.5, o.rho = 3, o.timestep = 0.05;
  o.max_iterations = 7;
  o.key_times = {0, 0.25, 1};
  ASSERT_TRUE(ApplyInbetweenOverrides(o, &p).ok());
  const v1::InbetweenParameters& q = p.parameters.inbetween();
  EXPECT_EQ(q.frames(), 30u);
  EXPECT_EQ(q.method(), v1::METHOD_ALEXA);
  EXPECT_EQ(q.timing(), v1::TIMING_CURVE_CATMULL_ROM);
  EXPECT_DOUBLE_EQ(q.lambda(), 2);
  EXPECT_DOUBLE_EQ(q.tau(), 0.25);
  EXPECT_DOUBLE_EQ(q.alpha(), 0.75);
  EXPECT_DOUBLE_EQ(q.epsilon(), 0.5);
  EXPECT_DOUBLE_EQ(q.rho(), 3);
  EXPECT_DOUBLE_EQ(q.timestep(), 0.05);
  EXPECT_EQ(q.max_iterations(), 7u);
  EXPECT_THAT(q.key_times(), ElementsAre(0, 0.25, 1));
  EXPECT_EQ(p.drawings[1].key_time, 0.25);  // also on the drawing, which servers read today
}

TEST(InbetweenOverridesTest, UnsetFlagsKeepTheProjectValues) {
  Project p = ThreeDrawings();
  p.parameters.mutable_inbetween()->set_tau(0.3);
  p.parameters.mutable_inbetween()->set_timing(v1::TIMING_CURVE_EASE_IN_OUT);
  p.drawings[0].key_time = 0, p.drawings[1].key_time = 0.6, p.drawings[2].key_time = 1;
  InbetweenOverrides o;
  o.alpha = 0.1;
  ASSERT_TRUE(ApplyInbetweenOverrides(o, &p).ok());
  const v1::InbetweenParameters& q = p.parameters.inbetween();
  EXPECT_DOUBLE_EQ(q.tau(), 0.3);
  EXPECT_DOUBLE_EQ(q.alpha(), 0.1);
  EXPECT_FALSE(q.has_lambda());
  EXPECT_EQ(q.timing(), v1::TIMING_CURVE_EASE_IN_OUT);
  EXPECT_THAT(q.key_times(), ElementsAre(0, 0.6, 1));  // from the drawings
}

TEST(InbetweenOverridesTest, FlagsWinOverTheProject) {
  Project p = ThreeDrawings();
  p.parameters.mutable_inbetween()->set_tau(0.3);
  p.drawings[0].key_time = 0, p.drawings[1].key_time = 0.6, p.drawings[2].key_time = 1;
  InbetweenOverrides o;
  o.tau = 0.05;
  o.key_times = {0, 0.1, 1};
  ASSERT_TRUE(ApplyInbetweenOverrides(o, &p).ok());
  EXPECT_DOUBLE_EQ(p.parameters.inbetween().tau(), 0.05);
  EXPECT_THAT(p.parameters.inbetween().key_times(), ElementsAre(0, 0.1, 1));
  EXPECT_EQ(p.drawings[1].key_time, 0.1);
}

TEST(InbetweenOverridesTest, OneEaseAmountAppliesToEverySegmentAndImpliesEaseInOut) {
  Project p = ThreeDrawings();
  InbetweenOverrides o;
  o.ease = {0.4};
  ASSERT_TRUE(ApplyInbetweenOverrides(o, &p).ok());
  EXPECT_EQ(p.parameters.inbetween().timing(), v1::TIMING_CURVE_EASE_IN_OUT);
  EXPECT_THAT(p.parameters.inbetween().ease(), ElementsAre(0.4, 0.4));
  o.ease = {0.1, 0.9};
  ASSERT_TRUE(ApplyInbetweenOverrides(o, &p).ok());
  EXPECT_THAT(p.parameters.inbetween().ease(), ElementsAre(0.1, 0.9));
}

struct BadFlag {
  const char* name;
  InbetweenOverrides overrides;
  const char* message;
};

class InbetweenOverridesErrorTest : public ::testing::TestWithParam<BadFlag> {};

TEST_P(InbetweenOverridesErrorTest, NamesTheFlag) {
  Project p = ThreeDrawings();
  absl::Status s = ApplyInbetweenOverrides(GetParam().overrides, &p);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(s.message()), HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Flags, InbetweenOverridesErrorTest,
    ::testing::Values(
        BadFlag{"timing", {.timing = "bouncy"}, "--timing: unknown timing curve 'bouncy'"},
        BadFlag{"ease_range", {.ease = {1.5}}, "--ease: amount 1.5 is not in [0, 1]"},
        BadFlag{"ease_count", {.ease = {0.1, 0.2, 0.3}}, "one per segment between keys (2)"},
        BadFlag{"ease_linear", {.timing = "linear", .ease = {0.5}}, "--ease: applies to"},
        BadFlag{"key_count", {.key_times = {0, 1}}, "--key-times: needs one time per drawing (3)"},
        BadFlag{"key_first", {.key_times = {0.1, 0.5, 1}}, "first time must be 0"},
        BadFlag{"key_order", {.key_times = {0, 0.7, 0.5}}, "increase strictly"},
        BadFlag{"key_equal", {.key_times = {0, 1, 1}}, "increase strictly"},
        BadFlag{"alpha", {.alpha = 2}, "--alpha: value 2 is not in [0, 1]"},
        BadFlag{"tau", {.tau = -1}, "--tau: value -1"},
        BadFlag{"rho", {.rho = 0}, "--rho: value 0 is not in (0,"},
        BadFlag{"timestep", {.timestep = 11}, "--timestep"},
        BadFlag{"iterations", {.max_iterations = 0}, "--max-iterations"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(ImportFlagsTest, FlagsWinOverTheProjectAndAreChecked) {
  Inputs inputs{.drawings = {"a.svg", "b.svg"}};
  absl::StatusOr<Project> p = ResolveProject(inputs);
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_FALSE(p->import_settings.gap_tolerance.has_value());  // the server's default
  EXPECT_FALSE(p->import_settings.min_area_fraction.has_value());

  inputs.import_flags = {.gap_tolerance = 0.0, .min_area_fraction = 0.1};
  p = ResolveProject(inputs);
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(p->import_settings.gap_tolerance, 0.0);
  EXPECT_EQ(p->import_settings.min_area_fraction, 0.1);

  for (auto [flags, message] :
       {std::pair{ImportSettings{.gap_tolerance = 0.5}, "--gap-tolerance: value 0.5 is not in"},
        {ImportSettings{.gap_tolerance = -0.001}, "--gap-tolerance: value -0.001"},
        {ImportSettings{.min_area_fraction = std::numeric_limits<double>::quiet_NaN()},
         "--min-area-fraction: value nan"}}) {
    inputs.import_flags = flags;
    absl::Status s = ResolveProject(inputs).status();
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(std::string(s.message()), HasSubstr(message));
  }
}

}  // namespace
}  // namespace inbetween::client
