// The `inbetween` subcommands (see commands.h).
#include "client/commands.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/auto_topology.h"
#include "client/drawing_fills.h"
#include "client/frames_output.h"
#include "client/render/art_json.h"
#include "client/render/color.h"
#include "client/render/export.h"
#include "client/render/svg_frames.h"
#include "client/svg_marks.h"
#include "server/proto_convert.h"

namespace inbetween::client {
namespace {

using nlohmann::json;

absl::StatusOr<std::string> ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot open ", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The offset of the first byte that does not belong to a well-formed UTF-8 sequence, or -1.
std::ptrdiff_t FirstInvalidUtf8(const std::string& text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const unsigned char c = p[i];
    size_t len = c < 0x80           ? 1
                 : (c >> 5) == 0x6  ? 2
                 : (c >> 4) == 0xE  ? 3
                 : (c >> 3) == 0x1E ? 4
                                    : 0;
    if (len == 0 || (len == 2 && c < 0xC2) || i + len > n) return static_cast<std::ptrdiff_t>(i);
    for (size_t k = 1; k < len; ++k) {
      if ((p[i + k] >> 6) != 0x2) return static_cast<std::ptrdiff_t>(i);
    }
    if (len == 3) {
      const unsigned cp = ((c & 0xFu) << 12) | ((p[i + 1] & 0x3Fu) << 6) | (p[i + 2] & 0x3Fu);
      if (cp < 0x800 || (cp >= 0xD800 && cp <= 0xDFFF)) return static_cast<std::ptrdiff_t>(i);
    } else if (len == 4) {
      const unsigned cp = ((c & 0x7u) << 18) | ((p[i + 1] & 0x3Fu) << 12) |
                          ((p[i + 2] & 0x3Fu) << 6) | (p[i + 3] & 0x3Fu);
      if (cp < 0x10000 || cp > 0x10FFFF) return static_cast<std::ptrdiff_t>(i);
    }
    i += len;
  }
  return -1;
}

// A drawing's SVG text: the request carries it as a protobuf string, which must be UTF-8.
absl::StatusOr<std::string> ReadSvg(const std::filesystem::path& path) {
  absl::StatusOr<std::string> text = ReadFile(path);
  if (!text.ok()) return text;
  if (const std::ptrdiff_t bad = FirstInvalidUtf8(*text); bad >= 0) {
    const auto line = 1 + std::count(text->begin(), text->begin() + bad, '\n');
    return absl::InvalidArgumentError(absl::StrCat("not UTF-8 text: byte ", bad, " (line ", line,
                                                   ") is not part of a UTF-8 character; ",
                                                   "save the SVG as UTF-8"));
  }
  return text;
}

absl::Status WriteText(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) return absl::UnavailableError(absl::StrCat("cannot write ", tmp.string()));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return absl::UnavailableError(absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

absl::Status Annotate(const absl::Status& status, const std::string& context) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(context, ": ", status.message()));
}

absl::StatusOr<v1::Method> ParseMethod(const std::string& name) {
  if (name == "linear") return v1::METHOD_LINEAR;
  if (name == "alexa") return v1::METHOD_ALEXA;
  if (name == "zhu17") return v1::METHOD_ZHU17;
  return absl::InvalidArgumentError(
      absl::StrCat("--method: unknown method '", name, "' (expected linear, alexa or zhu17)"));
}

v1::Polyline ToPolyline(const XYs& points) {
  v1::Polyline line;
  for (const XY& p : points) {
    v1::Point* q = line.add_points();
    q->set_x(p[0]);
    q->set_y(p[1]);
  }
  return line;
}

void ShowProgress(const RunContext& ctx, const v1::Progress& p) {
  if (ctx.progress) ctx.progress->Update(p.stage(), p.fraction(), p.detail());
}

void FinishProgress(const RunContext& ctx) {
  if (ctx.progress) ctx.progress->Finish();
}

// An import setting as PutDrawingRequest takes it: unset = 0 (the server's default), 0 (off) =
// a negative value.
double RequestFraction(const std::optional<double>& value) {
  if (!value) return 0;
  return *value > 0 ? *value : -1;
}

