// Contact sheet: every key frame plus a few evenly spaced inbetweens in a grid, each cell
// labelled with its frame number ("key" for key frames), for reviewing a sequence at a glance.
#pragma once

#include <filesystem>
#include <vector>

#include "absl/status/statusor.h"
#include "client/render/frame_set.h"
#include "client/render/raster.h"
#include "client/render/rgba_image.h"

namespace inbetween::render {

struct ContactSheetOptions {
  int cell_width = 256;  // pixels per cell image; its height follows the frames' aspect
  int columns = 4;       // at most; fewer when there are fewer cells
  int inbetweens = 6;    // evenly spaced non-key frames added to the keys
  std::string fill = "#3b7dd8";
  bool drawing_fills = true;  // FrameSet::fills (blended per frame) win over `fill` when present
  bool mesh_overlay = false;
  bool art = true;  // FrameSet::art when present, else the silhouette (RasterOptions::art)
};

// Height of the label strip under each cell image, in pixels.
inline constexpr int kContactSheetLabelHeight = 20;

// Positions in frames.frames shown on the sheet, ascending: every key that names an existing
// frame, plus `inbetweens` frames evenly spaced over the sequence (fewer if frames run out).
std::vector<size_t> ContactSheetFrames(const FrameSet& frames, int inbetweens);

// The sheet: columns = min(options.columns, cells), rows = ceil(cells / columns);
// width = columns * cell_width, height = rows * (cell image height + kContactSheetLabelHeight).
absl::StatusOr<RgbaImage> RenderContactSheet(const FrameSet& frames,
                                             const ContactSheetOptions& options = {});

// RenderContactSheet written as a PNG.
absl::Status WriteContactSheet(const std::filesystem::path& path, const FrameSet& frames,
                               const ContactSheetOptions& options = {});

}  // namespace inbetween::render
