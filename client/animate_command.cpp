// `inbetween animate` (see animate_command.h).
#include "client/animate_command.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "client/frames_output.h"
#include "client/progress_bar.h"

namespace inbetween::client {
namespace {

absl::StatusOr<std::string> ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot open ", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

absl::StatusOr<v1::Method> ParseMethod(const std::string& name) {
  if (name == "linear") return v1::METHOD_LINEAR;
  if (name == "alexa") return v1::METHOD_ALEXA;
  if (name == "zhu17") return v1::METHOD_ZHU17;
  return absl::InvalidArgumentError(
      absl::StrCat("--method: unknown method '", name, "' (expected linear, alexa or zhu17)"));
}

absl::Status Annotate(const absl::Status& status, const std::string& context) {
  return absl::Status(status.code(), absl::StrCat(context, ": ", status.message()));
}

}  // namespace

absl::Status RunAnimate(const AnimateOptions& options, InbetweenClient& client) {
  if (options.drawings.size() < 2 || options.drawings.size() > 16) {
    return absl::InvalidArgumentError(absl::StrCat("animate needs 2 to 16 drawings, got ",
                                                   options.drawings.size()));
  }
  absl::StatusOr<v1::Method> method = ParseMethod(options.method);
  if (!method.ok()) return method.status();

  absl::StatusOr<v1::Session> session = client.CreateSession("inbetween animate");
  if (!session.ok()) return Annotate(session.status(), "create session");

  for (size_t i = 0; i < options.drawings.size(); ++i) {
    const auto& path = options.drawings[i];
    absl::StatusOr<std::string> svg = ReadFile(path);
    if (!svg.ok()) return svg.status();
    auto put = client.PutSvgDrawing(*session, path.filename().string(), *svg);
    if (!put.ok()) {
      return Annotate(put.status(), absl::StrCat("drawing ", i + 1, " (", path.string(), ")"));
    }
    *session = put->session();
  }

  ProgressBar bar;
  auto built = client.BuildMultimesh(*session, [&](const v1::Progress& p) {
    if (!options.quiet) bar.Update(p.stage(), p.fraction());
  });
  bar.Finish();
  if (!built.ok()) return Annotate(built.status(), "build multimesh");

  v1::InbetweenParameters parameters;
  parameters.set_frames(options.frames);
  parameters.set_method(*method);
  auto frames = client.Inbetween(session->id(), parameters,
                                 [&](const v1::InbetweenFrame& f, uint32_t total) {
                                   if (!options.quiet) {
                                     bar.Update("frames", total ? (f.index() + 1.0) / total : 1.0);
                                   }
                                 });
  bar.Finish();
  if (!frames.ok()) return Annotate(frames.status(), "inbetween");

  render::SvgFrameOptions svg_options;
  svg_options.mesh_overlay = options.mesh_overlay;
  absl::Status written = WriteFrames(options.out_dir, *frames, svg_options);
  if (!written.ok()) return written;

  uint32_t inverted = 0;
  for (const auto& f : frames->frames) inverted += f.stats().inverted_triangles();
  if (!options.quiet) {
    std::fprintf(stderr, "%zu frames, %d triangles, %d vertices, %u inverted triangles\n",
                 frames->frames.size(), frames->header.triangles_size(),
                 frames->frames.empty() ? 0 : frames->frames[0].vertices_size(), inverted);
  }
  std::printf("%s\n", (options.out_dir / "frames.json").string().c_str());
  return absl::OkStatus();
}

int ExitCodeFor(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kOk:
      return 0;
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kFailedPrecondition:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kOutOfRange:
      return 3;  // the input (drawings, files, parameters) is the problem
    case absl::StatusCode::kUnavailable:
    case absl::StatusCode::kDeadlineExceeded:
    case absl::StatusCode::kUnauthenticated:
    case absl::StatusCode::kPermissionDenied:
      return 4;  // the server could not be reached or refused us
    case absl::StatusCode::kCancelled:
      return 130;  // interrupted (Ctrl-C)
    default:
      return 5;  // anything else: a server-side failure
  }
}

}  // namespace inbetween::client
