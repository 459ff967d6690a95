// Drawing import robustness (tests/data/bad/): near-duplicate points are merged before the
// checks (docs/project-file.md "Geometry clean-up"), SVG limits map to RESOURCE_EXHAUSTED naming
// the flag, and degenerate input is still refused after cleaning.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "server/drawing_import.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;
using ::testing::HasSubstr;

v1::Drawing PolylineDrawing(const std::vector<std::pair<double, double>>& points) {
  v1::Drawing drawing;
  drawing.set_name("d");
  v1::TopologyElement* e = drawing.mutable_polylines()->add_elements();
  e->set_kind(v1::ELEMENT_KIND_OUTLINE);
  for (auto [x, y] : points) {
    v1::Point* p = e->mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  return drawing;
}

TEST(DrawingImportRobustnessTest, DuplicateAndRepeatedClosingPointsAreMerged) {
  // tests/data/bad/outline_duplicate_points.json: used to be "crosses itself".
  const v1::Drawing drawing = PolylineDrawing(
      {{10, 10}, {110, 10}, {110, 10}, {110, 110}, {110, 110 + 1e-12}, {10, 110}, {10, 10}});
  absl::StatusOr<ImportedDrawing> imported = ImportDrawing(drawing, {}, "drawing", 1);
  ASSERT_TRUE(imported.ok()) << imported.status();
  ASSERT_EQ(imported->parsed.outlines.size(), 1u);
  EXPECT_EQ(imported->parsed.outlines[0].points.size(), 4u);
  // The stored element is the cleaned one.
  EXPECT_EQ(imported->elements[0].polyline().points_size(), 4);
  EXPECT_EQ(imported->equivalence_class.components(), 1u);
}

TEST(DrawingImportRobustnessTest, PointsFartherThanTheToleranceAreKept) {
  const v1::Drawing drawing = PolylineDrawing({{0, 0}, {1e-3, 0}, {100, 0}, {100, 100}, {0, 100}});
  absl::StatusOr<ImportedDrawing> imported = ImportDrawing(drawing, {}, "drawing", 1);
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_EQ(imported->parsed.outlines[0].points.size(), 5u);
}

TEST(DrawingImportRobustnessTest, CleaningNeverHidesADegenerateOutline) {
  absl::Status same =
      ImportDrawing(PolylineDrawing({{3, 3}, {3, 3}, {3, 3}, {3, 3}}), {}, "drawing", 1).status();
  EXPECT_EQ(same.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(same.message(),
              HasSubstr("(4 points, 1 after merging near-duplicates) has 1 points"));
  absl::Status line =
      ImportDrawing(PolylineDrawing({{0, 0}, {10, 0}, {10, 0}, {20, 0}}), {}, "drawing", 1)
          .status();
  EXPECT_EQ(line.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(line.message(), HasSubstr("zero area"));
  absl::Status bowtie =
      ImportDrawing(PolylineDrawing({{0, 0}, {10, 10}, {10, 10}, {10, 0}, {0, 20}}), {}, "drawing",
                    1)
          .status();
  EXPECT_EQ(bowtie.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bowtie.message(), HasSubstr("crosses itself"));
}

TEST(DrawingImportRobustnessTest, SvgFlattenBombIsResourceExhaustedNamingTheFlag) {
  v1::Drawing drawing;
  drawing.set_svg(
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><circle cx=\"0\" cy=\"0\" r=\"1e8\"/>"
      "<circle cx=\"3e8\" cy=\"0\" r=\"1e8\"/></svg>");
  absl::Status s =
      ImportDrawing(drawing, {.flatten_tolerance = 1e-6}, "drawing", 1, {}, "topology", 50000)
          .status();
  EXPECT_EQ(s.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(s.message(), HasSubstr("drawing.svg: SVG has more than 50000 points"));
  EXPECT_THAT(s.message(), HasSubstr("--max-drawing-points"));
}

TEST(DrawingImportRobustnessTest, UseFanOutIsResourceExhaustedWithoutThePointsFlag) {
  std::string s =
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><defs><rect id=\"l0\" width=\"1\" "
      "height=\"1\"/>";
  for (int k = 1; k <= 8; ++k) {
    s += "<g id=\"l" + std::to_string(k) + "\">";
    for (int j = 0; j < 10; ++j) s += "<use href=\"#l" + std::to_string(k - 1) + "\"/>";
    s += "</g>";
  }
  s += "</defs><use href=\"#l8\"/></svg>";
  v1::Drawing drawing;
  drawing.set_svg(s);
  absl::Status status = ImportDrawing(drawing, {}, "drawing", 1).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(status.message(), HasSubstr("more than 100000 elements"));
  EXPECT_THAT(status.message(), ::testing::Not(HasSubstr("--max-drawing-points")));
}

}  // namespace
}  // namespace inbetween::server
