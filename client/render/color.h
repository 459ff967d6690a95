// Colours given as CSS-style hex strings ("#3b7dd8"), parsed once for the raster encoders.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace inbetween::render {

struct Rgba8 {
  uint8_t r = 0, g = 0, b = 0, a = 255;
  bool operator==(const Rgba8&) const = default;
};

// Accepts "#rgb", "#rrggbb", "#rrggbbaa" and the names black, white, red, green, blue, gray.
// The error names the string and the accepted forms.
absl::StatusOr<Rgba8> ParseColor(std::string_view text);

// "#rrggbb" (alpha dropped).
std::string HexColor(const Rgba8& c);

}  // namespace inbetween::render
