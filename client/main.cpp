// `inbetween`: the animator's command-line tool. Without --server the service runs embedded
// in this process and is reached over an in-process gRPC channel (the same code path as remote).
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/commands.h"
#include "client/inbetween_client.h"
#include "server/inbetween_server.h"
#include "server/stop_signals.h"
#include "solver/core/retain_memory.h"

namespace {

using inbetween::client::ExitCodeFor;

constexpr int kUsageError = 2;
constexpr const char* kExitCodes =
    "Exit codes: 0 ok, 2 usage, 3 bad input, 4 server unreachable or refused, 5 server failure, "
    "130 interrupted.";

// Ctrl-C / SIGTERM cancel the RPC in flight; the command then exits with code 130.
// (main installed the handler: server/stop_signals.h).
void StartSignalThread(inbetween::client::InbetweenClient* client) {
  std::thread([client]() {
    inbetween::server::WaitForStopSignal();
    std::fprintf(stderr, "\ninterrupted: cancelling...\n");
    client->CancelInFlight();
  }).detach();
}

std::shared_ptr<grpc::ChannelCredentials> Credentials(const std::string& tls_ca) {
  if (tls_ca.empty()) return grpc::InsecureChannelCredentials();
  std::ifstream in(tls_ca);
  std::stringstream pem;
  pem << in.rdbuf();
  grpc::SslCredentialsOptions options;
  options.pem_root_certs = pem.str();
  return grpc::SslCredentials(options);
}

// --gap-tolerance and --min-area-fraction: how the drawings' SVG is imported (they override the
// project's "import" settings; ResolveProject checks the range).
void AddImportFlags(CLI::App* cmd, inbetween::client::ImportSettings* flags) {
  cmd->add_option_function<double>(
      "--gap-tolerance", [flags](double v) { flags->gap_tolerance = v; },
      "Close gaps in the paint narrower than this fraction of its bounding-box diagonal, "
      "[0, 0.1], 0 = off (default 0.002)");
  cmd->add_option_function<double>(
      "--min-area-fraction", [flags](double v) { flags->min_area_fraction = v; },
      "Drop pieces of paint and holes smaller than this fraction of its bounding-box area, "
      "[0, 0.1], 0 = off (default 1e-4)");
}

// Adds the drawings/--project inputs shared by several subcommands.
void AddInputs(CLI::App* cmd, inbetween::client::Inputs* inputs) {
  cmd->add_option("drawings", inputs->drawings, "SVG drawings in key order (2 to 16)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--project", inputs->project, "Project file (docs/project-file.md)")
      ->check(CLI::ExistingFile);
  AddImportFlags(cmd, &inputs->import_flags);
}

// The inbetween parameters animate and init accept (docs/cli.md); flags override the project.
struct InbetweenFlags {
  std::string timing;
  std::vector<double> ease, key_times;
  double lambda = 0, tau = 0, alpha = 0, epsilon = 0, rho = 0, timestep = 0;
  uint32_t max_iterations = 0;
};

void AddInbetweenFlags(CLI::App* cmd, InbetweenFlags* f) {
  cmd->add_option("--timing", f->timing,
                  "Weights between keys: linear (default) | catmull-rom | ease-in-out");
  cmd->add_option("--ease", f->ease,
                  "Ease amount in [0,1] per segment between keys (comma list; one value = every "
                  "segment); implies --timing ease-in-out")
      ->delimiter(',');
  cmd->add_option("--key-times", f->key_times,
                  "Normalized time of each key, comma list: first 0, last 1, strictly increasing")
      ->delimiter(',');
  cmd->add_option("--lambda", f->lambda, "Cohesive stiffness lambda (S-eq.6), default 1");
  cmd->add_option("--tau", f->tau, "Separation threshold tau (S-eq.6), default 0.1");
  cmd->add_option("--alpha", f->alpha,
                  "Shear vs stretch weight alpha in [0,1] (S-eq.7), default 0.5");
  cmd->add_option("--epsilon", f->epsilon, "Dynamics compliance epsilon (S-eq.28), 0 = none");
  cmd->add_option("--rho", f->rho, "Density rho (S-eq.28), default 1");
  cmd->add_option("--timestep", f->timestep, "Timestep h in seconds (S-eq.28), default 1/24");
  cmd->add_option("--max-iterations", f->max_iterations,
                  "Local-global iterations per frame, default 20");
}

// Copies the flags the user gave (and only those) into the overrides.
void ApplyInbetweenFlags(const CLI::App& cmd, const InbetweenFlags& f,
                         inbetween::client::InbetweenOverrides* o) {
  if (cmd.count("--timing")) o->timing = f.timing;
  o->ease = f.ease;
  o->key_times = f.key_times;
  const std::pair<const char*, std::pair<double, std::optional<double>*>> doubles[] = {
      {"--lambda", {f.lambda, &o->lambda}}, {"--tau", {f.tau, &o->tau}},
      {"--alpha", {f.alpha, &o->alpha}},    {"--epsilon", {f.epsilon, &o->epsilon}},
      {"--rho", {f.rho, &o->rho}},          {"--timestep", {f.timestep, &o->timestep}}};
  for (const auto& [flag, value] : doubles) {
    if (cmd.count(flag)) *value.second = value.first;
  }
  if (cmd.count("--max-iterations")) o->max_iterations = f.max_iterations;
}

}  // namespace

