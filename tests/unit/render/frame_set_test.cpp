// Tests client/render/frame_set.cpp: frames.json round trip, errors with JSON paths, no
// exceptions on wrong types, and CheckFrameSet.
#include "client/render/frame_set.h"

#include <gtest/gtest.h>

#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

TEST(FrameSetTest, JsonRoundTripKeepsEverything) {
  const FrameSet set = testing::MorphingRing(5);
  absl::StatusOr<FrameSet> back =
      FrameSetFromJson(nlohmann::json::parse(FrameSetToJson(set).dump()));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->triangles, set.triangles);
  EXPECT_EQ(back->keys, set.keys);
  ASSERT_EQ(back->frames.size(), set.frames.size());
  for (size_t f = 0; f < set.frames.size(); ++f) {
    EXPECT_EQ(back->frames[f].index, set.frames[f].index);
    EXPECT_DOUBLE_EQ(back->frames[f].time, set.frames[f].time);
    EXPECT_EQ(back->frames[f].weights, set.frames[f].weights);
    EXPECT_EQ(back->frames[f].vertices, set.frames[f].vertices);
  }
  EXPECT_TRUE(CheckFrameSet(*back).ok());
}

TEST(FrameSetTest, ValidStatsRoundTripAndAreChecked) {
  FrameSet set = testing::MorphingRing(3);
  set.frames[1].valid = FrameValidity{2, 1, -0.5, 1.75};
  const nlohmann::json doc = FrameSetToJson(set);
  EXPECT_FALSE(doc["frames"][0].contains("valid"));  // frames without stats stay as before
  absl::StatusOr<FrameSet> back = FrameSetFromJson(nlohmann::json::parse(doc.dump()));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_FALSE(back->frames[0].valid.has_value());
  ASSERT_TRUE(back->frames[1].valid.has_value());
  EXPECT_EQ(back->frames[1].valid->inverted_triangles, 2);
  EXPECT_EQ(back->frames[1].valid->boundary_overlaps, 1);
  EXPECT_EQ(back->frames[1].valid->min_area_ratio, -0.5);
  EXPECT_EQ(back->frames[1].valid->max_area_ratio, 1.75);

  nlohmann::json bad = doc;
  bad["frames"][1]["valid"]["boundary_overlaps"] = -1;
  absl::StatusOr<FrameSet> rejected = FrameSetFromJson(bad);
  ASSERT_FALSE(rejected.ok());
  EXPECT_NE(rejected.status().message().find("frames[1].valid.boundary_overlaps"),
            std::string::npos)
      << rejected.status();
}

// Parses `text` and expects an InvalidArgument error mentioning `path`.
void ExpectErrorAt(const std::string& text, const std::string& path) {
  absl::StatusOr<FrameSet> set = FrameSetFromJson(nlohmann::json::parse(text));
  ASSERT_FALSE(set.ok()) << text;
  EXPECT_EQ(set.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(set.status().message().find(path), std::string::npos)
      << "expected \"" << path << "\" in: " << set.status();
}

TEST(FrameSetTest, ErrorsNameTheJsonPath) {
  ExpectErrorAt("[]", "$");
  ExpectErrorAt(R"({"keys": [], "frames": []})", "triangles");
  ExpectErrorAt(R"({"triangles": [[0, 1]], "keys": [], "frames": []})", "triangles[0]");
  ExpectErrorAt(R"({"triangles": [], "keys": ["a"], "frames": []})", "keys[0]");
  ExpectErrorAt(R"({"triangles": [], "keys": [], "frames": [{"vertices": [[0, 0], [1]]}]})",
                "frames[0].vertices[1]");
  ExpectErrorAt(
      R"({"triangles": [], "keys": [], "frames": [{"vertices": [[0, 0]]}, {"vertices": []}]})",
      "frames[1]");
  ExpectErrorAt(R"({"triangles": [[0, 1, 5]], "keys": [], "frames": [{"vertices": [[0, 0]]}]})",
                "triangles[0]");
}

TEST(FrameSetTest, WrongFieldTypesAreErrorsNotExceptions) {
  ExpectErrorAt(R"({"triangles": [], "keys": [], "frames": [{"index": "x", "vertices": []}]})",
                "frames[0].index");
  ExpectErrorAt(R"({"triangles": [], "keys": [], "frames": [{"time": [], "vertices": []}]})",
                "frames[0].time");
  ExpectErrorAt(
      R"({"triangles": [], "keys": [], "frames": [{"weights": [1, "0"], "vertices": []}]})",
      "frames[0].weights[1]");
  ExpectErrorAt(R"({"triangles": [], "keys": [], "frames": [{"weights": 1, "vertices": []}]})",
                "frames[0].weights");
}

TEST(FrameSetTest, CheckFrameSetRejectsWhatRenderersCannotDraw) {
  EXPECT_FALSE(CheckFrameSet(FrameSet{}).ok());
  FrameSet set = testing::TwoSquares();
  EXPECT_TRUE(CheckFrameSet(set).ok());
  set.triangles.push_back({0, 1, 99});
  absl::Status s = CheckFrameSet(set);
  EXPECT_NE(s.message().find("triangles[4]"), std::string::npos) << s;
  set = testing::MorphingRing(3);
  set.frames[2].vertices.pop_back();
  EXPECT_NE(CheckFrameSet(set).message().find("frames[2]"), std::string::npos);
  set = testing::MorphingRing(3);
  set.frames[1].vertices[4][1] = std::nan("");
  EXPECT_NE(CheckFrameSet(set).message().find("frames[1].vertices[4]"), std::string::npos);
}

}  // namespace
}  // namespace inbetween::render
