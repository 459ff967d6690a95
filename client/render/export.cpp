// Export of every output format (see export.h).
#include "client/render/export.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/render/atomic_write.h"
#include "client/render/color.h"
#include "client/render/contact_sheet.h"
#include "client/render/gif_encoder.h"
#include "client/render/lottie_export.h"
#include "client/render/png_io.h"
#include "client/render/raster.h"
#include "client/render/svg_frames.h"
#include "client/render/webp_encoder.h"

namespace inbetween::render {
namespace {

namespace fs = std::filesystem;
using Wants = std::function<bool(std::string_view format)>;
using Progress = std::function<void(std::string_view stage, int done, int total)>;

std::string ValidFormats() {
  std::string list;
  for (std::string_view f : kExportFormats) {
    absl::StrAppend(&list, list.empty() ? "" : ", ", std::string(f));
  }
  return list;
}

absl::Status UnknownFormat(const std::string& name) {
  return absl::InvalidArgumentError(
      absl::StrCat("unknown output format \"", name, "\"; valid formats: ", ValidFormats()));
}

absl::StatusOr<std::vector<std::string>> CheckFormats(const std::vector<std::string>& formats) {
  std::vector<std::string> out;
  for (const std::string& f : formats) {
    if (std::find(kExportFormats.begin(), kExportFormats.end(), f) == kExportFormats.end()) {
      return UnknownFormat(f);
    }
    if (std::find(out.begin(), out.end(), f) == out.end()) out.push_back(f);
  }
  if (out.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("no output format given; valid formats: ", ValidFormats()));
  }
  return out;
}

// Contact sheet cells are half the frame width, within reason, 4 to a row.
ContactSheetOptions SheetOptions(const ExportOptions& options) {
  return {.cell_width = std::clamp(options.width / 2, 64, 512),
          .columns = 4,
          .inbetweens = 6,
          .fill = options.fill,
          .drawing_fills = options.drawing_fills,
          .mesh_overlay = options.mesh_overlay,
          .art = options.art};
}

// The GIF palette's anchor colours for frames drawn from art: every key layer's fill and stroke
// colour. Morphed colours blend corresponding layers' colours and cross-fades blend a layer into
// what lies under it, both on the palette's ramps between anchors. More than GifPalette's 16
// anchors: none (GifPalette's generic colour cube), which serves many colours evenly rather than
// the first 16 well and the rest badly.
std::vector<Rgba8> ArtPaletteColors(const FrameSet& frames, std::vector<Rgba8> colors) {
  constexpr size_t kMaxAnchors = 16;
  const auto add = [&](uint32_t rgb) {
    const Rgba8 c = {static_cast<uint8_t>(rgb >> 16), static_cast<uint8_t>(rgb >> 8),
                     static_cast<uint8_t>(rgb), 255};
    if (std::find(colors.begin(), colors.end(), c) == colors.end()) colors.push_back(c);
  };
  for (const solver::EmbeddedArt& key : frames.art) {
    for (const solver::EmbeddedLayer& layer : key.layers) {
      if (layer.paint.fill) add(layer.paint.fill->rgb);
      if (layer.paint.stroke) add(layer.paint.stroke->rgb);
    }
  }
  if (colors.size() > kMaxAnchors) colors.clear();
  return colors;
}

// A hidden folder inside DIR that is removed again unless released.
class StagingDir {
 public:
  static absl::StatusOr<StagingDir> Create(const fs::path& dir) {
    static std::atomic<int> counter{0};
    StagingDir s;
    std::error_code ec;
    s.created_dir_ = !fs::exists(dir, ec);
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
      return absl::UnavailableError(absl::StrCat("cannot create output directory ", dir.string(),
                                                 ec ? absl::StrCat(": ", ec.message()) : ""));
    }
    s.dir_ = dir;
    s.path_ = dir / absl::StrCat(".inbetween-export-", ::getpid(), "-", counter++);
    fs::create_directory(s.path_, ec);
    if (ec) {
      s.Discard();
      return absl::UnavailableError(
          absl::StrCat("cannot write in ", dir.string(), ": ", ec.message()));
    }
    return s;
  }
  StagingDir(StagingDir&& other) noexcept { *this = std::move(other); }
  StagingDir& operator=(StagingDir&& other) noexcept {
    std::swap(dir_, other.dir_);
    std::swap(path_, other.path_);
    std::swap(created_dir_, other.created_dir_);
    return *this;
  }
  ~StagingDir() { Discard(); }

  const fs::path& path() const { return path_; }

