// Every example under examples/ builds: each directory holding a project.json (docs/
// project-file.md) has its drawings imported with ImportSvg (cuts, openings and marks from the
// SVG convention or the project file) and meshed with BuildMultimesh; the multimesh must
// validate with no inverted triangle in any shape. Prints the meshing time per example.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace inbetween::solver {
namespace {

class ExamplesBuildTest : public ::testing::TestWithParam<std::string> {};

// The multimesh, its boundary loops and cohesive edges validate, it has one shape per drawing,
// and no triangle is inverted in any shape.
void ExpectValid(const Multimesh& mesh, size_t drawings) {
  EXPECT_TRUE(ValidateMultimesh(mesh).ok()) << ValidateMultimesh(mesh);
  EXPECT_TRUE(ValidateBoundaryLoops(mesh).ok()) << ValidateBoundaryLoops(mesh);
  EXPECT_TRUE(ValidateCohesiveEdges(mesh).ok()) << ValidateCohesiveEdges(mesh);
  ASSERT_EQ(mesh.num_shapes(), static_cast<int>(drawings));
  for (int s = 0; s < mesh.num_shapes(); ++s) {
    EXPECT_EQ(CountInverted(mesh.triangles, mesh.shapes[s]), 0) << "drawing " << s + 1;
  }
}

TEST_P(ExamplesBuildTest, BuildsAValidMultimesh) {
  absl::StatusOr<example_projects::Example> example = example_projects::Load(GetParam());
  ASSERT_TRUE(example.ok()) << example.status();
  for (const std::string& file : example->files) {
    const std::string text = example_projects::ReadFile(
        std::filesystem::path(INBETWEEN_SOURCE_DIR) / "examples" / GetParam() / file);
    EXPECT_LT(text.size(), 5000u) << file << ": keep example drawings small";
  }
  const std::vector<Drawing>& drawings = example->drawings;
  const MultimeshOptions& options = example->options;
  MultimeshReport report;
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, options, nullptr, nullptr, &report);
  ASSERT_TRUE(mesh.ok()) << GetParam() << ": " << mesh.status();
  ExpectValid(*mesh, drawings.size());
  std::printf("[ example  ] %-32s %2zu drawings %5d vertices %5d triangles %3d cohesive %7.1f ms\n",
              GetParam().c_str(), drawings.size(), report.vertices, report.triangles,
              report.cohesive_edges, 1e3 * report.seconds);
  RecordProperty("vertices", report.vertices);
  RecordProperty("ms", static_cast<int>(1e3 * report.seconds));
}

// MeshingParameters.corner_matching = ALWAYS (the API's and project file's choice): corners
// matched to corners from the start, on every loop where the drawings' corners match, must also
// give a valid multimesh (prints how many loops matched corners).
TEST_P(ExamplesBuildTest, BuildsWithCornersMatchedFromTheStart) {
  absl::StatusOr<example_projects::Example> example = example_projects::Load(GetParam());
  ASSERT_TRUE(example.ok()) << example.status();
  MultimeshOptions options = example->options;
  options.corner_matching = MultimeshOptions::CornerMatching::kAlways;
  MultimeshReport report;
  absl::StatusOr<Multimesh> mesh =
      BuildMultimesh(example->drawings, options, nullptr, nullptr, &report);
  ASSERT_TRUE(mesh.ok()) << GetParam() << ": " << mesh.status();
  EXPECT_LE(report.corner_matched_loops, report.boundary_loops);
  std::printf("[ corners  ] %-32s %d of %d loops corner-matched\n", GetParam().c_str(),
              report.corner_matched_loops, report.boundary_loops);
  ExpectValid(*mesh, example->drawings.size());
}

INSTANTIATE_TEST_SUITE_P(Examples, ExamplesBuildTest, ::testing::ValuesIn(example_projects::List()),
                         example_projects::TestName<::testing::TestParamInfo<std::string>>);

}  // namespace
}  // namespace inbetween::solver