// A project drawing as a PutDrawing request: its SVG text, name, key time, cuts and openings,
// and the project's import settings.
v1::PutDrawingRequest DrawingRequest(const ProjectDrawing& d, const ImportSettings& import,
                                     const v1::Session& session, std::string svg) {
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  request.set_gap_tolerance(RequestFraction(import.gap_tolerance));
  request.set_min_area_fraction(RequestFraction(import.min_area_fraction));
  request.mutable_drawing()->set_name(d.file.filename().string());
  request.mutable_drawing()->set_svg(std::move(svg));
  if (d.key_time) request.mutable_drawing()->set_key_time(*d.key_time);
  for (const auto& [lines, kind] : {std::pair{&d.cuts, v1::ELEMENT_KIND_CUT},
                                    std::pair{&d.openings, v1::ELEMENT_KIND_OPENING}}) {
    for (const XYs& line : *lines) {
      v1::TopologyElement* e = request.add_topology();
      e->set_kind(kind);
      *e->mutable_polyline() = ToPolyline(line);
    }
  }
  return request;
}

// The project's correspondences, else the marks drawn in the SVGs (data-corr), which the
// service does not keep with the drawings, set on the session (nothing when there are none).
absl::Status UploadCorrespondences(const Project& project, const std::vector<std::string>& svgs,
                                   const RunContext& ctx, v1::Session* session) {
  std::vector<XYs> marks = project.correspondences;
  if (marks.empty()) {
    absl::StatusOr<std::vector<XYs>> drawn = SvgMarkCorrespondences(svgs);
    if (!drawn.ok()) return drawn.status();
    marks = *std::move(drawn);
  }
  if (marks.empty()) return absl::OkStatus();
  v1::SetCorrespondencesRequest request;
  request.set_session_id(session->id());
  request.set_expected_version(session->version());
  for (const XYs& mark : marks) {
    *request.add_correspondences()->mutable_points() = ToPolyline(mark).points();
  }
  auto updated = ctx.client->SetCorrespondences(request);
  if (!updated.ok()) return Annotate(updated.status(), "correspondences");
  *session = *updated;
  return absl::OkStatus();
}

// Creates a session and uploads the project's drawings (with their cuts and openings) and
// correspondences. Errors name the drawing. `classes` (may be null) receives each drawing's
// equivalence class as the server imported it.
absl::StatusOr<v1::Session> UploadProject(const Project& project, const std::string& name,
                                          const RunContext& ctx,
                                          std::vector<v1::EquivalenceClass>* classes = nullptr) {
  auto session = ctx.client->CreateSession(name, project.parameters);
  if (!session.ok()) return Annotate(session.status(), "create session");
  std::vector<std::string> svgs;
  for (size_t i = 0; i < project.drawings.size(); ++i) {
    const ProjectDrawing& d = project.drawings[i];
    const std::string where = absl::StrCat("drawing ", i + 1, " (", d.file.string(), ")");
    auto svg = ReadSvg(d.file);
    if (!svg.ok()) return Annotate(svg.status(), where);
    svgs.push_back(*svg);
    auto put = ctx.client->PutDrawing(
        DrawingRequest(d, project.import_settings, *session, *std::move(svg)));
    if (!put.ok()) return Annotate(put.status(), where);
    *session = put->session();
    if (classes != nullptr) classes->push_back(put->equivalence_class());
  }
  if (absl::Status s = UploadCorrespondences(project, svgs, ctx, &*session); !s.ok()) return s;
  if (ctx.remote) std::printf("session %s\n", session->id().c_str());
  return session;
}

absl::StatusOr<v1::BuildMultimeshResult> Build(const v1::Session& session, const RunContext& ctx) {
  auto built =
      ctx.client->BuildMultimesh(session, [&](const v1::Progress& p) { ShowProgress(ctx, p); });
  FinishProgress(ctx);
  if (!built.ok()) return Annotate(AdviseAutoTopology(built.status()), "build multimesh");
  return built;
}

absl::StatusOr<v1::OptimizeComeshResult> Optimize(const v1::Session& session,
                                                  const RunContext& ctx) {
  auto optimized = ctx.client->OptimizeComesh(
      session,
      // The end is not known: the iterations' counters and energies, and the topology passes'
      // messages (the server's stage "comesh"), under one label.
      [&](const v1::ComeshIteration& it) {
        if (ctx.progress) {
          ctx.progress->Update(
              "optimize", -1.0,
              absl::StrFormat("outer %u inner %u map %.4f mesh %.4f vertices %u", it.outer(),
                              it.inner(), it.map_energy(), it.mesh_energy(), it.vertices()));
        }
      },
      [&](const v1::Progress& p) {
        if (ctx.progress && p.stage() == "comesh") {
          ctx.progress->Update("optimize", -1.0, p.detail());
        } else {
          ShowProgress(ctx, p);
        }
      });
  FinishProgress(ctx);
  if (!optimized.ok()) return Annotate(optimized.status(), "optimize comesh");
  return optimized;
}

