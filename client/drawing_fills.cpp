// Drawing fill colours (see drawing_fills.h).
#include "client/drawing_fills.h"

#include <optional>

#include "solver/io/svg_import.h"

namespace inbetween::client {

std::vector<render::Rgba8> DrawingFills(const std::vector<std::string>& svg_texts) {
  std::vector<std::optional<render::Rgba8>> found;
  std::optional<render::Rgba8> first;
  for (const std::string& text : svg_texts) {
    solver::SvgImportInfo info;
    if (!solver::ImportSvg(text, {}, &info).ok()) return {};
    std::optional<render::Rgba8> c;
    if (info.fill_rgb) {
      const uint32_t rgb = *info.fill_rgb;
      c = render::Rgba8{static_cast<uint8_t>(rgb >> 16), static_cast<uint8_t>(rgb >> 8),
                        static_cast<uint8_t>(rgb), 255};
      if (!first) first = c;
    }
    found.push_back(c);
  }
  if (!first) return {};
  std::vector<render::Rgba8> out;
  for (const auto& c : found) out.push_back(c.value_or(*first));
  return out;
}

}  // namespace inbetween::client
