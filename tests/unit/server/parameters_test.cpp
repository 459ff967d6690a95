// Parameters: ranges name the field, request values override session values, defaults apply.
#include "server/parameters.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

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

TEST(ParametersTest, MissingFeaturesAreUnimplemented) {
  v1::InbetweenParameters p;
  p.set_timing(v1::TIMING_CURVE_CATMULL_ROM);
  EXPECT_EQ(ToInbetweenPlan(p, "parameters").status().code(), absl::StatusCode::kUnimplemented);
}

}  // namespace
}  // namespace inbetween::server
