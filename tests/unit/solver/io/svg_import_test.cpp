// Property tests for ImportSvg: path commands, transforms, basic shapes, orientation, errors.
#include "solver/io/svg_import.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <libxml/parser.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "solver/geometry/polygon.h"
#include "tests/unit/solver/io/read_example.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

std::string Svg(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"200\">" + body +
         "</svg>";
}

Drawing ImportOk(const std::string& svg, double tolerance = 0.05) {
  SvgImportOptions options;
  options.tolerance = tolerance;
  absl::StatusOr<Drawing> d = ImportSvg(svg, options);
  EXPECT_TRUE(d.ok()) << d.status();
  return d.ok() ? *d : Drawing{};
}

void ExpectBox(const Points& p, double x0, double y0, double x1, double y1, double eps = 1e-9) {
  Point lo = p[0], hi = p[0];
  for (const Point& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  EXPECT_NEAR(lo.x(), x0, eps);
  EXPECT_NEAR(lo.y(), y0, eps);
  EXPECT_NEAR(hi.x(), x1, eps);
  EXPECT_NEAR(hi.y(), y1, eps);
}

TEST(SvgImportTest, AbsoluteLinesGiveOnePositiveOutlineWithoutClosingPoint) {
  // Drawn with negative orientation, with a repeated closing point and a duplicate point.
  Drawing d = ImportOk(Svg("<path d=\"M 0 0 L 0 50 L 0 50 L 40 50 L 40 0 L 0 0 Z\"/>"));
  ASSERT_EQ(d.outlines.size(), 1u);
  EXPECT_EQ(d.outlines[0].points.size(), 4u);
  EXPECT_DOUBLE_EQ(PolygonSignedArea(d.outlines[0].points), 2000.0);
}

TEST(SvgImportTest, RelativeAndOrthogonalCommandsMatchAbsolute) {
  Drawing a = ImportOk(Svg("<path d=\"M10 20 H 50 V 60 H 10 Z\"/>"));
  Drawing r = ImportOk(Svg("<path d=\"m10 20 h40 v40 h-40 z\"/>"));
  Drawing l = ImportOk(Svg("<path d=\"M10,20 l40,0 0,40 -40,0z\"/>"));
  ASSERT_EQ(a.outlines.size(), 1u);
  ASSERT_EQ(r.outlines.size(), 1u);
  ASSERT_EQ(l.outlines.size(), 1u);
  EXPECT_EQ(a.outlines[0].points, r.outlines[0].points);
  EXPECT_EQ(a.outlines[0].points, l.outlines[0].points);
}

TEST(SvgImportTest, ArcsFlattenWithinTolerance) {
  // Full circle of radius 40 around (100, 100) from two arcs (absolute and relative).
  const double tol = 0.05;
  Drawing d =
      ImportOk(Svg("<path d=\"M 60 100 A 40 40 0 0 1 140 100 a 40 40 0 0 1 -80 0 Z\"/>"), tol);
  ASSERT_EQ(d.outlines.size(), 1u);
  const Points& p = d.outlines[0].points;
  EXPECT_GT(p.size(), 20u);
  for (const Point& q : p) EXPECT_NEAR((q - Point(100, 100)).norm(), 40.0, 2e-3 * 40 + tol);
  // Chord midpoints stay within the tolerance of the circle (plus the cubic approximation).
  for (size_t i = 0; i < p.size(); ++i) {
    const Point mid = 0.5 * (p[i] + p[(i + 1) % p.size()]);
    EXPECT_GT((mid - Point(100, 100)).norm(), 40.0 - tol - 0.02);
  }
  EXPECT_NEAR(std::abs(PolygonSignedArea(p)), M_PI * 1600, 0.01 * M_PI * 1600);
}

TEST(SvgImportTest, CubicAndQuadraticShorthands) {
  // C/S and Q/T curves bulging out of the square's sides stay inside their control hulls.
  Drawing d =
      ImportOk(Svg("<path d=\"M 0 0 C 10 -10 30 -10 40 0 S 50 30 40 40 Q 20 50 0 40 T 0 0 Z\"/>"));
  ASSERT_EQ(d.outlines.size(), 1u);
  const Points& p = d.outlines[0].points;
  EXPECT_GT(p.size(), 12u);
  for (const Point& q : p) {
    EXPECT_TRUE(q.allFinite());
    EXPECT_GE(q.x(), -10.0);
    EXPECT_LE(q.x(), 50.0);
    EXPECT_GE(q.y(), -10.0);
    EXPECT_LE(q.y(), 50.0);
  }
  EXPECT_GT(PolygonSignedArea(p), 1600.0);  // bulges outward on three sides
  // The relative forms give the same outline.
  Drawing r = ImportOk(
      Svg("<path d=\"m 0 0 c 10 -10 30 -10 40 0 s 10 30 0 40 q -20 10 -40 0 t 0 -40 z\"/>"));
  ASSERT_EQ(r.outlines.size(), 1u);
  ASSERT_EQ(r.outlines[0].points.size(), p.size());
  for (size_t i = 0; i < p.size(); ++i) EXPECT_LT((r.outlines[0].points[i] - p[i]).norm(), 1e-9);
}

TEST(SvgImportTest, TransformsComposeThroughGroups) {
  Drawing d = ImportOk(Svg(
      "<g transform=\"translate(100 50)\"><g transform=\"scale(2)\">"
      "<rect x=\"0\" y=\"0\" width=\"10\" height=\"5\" transform=\"translate(1,1)\"/></g></g>"));
  ASSERT_EQ(d.outlines.size(), 1u);
  ExpectBox(d.outlines[0].points, 102, 52, 122, 62);
  EXPECT_NEAR(PolygonSignedArea(d.outlines[0].points), 200.0, 1e-9);
}

TEST(SvgImportTest, RotationMatrixAndMirrorKeepPositiveOrientation) {
  Drawing d = ImportOk(Svg(
      "<polygon points=\"0,0 10,0 10,10 0,10\" transform=\"matrix(-1 0 0 1 50 0) rotate(30)\"/>"));
  ASSERT_EQ(d.outlines.size(), 1u);
  EXPECT_NEAR(PolygonSignedArea(d.outlines[0].points), 100.0, 1e-9);
}

TEST(SvgImportTest, BasicShapes) {
  Drawing d =
      ImportOk(Svg("<rect x=\"0\" y=\"0\" width=\"30\" height=\"20\"/>"
                   "<circle cx=\"100\" cy=\"100\" r=\"10\"/>"
                   "<ellipse cx=\"150\" cy=\"30\" rx=\"20\" ry=\"10\"/>"
                   "<polygon points=\"0,100 30,100 15,130\"/>"
                   "<polyline points=\"0,150 30,150 30,180\"/>"
                   "<rect x=\"50\" y=\"150\" width=\"40\" height=\"30\" rx=\"5\"/>"));
  ASSERT_EQ(d.outlines.size(), 6u);
  const double expected[] = {600, M_PI * 100, M_PI * 200, 450, 450, 1200 - (4 - M_PI) * 25};
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(PolygonSignedArea(d.outlines[i].points), expected[i], 0.01 * expected[i]) << i;
  }
}

