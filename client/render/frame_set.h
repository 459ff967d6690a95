// Plain frame data for rendering and export: what frames.json holds, without gRPC types.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/render/color.h"
#include "nlohmann/json.hpp"
#include "solver/art/art_embedding.h"
#include "solver/core/art.h"

namespace inbetween::render {

using Vertex = std::array<double, 2>;

// What the service measured on a frame (frames.json "valid"; docs/file-formats.md).
struct FrameValidity {
  int inverted_triangles = 0;   // signed area <= 0
  int boundary_overlaps = 0;    // boundary vertices inside the shape + crossing boundary segments
  double min_area_ratio = 1.0;  // triangle area / its area blended over the drawings
  double max_area_ratio = 1.0;
  double hold_back = 0.0;  // how far non-overlap held the frame back (0 = not at all)
};

struct FrameData {
  int index = 0;
  double time = 0.0;                   // normalized [0, 1]
  std::vector<double> weights;         // example weights
  std::vector<Vertex> vertices;        // one per mesh vertex, user units (y down)
  std::optional<FrameValidity> valid;  // absent in frames.json written before this field
};

struct FrameSet {
  std::vector<std::array<int, 3>> triangles;  // shared by every frame
  std::vector<int> keys;                      // frame index of each key drawing
  std::vector<FrameData> frames;
  // Fill colour of each key drawing (input order) as the drawings gave it; empty = none known.
  std::vector<Rgba8> fills;
  // Each key drawing's art embedded in the mesh (input order; art[k].key == k), or empty: the
  // frames are drawn as their silhouette. frames.json "art" (docs/file-formats.md).
  std::vector<solver::EmbeddedArt> art;
};

// The art layers of frame `f` in paint order (solver::ArtForFrame of FrameSet::art with the
// frame's vertices and example weights). Errors when the set has no art or it does not fit the
// frame (CheckFrameSet rules that out for a checked set).
absl::StatusOr<std::vector<solver::ArtLayer>> FrameArt(const FrameSet& frames, size_t f);

// The fill of frame `f`: the key drawings' fills blended by the frame's example weights (clamped
// to [0, 255]; the first fill when the weights do not match), or nullopt without fills.
std::optional<Rgba8> FrameFill(const FrameSet& frames, size_t f);

// Parses a frames.json document (docs/file-formats.md). Errors name the JSON path
// ("frames[3].vertices[10]: expected [x, y]").
absl::StatusOr<FrameSet> FrameSetFromJson(const nlohmann::json& doc);

// Checks what every renderer relies on: at least one frame, the same vertex count in every frame,
// finite coordinates and triangle indices in range; with art, one embedded art per key whose
// points name triangles of the mesh, and per frame one finite weight per key, some > 0. Errors
// use frames.json paths.
absl::Status CheckFrameSet(const FrameSet& frames);

// The frames.json document for a frame set (inverse of FrameSetFromJson).
nlohmann::json FrameSetToJson(const FrameSet& frames);

}  // namespace inbetween::render
