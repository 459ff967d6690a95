// Tests client/project_file.cpp: schema checks with JSON paths, defaults, round trip.
#include "client/project_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace inbetween::client {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json Minimal() { return json::parse(R"({"version": 1, "drawings": ["a.svg", "b.svg"]})"); }

TEST(ProjectFileTest, MinimalProjectResolvesPathsAgainstTheBaseDir) {
  auto p = ParseProject(Minimal(), "/projects/walk");
  ASSERT_TRUE(p.ok()) << p.status();
  ASSERT_EQ(p->drawings.size(), 2u);
  EXPECT_EQ(p->drawings[1].file, std::filesystem::path("/projects/walk/b.svg"));
  EXPECT_FALSE(p->drawings[0].key_time.has_value());
  EXPECT_FALSE(p->parameters.inbetween().has_tau());
}

TEST(ProjectFileTest, FullProjectRoundTrips) {
  json doc = json::parse(R"({
    "version": 1,
    "drawings": [{"file": "a.svg", "key_time": 0, "cuts": [[[0,0],[1,1]]]},
                 {"file": "b.svg", "key_time": 1, "openings": [[[2,2],[3,3],[4,2]]]}],
    "correspondences": [[[0,0],[5,5]]],
    "import": {"gap_tolerance": 0.01, "min_area_fraction": 0},
    "meshing": {"boundary_vertices": 96, "shape_bound": 0.1, "corner_matching": "always"},
    "comesh": {"map_weight": 0.3, "max_outer_iterations": 7, "outline_corner_degrees": 40,
               "min_quality": 0.05, "slide_window": 0.15},
    "inbetween": {"method": "alexa", "frames": 30, "timing": "ease_in_out", "ease": [0.5],
                  "stiffness": [{"polygon": [[0,0],[1,0],[1,1]], "kappa": 10}],
                  "lambda": 2, "tau": 0.2, "alpha": 0.25, "epsilon": 0.5, "rho": 3,
                  "timestep": 0.05, "max_iterations": 40},
    "output": {"formats": ["svg", "gif"], "width": 256, "fps": 12, "fill": "#ff0000",
               "mesh_overlay": true}})");
  auto p = ParseProject(doc, "/base");
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(p->parameters.inbetween().method(), v1::METHOD_ALEXA);
  EXPECT_DOUBLE_EQ(p->parameters.inbetween().tau(), 0.2);
  EXPECT_DOUBLE_EQ(p->parameters.comesh().map_weight(), 0.3);
  EXPECT_DOUBLE_EQ(p->parameters.comesh().outline_corner_degrees(), 40.0);
  EXPECT_DOUBLE_EQ(p->parameters.comesh().min_quality(), 0.05);
  EXPECT_DOUBLE_EQ(p->parameters.comesh().slide_window(), 0.15);
  EXPECT_EQ(p->parameters.meshing().corner_matching(), v1::CORNER_MATCHING_ALWAYS);
  EXPECT_EQ(p->drawings[0].cuts.size(), 1u);
  EXPECT_EQ(p->drawings[1].openings[0].size(), 3u);
  EXPECT_EQ(p->output.width, 256);
  EXPECT_EQ(p->import_settings.gap_tolerance, 0.01);
  EXPECT_EQ(p->import_settings.min_area_fraction, 0.0);  // set: 0 = off, not the default
  json again = ProjectToJson(*p, "/base");
  EXPECT_EQ(again, doc) << again.dump(2);
}

struct BadCase {
  const char* json_text;
  const char* message;
};

class ProjectFileErrorTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(ProjectFileErrorTest, NamesTheJsonPath) {
  auto p = ParseProject(json::parse(GetParam().json_text), "/base");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(p.status().message(), HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, ProjectFileErrorTest,
    ::testing::Values(
        BadCase{R"([1,2])", "$: expected an object"},
        BadCase{R"({"drawings": ["a.svg", "b.svg"]})", "missing field 'version'"},
        BadCase{R"({"version": 2, "drawings": ["a.svg", "b.svg"]})", "unsupported version 2"},
        BadCase{R"({"version": 1, "drawings": ["a.svg"]})", "$.drawings: needs 2 to 16"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "colour": 1})",
                "$.colour: unknown field"},
        BadCase{R"({"version": 1, "drawings": ["a", {"file": 3}]})",
                "$.drawings[1].file: expected a string, got number"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "inbetween": {"tau": "big"}})",
                "$.inbetween.tau: expected a number, got string"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "inbetween": {"alpha": 2}})",
                "$.inbetween.alpha: value 2 out of range [0, 1]"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "comesh": {"outline_corner_degrees": 200}})",
                "$.comesh.outline_corner_degrees: value 200 out of range [0, 180]"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "import": {"gap_tolerance": 0.5}})",
                "$.import.gap_tolerance: value 0.5 out of range [0, 0.1]"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "import": {"min_area_fraction": -1}})",
                "$.import.min_area_fraction: value -1 out of range [0, 0.1]"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "import": {"flatten": 1}})",
                "$.import.flatten: unknown field"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "inbetween": {"method": "x"}})",
                "$.inbetween.method: unknown method 'x'"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "meshing": {"corner_matching": "sometimes"}})",
                "$.meshing.corner_matching: unknown corner matching 'sometimes'"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "meshing": {"boundary_alignment": "by eye"}})",
                "$.meshing.boundary_alignment: unknown boundary alignment 'by eye'"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "meshing": {"boundary_tolerance": 0.5}})",
                "$.meshing.boundary_tolerance"},
        BadCase{R"({"version": 1, "drawings": ["a", {"file": "b", "cuts": [[[0,0]]]}]})",
                "$.drawings[1].cuts[0]: needs at least 2 points"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "correspondences": [[[0,0]]]})",
                "$.correspondences[0]: needs at least 2 points"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"],
                    "inbetween": {"stiffness": [{"polygon": [[0,0],[1,0],[1,"x"]], "kappa": 1}]}})",
                "$.inbetween.stiffness[0].polygon[2][1]: expected a number"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "output": {"width": 1.5}})",
                "$.output.width: expected an integer"},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "output": {"fill": "bluish"}})",
                "$.output.fill: colour \"bluish\""},
        BadCase{R"({"version": 1, "drawings": ["a", "b"], "inbetween": {"timing": "bouncy"}})",
                "$.inbetween.timing: unknown timing curve 'bouncy'"},
        BadCase{R"({"version": 1, "drawings": [{"file": "a", "key_time": 0}, "b"]})",
                "$.drawings: key_time is set on 1 of 2 drawings"},
        BadCase{R"({"version": 1, "drawings": [{"file": "a", "key_time": 0},
                    {"file": "b", "key_time": 0.5}, {"file": "c", "key_time": 0.4}]})",
                "$.drawings: key_time: times must increase strictly: drawing 3"},
        BadCase{R"({"version": 1, "drawings": [{"file": "a", "key_time": 0},
                    {"file": "b", "key_time": 0.5}]})",
                "$.drawings: key_time: the first time must be 0 and the last 1"}));

TEST(ProjectFileTest, BoundaryAlignmentAndToleranceRoundTrip) {
  for (const char* name : {"features", "arc_length"}) {
    json doc = Minimal();
    doc["meshing"] = {{"boundary_alignment", name}, {"boundary_tolerance", 0.002}};
    auto p = ParseProject(doc, "/base");
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_NE(p->parameters.meshing().boundary_alignment(), v1::BOUNDARY_ALIGNMENT_UNSPECIFIED);
    EXPECT_DOUBLE_EQ(p->parameters.meshing().boundary_tolerance(), 0.002);
    const json back = ProjectToJson(*p, "/base")["meshing"];
    EXPECT_EQ(back["boundary_alignment"], name);
    EXPECT_DOUBLE_EQ(back["boundary_tolerance"].get<double>(), 0.002);
  }
  // Unset stays unset (the server's defaults) and is not written.
  auto p = ParseProject(Minimal(), "/base");
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_FALSE(p->parameters.meshing().has_boundary_tolerance());
  EXPECT_FALSE(ProjectToJson(*p, "/base").contains("meshing"));
}

TEST(ProjectFileTest, EveryCornerMatchingRoundTrips) {
  for (const char* name : {"when_arc_length_fails", "never", "always"}) {
    json doc = Minimal();
    doc["meshing"] = {{"corner_matching", name}};
    auto p = ParseProject(doc, "/base");
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_NE(p->parameters.meshing().corner_matching(), v1::CORNER_MATCHING_UNSPECIFIED);
    EXPECT_EQ(ProjectToJson(*p, "/base")["meshing"]["corner_matching"], name);
  }
  // Unset stays unset (the server's default) and is not written.
  auto p = ParseProject(Minimal(), "/base");
  ASSERT_TRUE(p.ok()) << p.status();
  EXPECT_EQ(p->parameters.meshing().corner_matching(), v1::CORNER_MATCHING_UNSPECIFIED);
  EXPECT_FALSE(ProjectToJson(*p, "/base").contains("meshing"));
}

TEST(ProjectFileTest, TimingAcceptsHyphensAndUnderscores) {
  for (const char* name : {"catmull-rom", "catmull_rom"}) {
    json doc = Minimal();
    doc["inbetween"] = {{"timing", name}};
    auto p = ParseProject(doc, "/base");
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_EQ(p->parameters.inbetween().timing(), v1::TIMING_CURVE_CATMULL_ROM);
  }
}

TEST(ProjectFileTest, FillIsOnlyWrittenWhenSet) {
  auto p = ParseProject(Minimal(), "/base");
  ASSERT_TRUE(p.ok());
  EXPECT_FALSE(p->output.fill.has_value());
  EXPECT_FALSE(ProjectToJson(*p, "/base")["output"].contains("fill"));
}

}  // namespace
}  // namespace inbetween::client