json MultimeshToJson(const v1::Multimesh& mesh) {
  json triangles = json::array();
  for (const auto& t : mesh.triangles()) triangles.push_back({t.a(), t.b(), t.c()});
  json shapes = json::array();
  for (const auto& s : mesh.shapes()) {
    json vertices = json::array();
    for (const auto& p : s.vertices()) vertices.push_back({p.x(), p.y()});
    shapes.push_back({{"vertices", std::move(vertices)}});
  }
  json cohesive = json::array();
  for (const auto& c : mesh.cohesive_edges()) cohesive.push_back({c.a(), c.b(), c.c(), c.d()});
  json out = {{"triangles", std::move(triangles)},
              {"shapes", std::move(shapes)},
              {"cohesive_edges", std::move(cohesive)},
              {"boundary", std::vector<uint32_t>(mesh.boundary().begin(), mesh.boundary().end())},
              {"pinned", std::vector<uint32_t>(mesh.pinned().begin(), mesh.pinned().end())}};
  // The drawings' art in mesh coordinates, as frames.json writes it (the service checked it).
  if (mesh.art_size() > 0) {
    if (absl::StatusOr<solver::Multimesh> m = server::MultimeshFromProto(mesh, "multimesh");
        m.ok()) {
      out["art"] = render::ArtToJson(m->art);
    }
  }
  return out;
}

// The multimesh's shapes as a frame set, so the SVG exporter can draw each shape's mesh.
render::FrameSet ShapesAsFrames(const v1::Multimesh& mesh) {
  render::FrameSet set;
  for (const auto& t : mesh.triangles()) {
    set.triangles.push_back(
        {static_cast<int>(t.a()), static_cast<int>(t.b()), static_cast<int>(t.c())});
  }
  for (int i = 0; i < mesh.shapes_size(); ++i) {
    render::FrameData f;
    f.index = i + 1;
    for (const auto& p : mesh.shapes(i).vertices()) f.vertices.push_back({p.x(), p.y()});
    set.frames.push_back(std::move(f));
    set.keys.push_back(i);
  }
  return set;
}

// Where --auto-topology writes the project: the --project file itself, else OUT/project.json.
std::filesystem::path AutoTopologyFile(const Inputs& inputs, const std::filesystem::path& out) {
  return inputs.project.empty() ? out / "project.json" : inputs.project;
}

absl::Status FlagError(const char* flag, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat(flag, ": ", what));
}

}  // namespace