TEST(SvgImportTest, HolesAreNegativeByNestingDepth) {
  // Outer square, a hole (drawn in the same direction, so evenodd), an island inside the hole.
  Drawing d =
      ImportOk(Svg("<path fill-rule=\"evenodd\" d=\"M0 0 H100 V100 H0 Z M20 20 H80 V80 H20 Z\"/>"
                   "<circle cx=\"50\" cy=\"50\" r=\"10\"/>"
                   "<rect x=\"150\" y=\"0\" width=\"10\" height=\"10\"/>"));
  ASSERT_EQ(d.outlines.size(), 4u);
  EXPECT_GT(PolygonSignedArea(d.outlines[0].points), 0);
  EXPECT_LT(PolygonSignedArea(d.outlines[1].points), 0);
  EXPECT_GT(PolygonSignedArea(d.outlines[2].points), 0);
  EXPECT_GT(PolygonSignedArea(d.outlines[3].points), 0);
}

TEST(SvgImportTest, UnfilledAndNonRenderingElementsAreIgnored) {
  // Unfilled and unstroked elements paint nothing (strokes are paint: svg_import_paint_test).
  Drawing d = ImportOk(Svg(
      "<title>t</title><desc>d</desc><metadata><x/></metadata>"
      "<defs><path id=\"template\" d=\"M0 0 H5 V5 Z\"/></defs>"
      "<path fill=\"none\" stroke=\"none\" d=\"M0 0 H50 V50 Z\"/>"
      "<path style=\"fill:none;stroke-width:0;stroke:red\" d=\"M0 0 H60 V60 Z\"/>"
      "<g fill=\"none\"><rect width=\"70\" height=\"70\"/></g>"
      "<g fill=\"none\"><rect fill=\"red\" data-name=\"kept\" width=\"80\" height=\"20\"/></g>"));
  ASSERT_EQ(d.outlines.size(), 1u);
  EXPECT_NEAR(PolygonSignedArea(d.outlines[0].points), 1600.0, 1e-9);
}

