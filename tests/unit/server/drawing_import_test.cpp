// Drawing import: elements by kind, ids, the graph-flow class and error naming; art and the
// import report (kept for stored drawings, checked like any input, written back by StoreImport);
// the import options' ranges.
#include "server/drawing_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "server/proto_convert.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;

TEST(DrawingImportTest, StoredElementsKeepTheirIdsAndGetAClass) {
  v1::Drawing drawing;
  *drawing.add_elements() = SquareOutline(0, 0, 1);
  drawing.mutable_elements(0)->set_id(7);
  v1::TopologyElement* opening = drawing.add_elements();
  opening->set_kind(v1::ELEMENT_KIND_OPENING);
  for (auto [x, y] : {std::pair{0.3, 0.5}, {0.7, 0.5}}) {
    v1::Point* p = opening->mutable_polyline()->add_points();
    p->set_x(x);
    p->set_y(y);
  }
  absl::StatusOr<ImportedDrawing> imported = ImportDrawingElements(drawing, "drawing 1", 1);
  ASSERT_TRUE(imported.ok()) << imported.status();
  ASSERT_EQ(imported->elements.size(), 2);
  EXPECT_EQ(imported->elements[0].id(), 7u);
  EXPECT_EQ(imported->elements[1].id(), 8u);
  EXPECT_EQ(imported->parsed.outlines.size(), 1u);
  EXPECT_EQ(imported->parsed.openings.size(), 1u);
  EXPECT_EQ(imported->equivalence_class.components(), 1u);
  EXPECT_EQ(imported->equivalence_class.holes(), 1u);
  EXPECT_EQ(imported->boundaries.loops.size(), 2u);

  drawing.mutable_elements(1)->set_id(7);
  imported = ImportDrawingElements(drawing, "drawing 1", 1);
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(imported.status().message(), HasSubstr("elements[1].id = 7 is repeated"));
}

// A stored drawing (a unit square) with SampleArt and a report.
v1::Drawing StoredDrawingWithArt() {
  v1::Drawing drawing;
  *drawing.add_elements() = SquareOutline(0, 0, 1);
  drawing.mutable_elements(0)->set_id(1);
  ToProto(SampleArt(), drawing.mutable_art());
  v1::ImportReport* report = drawing.mutable_import_report();
  report->set_silhouette_source(v1::SILHOUETTE_SOURCE_UNION);
  report->set_gaps_closed(2);
  report->set_gap_width(0.125);
  report->add_warnings("<text> (line 3): text is not imported");
  report->set_art_layers(2);
  return drawing;
}

TEST(DrawingImportTest, StoredArtAndReportAreKeptAndWrittenBack) {
  const v1::Drawing drawing = StoredDrawingWithArt();
  absl::StatusOr<ImportedDrawing> imported = ImportDrawingElements(drawing, "drawing 1", 1);
  ASSERT_TRUE(imported.ok()) << imported.status();
  ExpectSameArt(imported->parsed.art, SampleArt());
  EXPECT_EQ(imported->import_report.SerializeAsString(),
            drawing.import_report().SerializeAsString());

  v1::Drawing stored;
  ToProto(SampleArt(), stored.mutable_art());  // replaced, not appended to
  stored.mutable_import_report()->set_holes_dropped(9);
  StoreImport(*imported, &stored);
  EXPECT_EQ(stored.art_size(), 2);
  EXPECT_EQ(stored.SerializeAsString(), drawing.SerializeAsString());
}