absl::Status ApplyInbetweenOverrides(const InbetweenOverrides& o, Project* project) {
  v1::InbetweenParameters* params = project->parameters.mutable_inbetween();
  if (o.frames) params->set_frames(*o.frames);
  if (o.method) {
    auto method = ParseMethod(*o.method);
    if (!method.ok()) return method.status();
    params->set_method(*method);
  }
  if (o.timing) {
    std::optional<v1::TimingCurve> curve = TimingCurveFromName(*o.timing);
    if (!curve) {
      return FlagError("--timing", absl::StrCat("unknown timing curve '", *o.timing,
                                                "' (linear, catmull-rom, ease-in-out)"));
    }
    params->set_timing(*curve);
  }
  const size_t segments = project->drawings.size() - 1;
  if (!o.ease.empty()) {
    if (o.timing && params->timing() != v1::TIMING_CURVE_EASE_IN_OUT) {
      return FlagError("--ease", "applies to --timing ease-in-out only");
    }
    if (o.ease.size() != 1 && o.ease.size() != segments) {
      return FlagError("--ease", absl::StrCat("give one amount, or one per segment between keys (",
                                              segments, "), not ", o.ease.size()));
    }
    params->clear_ease();
    for (size_t i = 0; i < segments; ++i) {
      const double e = o.ease[o.ease.size() == 1 ? 0 : i];
      if (!(e >= 0 && e <= 1)) {
        return FlagError("--ease", absl::StrCat("amount ", e, " is not in [0, 1]"));
      }
      params->add_ease(e);
    }
    if (!o.timing) params->set_timing(v1::TIMING_CURVE_EASE_IN_OUT);
  }
  struct Bounded {
    const char* flag;
    const std::optional<double>& value;
    double min, max;
    bool open_min;
    void (v1::InbetweenParameters::*set)(double);
  };
  using P = v1::InbetweenParameters;
  for (const Bounded& b : {Bounded{"--lambda", o.lambda, 0, 1e9, false, &P::set_lambda},
                           Bounded{"--tau", o.tau, 0, 1e9, false, &P::set_tau},
                           Bounded{"--alpha", o.alpha, 0, 1, false, &P::set_alpha},
                           Bounded{"--epsilon", o.epsilon, 0, 1e6, false, &P::set_epsilon},
                           Bounded{"--rho", o.rho, 0, 1e9, true, &P::set_rho},
                           Bounded{"--timestep", o.timestep, 0, 10, true, &P::set_timestep}}) {
    if (!b.value) continue;
    const double v = *b.value;
    if (!std::isfinite(v) || v < b.min || v > b.max || (b.open_min && v == b.min)) {
      return FlagError(b.flag, absl::StrCat("value ", v, " is not in ", b.open_min ? "(" : "[",
                                            b.min, ", ", b.max, "]"));
    }
    (params->*b.set)(v);
  }
  if (o.max_iterations) {
    if (*o.max_iterations < 1 || *o.max_iterations > 10000) {
      return FlagError("--max-iterations",
                       absl::StrCat("value ", *o.max_iterations, " is not in [1, 10000]"));
    }
    params->set_max_iterations(*o.max_iterations);
  }
  // Key times: the flag replaces the drawings' key_time; either way they travel both as
  // InbetweenParameters.key_times and on each drawing.
  std::vector<double> key_times = o.key_times;
  if (!key_times.empty()) {
    if (absl::Status s = CheckKeyTimes(key_times, project->drawings.size()); !s.ok()) {
      return FlagError("--key-times", s.message());
    }
    for (size_t i = 0; i < key_times.size(); ++i) project->drawings[i].key_time = key_times[i];
  } else {
    for (const ProjectDrawing& d : project->drawings) {
      if (d.key_time) key_times.push_back(*d.key_time);
    }
    if (!key_times.empty()) {
      if (absl::Status s = CheckKeyTimes(key_times, project->drawings.size()); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("drawings' key_time: ", s.message()));
      }
    }
  }
  params->clear_key_times();
  for (double t : key_times) params->add_key_times(t);
  return absl::OkStatus();
}

absl::StatusOr<Project> ResolveProject(const Inputs& inputs) {
  Project project;
  if (!inputs.project.empty()) {
    auto loaded = LoadProject(inputs.project);
    if (!loaded.ok()) return loaded.status();
    project = *std::move(loaded);
  }
  if (!inputs.drawings.empty()) {
    project.drawings.clear();
    for (const auto& path : inputs.drawings) {
      ProjectDrawing d;
      d.file = path;
      project.drawings.push_back(std::move(d));
    }
  }
  const ImportSettings& flags = inputs.import_flags;
  for (const auto& [flag, value, setting] :
       {std::tuple{"--gap-tolerance", flags.gap_tolerance, &project.import_settings.gap_tolerance},
        std::tuple{"--min-area-fraction", flags.min_area_fraction,
                   &project.import_settings.min_area_fraction}}) {
    if (!value) continue;
    if (!(*value >= 0 && *value <= kMaxImportFraction)) {  // false for NaN
      return FlagError(flag, absl::StrCat("value ", *value, " is not in [0, ", kMaxImportFraction,
                                          "] (0 = off)"));
    }
    *setting = *value;
  }
  if (project.drawings.size() < 2 || project.drawings.size() > 16) {
    return absl::InvalidArgumentError(
        absl::StrCat("need 2 to 16 drawings (on the command line or in --project), got ",
                     project.drawings.size()));
  }
  return project;
}

namespace {

// Whether frames are drawn from the drawings' art: --render art|silhouette, else art unless a
// fill colour was asked for (one colour is what --fill means).
absl::StatusOr<bool> DrawArt(const std::optional<std::string>& render, bool fill_given) {
  if (!render) return !fill_given;
  if (*render == "art") return true;
  if (*render == "silhouette") return false;
  return FlagError("--render", absl::StrCat("unknown mode '", *render, "' (art or silhouette)"));
}

}  // namespace