TEST(SvgImportTest, MissingNamespaceIsAccepted) {
  Drawing d = ImportOk("<svg><path d=\"M0 0 H10 V10 H0 Z\"/></svg>");
  ASSERT_EQ(d.outlines.size(), 1u);
}

TEST(SvgImportTest, MalformedXmlNamesTheLine) {
  absl::StatusOr<Drawing> d =
      ImportSvg("<svg xmlns=\"http://www.w3.org/2000/svg\">\n<path d=\"M0 0\"\n</svg>");
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("line 3"));
}

// libxml2 prints a failed input encoding conversion on stderr through its generic handler, past
// XML_PARSE_NOERROR; in the server that was user input writing to the log (found by fuzzing).
TEST(SvgImportTest, UndecodableBytesAreAnErrorAndNothingIsPrinted) {
  const std::string svg =
      "<?xml version=\"1.0\" encoding=\"ISO-2022-JP\"?>\n<svg>\x1b$B\xff\xff</svg>";
  ::testing::internal::CaptureStderr();
  absl::StatusOr<Drawing> d = ImportSvg(svg);
  const std::string printed = ::testing::internal::GetCapturedStderr();
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("not well-formed XML"));
  EXPECT_EQ(printed, "");
  // The thread's own handler is back afterwards: libxml2 prints again outside ImportSvg.
  ::testing::internal::CaptureStderr();
  xmlParserCtxt* ctxt = xmlNewParserCtxt();
  xmlDoc* doc = xmlCtxtReadMemory(ctxt, svg.data(), static_cast<int>(svg.size()), "t.svg", nullptr,
                                  XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
  if (doc != nullptr) xmlFreeDoc(doc);
  xmlFreeParserCtxt(ctxt);
  EXPECT_THAT(::testing::internal::GetCapturedStderr(), HasSubstr("encoding error"));
}

TEST(SvgImportTest, BadPathDataNamesTheElement) {
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<path id=\"wing\" d=\"M 0 0 L 10 banana Z\"/>"));
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("<path id=\"wing\">"));
  EXPECT_THAT(d.status().message(), HasSubstr("line 1"));
}

TEST(SvgImportTest, NonFiniteCoordinatesAreRejected) {
  for (const char* data : {"M 0 0 L 1e999 0 L 0 10 Z", "M 0 0 L nan 0 L 0 10 Z"}) {
    absl::StatusOr<Drawing> d = ImportSvg(Svg(std::string("<path id=\"p\" d=\"") + data + "\"/>"));
    ASSERT_FALSE(d.ok()) << data;
    EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(d.status().message(), HasSubstr("id=\"p\"")) << d.status();
  }
}

TEST(SvgImportTest, NoFilledShapeIsAnError) {
  absl::StatusOr<Drawing> d = ImportSvg(Svg("<path fill=\"none\" d=\"M0 0 H10 V10 Z\"/>"));
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("no filled shape"));
}

