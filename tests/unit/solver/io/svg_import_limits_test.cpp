// SVG import limits (tests/data/bad/svg_flatten_bomb, svg_huge_path, svg_use_bomb): documents
// that would expand to millions of points or elements are refused before the work is done.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

std::string Svg(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\">" + body + "</svg>";
}

TEST(SvgImportLimitsTest, HugeCirclesWithATinyToleranceAreRefused) {
  std::string body;
  for (int i = 0; i < 10; ++i) {
    body += "<circle cx=\"" + std::to_string(i * 3e8) + "\" cy=\"0\" r=\"1e8\"/>";
  }
  SvgImportOptions options;
  options.tolerance = 1e-6;
  absl::StatusOr<Drawing> d = ImportSvg(Svg(body), options);
  ASSERT_EQ(d.status().code(), absl::StatusCode::kResourceExhausted) << d.status();
  EXPECT_THAT(d.status().message(), HasSubstr("more than 1000000 points once its curves"));
}

TEST(SvgImportLimitsTest, PathDataAboveMaxPointsIsRefused) {
  std::string d = "M0 0";
  for (int i = 0; i < 2000; ++i) d += (i % 2 == 0) ? " h1" : " v1";
  SvgImportOptions options;
  options.max_points = 1000;
  absl::StatusOr<Drawing> drawing = ImportSvg(Svg("<path d=\"" + d + " z\"/>"), options);
  ASSERT_EQ(drawing.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(drawing.status().message(), HasSubstr("more than 1000 points in its path data"));
  options.max_points = 5000;
  EXPECT_TRUE(ImportSvg(Svg("<path d=\"" + d + " z\"/>"), options).ok());
}

TEST(SvgImportLimitsTest, ACircleWithinTheLimitImports) {
  SvgImportOptions options;
  options.max_points = 100000;
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<circle cx=\"0\" cy=\"0\" r=\"50\"/>"), options);
  ASSERT_TRUE(d.ok()) << d.status();
  ASSERT_EQ(d->outlines.size(), 1u);
  EXPECT_GT(d->outlines[0].points.size(), 16u);
  options.max_points = 8;
  EXPECT_EQ(ImportSvg(Svg("<circle cx=\"0\" cy=\"0\" r=\"50\"/>"), options).status().code(),
            absl::StatusCode::kResourceExhausted);
}

// 10 levels of 10 uses each: 10^10 copies of one rect if expanded.
TEST(SvgImportLimitsTest, UseFanOutIsRefusedNamingTheUse) {
  std::string s = "<defs><rect id=\"l0\" x=\"0\" y=\"0\" width=\"1\" height=\"1\"/>";
  for (int k = 1; k <= 10; ++k) {
    s += "<g id=\"l" + std::to_string(k) + "\">";
    for (int j = 0; j < 10; ++j) {
      // Half of them through xlink:href, which must be counted as well.
      s += j % 2 ? "<use href=\"#l" + std::to_string(k - 1) + "\"/>"
                 : "<use xlink:href=\"#l" + std::to_string(k - 1) + "\"/>";
    }
    s += "</g>";
  }
  s += "</defs><use href=\"#l10\"/>";
  const std::string doc =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">" +
      s + "</svg>";
  absl::StatusOr<Drawing> d = ImportSvg(doc);
  ASSERT_EQ(d.status().code(), absl::StatusCode::kResourceExhausted) << d.status();
  EXPECT_THAT(d.status().message(), HasSubstr("<use"));
  EXPECT_THAT(d.status().message(), HasSubstr("more than 100000 elements"));
}

TEST(SvgImportLimitsTest, ModestUseFanOutStillExpands) {
  const std::string doc =
      Svg("<defs><rect id=\"r\" x=\"0\" y=\"0\" width=\"1\" height=\"1\"/></defs>"
          "<use href=\"#r\" x=\"0\"/><use href=\"#r\" x=\"3\"/><use href=\"#r\" x=\"6\"/>");
  absl::StatusOr<Drawing> d = ImportSvg(doc);
  ASSERT_TRUE(d.ok()) << d.status();
  EXPECT_EQ(d->outlines.size(), 3u);
}

// svg_import_fuzz finding (build/fuzz/artifacts/svg_import_fuzz/crash-328c010a…): a non-ASCII
// colour made Boost.Spirit (inside SVG++) fail an assertion, i.e. abort the process in builds
// with assertions on. Such attributes are refused before SVG++ reads them.
TEST(SvgImportLimitsTest, NonAsciiParsedAttributeIsInvalidNotAnAbort) {
  absl::StatusOr<Drawing> d =
      ImportSvg(Svg("<path id=\"face\" fill=\"\xdd\x9a\xc7\x98"
                    "040\" d=\"M 0 0 H 10 V 10 H 0 Z\"/>"));
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("<path id=\"face\"> (line 1): attribute \"fill\" "
                                              "has a non-ASCII character"));
  // Non-ASCII text where SVG++ does not parse it (ids, titles) is fine.
  EXPECT_TRUE(ImportSvg(Svg("<title>\xc3\xa9t\xc3\xa9</title><rect id=\"\xc3\xa9\" "
                            "width=\"1\" height=\"1\"/>"))
                  .ok());
}

// svg_import_fuzz finding (build/fuzz/artifacts/svg_import_fuzz/oom-90ec7607…): two uses of an
// element inside itself. Copies were taken while the round grew the element, doubling it per
// use (2^uses per round): 4 GB in 3 s. Copies now come from the round's starting state.
TEST(SvgImportLimitsTest, SelfNestedUsesDoNotExplode) {
  absl::StatusOr<Drawing> d = ImportSvg(
      Svg("<g id=\"g\"><g id=\"g\"><rect width=\"5\" height=\"5\"/><use href=\"#g\" x=\"10\"/></g>"
          "<use href=\"#g\" x=\"10\"/></g>"));
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("<use"));
}

TEST(SvgImportLimitsTest, NonPositiveMaxPointsIsInvalid) {
  SvgImportOptions options;
  options.max_points = 0;
  EXPECT_EQ(ImportSvg(Svg("<rect width=\"1\" height=\"1\"/>"), options).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inbetween::solver