absl::Status RunAnimate(const AnimateOptions& options, const RunContext& ctx) {
  auto project = ResolveProject(options.inputs);
  if (!project.ok()) return project.status();
  if (options.auto_topology) {
    absl::Status s =
        ApplyAutoTopology(&*project, AutoTopologyFile(options.inputs, options.out_dir), ctx.quiet);
    if (!s.ok()) return s;
  }
  if (absl::Status s = ApplyInbetweenOverrides(options.overrides, &*project); !s.ok()) return s;
  const v1::InbetweenParameters* params = &project->parameters.inbetween();
  render::ExportOptions out;
  out.dir = options.out_dir;
  auto formats =
      render::ParseFormats(options.formats.value_or(absl::StrJoin(project->output.formats, ",")));
  if (!formats.ok()) return Annotate(formats.status(), "--format");
  out.formats = *formats;
  out.width = options.width.value_or(project->output.width);
  out.fps = options.fps.value_or(project->output.fps);
  // An explicit colour (--fill, then output.fill) wins over the drawings' own fills.
  const std::optional<std::string> fill = options.fill ? options.fill : project->output.fill;
  if (fill) {
    if (auto c = render::ParseColor(*fill); !c.ok()) return Annotate(c.status(), "fill");
    out.fill = *fill;
  }
  out.drawing_fills = !fill.has_value();
  out.mesh_overlay = options.mesh_overlay.value_or(project->output.mesh_overlay);
  out.transparent = options.transparent;
  absl::StatusOr<bool> art = DrawArt(options.render, fill.has_value());
  if (!art.ok()) return art.status();
  out.art = *art;

  auto session = UploadProject(*project, "inbetween animate", ctx);
  if (!session.ok()) return session.status();
  auto built = Build(*session, ctx);
  if (!built.ok()) return built.status();
  if (options.optimize) {
    auto optimized = Optimize(built->session(), ctx);
    if (!optimized.ok()) return optimized.status();
  }
  auto frames = ctx.client->Inbetween(
      session->id(), *params, [&](const v1::InbetweenFrame& f, uint32_t total) {
        if (ctx.progress) ctx.progress->Update("frames", total ? (f.index() + 1.0) / total : 1.0);
      });
  FinishProgress(ctx);
  if (!frames.ok()) return Annotate(frames.status(), "inbetween");

  out.progress = [&](std::string_view stage, int done, int total) {
    if (ctx.progress) {
      ctx.progress->Update(absl::StrCat("write ", std::string(stage)),
                           total ? double(done) / total : 1.0);
    }
  };
  render::FrameSet frame_set = ToFrameSet(*frames);
  {
    std::vector<std::string> svgs;
    for (const ProjectDrawing& d : project->drawings) {
      auto svg = ReadFile(d.file);
      if (svg.ok()) svgs.push_back(*std::move(svg));
    }
    if (svgs.size() == project->drawings.size()) {
      frame_set.fills = DrawingFills(svgs);
    }
  }
  // The art goes into frames.json whatever --render says, so `render` can draw either. Without
  // it the frames are still right: one warning line, and silhouettes.
  if (absl::Status art = AddHeaderArt(frames->header, &frame_set); !art.ok()) {
    std::fprintf(stderr, "warning: drawing art: %s; frames are drawn as one-colour silhouettes\n",
                 std::string(art.message()).c_str());
  }
  absl::Status written = render::ExportFrames(frame_set, out);
  FinishProgress(ctx);
  if (!written.ok()) return written;

  uint32_t inverted = 0;
  for (const auto& f : frames->frames) inverted += f.stats().inverted_triangles();
  if (!ctx.quiet) {
    std::fprintf(stderr, "%zu frames, %d triangles, %d vertices, %u inverted triangles -> %s\n",
                 frames->frames.size(), frames->header.triangles_size(),
                 frames->frames.empty() ? 0 : frames->frames[0].vertices_size(), inverted,
                 options.out_dir.string().c_str());
  }
  std::printf("%s\n", (options.out_dir / "frames.json").string().c_str());
  return absl::OkStatus();
}

// "boundary: 2 loop(s), vertices per loop 180, 24; outlines within 0.098% of the diagonal" (the
// build's MultimeshStats: the keys' outline tolerance achieved), on stderr.
static void PrintBoundarySummary(const v1::MultimeshStats& stats) {
  if (stats.loop_vertices_size() == 0) return;
  std::string per_loop;
  for (int i = 0; i < stats.loop_vertices_size() && i < 12; ++i) {
    absl::StrAppend(&per_loop, i ? ", " : "", stats.loop_vertices(i));
  }
  if (stats.loop_vertices_size() > 12) absl::StrAppend(&per_loop, ", ...");
  std::fprintf(stderr,
               "boundary: %d loop(s), vertices per loop %s; outlines within %.4g%% of the "
               "diagonal\n",
               stats.loop_vertices_size(), per_loop.c_str(), 100.0 * stats.achieved_tolerance());
}

