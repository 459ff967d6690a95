// frames.json "art": each key drawing's art embedded in the mesh (solver/art/art_embedding.h),
// written once for the whole sequence so that any frame's art follows from the frame's vertices
// and example weights alone (docs/file-formats.md, "art").
#pragma once

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "nlohmann/json.hpp"
#include "solver/art/art_embedding.h"

namespace inbetween::render {

// The "art" array: per key {"key", "layers": [{"id", "name", "opacity", "fill", "stroke",
// "paths": [{"closed", "points": [[triangle, b0, b1, b2], ...]}]}]}. A point's corners are not
// written: they are its triangle's vertices, in the triangle's order.
nlohmann::json ArtToJson(const std::vector<solver::EmbeddedArt>& art);

// Parses the "art" array for a mesh of `triangles` over `num_vertices` vertices. Errors name the
// JSON path ("art[0].layers[2].paths[0].points[5]: triangle 900 out of range [0, 120)").
absl::StatusOr<std::vector<solver::EmbeddedArt>> ArtFromJson(
    const nlohmann::json& art, const std::vector<std::array<int, 3>>& triangles, int num_vertices);

}  // namespace inbetween::render
