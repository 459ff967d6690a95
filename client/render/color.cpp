// Colour parsing (see color.h).
#include "client/render/color.h"

#include <array>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inbetween::render {
namespace {

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  c = absl::ascii_tolower(c);
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

absl::StatusOr<Rgba8> ParseColor(std::string_view text) {
  static constexpr std::array<std::pair<std::string_view, Rgba8>, 6> kNames = {{
      {"black", {0, 0, 0, 255}},
      {"white", {255, 255, 255, 255}},
      {"red", {255, 0, 0, 255}},
      {"green", {0, 128, 0, 255}},
      {"blue", {0, 0, 255, 255}},
      {"gray", {128, 128, 128, 255}},
  }};
  const std::string lower = absl::AsciiStrToLower(std::string(text));
  for (const auto& [name, color] : kNames) {
    if (lower == name) return color;
  }
  const auto error = [&] {
    return absl::InvalidArgumentError(absl::StrCat(
        "colour \"", std::string(text), "\": expected #rgb, #rrggbb or #rrggbbaa (e.g. #3b7dd8)"));
  };
  if (text.empty() || text[0] != '#') return error();
  std::string_view hex = text.substr(1);
  std::array<int, 8> d{};
  for (size_t i = 0; i < hex.size() && i < d.size(); ++i) {
    d[i] = HexDigit(hex[i]);
    if (d[i] < 0) return error();
  }
  const auto byte = [&](int i) { return static_cast<uint8_t>(d[i] * 16 + d[i + 1]); };
  switch (hex.size()) {
    case 3:
      return Rgba8{static_cast<uint8_t>(d[0] * 17), static_cast<uint8_t>(d[1] * 17),
                   static_cast<uint8_t>(d[2] * 17), 255};
    case 6:
      return Rgba8{byte(0), byte(2), byte(4), 255};
    case 8:
      return Rgba8{byte(0), byte(2), byte(4), byte(6)};
    default:
      return error();
  }
}

std::string HexColor(const Rgba8& c) { return absl::StrFormat("#%02x%02x%02x", c.r, c.g, c.b); }

}  // namespace inbetween::render
