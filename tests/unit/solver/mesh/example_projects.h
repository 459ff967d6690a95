// Test and benchmark helper: the example projects under examples/ (each directory holding a
// project.json, docs/project-file.md) read into the solver's inputs — the drawings imported with
// ImportSvg (cuts, openings and marks from the SVG convention or the project file) and the
// meshing options (correspondence marks, "meshing"). The project's inbetweening settings
// (stiffness regions, timing) are the CLI's business and are not read here.
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "solver/io/svg_import.h"
#include "solver/mesh/build_multimesh.h"

namespace inbetween::solver::example_projects {

// Paths relative to examples/ of every directory with a project.json, sorted.
inline std::vector<std::string> List() {
  namespace fs = std::filesystem;
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

// A gtest parameter name for example NAME (pentagon_star/hard1 -> pentagon_star_hard1); `info` is
// a ::testing::TestParamInfo<std::string> (a template here so that benchmarks need no gtest).
template <class ParamInfo>
std::string TestName(const ParamInfo& info) {
  std::string name = info.param;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

inline Points ReadPolyline(const nlohmann::json& j) {
  Points p;
  for (const auto& xy : j) p.emplace_back(xy.at(0).get<double>(), xy.at(1).get<double>());
  return p;
}

struct Example {
  std::vector<std::string> files;  // the drawings' SVG files, in project order
  std::vector<Drawing> drawings;
  MultimeshOptions options;
};

// Reads examples/NAME. Errors name the file and what is wrong.
inline absl::StatusOr<Example> Load(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(INBETWEEN_SOURCE_DIR) / "examples" / name;
  Example out;
  try {
    const nlohmann::json project = nlohmann::json::parse(ReadFile(dir / "project.json"));
    if (project.at("version").get<int>() != 1) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": project version is not 1"));
    }
    for (const nlohmann::json& entry : project.at("drawings")) {
      const std::string file =
          entry.is_string() ? entry.get<std::string>() : entry.at("file").get<std::string>();
      const std::string text = ReadFile(dir / file);
      if (text.empty()) return absl::NotFoundError(absl::StrCat(name, "/", file, ": empty"));
      absl::StatusOr<Drawing> drawing = ImportSvg(text);
      if (!drawing.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, "/", file, ": ", drawing.status().message()));
      }
      if (entry.is_object()) {
        for (const auto& cut : entry.value("cuts", nlohmann::json::array()))
          drawing->cuts.push_back(ReadPolyline(cut));
        for (const auto& opening : entry.value("openings", nlohmann::json::array()))
          drawing->openings.push_back(ReadPolyline(opening));
      }
      out.files.push_back(file);
      out.drawings.push_back(*std::move(drawing));
    }
    for (const auto& mark : project.value("correspondences", nlohmann::json::array())) {
      out.options.marks.push_back(ReadPolyline(mark));
    }
    if (project.contains("meshing")) {
      const nlohmann::json& m = project["meshing"];
      out.options.boundary_vertices = m.value("boundary_vertices", out.options.boundary_vertices);
      out.options.max_edge_relative = m.value("max_edge_relative", out.options.max_edge_relative);
      out.options.shape_bound = m.value("shape_bound", out.options.shape_bound);
    }
  } catch (const nlohmann::json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat(name, "/project.json: ", e.what()));
  }
  return out;
}

}  // namespace inbetween::solver::example_projects
