// The key drawings' art embedded in the multimesh, on the client: the service keeps drawings as
// outlines, while the CLI still has their SVG text, so it imports the art itself and embeds it in
// the mesh the service built (solver/art/art_embedding.h). Every renderer then draws a frame's
// art from its vertices and example weights (render::FrameArt).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/art/art_embedding.h"
#include "solver/io/svg_import.h"

namespace inbetween::client {

// One EmbeddedArt per drawing (input order), drawing k's art in shape k of `mesh`. `import`
// must flatten curves as the service did (its tolerance; gap and area settings only change the
// outlines, never the art). Errors: a drawing that does not import or has no art (nothing
// painted), a mesh whose shape count differs from the drawings', or EmbedArt's errors; each
// names the drawing ("drawing 2: ...").
absl::StatusOr<std::vector<solver::EmbeddedArt>> EmbedDrawingArt(
    const std::vector<std::string>& svg_texts, const v1::Multimesh& mesh,
    const solver::SvgImportOptions& import = {});

}  // namespace inbetween::client