int main(int argc, char** argv) {
  // One job per process: freed memory stays for reuse (solver/core/retain_memory.h).
  inbetween::solver::RetainFreedMemory();
  // SIGINT / SIGTERM reach the signal thread through a handler and a pipe, whichever thread the
  // kernel picks (libraries start threads before main).
  if (!inbetween::server::InstallStopSignals()) {
    std::fprintf(stderr, "inbetween: cannot install the SIGINT/SIGTERM handler\n");
    return 1;
  }

  CLI::App app{"inbetween: 2D inbetween animation from a few key drawings"};
  app.require_subcommand(1);
  app.footer(kExitCodes);
  std::string server, token, tls_ca, progress = "auto";
  bool quiet = false;
  app.add_option("--server", server,
                 "HOST:PORT of an inbetween-server; without it the service runs embedded");
  app.add_option("--token", token, "Bearer token for the server");
  app.add_option("--tls-ca", tls_ca, "PEM file of the CA that signed the server's certificate")
      ->check(CLI::ExistingFile);
  app.add_option("--progress", progress, "auto (bar on a terminal) | json (one line per event)")
      ->check(CLI::IsMember({"auto", "json"}));
  app.add_flag("-q,--quiet", quiet, "No progress output");

  // animate
  inbetween::client::AnimateOptions animate;
  std::string method;
  uint32_t frames = 0;
  std::string formats;
  int width = 0;
  double fps = 0;
  bool overlay = false;
  std::string fill;
  InbetweenFlags animate_flags;
  CLI::App* animate_cmd = app.add_subcommand("animate", "Inbetween frames from 2-16 drawings");
  AddInputs(animate_cmd, &animate.inputs);
  animate_cmd->add_option("--out", animate.out_dir, "Output directory")->required();
  animate_cmd->add_option("--frames", frames, "Frames including the keys (default 24)")
      ->check(CLI::Range(2, 100000));
  animate_cmd->add_option("--method", method, "zhu17 (default) | alexa | linear")
      ->check(CLI::IsMember({"linear", "alexa", "zhu17"}));
  animate_cmd->add_option("--format", formats,
                          "Comma list of svg,json,png,gif,webp,lottie,contact (default "
                          "svg,json,gif)");
  animate_cmd->add_option("--size", width, "Raster width in pixels (default 512)")
      ->check(CLI::Range(8, 16384));
  animate_cmd->add_option("--fps", fps, "Frames per second of GIF/WebP/Lottie (default 24)")
      ->check(CLI::Range(0.1, 240.0));
  AddInbetweenFlags(animate_cmd, &animate_flags);
  animate_cmd->add_option("--fill", fill,
                          "Fill colour (#rrggbb) instead of the drawings' own fill colours");
  std::string animate_render;
  animate_cmd
      ->add_option("--render", animate_render,
                   "art (default): the drawings' art; silhouette: the shape in one colour "
                   "(the default with --fill)")
      ->check(CLI::IsMember({"art", "silhouette"}));
  animate_cmd->add_flag("--mesh", overlay, "Draw the triangle mesh over every frame");
  std::string animate_overlay;
  animate_cmd->add_option("--overlay", animate_overlay, "mesh: same as --mesh; none: no overlay")
      ->check(CLI::IsMember({"mesh", "none"}));
  animate_cmd->add_flag("--transparent", animate.transparent, "Transparent background");
  animate_cmd->add_flag("--optimize", animate.optimize, "Optimize the comesh before inbetweening");
  animate_cmd->add_flag("--auto-topology", animate.auto_topology,
                        "When the drawings' topology differs, propose cuts and write them to "
                        "--project (else OUT/project.json)");
  animate_cmd->footer(
      "Examples:\n"
      "  inbetween animate square.svg hexagon.svg --frames 24 --out out/\n"
      "  inbetween animate --project walk.json --out out/ --format gif,webp,lottie --size 640\n"
      "  inbetween --server 127.0.0.1:50051 animate a.svg b.svg c.svg --out out/ --method alexa\n"
      "  inbetween animate a.svg b.svg c.svg --out out/ --key-times 0,0.3,1 --tau 0.05\n"
      "  inbetween animate disc.svg ring.svg --out out/ --auto-topology   (cuts -> "
      "out/project.json)\n"
      "Writes OUT/frames.json, OUT/frame_NNNN.svg, OUT/animation.gif ...; prints the path of "
      "frames.json (and the session id when --server is used).");

  // mesh / optimize
  inbetween::client::MeshOptions mesh;
  CLI::App* mesh_cmd = app.add_subcommand("mesh", "Build the multimesh of 2-16 drawings");
  AddInputs(mesh_cmd, &mesh.inputs);
  mesh_cmd->add_option("--out", mesh.out_dir, "Output directory")->required();
  mesh_cmd->add_flag("--auto-topology", mesh.auto_topology,
                     "Propose cuts when the topology differs (see animate)");
  mesh_cmd->footer(
      "Examples:\n  inbetween mesh mouth_closed.svg mouth_open.svg --out mesh/\n"
      "  inbetween mesh disc.svg ring.svg --out mesh/ --auto-topology   (writes "
      "mesh/project.json)\n"
      "Writes OUT/multimesh.json and OUT/shape_N.svg (each shape with its mesh).");
  inbetween::client::MeshOptions optimize;
  optimize.optimize = true;
  CLI::App* optimize_cmd =
      app.add_subcommand("optimize", "Build and optimize the multimesh (comesh optimization)");
  AddInputs(optimize_cmd, &optimize.inputs);
  optimize_cmd->add_option("--out", optimize.out_dir, "Output directory")->required();
  optimize_cmd->add_flag("--auto-topology", optimize.auto_topology,
                         "Propose cuts when the topology differs (see animate)");
  optimize_cmd->footer(
      "Examples:\n  inbetween optimize square.svg hexagon.svg --out mesh/\n"
      "Writes OUT/multimesh.json, OUT/shape_N.svg and OUT/report.json.");

  // render
  inbetween::client::RenderOptions render;
  CLI::App* render_cmd = app.add_subcommand("render", "Render a frames.json to images");
  render_cmd->add_option("frames", render.frames_json, "frames.json")
      ->required()
      ->check(CLI::ExistingFile);
  render_cmd->add_option("--out", render.out_dir, "Output directory")->required();
  render_cmd->add_option("--format", render.formats, "Comma list (see animate)")
      ->default_val("svg,json,gif");
  render_cmd->add_option("--size", render.width, "Raster width in pixels")
      ->default_val(512)
      ->check(CLI::Range(8, 16384));
  render_cmd->add_option("--fps", render.fps, "Frames per second")->default_val(24);
  std::string render_fill;
  render_cmd->add_option("--fill", render_fill,
                         "Fill colour (#rrggbb); default: the drawings' fills in frames.json, else "
                         "#3b7dd8");
  std::string render_render;
  render_cmd
      ->add_option("--render", render_render,
                   "art (default, when frames.json has art) | silhouette (see animate)")
      ->check(CLI::IsMember({"art", "silhouette"}));
  render_cmd->add_flag("--mesh", render.mesh_overlay, "Draw the triangle mesh");
  std::string render_overlay;
  render_cmd->add_option("--overlay", render_overlay, "mesh: same as --mesh; none: no overlay")
      ->check(CLI::IsMember({"mesh", "none"}));
  render_cmd->add_flag("--transparent", render.transparent, "Transparent background");
  render_cmd->footer("Examples:\n  inbetween render out/frames.json --out out/ --format png,gif");

  // inspect
  std::string inspect_id;
  CLI::App* inspect_cmd =
      app.add_subcommand("inspect", "Show a session's state, or list your sessions");
  inspect_cmd->add_option("session", inspect_id, "Session id (omit to list every session)");
  inbetween::client::Inputs inspect_project;
  inspect_cmd
      ->add_option("--project", inspect_project.project,
                   "Inspect a project file instead: classes, multimesh size and energies")
      ->check(CLI::ExistingFile)
      ->excludes(inspect_cmd->get_option("session"));
  AddImportFlags(inspect_cmd, &inspect_project.import_flags);
  inspect_cmd->footer(
      "Examples:\n  inbetween --server 127.0.0.1:50051 inspect\n"
      "  inbetween --server 127.0.0.1:50051 inspect 4f2a9c...\n"
      "  inbetween inspect --project walk.json");

  // validate
  inbetween::client::Inputs validate;
  CLI::App* validate_cmd =
      app.add_subcommand("validate", "Check drawings and a project file; report every problem");
  AddInputs(validate_cmd, &validate);
  validate_cmd->footer(
      "Examples:\n  inbetween validate --project walk.json\n"
      "  inbetween validate a.svg b.svg");

  // init
  inbetween::client::Inputs init;
  std::string init_out;
  bool force = false;
  CLI::App* init_cmd = app.add_subcommand("init", "Write a project file for some drawings");
  init_cmd->add_option("drawings", init.drawings, "SVG drawings in key order")
      ->required()
      ->check(CLI::ExistingFile);
  init_cmd->add_option("--out,-o", init_out, "Project file to write")->required();
  init_cmd->add_option("--frames", frames, "Frames including the keys");
  init_cmd->add_option("--method", method, "zhu17 | alexa | linear")
      ->check(CLI::IsMember({"linear", "alexa", "zhu17"}));
  InbetweenFlags init_flags;
  AddInbetweenFlags(init_cmd, &init_flags);
  AddImportFlags(init_cmd, &init.import_flags);
  init_cmd->add_flag("--force", force, "Overwrite an existing file");
  init_cmd->footer("Examples:\n  inbetween init pose*.svg -o walk.json --frames 48");

  for (CLI::App* cmd :
       {animate_cmd, mesh_cmd, optimize_cmd, render_cmd, inspect_cmd, validate_cmd, init_cmd}) {
    cmd->fallthrough();  // global options may also follow the subcommand
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kUsageError;
  }

  inbetween::client::InbetweenOverrides overrides;
  if (frames != 0) overrides.frames = frames;
  if (!method.empty()) overrides.method = method;
  const auto mode = quiet                ? inbetween::client::ProgressMode::kQuiet
                    : progress == "json" ? inbetween::client::ProgressMode::kJson
                                         : inbetween::client::ProgressMode::kAuto;
  inbetween::client::ProgressBar bar(mode);

  auto report = [](const absl::Status& status) {
    if (!status.ok()) std::fprintf(stderr, "error: %s\n", std::string(status.message()).c_str());
    return ExitCodeFor(status);
  };
  if (*render_cmd) {
    if (render_cmd->count("--fill")) render.fill = render_fill;
    if (render_cmd->count("--render")) render.render = render_render;
    if (render_overlay == "mesh") render.mesh_overlay = true;
    return report(inbetween::client::RunRender(render, bar));
  }
  if (*init_cmd) {
    ApplyInbetweenFlags(*init_cmd, init_flags, &overrides);
    return report(inbetween::client::RunInit(init, init_out, overrides, force));
  }

  std::unique_ptr<inbetween::server::InbetweenServer> embedded;
  std::shared_ptr<grpc::Channel> channel;
  if (server.empty()) {
    inbetween::server::ServerOptions options;  // no listening port: in-process only
    auto started = inbetween::server::InbetweenServer::Start(options);
    if (!started.ok()) {
      std::fprintf(stderr, "error: cannot start the embedded service: %s\n",
                   std::string(started.status().message()).c_str());
      return 5;
    }
    embedded = std::move(*started);
    channel = embedded->InProcessChannel();
  } else {
    channel = inbetween::client::CreateChannelForServer(server, Credentials(tls_ca));
  }

  inbetween::client::ClientOptions client_options;
  client_options.token = token;
  if (!quiet) {
    // A replica went away mid-call (docs/scale-out.md): say what is retried and from where.
    client_options.on_retry = [](const inbetween::client::RetryEvent& e) {
      const std::string from =
          e.method == "Inbetween" ? absl::StrCat(", resuming at frame ", e.resume_frame) : "";
      std::fprintf(stderr, "retry: %s attempt %d failed (%s); attempt %d in %lld ms%s\n",
                   e.method.c_str(), e.failed_attempt, e.status.ToString().c_str(),
                   e.failed_attempt + 1, static_cast<long long>(e.backoff.count()), from.c_str());
    };
  }
  inbetween::client::InbetweenClient client(channel, std::move(client_options));
  StartSignalThread(&client);
  const inbetween::client::RunContext ctx{
      .client = &client, .progress = &bar, .remote = !server.empty(), .quiet = quiet};
  absl::Status status;
  if (*animate_cmd) {
    if (!animate.inputs.project.empty() || !animate.inputs.drawings.empty()) {
      ApplyInbetweenFlags(*animate_cmd, animate_flags, &overrides);
      animate.overrides = overrides;
      if (animate_cmd->count("--fill")) animate.fill = fill;
      if (animate_cmd->count("--render")) animate.render = animate_render;
      if (!formats.empty()) animate.formats = formats;
      if (width != 0) animate.width = width;
      if (fps != 0) animate.fps = fps;
      if (overlay || animate_overlay == "mesh") animate.mesh_overlay = true;
      if (animate_overlay == "none") animate.mesh_overlay = false;
    }
    status = inbetween::client::RunAnimate(animate, ctx);
  } else if (*mesh_cmd) {
    status = inbetween::client::RunMesh(mesh, ctx);
  } else if (*optimize_cmd) {
    status = inbetween::client::RunMesh(optimize, ctx);
  } else if (*inspect_cmd) {
    if (!inspect_project.project.empty()) {
      status = inbetween::client::RunInspectProject(inspect_project, ctx);
    } else if (inspect_id.empty() && server.empty()) {
      status = absl::InvalidArgumentError(
          "inspect without a session id lists a server's sessions: give --server HOST:PORT");
    } else {
      status = inbetween::client::RunInspect(inspect_id, ctx);
    }
  } else if (*validate_cmd) {
    status = inbetween::client::RunValidate(validate, ctx);
  }
  if (embedded) embedded->Shutdown();
  return report(status);
}
