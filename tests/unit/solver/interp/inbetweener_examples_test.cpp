// Every interpolation method runs on every example under examples/ (its built multimesh): the
// inbetweener is created, hits the first key and solves the frame halfway to the second. Caught a
// shared pin across the two pieces of examples/split under alexa (singular: "factoring example
// 0's ARAP matrix ... not positive definite").
#include <gtest/gtest.h>

#include <string>

#include "solver/interp/inbetweener.h"
#include "solver/mesh/build_multimesh.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace inbetween::solver {
namespace {

class InbetweenerExamplesTest : public ::testing::TestWithParam<std::string> {};

TEST_P(InbetweenerExamplesTest, EveryMethodCreatesAndSolves) {
  absl::StatusOr<example_projects::Example> example = example_projects::Load(GetParam());
  ASSERT_TRUE(example.ok()) << example.status();
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(example->drawings, example->options);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  const int keys = mesh->num_shapes();
  for (InterpMethod method : {InterpMethod::kLinear, InterpMethod::kAlexa, InterpMethod::kZhu17}) {
    InbetweenOptions options;
    options.method = method;
    absl::StatusOr<Inbetweener> ib = Inbetweener::Create(*mesh, options);
    ASSERT_TRUE(ib.ok()) << static_cast<int>(method) << ": " << ib.status();
    ExampleWeights first(keys, 0.0), half(keys, 0.0);
    first[0] = 1.0;
    half[0] = half[1] = 0.5;
    absl::StatusOr<Frame> key = ib->Solve(first, Frame{});
    ASSERT_TRUE(key.ok()) << static_cast<int>(method) << ": " << key.status();
    double error = 0.0;
    for (int v = 0; v < mesh->num_vertices(); ++v) {
      error = std::max(error, (key->vertices[v] - mesh->shapes[0][v]).norm());
    }
    EXPECT_LT(error, 1e-6) << static_cast<int>(method);
    absl::StatusOr<Frame> mid = ib->Solve(half, *key);
    ASSERT_TRUE(mid.ok()) << static_cast<int>(method) << ": " << mid.status();
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, InbetweenerExamplesTest,
                         ::testing::ValuesIn(example_projects::List()),
                         example_projects::TestName<::testing::TestParamInfo<std::string>>);

}  // namespace
}  // namespace inbetween::solver