  // Moves every staged file into DIR.
  absl::Status Commit(ExportReport* report) {
    std::error_code ec;
    std::vector<fs::path> staged;
    for (const auto& entry : fs::directory_iterator(path_, ec)) staged.push_back(entry.path());
    if (ec) return absl::UnavailableError(absl::StrCat("cannot list ", path_.string()));
    std::sort(staged.begin(), staged.end());
    for (const fs::path& from : staged) {
      const fs::path to = dir_ / from.filename();
      const uint64_t size = fs::file_size(from, ec);
      fs::rename(from, to, ec);
      if (ec) {
        return absl::UnavailableError(
            absl::StrCat("cannot move ", from.string(), " to ", to.string(), ": ", ec.message()));
      }
      if (report != nullptr) {
        report->files.push_back(to);
        report->bytes += size;
      }
    }
    created_dir_ = false;  // DIR now holds output: keep it
    Discard();
    return absl::OkStatus();
  }

 private:
  StagingDir() = default;
  void Discard() {
    std::error_code ignored;
    if (!path_.empty()) fs::remove_all(path_, ignored);
    if (created_dir_ && !dir_.empty()) fs::remove(dir_, ignored);  // only if still empty
    path_.clear();
    created_dir_ = false;
  }

  fs::path dir_;
  fs::path path_;
  bool created_dir_ = false;
};

}  // namespace

absl::StatusOr<std::vector<std::string>> ParseFormats(const std::string& list) {
  std::vector<std::string> formats;
  for (absl::string_view part : absl::StrSplit(list, ',', absl::SkipWhitespace())) {
    formats.push_back(absl::AsciiStrToLower(absl::StripAsciiWhitespace(part)));
  }
  return CheckFormats(formats);
}