absl::Status RunMesh(const MeshOptions& options, const RunContext& ctx) {
  auto project = ResolveProject(options.inputs);
  if (!project.ok()) return project.status();
  if (options.auto_topology) {
    absl::Status s =
        ApplyAutoTopology(&*project, AutoTopologyFile(options.inputs, options.out_dir), ctx.quiet);
    if (!s.ok()) return s;
  }
  auto session =
      UploadProject(*project, options.optimize ? "inbetween optimize" : "inbetween mesh", ctx);
  if (!session.ok()) return session.status();
  auto built = Build(*session, ctx);
  if (!built.ok()) return built.status();
  v1::Multimesh mesh = built->multimesh();
  json report;
  if (options.optimize) {
    auto optimized = Optimize(built->session(), ctx);
    if (!optimized.ok()) return optimized.status();
    mesh = optimized->multimesh();
    report = {{"vertices_before", built->stats().vertices()},
              {"vertices_after", optimized->stats().vertices()},
              {"inner", optimized->inner_iterations()},
              {"outer", optimized->outer_iterations()},
              {"seconds", optimized->seconds()},
              {"map_energy", optimized->stats().map_energy()},
              {"mesh_energy", optimized->stats().mesh_energy()},
              {"worst_quality", optimized->stats().worst_quality()},
              {"corner_matched_loops", built->stats().corner_matched_loops()},
              {"overlays", built->stats().overlays()},
              {"loop_vertices", std::vector<uint32_t>(built->stats().loop_vertices().begin(),
                                                      built->stats().loop_vertices().end())},
              {"achieved_tolerance", built->stats().achieved_tolerance()}};
  }
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) return absl::UnavailableError(absl::StrCat("cannot create ", options.out_dir.string()));
  absl::Status s =
      WriteText(options.out_dir / "multimesh.json", MultimeshToJson(mesh).dump() + "\n");
  if (!s.ok()) return s;
  const render::FrameSet shapes = ShapesAsFrames(mesh);
  render::SvgFrameOptions svg;
  svg.mesh_overlay = true;
  for (size_t i = 0; i < shapes.frames.size(); ++i) {
    s = WriteText(options.out_dir / absl::StrCat("shape_", i + 1, ".svg"),
                  render::FrameSvg(shapes, i, svg));
    if (!s.ok()) return s;
  }
  if (options.optimize) {
    s = WriteText(options.out_dir / "report.json", report.dump(2) + "\n");
    if (!s.ok()) return s;
  }
  const auto& stats = built->stats();
  if (!ctx.quiet) {
    std::fprintf(stderr, "%u shapes, %d vertices, %d triangles, %zu cohesive edges -> %s\n",
                 stats.shapes(), mesh.shapes_size() ? mesh.shapes(0).vertices_size() : 0,
                 mesh.triangles_size(), static_cast<size_t>(mesh.cohesive_edges_size()),
                 options.out_dir.string().c_str());
    PrintBoundarySummary(stats);
    if (stats.corner_matched_loops() > 0) {
      std::fprintf(stderr,
                   "boundary correspondence: corners matched to corners on %u loop(s) (arc "
                   "length could not be meshed, or project meshing.corner_matching = always)\n",
                   stats.corner_matched_loops());
    }
    if (stats.overlays() > 0) {
      std::fprintf(stderr,
                   "no drawing's mesh mapped into every drawing: %u overlaid with a triangulation "
                   "of the drawing (thin triangles, which comesh optimization removes)\n",
                   stats.overlays());
    }
  }
  std::printf("%s\n", (options.out_dir / "multimesh.json").string().c_str());
  return absl::OkStatus();
}

absl::Status RunRender(const RenderOptions& options, ProgressBar& progress) {
  auto text = ReadFile(options.frames_json);
  if (!text.ok()) return text.status();
  json doc = json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) {
    return absl::InvalidArgumentError(absl::StrCat(options.frames_json.string(), ": not JSON"));
  }
  auto frames = render::FrameSetFromJson(doc);
  if (!frames.ok()) return Annotate(frames.status(), options.frames_json.string());
  render::ExportOptions out;
  out.dir = options.out_dir;
  auto formats = render::ParseFormats(options.formats);
  if (!formats.ok()) return Annotate(formats.status(), "--format");
  out.formats = *formats;
  out.width = options.width;
  out.fps = options.fps;
  if (options.fill) out.fill = *options.fill;
  out.drawing_fills = !options.fill.has_value();
  absl::StatusOr<bool> art = DrawArt(options.render, options.fill.has_value());
  if (!art.ok()) return art.status();
  out.art = *art;
  out.mesh_overlay = options.mesh_overlay;
  out.transparent = options.transparent;
  out.progress = [&](std::string_view stage, int done, int total) {
    progress.Update(absl::StrCat("write ", std::string(stage)), total ? double(done) / total : 1.0);
  };
  render::ExportReport report;
  absl::Status s = render::ExportFrames(*frames, out, &report);
  progress.Finish();
  if (!s.ok()) return s;
  for (const auto& f : report.files) std::printf("%s\n", (options.out_dir / f).string().c_str());
  return absl::OkStatus();
}

