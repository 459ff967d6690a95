// Cuts of several drawings along the same stretch of boundary (boundary_correspondence.cpp,
// "Cuts of several drawings ..."): slits that end at the same places relative to the marks
// build; slits whose ends differ from drawing to drawing are refused with what to do, instead of
// the breakpoint mirroring running for minutes and exploding the mesh (a 16-key walk did so).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

// A 10 x 10 square with a slit from (x, 0) on its bottom edge up to (x + lean, depth). With
// `rounded`, each corner is a quarter circle of radius 1 in 100 steps (0.9 degrees: no vertex
// of the outline turns by a degree; the only corners are the slit's mouth and tip).
Drawing SlitSquare(double x, double lean, double depth, bool rounded = false) {
  Drawing d;
  if (!rounded) {
    d.outlines.push_back({{{0, 0}, {10, 0}, {10, 10}, {0, 10}}});
  } else {
    Outline o;
    const Point centres[4] = {{9, 1}, {9, 9}, {1, 9}, {1, 1}};
    for (int c = 0; c < 4; ++c) {
      for (int k = 0; k <= 100; ++k) {
        const double angle = (c - 1) * std::numbers::pi / 2 + k * std::numbers::pi / 200;
        o.points.push_back(centres[c] + Point(std::cos(angle), std::sin(angle)));
      }
    }
    d.outlines.push_back(o);
  }
  d.cuts.push_back({{x, 0}, {x + lean, depth}});
  return d;
}

TEST(BuildMultimeshCutEndsTest, SlitsEndingAtTheSamePlacesBuild) {
  // The same slit in three drawings, the drawings moved: every mirror agrees.
  std::vector<Drawing> drawings;
  for (int k = 0; k < 3; ++k) {
    Drawing d = SlitSquare(4, 1, 6);
    for (Point& p : d.outlines[0].points) p += Point(20.0 * k, 0);
    for (Point& p : d.cuts[0]) p += Point(20.0 * k, 0);
    drawings.push_back(d);
  }
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, {});
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_TRUE(ValidateMultimesh(*mesh).ok());
}

TEST(BuildMultimeshCutEndsTest, SlitsEndingAtDifferentPlacesAreRefusedWithWhatToDo) {
  // Slits at different places and of different depths in four drawings, nothing marked, matched
  // by arc length alone: each drawing's mirror maps the others' breakpoints somewhere new.
  const std::vector<Drawing> drawings = {
      SlitSquare(3.1, 0.3, 5.3, true), SlitSquare(4.7, -0.4, 6.9, true),
      SlitSquare(5.9, 0.8, 4.1, true), SlitSquare(3.8, 0.1, 7.7, true)};
  MultimeshOptions arc_length;
  arc_length.corner_matching = MultimeshOptions::CornerMatching::kNever;
  arc_length.correspondence = MultimeshOptions::Correspondence::kArcLength;
  const absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, arc_length);
  ASSERT_FALSE(mesh.ok()) << mesh->shapes[0].size() << " vertices";
  EXPECT_EQ(mesh.status().code(), absl::StatusCode::kInvalidArgument) << mesh.status();
  EXPECT_THAT(mesh.status().message(), HasSubstr("cuts or openings of drawings 1, 2, 3, 4"));
  EXPECT_THAT(mesh.status().message(), HasSubstr("pin both ends of every cut"));
  // By default the second attempt matches the slits' mouths and tips, the loop's only corners,
  // corner to corner (the slit mouth is not the loop's start, so this needs the matched corners'
  // arcs measured from the first matched corner, not from the loop's start), and builds.
  MultimeshReport report;
  MultimeshOptions fallback;
  fallback.correspondence = MultimeshOptions::Correspondence::kArcLength;
  const absl::StatusOr<Multimesh> matched =
      BuildMultimesh(drawings, fallback, nullptr, nullptr, &report);
  ASSERT_TRUE(matched.ok()) << matched.status();
  EXPECT_TRUE(ValidateMultimesh(*matched).ok()) << ValidateMultimesh(*matched);
  EXPECT_EQ(report.corner_matched_loops, 1);
  // The feature alignment (the default) pairs the mouths and tips at the first attempt.
  const absl::StatusOr<Multimesh> aligned = BuildMultimesh(drawings, {});
  ASSERT_TRUE(aligned.ok()) << aligned.status();
  EXPECT_TRUE(ValidateMultimesh(*aligned).ok()) << ValidateMultimesh(*aligned);
}

// The same slits in squares: matched by arc length they are refused like the rounded ones
// above; the second attempt matches the four corners corner to corner, which pins every
// drawing's parameterization, and the mirrored slit ends stay few enough to build.
TEST(BuildMultimeshCutEndsTest, SlitsInSquaresBuildOnceTheCornersAreMatched) {
  const std::vector<Drawing> drawings = {SlitSquare(3.1, 0.3, 5.3), SlitSquare(4.7, -0.4, 6.9),
                                         SlitSquare(5.9, 0.8, 4.1), SlitSquare(3.8, 0.1, 7.7)};
  MultimeshOptions arc_length;
  arc_length.corner_matching = MultimeshOptions::CornerMatching::kNever;
  arc_length.correspondence = MultimeshOptions::Correspondence::kArcLength;
  const absl::StatusOr<Multimesh> refused = BuildMultimesh(drawings, arc_length);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.status().message(), HasSubstr("pin both ends of every cut"));
  std::vector<std::string> details;
  std::vector<double> fractions;
  MultimeshOptions fallback;
  fallback.correspondence = MultimeshOptions::Correspondence::kArcLength;
  const absl::StatusOr<Multimesh> mesh =
      BuildMultimesh(drawings, fallback, nullptr,
                     [&](const std::string&, double fraction, const std::string& detail) {
                       details.push_back(detail);
                       fractions.push_back(fraction);
                     });
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_TRUE(ValidateMultimesh(*mesh).ok()) << ValidateMultimesh(*mesh);
  EXPECT_FALSE(mesh->cohesive_edges.empty());
  // The progress says why the build started again, and never goes back.
  EXPECT_THAT(details, ::testing::Contains(HasSubstr("again with corners matched to corners")));
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
}

}  // namespace
}  // namespace inbetween::solver
