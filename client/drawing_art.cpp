// Drawing art on the client (see drawing_art.h).
#include "client/drawing_art.h"

#include "absl/strings/str_cat.h"
#include "server/proto_convert.h"

namespace inbetween::client {

absl::StatusOr<std::vector<solver::EmbeddedArt>> EmbedDrawingArt(
    const std::vector<std::string>& svg_texts, const v1::Multimesh& mesh,
    const solver::SvgImportOptions& import) {
  // The shared proto -> solver conversion, so the client reads the mesh as the service does.
  absl::StatusOr<solver::Multimesh> multimesh = server::MultimeshFromProto(mesh, "multimesh");
  if (!multimesh.ok()) return multimesh.status();
  if (multimesh->num_shapes() != static_cast<int>(svg_texts.size())) {
    return absl::InvalidArgumentError(absl::StrCat("the multimesh has ", multimesh->num_shapes(),
                                                   " shapes for ", svg_texts.size(), " drawings"));
  }
  std::vector<solver::EmbeddedArt> out;
  for (size_t k = 0; k < svg_texts.size(); ++k) {
    const std::string where = absl::StrCat("drawing ", k + 1, ": ");
    absl::StatusOr<solver::Drawing> drawing = solver::ImportSvg(svg_texts[k], import);
    if (!drawing.ok())
      return absl::Status(drawing.status().code(), absl::StrCat(where, drawing.status().message()));
    if (drawing->art.empty()) return absl::InvalidArgumentError(absl::StrCat(where, "no art"));
    absl::StatusOr<solver::EmbeddedArt> art =
        solver::EmbedArt(*multimesh, static_cast<int>(k), drawing->art);
    if (!art.ok()) {
      return absl::Status(art.status().code(), absl::StrCat(where, art.status().message()));
    }
    out.push_back(*std::move(art));
  }
  return out;
}

}  // namespace inbetween::client
