// Tests client/svg_marks.cpp: data-corr marks drawn in the SVGs become project correspondences
// (one point per drawing, ordered by id); missing or repeated ids are refused naming the drawing.
#include "client/svg_marks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace inbetween::client {
namespace {

using ::testing::HasSubstr;

std::string Svg(const std::string& marks) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\"><rect width=\"100\" height=\"50\"/>" + marks +
         "</svg>";
}

// A 2x2 square centred on (x, y): the mark's point is the centre of its bounding box.
std::string Mark(int id, int x, int y) {
  return "<rect data-corr=\"" + std::to_string(id) + "\" x=\"" + std::to_string(x - 1) + "\" y=\"" +
         std::to_string(y - 1) + "\" width=\"2\" height=\"2\"/>";
}

TEST(SvgMarksTest, MarksBecomeCorrespondencesOrderedById) {
  auto marks = SvgMarkCorrespondences(
      {Svg(Mark(7, 100, 25) + Mark(2, 0, 10)), Svg(Mark(2, 5, 0) + Mark(7, 50, 50))});
  ASSERT_TRUE(marks.ok()) << marks.status();
  ASSERT_EQ(marks->size(), 2u);
  EXPECT_EQ((*marks)[0], (XYs{{0, 10}, {5, 0}}));  // id 2 first
  EXPECT_EQ((*marks)[1], (XYs{{100, 25}, {50, 50}}));
}

TEST(SvgMarksTest, NoMarksGiveNothing) {
  auto marks = SvgMarkCorrespondences({Svg(""), Svg("")});
  ASSERT_TRUE(marks.ok());
  EXPECT_TRUE(marks->empty());
}

TEST(SvgMarksTest, MarkMissingFromADrawingIsAnError) {
  auto marks = SvgMarkCorrespondences({Svg(Mark(3, 0, 0)), Svg("")});
  ASSERT_FALSE(marks.ok());
  EXPECT_THAT(marks.status().message(), HasSubstr("is in drawing 1 but not in drawing 2"));
}

TEST(SvgMarksTest, RepeatedMarkIsAnError) {
  auto marks = SvgMarkCorrespondences({Svg(Mark(3, 0, 0)), Svg(Mark(3, 0, 0) + Mark(3, 1, 1))});
  ASSERT_FALSE(marks.ok());
  EXPECT_THAT(marks.status().message(), HasSubstr("drawing 2"));
  EXPECT_THAT(marks.status().message(), HasSubstr("appears twice"));
}

}  // namespace
}  // namespace inbetween::client
