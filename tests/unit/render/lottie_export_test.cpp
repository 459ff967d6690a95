// Tests client/render/lottie_export.cpp against the structural rules of the Lottie 5.x schema
// that lottie-web relies on: required keys and types, one path keyframe per frame, every path
// closed with equal v/i/o lengths and the same vertex count in every keyframe.
#include "client/render/lottie_export.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/unit/render/test_frames.h"

namespace inbetween::render {
namespace {

using json = nlohmann::json;

void ExpectStaticNumber(const json& property, const std::string& what) {
  ASSERT_TRUE(property.is_object()) << what;
  EXPECT_EQ(property.value("a", -1), 0) << what;
  ASSERT_TRUE(property.contains("k")) << what;
  EXPECT_TRUE(property["k"].is_number() || property["k"].is_array()) << what;
}

// A bezier path object: closed, v/i/o arrays of [x, y] pairs of equal length.
void ExpectClosedPath(const json& path, size_t vertices, double w, double h) {
  ASSERT_TRUE(path.is_object());
  EXPECT_EQ(path.value("c", false), true);
  for (const char* key : {"v", "i", "o"}) {
    ASSERT_TRUE(path.contains(key) && path[key].is_array()) << key;
    ASSERT_EQ(path[key].size(), vertices) << key;
    for (const json& p : path[key]) {
      ASSERT_TRUE(p.is_array() && p.size() == 2 && p[0].is_number() && p[1].is_number()) << key;
    }
  }
  for (const json& p : path["v"]) {  // inside the composition
    EXPECT_GE(p[0].get<double>(), 0);
    EXPECT_LE(p[0].get<double>(), w);
    EXPECT_GE(p[1].get<double>(), 0);
    EXPECT_LE(p[1].get<double>(), h);
  }
  for (const json& p : path["i"]) EXPECT_EQ(p, json::parse("[0, 0]"));
}

void ExpectValidLottie(const json& doc, int frames, size_t loops) {
  ASSERT_TRUE(doc.is_object());
  ASSERT_TRUE(doc["v"].is_string());
  EXPECT_EQ(doc["v"].get<std::string>().substr(0, 2), "5.");
  for (const char* key : {"fr", "ip", "op", "w", "h"}) {
    ASSERT_TRUE(doc.contains(key) && doc[key].is_number()) << key;
  }
  EXPECT_EQ(doc["ip"], 0);
  EXPECT_EQ(doc["op"], frames);
  EXPECT_GT(doc["w"].get<int>(), 0);
  EXPECT_GT(doc["h"].get<int>(), 0);
  ASSERT_TRUE(doc["layers"].is_array());
  ASSERT_EQ(doc["layers"].size(), 1u);
  const json& layer = doc["layers"][0];
  EXPECT_EQ(layer["ty"], 4);
  EXPECT_EQ(layer["ip"], 0);
  EXPECT_EQ(layer["op"], frames);
  EXPECT_EQ(layer["st"], 0);
  ASSERT_TRUE(layer["ks"].is_object());
  for (const char* key : {"o", "r", "p", "a", "s"}) ExpectStaticNumber(layer["ks"][key], key);
  ASSERT_TRUE(layer["shapes"].is_array());
  ASSERT_EQ(layer["shapes"].size(), 1u);
  const json& group = layer["shapes"][0];
  EXPECT_EQ(group["ty"], "gr");
  ASSERT_TRUE(group["it"].is_array());
  const json& items = group["it"];
  ASSERT_EQ(items.size(), loops + 2);  // paths, fill, transform (transform last)
  EXPECT_EQ(items.back()["ty"], "tr");
  for (const char* key : {"p", "a", "s", "r", "o"}) ExpectStaticNumber(items.back()[key], key);
  const json& fill = items[loops];
  EXPECT_EQ(fill["ty"], "fl");
  ExpectStaticNumber(fill["c"], "fill colour");
  ASSERT_EQ(fill["c"]["k"].size(), 4u);
  for (const json& c : fill["c"]["k"]) {
    EXPECT_GE(c.get<double>(), 0);
    EXPECT_LE(c.get<double>(), 1);
  }
  ExpectStaticNumber(fill["o"], "fill opacity");
  const double w = doc["w"], h = doc["h"];
  for (size_t l = 0; l < loops; ++l) {
    const json& sh = items[l];
    EXPECT_EQ(sh["ty"], "sh");
    const json& ks = sh["ks"];
    if (frames == 1) {
      EXPECT_EQ(ks["a"], 0);
      ExpectClosedPath(ks["k"], ks["k"]["v"].size(), w, h);
      continue;
    }
    EXPECT_EQ(ks["a"], 1);
    ASSERT_TRUE(ks["k"].is_array());
    ASSERT_EQ(ks["k"].size(), static_cast<size_t>(frames));  // one keyframe per frame
    const size_t vertices = ks["k"][0]["s"][0]["v"].size();
    EXPECT_GE(vertices, 3u);
    for (int f = 0; f < frames; ++f) {
      const json& key = ks["k"][f];
      EXPECT_EQ(key["t"], f);
      ASSERT_TRUE(key["s"].is_array());
      ASSERT_EQ(key["s"].size(), 1u);
      ExpectClosedPath(key["s"][0], vertices, w, h);  // same count: players interpolate
      if (f + 1 < frames) {
        for (const char* e : {"i", "o"}) {
          ASSERT_TRUE(key[e].is_object()) << e;
          EXPECT_TRUE(key[e]["x"].is_number() && key[e]["y"].is_number()) << e;
        }
      }
    }
  }
}

TEST(LottieExportTest, AnimationFollowsTheSchema) {
  const FrameSet set = testing::MorphingRing(15);
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 400, .fps = 30, .fill = "#ff8000"});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectValidLottie(*doc, 15, 2);
  EXPECT_EQ((*doc)["fr"], 30.0);
  EXPECT_EQ((*doc)["w"], 400);
  EXPECT_EQ((*doc)["layers"][0]["shapes"][0]["it"][2]["c"]["k"],
            json::parse("[1.0, 0.5019607843137255, 0.0, 1]"));
}