TEST(SvgImportTest, EntitiesAreNeverExpanded) {
  const std::string internal =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE svg [ <!ENTITY sq \"M0 0 H10 V10 H0 Z\"> ]>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"&sq;\"/></svg>";
  absl::StatusOr<Drawing> d = ImportSvg(internal);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("entity"));

  const std::string external =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE svg [ <!ENTITY x SYSTEM \"file:///etc/passwd\"> ]>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><title>&x;</title>"
      "<path d=\"M0 0 H10 V10 H0 Z\"/></svg>";
  d = ImportSvg(external);
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("entity"));

  // A declared but unused entity is harmless.
  const std::string unused =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE svg [ <!ENTITY sq \"M0 0 H10 V10 H0 Z\"> ]>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"M0 0 H5 V5 H0 Z\"/></svg>";
  Drawing ok = ImportOk(unused);
  ASSERT_EQ(ok.outlines.size(), 1u);
  EXPECT_NEAR(PolygonSignedArea(ok.outlines[0].points), 25.0, 1e-12);
}

TEST(SvgImportTest, ExampleFilesImport) {
  for (const char* name : {"square_hexagon/square.svg", "square_hexagon/hexagon.svg",
                           "bar_arch/bar.svg", "bar_arch/arch.svg"}) {
    const std::string text = ReadExample(name);
    Drawing d = ImportOk(text);
    ASSERT_EQ(d.outlines.size(), 1u) << name;
    EXPECT_GT(PolygonSignedArea(d.outlines[0].points), 0) << name;
  }
}

}  // namespace
}  // namespace inbetween::solver

