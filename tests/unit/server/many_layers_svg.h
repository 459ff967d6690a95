// A drawing of many small painted layers, for tests of art too large for one message.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inbetween::server::testing {

// `n` small filled discs on a grey ground, moved by `dx`, each its own layer drawn as a polygon
// of 120 points (about 3 MiB of art per key in mesh coordinates at n = 2,000); colours vary.
inline std::string ManyLayersSvg(int n, double dx) {
  std::string body;
  for (int i = 0; i < n; ++i) {
    const double cx = dx + (i % 50) * 4.0 + 1.75, cy = (i / 50) * 4.0 + 1.75;
    body += "<polygon points=\"";
    for (int j = 0; j < 120; ++j) {
      const double a = 2 * M_PI * j / 120;
      absl::StrAppendFormat(&body, "%.3f,%.3f ", cx + 1.7 * std::cos(a), cy + 1.7 * std::sin(a));
    }
    absl::StrAppendFormat(&body, R"(" fill="#%06x"/>)",
                          (static_cast<uint32_t>(i) * 2654435761u) & 0xffffffu);
  }
  return absl::StrCat(R"(<svg xmlns="http://www.w3.org/2000/svg" viewBox="-10 -10 230 190">)",
                      R"(<rect x="-2" y="-2" width="204" height="164" fill="#eeeeee"/>)", body,
                      "</svg>");
}

}  // namespace inbetween::server::testing
