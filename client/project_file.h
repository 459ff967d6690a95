// The project file (JSON, versioned; schema in docs/project-file.md): the drawings, their cuts,
// openings and correspondences, key times and timing, every solver parameter, output settings.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "inbetween/v1/inbetween.pb.h"
#include "nlohmann/json.hpp"

namespace inbetween::client {

inline constexpr int kProjectFileVersion = 1;

using XY = std::array<double, 2>;
using XYs = std::vector<XY>;

struct ProjectDrawing {
  std::filesystem::path file;      // SVG, relative paths resolved against the project's folder
  std::optional<double> key_time;  // normalized [0, 1]
  std::vector<XYs> cuts;           // open polylines
  std::vector<XYs> openings;       // open polylines
};

// Largest gap_tolerance and min_area_fraction (PutDrawingRequest's range).
inline constexpr double kMaxImportFraction = 0.1;

// How the drawings' SVG is imported (PutDrawingRequest); unset = the server's default. Each in
// [0, kMaxImportFraction], 0 = off, as solver::SvgImportOptions reads them.
struct ImportSettings {
  // Gaps in the paint narrower than this fraction of its bounding-box diagonal are closed.
  std::optional<double> gap_tolerance;
  // Pieces of paint and holes smaller than this fraction of its bounding-box area are dropped.
  std::optional<double> min_area_fraction;
};

struct OutputSettings {
  std::vector<std::string> formats = {"svg", "json", "gif"};
  int width = 512;                  // raster width in pixels
  double fps = 24.0;                // animation rate for GIF/WebP/Lottie
  std::optional<std::string> fill;  // unset = the drawings' own fill colours, else the default
  bool mesh_overlay = false;
};

struct Project {
  int version = kProjectFileVersion;
  std::vector<ProjectDrawing> drawings;
  std::vector<XYs> correspondences;  // each: one point per drawing
  v1::Parameters parameters;         // meshing, comesh, inbetween (unset = server defaults)
  ImportSettings import_settings;    // "import"
  OutputSettings output;
};

// Parses and checks a project document. Unknown fields and wrong types are errors naming the
// JSON path ("$.inbetween.tau: expected a number, got string"); relative drawing paths are
// resolved against `base_dir`.
absl::StatusOr<Project> ParseProject(const nlohmann::json& doc,
                                     const std::filesystem::path& base_dir);

// "linear", "catmull-rom" / "catmull_rom", "ease-in-out" / "ease_in_out"; nullopt otherwise.
std::optional<v1::TimingCurve> TimingCurveFromName(std::string_view name);

// Key times for `drawings` drawings: one each, first 0, last 1, strictly increasing. The error
// message says what is wrong (without naming where the list came from).
absl::Status CheckKeyTimes(const std::vector<double>& key_times, size_t drawings);

// Reads and parses a project file; errors start with the file name.
absl::StatusOr<Project> LoadProject(const std::filesystem::path& path);

// The document for a project; drawing paths are written relative to `base_dir` when possible.
nlohmann::json ProjectToJson(const Project& project, const std::filesystem::path& base_dir);

}  // namespace inbetween::client