namespace {

// The GIF palette: background, the fill (or every key's fill, whose blends lie on the ramps
// between them), the overlay colour; with art, the art's colours instead of the fills.
std::vector<Rgba8> GifPalette(const FrameSet& frames, const ExportOptions& options,
                              const Rgba8& fill, const FrameRasterizer& raster) {
  std::vector<Rgba8> palette;
  if (!options.transparent) palette.push_back(raster.background());
  if (options.drawing_fills && !frames.fills.empty()) {
    for (const Rgba8& c : frames.fills) {
      if (std::find(palette.begin(), palette.end(), c) == palette.end()) palette.push_back(c);
    }
  } else {
    palette.push_back(fill);
  }
  if (options.mesh_overlay) palette.push_back(kMeshOverlayColor);
  if (raster.draws_art()) {
    std::vector<Rgba8> base;
    if (!options.transparent) base.push_back(raster.background());
    if (options.mesh_overlay) base.push_back(kMeshOverlayColor);
    palette = ArtPaletteColors(frames, std::move(base));
  }
  return palette;
}

// What the requested formats need, made before anything is written: a format that cannot be
// produced fails the export before a file appears.
struct Encoders {
  std::optional<FrameRasterizer> raster;  // png, gif, webp
  std::optional<GifEncoder> gif;
  std::optional<WebpEncoder> webp;
  std::optional<std::string> lottie;  // the document
  std::optional<RgbaImage> sheet;     // contact
};

absl::StatusOr<Encoders> MakeEncoders(const FrameSet& frames, const ExportOptions& options,
                                      const Wants& wants, const Rgba8& fill) {
  Encoders e;
  if (wants("png") || wants("gif") || wants("webp")) {
    absl::StatusOr<FrameRasterizer> r =
        FrameRasterizer::Create(frames, {.width = options.width,
                                         .fill = options.fill,
                                         .drawing_fills = options.drawing_fills,
                                         .mesh_overlay = options.mesh_overlay,
                                         .transparent = options.transparent,
                                         .art = options.art});
    if (!r.ok()) return r.status();
    e.raster.emplace(*std::move(r));
  }
  if (wants("gif")) {
    GifOptions gif_options = {.fps = options.fps,
                              .loop_count = 0,
                              .transparent = options.transparent,
                              .palette_colors = GifPalette(frames, options, fill, *e.raster)};
    absl::StatusOr<GifEncoder> gif =
        GifEncoder::Create(e.raster->width(), e.raster->height(), std::move(gif_options));
    if (!gif.ok()) return gif.status();
    e.gif.emplace(*std::move(gif));
  }
  if (wants("webp")) {
    absl::StatusOr<WebpEncoder> webp = WebpEncoder::Create(
        e.raster->width(), e.raster->height(),
        {.fps = options.fps, .lossless = options.webp_lossless, .quality = options.webp_quality});
    if (!webp.ok()) return webp.status();
    e.webp.emplace(*std::move(webp));
  }
  if (wants("lottie")) {
    absl::StatusOr<nlohmann::json> doc =
        LottieAnimation(frames, {.width = options.width,
                                 .fps = options.fps,
                                 .fill = options.fill,
                                 .drawing_fills = options.drawing_fills,
                                 .art = options.art});
    if (!doc.ok()) return doc.status();
    e.lottie = doc->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  if (wants("contact")) {
    absl::StatusOr<RgbaImage> sheet = RenderContactSheet(frames, SheetOptions(options));
    if (!sheet.ok()) return sheet.status();
    e.sheet.emplace(*std::move(sheet));
  }
  return e;
}

// The raster frames: each rendered once, then written as PNG and added to the GIF and WebP.
absl::Status WriteRasterFrames(const fs::path& out, const FrameSet& frames, const Wants& wants,
                               Encoders& e, const Progress& progress) {
  const int n = static_cast<int>(frames.frames.size());
  for (int f = 0; f < n; ++f) {
    const RgbaImage image = e.raster->Render(f);
    if (wants("png")) {
      const fs::path path = out / absl::StrFormat("frame_%04d.png", frames.frames[f].index);
      if (absl::Status s = WritePng(path, image); !s.ok()) return s;
    }
    if (e.gif) {
      if (absl::Status s = e.gif->AddFrame(image); !s.ok()) return s;
    }
    if (e.webp) {
      if (absl::Status s = e.webp->AddFrame(image); !s.ok()) return s;
    }
    progress("frames", f + 1, n);
  }
  return absl::OkStatus();
}

// A finished animation's bytes, written atomically as `name`.
absl::Status WriteAnimation(const fs::path& out, const char* name,
                            absl::StatusOr<std::string> bytes) {
  if (!bytes.ok()) return bytes.status();
  return WriteFileAtomically(out / name, *bytes);
}

// Every requested file, written into the staging folder `out`.
absl::Status WriteFiles(const fs::path& out, const FrameSet& frames, const ExportOptions& options,
                        const Wants& wants, Encoders& e, const Progress& progress) {
  if (wants("json")) {
    if (absl::Status s =
            WriteFileAtomically(out / "frames.json", FrameSetToJson(frames).dump() + "\n");
        !s.ok()) {
      return s;
    }
    progress("json", 1, 1);
  }
  if (wants("svg")) {
    if (absl::Status s = WriteSvgFrames(out, frames,
                                        {.fill = options.fill,
                                         .drawing_fills = options.drawing_fills,
                                         .mesh_overlay = options.mesh_overlay,
                                         .art = options.art});
        !s.ok()) {
      return s;
    }
    progress("svg", 1, 1);
  }
  if (e.raster) {
    if (absl::Status s = WriteRasterFrames(out, frames, wants, e, progress); !s.ok()) return s;
  }
  if (e.gif) {
    if (absl::Status s = WriteAnimation(out, "animation.gif", e.gif->Finish()); !s.ok()) return s;
    progress("gif", 1, 1);
  }
  if (e.webp) {
    if (absl::Status s = WriteAnimation(out, "animation.webp", e.webp->Finish()); !s.ok()) {
      return s;
    }
    progress("webp", 1, 1);
  }
  if (e.lottie) {
    if (absl::Status s = WriteFileAtomically(out / "animation.lottie.json", *e.lottie); !s.ok()) {
      return s;
    }
    progress("lottie", 1, 1);
  }
  if (e.sheet) {
    if (absl::Status s = WritePng(out / "contact_sheet.png", *e.sheet); !s.ok()) return s;
    progress("contact", 1, 1);
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ExportFrames(const FrameSet& frames, const ExportOptions& options,
                          ExportReport* report) {
  // 1. Validate everything and set up the encoders before touching the file system.
  absl::StatusOr<std::vector<std::string>> formats = CheckFormats(options.formats);
  if (!formats.ok()) return formats.status();
  const Wants wants = [&](std::string_view f) {
    return std::find(formats->begin(), formats->end(), f) != formats->end();
  };
  if (options.dir.empty()) return absl::InvalidArgumentError("no output directory given");
  if (!(options.fps > 0) || !std::isfinite(options.fps)) {
    return absl::InvalidArgumentError(
        absl::StrCat("frame rate ", options.fps, " must be positive"));
  }
  // The fill also goes verbatim into the SVG, so it is checked for every format.
  absl::StatusOr<Rgba8> fill = ParseColor(options.fill);
  if (!fill.ok()) return fill.status();
  if (absl::Status s = CheckFrameSet(frames); !s.ok()) return s;
  absl::StatusOr<Encoders> encoders = MakeEncoders(frames, options, wants, *fill);
  if (!encoders.ok()) return encoders.status();
  const Progress progress = [&](std::string_view stage, int done, int total) {
    if (options.progress) options.progress(stage, done, total);
  };

  // 2. Produce every file in the staging folder.
  absl::StatusOr<StagingDir> staging = StagingDir::Create(options.dir);
  if (!staging.ok()) return staging.status();
  if (absl::Status s = WriteFiles(staging->path(), frames, options, wants, *encoders, progress);
      !s.ok()) {
    return s;
  }

  // 3. Move the files into place.
  return staging->Commit(report);
}

}  // namespace inbetween::render