namespace {

constexpr const char* SilhouetteSourceName(v1::SilhouetteSource source) {
  switch (source) {
    case v1::SILHOUETTE_SOURCE_ELEMENTS:
      return "elements";
    case v1::SILHOUETTE_SOURCE_UNION:
      return "union";
    case v1::SILHOUETTE_SOURCE_OUTLINE_CLASS:
      return "outline class";
    default:
      return "unspecified";
  }
}

// What importing a drawing did (validate): one line of facts, then one line per warning, each
// starting with `where` ("drawing 1 (face.svg)").
void PrintImportReport(const std::string& where, const v1::ImportReport& r) {
  std::printf(
      "%s: silhouette %s; %u art layer%s; gaps closed %u, slits closed %u, islands dropped %u, "
      "holes dropped %u (gap width %g, area threshold %g)\n",
      where.c_str(), SilhouetteSourceName(r.silhouette_source()), r.art_layers(),
      r.art_layers() == 1 ? "" : "s", r.gaps_closed(), r.slits_closed(), r.islands_dropped(),
      r.holes_dropped(), r.gap_width(), r.min_area());
  for (const std::string& warning : r.warnings()) {
    std::printf("%s: warning: %s\n", where.c_str(), warning.c_str());
  }
}

std::string ClassText(const v1::EquivalenceClass& c) {
  return absl::StrCat(c.components(), c.components() == 1 ? " component, " : " components, ",
                      c.holes(), c.holes() == 1 ? " hole" : " holes");
}

// The session's state: stage, drawings (with their classes when known), multimesh statistics.
void PrintSession(const v1::Session& s, const std::vector<v1::EquivalenceClass>& classes) {
  std::printf("session %s\nversion %llu\nstage %s\n", s.id().c_str(),
              static_cast<unsigned long long>(s.version()), v1::Stage_Name(s.stage()).c_str());
  for (int i = 0; i < s.drawings_size(); ++i) {
    const v1::Drawing& d = s.drawings(i);
    int outlines = 0, cuts = 0, openings = 0;
    for (const auto& e : d.elements()) {
      outlines += e.kind() == v1::ELEMENT_KIND_OUTLINE;
      cuts += e.kind() == v1::ELEMENT_KIND_CUT;
      openings += e.kind() == v1::ELEMENT_KIND_OPENING;
    }
    const std::string klass =
        i < static_cast<int>(classes.size()) ? absl::StrCat("; ", ClassText(classes[i])) : "";
    std::printf("drawing %d (id %u, %s): %d outlines, %d cuts, %d openings%s\n", i + 1, d.id(),
                d.name().c_str(), outlines, cuts, openings, klass.c_str());
  }
  if (s.stage() >= v1::STAGE_MULTIMESH) {
    const auto& m = s.multimesh_stats();
    std::printf(
        "multimesh: %u shapes, %u vertices, %u triangles, map energy %.4f, "
        "mesh energy %.4f, %u inverted\n",
        m.shapes(), m.vertices(), m.triangles(), m.map_energy(), m.mesh_energy(),
        m.inverted_triangles());
  }
}

}  // namespace

absl::Status RunInspect(const std::string& session_id, const RunContext& ctx) {
  if (session_id.empty()) {
    auto sessions = ctx.client->ListSessions();
    if (!sessions.ok()) return sessions.status();
    for (const auto& s : *sessions) {
      // Summaries carry the count, not the drawings; a server that does not keep it: "?".
      const std::string drawings =
          s.has_drawing_count() ? std::to_string(s.drawing_count()) : "?";
      std::printf("%s\tversion %llu\t%s drawings\t%s\t%s\n", s.id().c_str(),
                  static_cast<unsigned long long>(s.version()), drawings.c_str(),
                  v1::Stage_Name(s.stage()).c_str(), s.display_name().c_str());
    }
    return absl::OkStatus();
  }
  auto got = ctx.client->GetSession(session_id, /*full=*/true);
  if (!got.ok()) return got.status();
  PrintSession(got->session(), {});
  return absl::OkStatus();
}

