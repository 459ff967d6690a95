// ArtToSvgPaths: one <path> per painted layer, in paint order, with every paint attribute.
#include "solver/art/art_svg.h"

#include <gtest/gtest.h>

#include "tests/unit/solver/art/art_test_helpers.h"

namespace inbetween::solver {
namespace {

using art_test::FillLayer;
using art_test::StrokeLayer;

TEST(ArtSvgTest, PathsWithTheirPaintInOrder) {
  ArtLayer face = FillLayer({{0, 0}, {10, 0}, {10, 8}}, 0xf0c080, 0.5);
  face.paths.push_back({{{2, 2}, {3, 2}, {3, 3}}, true});
  face.fill->even_odd = true;
  face.opacity = 0.25;
  face.name = "face \"A\" & <B>";
  ArtLayer line = StrokeLayer({{1, 1}, {9.5, 7.25}}, 0x0000ff, 1.5);
  line.stroke->cap = LineCap::kRound;
  line.stroke->join = LineJoin::kBevel;
  line.stroke->opacity = 0.75;
  line.stroke->dashes = {2, 1};
  line.stroke->dash_offset = 0.5;
  ArtLayer miter = StrokeLayer({{0, 0}, {1, 0}, {1, 1}}, 0x102030, 2, true);
  miter.stroke->miter_limit = 10;
  ArtLayer unpainted = FillLayer({{0, 0}, {1, 1}, {0, 1}}, 0);
  unpainted.fill.reset();
  const std::string svg = ArtToSvgPaths({face, unpainted, line, miter});
  EXPECT_EQ(svg,
            "<path data-layer=\"face &quot;A&quot; &amp; &lt;B&gt;\" fill=\"#f0c080\" "
            "fill-opacity=\"0.5\" fill-rule=\"evenodd\" stroke=\"none\" opacity=\"0.25\" "
            "d=\"M0 0 L10 0 L10 8Z M2 2 L3 2 L3 3Z\"/>\n"
            "<path fill=\"none\" stroke=\"#0000ff\" stroke-width=\"1.5\" stroke-opacity=\"0.75\" "
            "stroke-linecap=\"round\" stroke-linejoin=\"bevel\" stroke-dasharray=\"2 1\" "
            "stroke-dashoffset=\"0.5\" d=\"M1 1 L9.5 7.25\"/>\n"
            "<path fill=\"none\" stroke=\"#102030\" stroke-width=\"2\" stroke-miterlimit=\"10\" "
            "d=\"M0 0 L1 0 L1 1Z\"/>\n");
}

TEST(ArtSvgTest, EmptyArtWritesNothing) {
  EXPECT_EQ(ArtToSvgPaths({}), "");
  ArtLayer empty = FillLayer({}, 0);
  EXPECT_EQ(ArtToSvgPaths({empty}), "");
}

}  // namespace
}  // namespace inbetween::solver