TEST(LottieExportTest, HolesWindAgainstTheOutsideForTheNonzeroFill) {
  const FrameSet set = testing::SquareWithHole();
  absl::StatusOr<json> doc = LottieAnimation(set, {.width = 100});
  ASSERT_TRUE(doc.ok()) << doc.status();
  ExpectValidLottie(*doc, 1, 2);
  const json& items = (*doc)["layers"][0]["shapes"][0]["it"];
  EXPECT_EQ(items[2]["r"], 1);  // nonzero
  std::vector<double> areas;
  for (int l = 0; l < 2; ++l) {
    const json& v = items[l]["ks"]["k"]["v"];
    double twice = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      const json& p = v[i];
      const json& q = v[(i + 1) % v.size()];
      twice += p[0].get<double>() * q[1].get<double>() - p[1].get<double>() * q[0].get<double>();
    }
    areas.push_back(twice / 2);
  }
  EXPECT_LT(areas[0] * areas[1], 0);  // opposite orientation
}

TEST(LottieExportTest, WritesAFileThatParsesBackAndReportsErrors) {
  const auto path = std::filesystem::temp_directory_path() / "inbetween_lottie_test.json";
  ASSERT_TRUE(WriteLottie(path, testing::MorphingRing(4), {.fps = 12}).ok());
  std::ifstream in(path);
  ExpectValidLottie(json::parse(in), 4, 2);
  std::filesystem::remove(path);
  EXPECT_FALSE(LottieAnimation(testing::MorphingRing(4), {.fps = 0}).ok());
  EXPECT_FALSE(LottieAnimation(testing::MorphingRing(4), {.fill = "nope"}).ok());
  EXPECT_FALSE(LottieAnimation(FrameSet{}).ok());
}

}  // namespace
}  // namespace inbetween::render
