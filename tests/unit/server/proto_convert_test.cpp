// Proto <-> solver conversions (server/proto_convert.cpp): art comes back field for field, the
// proto's UNSPECIFIED and unknown line caps and joins read as SVG's initial values, and the import
// report carries every number of SvgImportInfo.
#include "server/proto_convert.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

TEST(ProtoConvertTest, ArtRoundTripsFieldForField) {
  const std::vector<solver::ArtLayer> art = SampleArt();
  google::protobuf::RepeatedPtrField<v1::ArtLayer> proto;
  ToProto(art, &proto);
  ASSERT_EQ(proto.size(), 2);
  EXPECT_EQ(proto[0].id(), "body");
  EXPECT_EQ(proto[0].name(), "torso");
  EXPECT_TRUE(proto[0].has_fill());
  EXPECT_FALSE(proto[0].has_stroke());
  EXPECT_FALSE(proto[1].has_fill());
  EXPECT_EQ(proto[1].stroke().cap(), v1::LINE_CAP_ROUND);
  EXPECT_EQ(proto[1].stroke().join(), v1::LINE_JOIN_BEVEL);
  ExpectSameArt(FromProto(proto), art);

  // Through the wire format too (what a store or an archive keeps).
  google::protobuf::RepeatedPtrField<v1::ArtLayer> parsed;
  for (const v1::ArtLayer& layer : proto) {
    ASSERT_TRUE(parsed.Add()->ParseFromString(layer.SerializeAsString()));
  }
  ExpectSameArt(FromProto(parsed), art);
}

TEST(ProtoConvertTest, EmbeddedArtRoundTripsAndIndicesAreChecked) {
  const std::vector<solver::Triangle> triangles = {{0, 1, 2}, {0, 2, 3}};
  solver::EmbeddedArt art;
  art.key = 1;
  art.num_vertices = 4;
  art.layers.push_back({.paint = SampleArt()[0], .paths = {}});
  art.layers[0].paint.paths.clear();
  solver::EmbeddedPath& path = art.layers[0].paths.emplace_back();
  path.closed = true;
  for (int t : {0, 1, 1}) {
    solver::EmbeddedPoint& e = path.points.emplace_back();
    e.triangle = t;
    e.corners = triangles[t];
    e.barycentric = {0.25 + t, 0.5, 0.25 - t};
  }
  v1::KeyArt proto;
  ToProto(art, &proto);
  absl::StatusOr<solver::EmbeddedArt> back = EmbeddedArtFromProto(proto, triangles, 4, "art[1]");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->key, 1);
  EXPECT_EQ(back->num_vertices, 4);
  ASSERT_EQ(back->layers.size(), 1u);
  EXPECT_EQ(back->layers[0].paint.id, "body");
  EXPECT_TRUE(back->layers[0].paint.paths.empty());
  ASSERT_EQ(back->layers[0].paths.size(), 1u);
  EXPECT_TRUE(back->layers[0].paths[0].closed);
  ASSERT_EQ(back->layers[0].paths[0].points.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const solver::EmbeddedPoint& got = back->layers[0].paths[0].points[i];
    EXPECT_EQ(got.triangle, path.points[i].triangle);
    EXPECT_EQ(got.corners, path.points[i].corners);
    EXPECT_EQ(got.barycentric, path.points[i].barycentric);
  }

  v1::KeyArt bad = proto;
  bad.mutable_layers(0)->mutable_paths(0)->set_triangles(2, 2);
  EXPECT_EQ(EmbeddedArtFromProto(bad, triangles, 4, "art[1]").status().message(),
            "art[1].layers[0].paths[0].triangles[2] refers to triangle 2 of 2");
  bad = proto;
  bad.mutable_layers(0)->mutable_paths(0)->add_barycentric(0.5);
  EXPECT_EQ(EmbeddedArtFromProto(bad, triangles, 4, "art[1]").status().message(),
            "art[1].layers[0].paths[0] has 10 barycentric coordinates for 3 points (3 per point)");
}

TEST(ProtoConvertTest, UnspecifiedCapAndJoinAreButtAndMiter) {
  v1::ArtLayer layer;
  layer.mutable_stroke()->set_width(2);
  EXPECT_EQ(FromProto(layer).stroke->cap, solver::LineCap::kButt);
  EXPECT_EQ(FromProto(layer).stroke->join, solver::LineJoin::kMiter);
  layer.mutable_stroke()->set_cap(static_cast<v1::LineCap>(17));  // a later version's value
  layer.mutable_stroke()->set_join(static_cast<v1::LineJoin>(17));
  EXPECT_EQ(FromProto(layer).stroke->cap, solver::LineCap::kButt);
  EXPECT_EQ(FromProto(layer).stroke->join, solver::LineJoin::kMiter);
  for (auto [cap, want] : {std::pair{solver::LineCap::kButt, v1::LINE_CAP_BUTT},
                           {solver::LineCap::kSquare, v1::LINE_CAP_SQUARE}}) {
    solver::ArtLayer art;
    art.stroke.emplace().cap = cap;
    v1::ArtLayer out;
    ToProto(art, &out);
    EXPECT_EQ(out.stroke().cap(), want);
    EXPECT_EQ(out.stroke().join(), v1::LINE_JOIN_MITER);
  }
  solver::ArtLayer round;
  round.stroke.emplace().join = solver::LineJoin::kRound;
  v1::ArtLayer out;
  ToProto(round, &out);
  EXPECT_EQ(out.stroke().join(), v1::LINE_JOIN_ROUND);
  EXPECT_EQ(FromProto(out).stroke->join, solver::LineJoin::kRound);
}

TEST(ProtoConvertTest, ImportReportCarriesEveryNumber) {
  solver::SvgImportInfo info;
  info.source = solver::SilhouetteSource::kOutlineClass;
  info.cleaning = {.gaps_closed = 1,
                   .slits_closed = 2,
                   .islands_dropped = 3,
                   .holes_dropped = 4,
                   .gap_width = 0.25,
                   .min_area = 1.0 / 3.0};
  info.warnings = {"<text id=\"t\"> (line 4): text is not imported", "second"};
  const v1::ImportReport report = ToProto(info, 7);
  EXPECT_EQ(report.silhouette_source(), v1::SILHOUETTE_SOURCE_OUTLINE_CLASS);
  EXPECT_EQ(report.gaps_closed(), 1u);
  EXPECT_EQ(report.slits_closed(), 2u);
  EXPECT_EQ(report.islands_dropped(), 3u);
  EXPECT_EQ(report.holes_dropped(), 4u);
  EXPECT_EQ(report.gap_width(), 0.25);
  EXPECT_EQ(report.min_area(), 1.0 / 3.0);
  ASSERT_EQ(report.warnings_size(), 2);
  EXPECT_EQ(report.warnings(0), info.warnings[0]);
  EXPECT_EQ(report.warnings(1), "second");
  EXPECT_EQ(report.art_layers(), 7u);

  info.source = solver::SilhouetteSource::kElements;
  EXPECT_EQ(ToProto(info, 0).silhouette_source(), v1::SILHOUETTE_SOURCE_ELEMENTS);
  info.source = solver::SilhouetteSource::kUnion;
  EXPECT_EQ(ToProto(info, 0).silhouette_source(), v1::SILHOUETTE_SOURCE_UNION);
}

}  // namespace
}  // namespace inbetween::server::testing
