// Every example under examples/ builds: each directory holding a project.json (docs/
// project-file.md) has its drawings imported with ImportSvg (cuts, openings and marks from the
// SVG convention or the project file) and meshed with BuildMultimesh; the multimesh must
// validate with no inverted triangle in any shape. Prints the meshing time per example.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "solver/io/svg_import.h"
#include "solver/mesh/build_multimesh.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> ExampleProjects() {
  std::vector<std::string> out;
  const fs::path root = fs::path(INBETWEEN_SOURCE_DIR) / "examples";
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file() && entry.path().filename() == "project.json") {
      out.push_back(fs::relative(entry.path().parent_path(), root).string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

Points ReadPolyline(const nlohmann::json& j) {
  Points p;
  for (const auto& xy : j) p.emplace_back(xy.at(0).get<double>(), xy.at(1).get<double>());
  return p;
}

class ExamplesBuildTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ExamplesBuildTest, BuildsAValidMultimesh) {
  const fs::path dir = fs::path(INBETWEEN_SOURCE_DIR) / "examples" / GetParam();
  const nlohmann::json project = nlohmann::json::parse(ReadFile(dir / "project.json"));
  ASSERT_EQ(project.at("version").get<int>(), 1);
  std::vector<Drawing> drawings;
  for (const nlohmann::json& entry : project.at("drawings")) {
    const std::string file =
        entry.is_string() ? entry.get<std::string>() : entry.at("file").get<std::string>();
    const std::string text = ReadFile(dir / file);
    ASSERT_FALSE(text.empty()) << file;
    EXPECT_LT(text.size(), 5000u) << file << ": keep example drawings small";
    absl::StatusOr<Drawing> drawing = ImportSvg(text);
    ASSERT_TRUE(drawing.ok()) << file << ": " << drawing.status();
    if (entry.is_object()) {
      for (const auto& cut : entry.value("cuts", nlohmann::json::array()))
        drawing->cuts.push_back(ReadPolyline(cut));
      for (const auto& opening : entry.value("openings", nlohmann::json::array()))
        drawing->openings.push_back(ReadPolyline(opening));
    }
    drawings.push_back(*std::move(drawing));
  }
  MultimeshOptions options;
  for (const auto& mark : project.value("correspondences", nlohmann::json::array())) {
    options.marks.push_back(ReadPolyline(mark));
  }
  if (project.contains("meshing")) {
    const nlohmann::json& m = project["meshing"];
    options.boundary_vertices = m.value("boundary_vertices", options.boundary_vertices);
    options.max_edge_relative = m.value("max_edge_relative", options.max_edge_relative);
    options.shape_bound = m.value("shape_bound", options.shape_bound);
  }
  MultimeshReport report;
  absl::StatusOr<Multimesh> mesh = BuildMultimesh(drawings, options, nullptr, nullptr, &report);
  ASSERT_TRUE(mesh.ok()) << GetParam() << ": " << mesh.status();
  EXPECT_TRUE(ValidateMultimesh(*mesh).ok()) << ValidateMultimesh(*mesh);
  EXPECT_TRUE(ValidateBoundaryLoops(*mesh).ok()) << ValidateBoundaryLoops(*mesh);
  EXPECT_TRUE(ValidateCohesiveEdges(*mesh).ok()) << ValidateCohesiveEdges(*mesh);
  ASSERT_EQ(mesh->num_shapes(), static_cast<int>(drawings.size()));
  for (int s = 0; s < mesh->num_shapes(); ++s) {
    EXPECT_EQ(CountInverted(mesh->triangles, mesh->shapes[s]), 0) << "drawing " << s + 1;
  }
  std::printf("[ example  ] %-32s %2zu drawings %5d vertices %5d triangles %3d cohesive %7.1f ms\n",
              GetParam().c_str(), drawings.size(), report.vertices, report.triangles,
              report.cohesive_edges, 1e3 * report.seconds);
  RecordProperty("vertices", report.vertices);
  RecordProperty("ms", static_cast<int>(1e3 * report.seconds));
}

INSTANTIATE_TEST_SUITE_P(Examples, ExamplesBuildTest, ::testing::ValuesIn(ExampleProjects()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace inbetween::solver
