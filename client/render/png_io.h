// PNG encoding and decoding of RgbaImage through cairo.
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/statusor.h"
#include "client/render/rgba_image.h"

namespace inbetween::render {

// The PNG file bytes of `image`.
absl::StatusOr<std::string> EncodePng(const RgbaImage& image);

// Writes `image` to `path` (temp name, then rename).
absl::Status WritePng(const std::filesystem::path& path, const RgbaImage& image);

// Reads a PNG file.
absl::StatusOr<RgbaImage> ReadPng(const std::filesystem::path& path);

}  // namespace inbetween::render
