// Drawing import: elements by kind, ids, the graph-flow class and error naming.
#include "server/drawing_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace inbetween::server::testing
