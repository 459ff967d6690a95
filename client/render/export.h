// One entry point for every output format of `inbetween animate` / `inbetween render`:
// SVG frames, frames.json, PNG frames, animated GIF and WebP, Lottie JSON and a contact sheet.
// Files (in DIR): frame_NNNN.svg, frames.json, frame_NNNN.png, animation.gif, animation.webp,
// animation.lottie.json, contact_sheet.png (NNNN = FrameData::index, 4 digits).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/render/frame_set.h"

namespace inbetween::render {

// Every format name ExportOptions::formats accepts.
inline constexpr std::array<std::string_view, 7> kExportFormats = {
    "svg", "json", "png", "gif", "webp", "lottie", "contact"};

struct ExportOptions {
  std::filesystem::path dir;                                  // created if missing
  std::vector<std::string> formats = {"svg", "json", "gif"};  // any of kExportFormats
  int width = 512;               // raster and Lottie width in px; height from the aspect ratio
  double fps = 24;               // GIF, WebP and Lottie frame rate
  std::string fill = "#3b7dd8";  // shape colour, #rgb / #rrggbb (see ParseColor)
  // The drawings' own fills (FrameSet::fills, blended per frame) instead of `fill` when present.
  bool drawing_fills = true;
  // The drawings' art (FrameSet::art) on SVG, PNG, GIF, WebP, Lottie and the contact sheet when
  // the set has art; false (or no art): the one-colour silhouette (`fill` / the drawings' fills).
  bool art = true;
  bool mesh_overlay = false;  // triangle edges on SVG, PNG, GIF, WebP and contact sheet
  bool transparent = false;   // PNG, GIF (1-bit) and WebP background; else white
  bool webp_lossless = true;  // else lossy at webp_quality
  float webp_quality = 80;    // 0..100
  // Called as work completes: a stage name ("frames", "gif", "webp", "lottie", "contact",
  // "svg", "json"), and done out of total steps of that stage.
  std::function<void(std::string_view stage, int done, int total)> progress;
};

struct ExportReport {
  std::vector<std::filesystem::path> files;  // written, in DIR
  uint64_t bytes = 0;                        // total size of `files`
};

// "svg,json,gif" -> {"svg", "json", "gif"} (whitespace trimmed, duplicates dropped), or
// InvalidArgument naming the unknown format and listing the valid ones.
absl::StatusOr<std::vector<std::string>> ParseFormats(const std::string& list);

// Writes the requested formats of `frames` into options.dir. Everything is validated and the
// encoders set up before any file is written; the files are produced in a hidden staging folder
// inside DIR and moved into place only when every format succeeded, so a failure leaves DIR as it
// was (a DIR the call created is removed again). Errors: InvalidArgument for unknown formats
// (naming it and listing the valid ones), bad options or frames; Unavailable for I/O.
absl::Status ExportFrames(const FrameSet& frames, const ExportOptions& options,
                          ExportReport* report = nullptr);

}  // namespace inbetween::render
