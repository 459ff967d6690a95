// SVG correspondence marks -> project correspondences (see svg_marks.h).
#include "client/svg_marks.h"

#include <map>
#include <optional>

#include "absl/strings/str_cat.h"
#include "solver/io/svg_import.h"

namespace inbetween::client {

absl::StatusOr<std::vector<XYs>> SvgMarkCorrespondences(const std::vector<std::string>& svg_texts) {
  const size_t n = svg_texts.size();
  std::map<int, std::vector<std::optional<XY>>> by_id;
  for (size_t d = 0; d < n; ++d) {
    absl::StatusOr<solver::Drawing> drawing = solver::ImportSvg(svg_texts[d]);
    if (!drawing.ok()) return std::vector<XYs>{};
    for (const solver::CorrespondenceMark& mark : drawing->marks) {
      std::vector<std::optional<XY>>& points = by_id[mark.id];
      points.resize(n);
      if (points[d]) {
        return absl::InvalidArgumentError(absl::StrCat(
            "drawing ", d + 1, ": correspondence mark data-corr=\"", mark.id, "\" appears twice"));
      }
      points[d] = XY{mark.point.x(), mark.point.y()};
    }
  }
  std::vector<XYs> out;
  for (const auto& [id, points] : by_id) {
    XYs mark;
    for (size_t d = 0; d < n; ++d) {
      if (!points[d]) {
        size_t has = 0;
        while (!points[has]) ++has;
        return absl::InvalidArgumentError(absl::StrCat("correspondence mark data-corr=\"", id,
                                                       "\" is in drawing ", has + 1,
                                                       " but not in drawing ", d + 1));
      }
      mark.push_back(*points[d]);
    }
    out.push_back(std::move(mark));
  }
  return out;
}

}  // namespace inbetween::client