namespace inbetween::solver {
namespace {

TEST(SvgImportTest, CutAndOpeningClassesBecomePolylines) {
  absl::StatusOr<Drawing> d = ImportSvg(R"(<svg xmlns="http://www.w3.org/2000/svg">
    <rect x="0" y="0" width="10" height="10"/>
    <path class="cut" d="M 5 -1 L 5 11" stroke="red" fill="none"/>
    <polyline class="mouth opening" points="2,5 5,6 8,5" fill="none"/>
    <line class="cut" x1="-1" y1="2" x2="11" y2="2"/>
  </svg>)");
  ASSERT_TRUE(d.ok()) << d.status();
  EXPECT_EQ(d->outlines.size(), 1u);
  ASSERT_EQ(d->cuts.size(), 2u);
  EXPECT_EQ(d->cuts[0], (Points{{5, -1}, {5, 11}}));
  ASSERT_EQ(d->openings.size(), 1u);
  EXPECT_EQ(d->openings[0].size(), 3u);
}

TEST(SvgImportTest, FillRuleNonzeroKeepsOnlyWindingChanges) {
  // nonzero (SVG's default): an inner subpath drawn the same way is filled on both sides.
  EXPECT_EQ(ImportOk(Svg("<path d=\"M0 0 H100 V100 H0 Z M20 20 H80 V80 H20 Z\"/>")).outlines.size(),
            1u);
  // Drawn the other way it is a hole under both rules.
  for (const char* rule : {"nonzero", "evenodd"}) {
    Drawing d = ImportOk(Svg(std::string("<path fill-rule=\"") + rule +
                             "\" d=\"M0 0 H100 V100 H0 Z M20 20 V80 H80 V20 Z\"/>"));
    ASSERT_EQ(d.outlines.size(), 2u) << rule;
    EXPECT_LT(PolygonSignedArea(d.outlines[1].points), 0) << rule;
  }
  // Inherited from a group; an island inside a same-direction ring stays under evenodd.
  Drawing d =
      ImportOk(Svg("<g fill-rule=\"evenodd\"><path d=\"M0 0 H100 V100 H0 Z M20 20 H80 V80 H20 Z "
                   "M40 40 H60 V60 H40 Z\"/></g>"));
  EXPECT_EQ(d.outlines.size(), 3u);
  Drawing nonzero =
      ImportOk(Svg("<path d=\"M0 0 H100 V100 H0 Z M20 20 V80 H80 V20 Z M40 40 H60 V60 H40 Z\"/>"));
  EXPECT_EQ(nonzero.outlines.size(), 3u);  // windings 1 | 0 | 1
}

TEST(SvgImportTest, UseElementsAreExpanded) {
  Drawing d = ImportOk(R"svg(<svg xmlns="http://www.w3.org/2000/svg"
      xmlns:xlink="http://www.w3.org/1999/xlink">
    <defs><g id="tile"><rect width="10" height="10"/></g></defs>
    <use href="#tile" x="100" y="0"/>
    <use xlink:href="#tile" transform="translate(0 50) scale(2)" y="5"/>
    <rect id="base" x="0" y="0" width="4" height="4"/>
    <use href="#base" x="20"/>
  </svg>)svg");
  ASSERT_EQ(d.outlines.size(), 4u);
  ExpectBox(d.outlines[0].points, 100, 0, 110, 10);
  ExpectBox(d.outlines[1].points, 0, 60, 20, 80);
  ExpectBox(d.outlines[2].points, 0, 0, 4, 4);
  ExpectBox(d.outlines[3].points, 20, 0, 24, 4);
  absl::StatusOr<Drawing> unknown =
      ImportSvg(Svg("<rect width=\"5\" height=\"5\"/>"
                    "<use id=\"u\" href=\"#nothing\"/>"));
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(unknown.status().message(), HasSubstr("<use id=\"u\">"));
  EXPECT_THAT(unknown.status().message(), HasSubstr("unknown id"));
  absl::StatusOr<Drawing> loop =
      ImportSvg(Svg("<rect width=\"5\" height=\"5\"/>"
                    "<g id=\"a\"><use href=\"#a\"/></g>"));
  EXPECT_EQ(loop.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(loop.status().message(), HasSubstr("nested too deeply"));
}

TEST(SvgImportTest, DataCorrElementsBecomeMarks) {
  Drawing d =
      ImportOk(Svg("<rect width=\"50\" height=\"50\"/>"
                   "<g transform=\"translate(10 20)\">"
                   "<circle data-corr=\"3\" cx=\"40\" cy=\"0\" r=\"2\" fill=\"red\"/></g>"
                   "<rect class=\"mark\" data-corr=\"1\" x=\"-1\" y=\"9\" width=\"2\" "
                   "height=\"2\"/>"));
  ASSERT_EQ(d.outlines.size(), 1u);  // marks are never outlines
  ASSERT_EQ(d.marks.size(), 2u);
  EXPECT_EQ(d.marks[0].id, 3);
  EXPECT_NEAR((d.marks[0].point - Point(50, 20)).norm(), 0, 1e-9);
  EXPECT_EQ(d.marks[1].id, 1);
  EXPECT_NEAR((d.marks[1].point - Point(0, 10)).norm(), 0, 1e-9);
  absl::StatusOr<Drawing> bad =
      ImportSvg(Svg("<rect width=\"5\" height=\"5\"/><circle id=\"m\" data-corr=\"x\" r=\"1\"/>"));
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("<circle id=\"m\">"));
  EXPECT_THAT(bad.status().message(), HasSubstr("not a mark number"));
}

TEST(SvgImportTest, AllExampleDrawingsImport) {
  namespace fs = std::filesystem;
  int files = 0;
  for (const auto& entry :
       fs::recursive_directory_iterator(fs::path(INBETWEEN_SOURCE_DIR) / "examples")) {
    if (entry.path().extension() != ".svg") continue;
    const std::string relative =
        fs::relative(entry.path(), fs::path(INBETWEEN_SOURCE_DIR) / "examples").string();
    Drawing d = ImportOk(ReadExample(relative));
    EXPECT_FALSE(d.outlines.empty()) << relative;
    ++files;
  }
  EXPECT_GT(files, 20);
}

}  // namespace
}  // namespace inbetween::solver
