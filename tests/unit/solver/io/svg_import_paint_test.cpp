// Tests ImportSvg on layered drawings: every painted element kept as an art layer in paint order,
// the outlines the boundary of the union of all paint, the cleaning and what it reports.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "solver/geometry/polygon.h"
#include "solver/io/paint_union.h"
#include "solver/io/svg_import.h"

namespace inbetween::solver {
namespace {

using ::testing::HasSubstr;

std::string Svg(const std::string& body, const std::string& attributes = "") {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 200 200\"" + attributes + ">" +
         body + "</svg>";
}

struct Imported {
  Drawing drawing;
  SvgImportInfo info;
};

Imported ImportOk(const std::string& svg, SvgImportOptions options = {}) {
  Imported out;
  absl::StatusOr<Drawing> d = ImportSvg(svg, options, &out.info);
  EXPECT_TRUE(d.ok()) << d.status();
  if (d.ok()) out.drawing = *d;
  return out;
}

int Outers(const Drawing& d) {
  int n = 0;
  for (const Outline& o : d.outlines) n += PolygonSignedArea(o.points) > 0;
  return n;
}
int Holes(const Drawing& d) { return static_cast<int>(d.outlines.size()) - Outers(d); }
double Area(const Drawing& d) {
  double a = 0;
  for (const Outline& o : d.outlines) a += PolygonSignedArea(o.points);
  return a;
}

// A face with two eyes and a mouth painted on it: one outline, no holes, four layers.
TEST(SvgImportPaintTest, EyesPaintedOnAFaceAreArtNotHoles) {
  Imported im = ImportOk(Svg(R"svg(
    <circle id="face" cx="100" cy="100" r="80" fill="#fcea2b"/>
    <circle id="eye-left" cx="70" cy="80" r="8" fill="#000"/>
    <circle id="eye-right" cx="130" cy="80" r="8" fill="#000"/>
    <path id="mouth" d="M60 130 Q100 170 140 130 Z" fill="#ea5a47"/>)svg"));
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(Holes(im.drawing), 0);
  EXPECT_NEAR(Area(im.drawing), std::numbers::pi * 80 * 80, 0.01 * 80 * 80 * 3.2);
  ASSERT_EQ(im.drawing.art.size(), 4u);
  EXPECT_EQ(im.drawing.art[0].id, "face");
  EXPECT_EQ(im.drawing.art[3].id, "mouth");
  ASSERT_TRUE(im.drawing.art[0].fill.has_value());
  EXPECT_EQ(im.drawing.art[0].fill->rgb, 0xfcea2bu);
  EXPECT_EQ(im.drawing.art[1].fill->rgb, 0x000000u);
  EXPECT_EQ(im.info.source, SilhouetteSource::kUnion);
}

// A black stroke drawn over a coloured fill: the silhouette grows by half the stroke width.
TEST(SvgImportPaintTest, StrokeOverFillWidensTheSilhouette) {
  Imported im = ImportOk(Svg(R"svg(
    <rect x="50" y="50" width="100" height="60" fill="#ff0000"/>
    <rect x="50" y="50" width="100" height="60" fill="none" stroke="#000" stroke-width="10"
          stroke-linejoin="miter"/>)svg"));
  ASSERT_EQ(im.drawing.outlines.size(), 1u);
  EXPECT_NEAR(Area(im.drawing), 110.0 * 70.0, 1e-3);
  ASSERT_EQ(im.drawing.art.size(), 2u);
  EXPECT_FALSE(im.drawing.art[1].fill.has_value());
  ASSERT_TRUE(im.drawing.art[1].stroke.has_value());
  EXPECT_DOUBLE_EQ(im.drawing.art[1].stroke->width, 10.0);
  EXPECT_EQ(im.drawing.art[1].stroke->join, LineJoin::kMiter);
}

// Round caps extend an open stroke by half its width at each end; butt caps do not.
TEST(SvgImportPaintTest, StrokeCapsCoverTheirArea) {
  Imported butt = ImportOk(
      Svg(R"svg(<path d="M50 100 H150" fill="none" stroke="#000" stroke-width="20"/>)svg"));
  Imported round = ImportOk(Svg(R"svg(<path d="M50 100 H150" fill="none" stroke="#000"
      stroke-width="20" stroke-linecap="round"/>)svg"));
  EXPECT_NEAR(Area(butt.drawing), 100.0 * 20.0, 1e-3);
  EXPECT_NEAR(Area(round.drawing), 100.0 * 20.0 + std::numbers::pi * 100.0, 4.0);
  EXPECT_EQ(round.drawing.art[0].stroke->cap, LineCap::kRound);
}

// A transform scales the stroke with the geometry.
TEST(SvgImportPaintTest, TransformScalesStrokeWidth) {
  Imported im = ImportOk(Svg(R"svg(<g transform="scale(2)"><path d="M25 50 H75" fill="none"
      stroke="#000" stroke-width="5"/></g>)svg"));
  ASSERT_EQ(im.drawing.art.size(), 1u);
  EXPECT_DOUBLE_EQ(im.drawing.art[0].stroke->width, 10.0);
  EXPECT_NEAR(Area(im.drawing), 100.0 * 10.0, 1e-3);
}

// Two fills meeting with a hairline gap become one piece; the cleaning says so.
TEST(SvgImportPaintTest, HairlineGapBetweenFillsIsClosed) {
  const std::string svg = Svg(R"svg(
    <rect x="20" y="50" width="80" height="100" fill="#336699"/>
    <rect x="100.05" y="50" width="80" height="100" fill="#6699cc"/>)svg");
  Imported im = ImportOk(svg);
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(im.info.cleaning.gaps_closed, 1);
  EXPECT_EQ(im.info.source, SilhouetteSource::kUnion);
  EXPECT_GT(im.info.cleaning.gap_width, 0.05);
  // Without gap closing the two stay apart (and are the elements' own outlines).
  SvgImportOptions no_gaps;
  no_gaps.gap_tolerance = 0;
  Imported apart = ImportOk(svg, no_gaps);
  EXPECT_EQ(Outers(apart.drawing), 2);
  EXPECT_EQ(apart.info.cleaning.gaps_closed, 0);
}

// A ring drawn as a stroked circle: one outline and one hole (the unpainted middle).
TEST(SvgImportPaintTest, RingOfStrokesHasAHole) {
  Imported im = ImportOk(Svg(R"svg(<circle cx="100" cy="100" r="60" fill="none" stroke="#000"
      stroke-width="20"/>)svg"));
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(Holes(im.drawing), 1);
  EXPECT_NEAR(Area(im.drawing), std::numbers::pi * (70.0 * 70.0 - 50.0 * 50.0), 20.0);
}

// A square ring made of four dashes that nearly meet: the hairline gaps between them (in the
// middle of each side) are closed.
TEST(SvgImportPaintTest, RingOfDashedStrokeWithHairlineGapsCloses) {
  Imported im = ImportOk(Svg(R"svg(<rect x="50" y="50" width="100" height="100" fill="none"
      stroke="#000" stroke-width="20" stroke-dasharray="99.9 0.1" stroke-dashoffset="-50"/>)svg"));
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(Holes(im.drawing), 1);
  EXPECT_EQ(im.info.cleaning.gaps_closed, 3);  // four pieces become one
  EXPECT_EQ(im.drawing.art[0].stroke->dashes.size(), 2u);
}

// A donut drawn as one element with a nested subpath (the one-colour convention) and the same
// donut drawn with an icing layer on top: both have one hole; the first keeps its own outlines.
TEST(SvgImportPaintTest, OneColourConventionKeepsItsOwnOutlines) {
  const std::string body =
      R"svg(<path fill-rule="evenodd" d="M20 20 H180 V180 H20 Z M70 70 V130 H130 V70 Z"/>)svg";
  Imported plain = ImportOk(Svg(body));
  EXPECT_EQ(plain.info.source, SilhouetteSource::kElements);
  ASSERT_EQ(plain.drawing.outlines.size(), 2u);
  EXPECT_EQ(plain.drawing.outlines[0].points.size(), 4u);
  EXPECT_EQ(plain.drawing.outlines[0].points[0], Point(20, 20));
  Imported iced =
      ImportOk(Svg(body + R"svg(<rect x="30" y="30" width="20" height="20" fill="pink"/>)svg"));
  EXPECT_EQ(iced.info.source, SilhouetteSource::kUnion);
  EXPECT_EQ(Outers(iced.drawing), 1);
  EXPECT_EQ(Holes(iced.drawing), 1);
  EXPECT_EQ(iced.drawing.art.size(), 2u);
}

// Separate, disjoint filled elements (two parts) are the old convention too.
TEST(SvgImportPaintTest, DisjointElementsKeepTheirOutlines) {
  Imported im = ImportOk(Svg(R"svg(<rect x="10" y="10" width="50" height="50"/>
      <rect x="100" y="100" width="50" height="50"/>)svg"));
  EXPECT_EQ(im.info.source, SilhouetteSource::kElements);
  EXPECT_EQ(Outers(im.drawing), 2);
}

// Specks and pinholes below the area fraction are dropped and counted (in a layered drawing;
// a one-colour drawing keeps its own outlines, specks and all, as it always did).
TEST(SvgImportPaintTest, SpecksAndPinholesAreDropped) {
  const std::string body = R"svg(
    <path fill-rule="evenodd" d="M20 20 H180 V180 H20 Z M100 100 h0.5 v0.5 h-0.5 Z"/>
    <rect x="190" y="190" width="0.4" height="0.4"/>)svg";
  Imported one_colour = ImportOk(Svg(body));
  EXPECT_EQ(one_colour.info.source, SilhouetteSource::kElements);
  EXPECT_EQ(one_colour.drawing.outlines.size(), 3u);
  Imported im = ImportOk(Svg(body + R"svg(<circle cx="60" cy="60" r="10" fill="#fff"/>)svg"));
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(Holes(im.drawing), 0);
  EXPECT_EQ(im.info.cleaning.islands_dropped, 1);
  EXPECT_EQ(im.info.cleaning.holes_dropped, 1);
}

// Hidden elements and transparent paint are not paint, and not art.
TEST(SvgImportPaintTest, HiddenElementsAreNotPaint) {
  Imported im = ImportOk(Svg(R"svg(
    <rect x="50" y="50" width="100" height="100"/>
    <rect x="0" y="0" width="20" height="20" display="none"/>
    <g style="display:none"><rect x="180" y="0" width="20" height="20"/></g>
    <rect x="0" y="180" width="20" height="20" visibility="hidden"/>
    <rect x="180" y="180" width="20" height="20" opacity="0"/>
    <g opacity="0"><rect x="90" y="0" width="20" height="20"/></g>
    <rect x="0" y="90" width="20" height="20" fill-opacity="0"/>)svg"));
  EXPECT_EQ(Outers(im.drawing), 1);
  EXPECT_EQ(im.drawing.art.size(), 1u);
}

// Group opacity multiplies into each element's; fill-opacity is the fill's own.
TEST(SvgImportPaintTest, OpacitiesAreKept) {
  Imported im = ImportOk(Svg(R"svg(<g opacity="0.5"><rect width="50" height="50" opacity="0.5"
      fill="#123456" fill-opacity="0.8"/></g>)svg"));
  ASSERT_EQ(im.drawing.art.size(), 1u);
  EXPECT_DOUBLE_EQ(im.drawing.art[0].opacity, 0.25);
  EXPECT_DOUBLE_EQ(im.drawing.art[0].fill->opacity, 0.8);
  EXPECT_EQ(im.drawing.art[0].fill->rgb, 0x123456u);
}

// A gradient arrives as the mean of its stops, with a warning naming the element.
TEST(SvgImportPaintTest, GradientIsItsMeanColourWithAWarning) {
  Imported im =
      ImportOk(Svg(R"svg(<defs><linearGradient id="g"><stop offset="0" stop-color="#000000"/>
      <stop offset="1" style="stop-color:#ffffff"/></linearGradient></defs>
      <rect id="r" width="50" height="50" fill="url(#g)"/>)svg"));
  ASSERT_EQ(im.drawing.art.size(), 1u);
  const uint32_t rgb = im.drawing.art[0].fill->rgb;
  EXPECT_NEAR(static_cast<int>((rgb >> 16) & 0xff), 128, 1);
  ASSERT_EQ(im.info.warnings.size(), 1u);
  EXPECT_THAT(im.info.warnings[0], HasSubstr("id=\"r\""));
  EXPECT_THAT(im.info.warnings[0], HasSubstr("mean colour"));
}

// style="" wins over the presentation attribute, whatever its spacing and other declarations.
TEST(SvgImportPaintTest, StyleDeclarationsOverrideStopAttributes) {
  Imported im =
      ImportOk(Svg(R"svg(<defs><linearGradient id="g"><stop offset="0" stop-color="#000000"/>
      <stop offset="1" stop-color="#000000" style=" stop-opacity : 1 ;stop-color :  #ffffff ;"/>
      </linearGradient></defs><rect width="50" height="50" fill="url(#g)"/>)svg"));
  ASSERT_EQ(im.drawing.art.size(), 1u);
  EXPECT_NEAR(static_cast<int>((im.drawing.art[0].fill->rgb >> 16) & 0xff), 128, 1);
}

// A gradient without stops paints nothing (SVG's rule), said in a warning.
TEST(SvgImportPaintTest, GradientWithoutStopsPaintsNothing) {
  Imported im = ImportOk(Svg(R"svg(<defs><linearGradient id="empty"/></defs>
      <rect width="50" height="50" fill="url(#empty)"/><rect x="60" width="50" height="50"/>)svg"));
  EXPECT_EQ(im.drawing.art.size(), 1u);
  ASSERT_EQ(im.info.warnings.size(), 1u);
  EXPECT_THAT(im.info.warnings[0], HasSubstr("no stops"));
}

// Text, images and filters: a warning naming the element, then ignored.
TEST(SvgImportPaintTest, TextImagesAndFiltersAreWarnedAbout) {
  Imported im = ImportOk(Svg(R"svg(<rect width="50" height="50"/><text id="label">Hi</text>
      <image id="photo" href="x.png" width="10" height="10"/>
      <rect id="blurred" x="60" width="50" height="50" filter="url(#f)"/>)svg"));
  ASSERT_EQ(im.info.warnings.size(), 3u);
  EXPECT_THAT(im.info.warnings[0], HasSubstr("<text id=\"label\">"));
  EXPECT_THAT(im.info.warnings[1], HasSubstr("<image id=\"photo\">"));
  EXPECT_THAT(im.info.warnings[2], HasSubstr("<rect id=\"blurred\">"));
}

// class="outline" defines the silhouette: a shadow painted beside the body is left out.
TEST(SvgImportPaintTest, OutlineClassDefinesTheSilhouette) {
  Imported im = ImportOk(Svg(R"svg(
    <ellipse id="shadow" cx="100" cy="180" rx="60" ry="10" fill="#888"/>
    <circle class="outline" cx="100" cy="90" r="60" fill="#f00"/>
    <circle cx="80" cy="80" r="5" fill="#000"/>)svg"));
  EXPECT_EQ(im.info.source, SilhouetteSource::kOutlineClass);
  ASSERT_EQ(im.drawing.outlines.size(), 1u);
  EXPECT_NEAR(Area(im.drawing), std::numbers::pi * 60 * 60, 40.0);
  EXPECT_EQ(im.drawing.art.size(), 3u);  // the shadow is still art
}

// Open and self-intersecting fills are resolved by their fill-rule.
TEST(SvgImportPaintTest, SelfIntersectingFillIsResolvedByTheUnion) {
  // A bow tie: the path crosses itself at (100, 100).
  Imported im = ImportOk(Svg(R"svg(<rect width="200" height="20" y="180"/>
      <path d="M20 20 L180 180 L180 20 L20 180" fill="#00f"/>)svg"));
  for (const Outline& o : im.drawing.outlines) {
    EXPECT_FALSE(FindSelfIntersection(o.points, 100000, nullptr).has_value());
  }
}

// Errors: a drawing of hairlines only, paint only outside the view box, nothing painted.
TEST(SvgImportPaintTest, HairlinesOnlyIsAnError) {
  absl::StatusOr<Drawing> d = ImportSvg(
      Svg(R"svg(<path d="M10 10 L190 190" fill="none" stroke="#000" stroke-width="0.2"/>)svg"));
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("nowhere wider than the gap tolerance"));
}

// Paint entirely outside the viewBox imports (coordinates are user units as written), with a
// warning: a browser would show nothing. Paint partly inside gets none.
TEST(SvgImportPaintTest, PaintOutsideTheViewBoxIsWarnedAbout) {
  Imported outside = ImportOk(Svg(R"svg(<rect x="500" y="500" width="50" height="50" fill="#f00"/>
      <circle cx="-300" cy="40" r="20"/>)svg"));
  EXPECT_EQ(outside.drawing.outlines.size(), 2u);
  ASSERT_EQ(outside.info.warnings.size(), 1u);
  EXPECT_THAT(outside.info.warnings[0], HasSubstr("outside the viewBox"));
  Imported partly = ImportOk(Svg(R"svg(<rect x="150" y="150" width="100" height="100"/>)svg"));
  EXPECT_TRUE(partly.info.warnings.empty());
}

// Coordinates beyond |x| <= 1e9 are left to the service's coordinate check (no union).
TEST(SvgImportPaintTest, HugeCoordinatesSkipTheUnion) {
  Imported im = ImportOk(Svg(R"svg(<path d="M 0 0 L 1e308 0 L 0 1e308 Z"/>)svg"));
  ASSERT_EQ(im.drawing.outlines.size(), 1u);
  EXPECT_EQ(im.drawing.outlines[0].points[1].x(), 1e308);
}

TEST(SvgImportPaintTest, ZeroWidthStrokeIsNotPaint) {
  SvgImportInfo info;
  absl::StatusOr<Drawing> d =
      ImportSvg(Svg(R"svg(<path id="p" d="M10 10 L190 190" fill="none" stroke="#000"
          stroke-width="0"/>)svg"),
                {}, &info);
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("nothing is painted"));
}

TEST(SvgImportPaintTest, TooManyLayersIsResourceExhausted) {
  std::string body;
  for (int i = 0; i < 20; ++i) {
    body += "<rect x=\"" + std::to_string(i * 5) + "\" width=\"4\" height=\"4\"/>";
  }
  SvgImportOptions options;
  options.max_layers = 10;
  absl::StatusOr<Drawing> d = ImportSvg(Svg(body), options);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(d.status().message(), HasSubstr("more than 10 painted layers"));
}

TEST(SvgImportPaintTest, NegativeStrokeWidthNamesTheElement) {
  absl::StatusOr<Drawing> d = ImportSvg(
      Svg(R"svg(<rect id="r" width="50" height="50" stroke="#000" stroke-width="-2"/>)svg"));
  ASSERT_FALSE(d.ok());
  EXPECT_THAT(d.status().message(), HasSubstr("id=\"r\""));
  EXPECT_THAT(d.status().message(), HasSubstr("stroke-width is negative"));
}

// Layers are named by data-layer on the element or a group around it.
TEST(SvgImportPaintTest, DataLayerNamesLayers) {
  Imported im = ImportOk(Svg(R"svg(<g data-layer="body"><rect width="50" height="50"/></g>
      <circle data-layer="eye" cx="20" cy="20" r="5" fill="#fff"/>)svg"));
  ASSERT_EQ(im.drawing.art.size(), 2u);
  EXPECT_EQ(im.drawing.art[0].name, "body");
  EXPECT_EQ(im.drawing.art[1].name, "eye");
}

// Dashes: the pattern's pieces along a polyline, offset and zero-length dashes included.
TEST(DashPolylineTest, SplitsAlongThePattern) {
  const Points line = {Point(0, 0), Point(10, 0)};
  std::vector<Points> pieces = DashPolyline(line, false, {2, 1}, 0);
  ASSERT_EQ(pieces.size(), 4u);  // [0,2] [3,5] [6,8] [9,10]
  EXPECT_NEAR(pieces[1].front().x(), 3, 1e-12);
  EXPECT_NEAR(pieces[3].back().x(), 10, 1e-12);
  std::vector<Points> shifted = DashPolyline(line, false, {2, 1}, 1);
  ASSERT_FALSE(shifted.empty());
  EXPECT_NEAR(shifted[0].back().x(), 1, 1e-12);
  std::vector<Points> dots = DashPolyline(line, false, {0, 5}, 0);
  ASSERT_GE(dots.size(), 2u);  // points at 0 and 5 (and 10, where the path ends)
  EXPECT_EQ(dots[0].front(), Point(0, 0));
  EXPECT_EQ(dots[0].back(), Point(0, 0));
  EXPECT_EQ(dots[1].front(), Point(5, 0));
}

}  // namespace
}  // namespace inbetween::solver