TEST(DrawingImportTest, StoredArtIsCheckedNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::pair<std::function<void(v1::ArtLayer&)>, std::string> cases[] = {
      {[&](v1::ArtLayer& l) { l.mutable_paths(0)->mutable_points(1)->set_x(nan); },
       "drawing 1.art[0] (id \"body\").paths[0] point 1"},
      {[](v1::ArtLayer& l) { l.mutable_paths(0)->mutable_points(2)->set_y(2e9); },
       ".art[0] (id \"body\").paths[0] point 2"},
      {[](v1::ArtLayer& l) { l.set_opacity(1.5); }, ".art[0] (id \"body\").opacity = 1.5"},
      {[](v1::ArtLayer& l) { l.mutable_fill()->set_rgb(0x1000000); },
       ".fill.rgb = 0x1000000 is not"},
      {[&](v1::ArtLayer& l) { l.mutable_fill()->set_opacity(nan); }, ".fill.opacity = nan"},
      {[](v1::ArtLayer& l) { l.mutable_stroke()->set_width(0); }, ".stroke.width = 0"},
      {[](v1::ArtLayer& l) {
         l.mutable_stroke()->set_width(1);
         l.mutable_stroke()->add_dashes(-1);
       },
       ".stroke.dashes[0] = -1"},
  };
  for (const auto& [damage, message] : cases) {
    v1::Drawing drawing = StoredDrawingWithArt();
    damage(*drawing.mutable_art(0));
    absl::Status status = ImportDrawingElements(drawing, "drawing 1", 1).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(status.message(), HasSubstr(message));
  }
  // The second layer has no id: named by its index alone.
  v1::Drawing drawing = StoredDrawingWithArt();
  drawing.mutable_art(1)->mutable_stroke()->set_opacity(-0.5);
  EXPECT_THAT(ImportDrawingElements(drawing, "drawing 1", 1).status().message(),
              HasSubstr("drawing 1.art[1].stroke.opacity = -0.5"));
  // Art counts against the drawing's point limit.
  drawing = StoredDrawingWithArt();
  EXPECT_EQ(ImportDrawingElements(drawing, "drawing 1", 1, 8).status().code(),
            absl::StatusCode::kResourceExhausted);
}

TEST(DrawingImportTest, PolylinesHaveNoArtAndReportElements) {
  v1::Drawing drawing;
  *drawing.mutable_polylines()->add_elements() = SquareOutline(0, 0, 1);
  // Output-only fields of a request are ignored.
  ToProto(SampleArt(), drawing.mutable_art());
  drawing.mutable_import_report()->set_silhouette_source(v1::SILHOUETTE_SOURCE_UNION);
  drawing.mutable_import_report()->set_art_layers(2);
  absl::StatusOr<ImportedDrawing> imported = ImportDrawing(drawing, {}, "drawing", 1);
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_TRUE(imported->parsed.art.empty());
  v1::ImportReport want;
  want.set_silhouette_source(v1::SILHOUETTE_SOURCE_ELEMENTS);
  EXPECT_EQ(imported->import_report.SerializeAsString(), want.SerializeAsString());
  StoreImport(*imported, &drawing);
  EXPECT_EQ(drawing.art_size(), 0);
  EXPECT_EQ(drawing.import_report().SerializeAsString(), want.SerializeAsString());
}

TEST(DrawingImportTest, ImportFractionsAreCheckedNamingTheField) {
  v1::Drawing drawing;
  *drawing.mutable_polylines()->add_elements() = SquareOutline(0, 0, 1);
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {0.5, 0.1000001, inf, -inf, std::numeric_limits<double>::quiet_NaN()}) {
    absl::Status status = ImportDrawing(drawing, {.gap_tolerance = bad}, "drawing", 1).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_THAT(status.message(), HasSubstr("gap_tolerance = ")) << bad;
    status = ImportDrawing(drawing, {.min_area_fraction = bad}, "drawing", 1).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_THAT(status.message(), HasSubstr("min_area_fraction = ")) << bad;
  }
  for (double good : {0.0, 1e-6, 0.1, -1.0, -1e9}) {
    EXPECT_TRUE(
        ImportDrawing(drawing, {.gap_tolerance = good, .min_area_fraction = good}, "drawing", 1)
            .ok())
        << good;
  }
}

}  // namespace
}  // namespace inbetween::server::testing