absl::Status RunInspectProject(const Inputs& inputs, const RunContext& ctx) {
  absl::StatusOr<Project> project = ResolveProject(inputs);
  if (!project.ok()) return project.status();
  std::vector<v1::EquivalenceClass> classes;
  auto session = UploadProject(*project, "inbetween inspect", ctx, &classes);
  if (!session.ok()) return session.status();
  // The multimesh's numbers (vertex counts, energies) come from building it; drawings whose
  // classes differ are printed with their classes and the build's reason.
  auto built = ctx.client->BuildMultimesh(*session, nullptr);
  if (built.ok()) *session = built->session();
  PrintSession(*session, classes);
  if (!built.ok()) {
    std::printf("multimesh: not built: %s\n", std::string(built.status().message()).c_str());
  }
  return absl::OkStatus();
}

absl::Status RunValidate(const Inputs& inputs, const RunContext& ctx) {
  std::vector<std::string> problems;
  absl::StatusOr<Project> project = ResolveProject(inputs);
  if (!project.ok()) {
    problems.push_back(std::string(project.status().message()));
  } else {
    // The drawings go up as `animate` sends them (cuts, openings, key times, correspondences),
    // so what validates is what animates.
    auto session = ctx.client->CreateSession("inbetween validate", project->parameters);
    if (!session.ok()) return session.status();
    // Every drawing on its own, so one bad drawing does not hide the next.
    int imported = 0;
    std::vector<std::string> svgs;
    for (size_t i = 0; i < project->drawings.size(); ++i) {
      const ProjectDrawing& d = project->drawings[i];
      const std::string where = absl::StrCat("drawing ", i + 1, " (", d.file.string(), ")");
      auto svg = ReadSvg(d.file);
      if (!svg.ok()) {
        problems.push_back(absl::StrCat(where, ": ", svg.status().message()));
        continue;
      }
      svgs.push_back(*svg);
      auto put = ctx.client->PutDrawing(
          DrawingRequest(d, project->import_settings, *session, *std::move(svg)));
      if (!put.ok()) {
        problems.push_back(absl::StrCat(where, ": ", put.status().message()));
        continue;
      }
      PrintImportReport(where, put->import_report());
      *session = put->session();
      ++imported;
    }
    if (problems.empty()) {
      if (absl::Status s = UploadCorrespondences(*project, svgs, ctx, &*session); !s.ok()) {
        problems.push_back(std::string(s.message()));
      }
    }
    // Whether the drawings fit together (same topology, mappable) only the build can tell.
    if (problems.empty() && imported >= 2) {
      auto built = ctx.client->BuildMultimesh(*session, nullptr);
      if (!built.ok()) {
        problems.push_back(absl::StrCat("build: ", AdviseAutoTopology(built.status()).message()));
      } else if (!ctx.quiet) {
        PrintBoundarySummary(built->stats());
      }
    }
  }
  for (const auto& p : problems) std::printf("%s\n", p.c_str());
  if (problems.empty()) {
    std::printf("ok\n");
    return absl::OkStatus();
  }
  return absl::InvalidArgumentError(absl::StrCat(problems.size(), " problem(s) found"));
}

absl::Status RunInit(const Inputs& inputs, const std::filesystem::path& project_out,
                     const InbetweenOverrides& overrides, bool force) {
  if (!force && std::filesystem::exists(project_out)) {
    return absl::AlreadyExistsError(
        absl::StrCat(project_out.string(), " exists (use --force to overwrite)"));
  }
  auto project = ResolveProject(inputs);
  if (!project.ok()) return project.status();
  for (const auto& d : project->drawings) {
    if (!std::filesystem::exists(d.file)) {
      return absl::NotFoundError(absl::StrCat("cannot open ", d.file.string()));
    }
  }
  if (absl::Status s = ApplyInbetweenOverrides(overrides, &*project); !s.ok()) return s;
  const auto base = std::filesystem::absolute(project_out).parent_path();
  for (auto& d : project->drawings) d.file = std::filesystem::absolute(d.file);
  absl::Status s = WriteText(project_out, ProjectToJson(*project, base).dump(2) + "\n");
  if (!s.ok()) return s;
  std::printf("%s\n", project_out.string().c_str());
  return absl::OkStatus();
}

int ExitCodeFor(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kOk:
      return 0;
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kFailedPrecondition:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kAlreadyExists:
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
      return 5;  // anything else: a server-side failure (including UNIMPLEMENTED)
  }
}

}  // namespace inbetween::client
