// Tests the fill colour solver/io/svg_import.cpp reports (SvgImportInfo::fill_rgb): plain colours
// in attributes and styles, inheritance, and the cases that give no colour.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

std::optional<uint32_t> FillOf(const std::string& body) {
  SvgImportInfo info;
  info.fill_rgb = 0x123456;  // must be overwritten
  auto drawing =
      ImportSvg("<svg xmlns=\"http://www.w3.org/2000/svg\">" + body + "</svg>", {}, &info);
  EXPECT_TRUE(drawing.ok()) << drawing.status();
  return info.fill_rgb;
}

TEST(SvgImportFillTest, HexAttribute) {
  EXPECT_EQ(FillOf(R"(<rect width="10" height="10" fill="#2f6f8f"/>)"), 0x2f6f8fu);
}

TEST(SvgImportFillTest, NamedColourAndShortHex) {
  EXPECT_EQ(FillOf(R"(<circle r="5" fill="red"/>)"), 0xff0000u);
  EXPECT_EQ(FillOf(R"(<circle r="5" fill="#0a0"/>)"), 0x00aa00u);
}

TEST(SvgImportFillTest, StyleAndInheritance) {
  EXPECT_EQ(FillOf(R"(<rect width="10" height="10" style="fill:#102030"/>)"), 0x102030u);
  EXPECT_EQ(FillOf(R"(<g fill="#abcdef"><path d="M0 0H10V10H0Z"/></g>)"), 0xabcdefu);
}

TEST(SvgImportFillTest, LargestFilledShapeWins) {
  EXPECT_EQ(FillOf(R"(<rect width="2" height="2" fill="#ff0000"/>)"
                   R"(<rect x="10" width="20" height="20" fill="#00ff00"/>)"),
            0x00ff00u);
}

TEST(SvgImportFillTest, NoPlainColourGivesNothing) {
  EXPECT_EQ(FillOf(R"(<rect width="10" height="10"/>)"), std::nullopt);  // initial black
  EXPECT_EQ(FillOf(R"(<rect width="10" height="10" fill="currentColor"/>)"), std::nullopt);
  const std::string gradient =
      R"svg(<g fill="#abcdef"><rect width="10" height="10" fill="url(#g)"/></g>)svg";
  EXPECT_EQ(FillOf(gradient), std::nullopt);
}

TEST(SvgImportFillTest, UnfilledShapesDoNotCount) {
  EXPECT_EQ(FillOf(R"(<rect width="100" height="100" fill="none" stroke="#000"/>)"
                   R"(<rect width="5" height="5" fill="#334455"/>)"),
            0x334455u);
}

}  // namespace
}  // namespace inbetween::solver
