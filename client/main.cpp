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

// Options every subcommand takes (they may also follow the subcommand).
struct GlobalFlags {
  std::string server, token, tls_ca, progress = "auto";
  bool quiet = false;
};

void AddGlobalFlags(CLI::App& app, GlobalFlags* g) {
  app.add_option("--server", g->server,
                 "HOST:PORT of an inbetween-server; without it the service runs embedded");
  app.add_option("--token", g->token, "Bearer token for the server");
  app.add_option("--tls-ca", g->tls_ca, "PEM file of the CA that signed the server's certificate")
      ->check(CLI::ExistingFile);
  app.add_option("--progress", g->progress, "auto (bar on a terminal) | json (one line per event)")
      ->check(CLI::IsMember({"auto", "json"}));
  app.add_flag("-q,--quiet", g->quiet, "No progress output");
}

// --frames and --method, which animate and init both set.
struct FrameFlags {
  uint32_t frames = 0;
  std::string method;
};

struct AnimateCommand {
  CLI::App* cmd = nullptr;
  inbetween::client::AnimateOptions options;
  std::string formats, fill, render, overlay;
  int width = 0;
  double fps = 0;
  bool mesh = false;
  InbetweenFlags flags;
};

void AddAnimate(CLI::App& app, FrameFlags* shared, AnimateCommand* a) {
  CLI::App* cmd = a->cmd = app.add_subcommand("animate", "Inbetween frames from 2-16 drawings");
  AddInputs(cmd, &a->options.inputs);
  cmd->add_option("--out", a->options.out_dir, "Output directory")->required();
  cmd->add_option("--frames", shared->frames, "Frames including the keys (default 24)")
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--method", shared->method, "zhu17 (default) | alexa | linear")
      ->check(CLI::IsMember({"linear", "alexa", "zhu17"}));
  cmd->add_option("--format", a->formats,
                  "Comma list of svg,json,png,gif,webp,lottie,contact (default "
                  "svg,json,gif)");
  cmd->add_option("--size", a->width, "Raster width in pixels (default 512)")
      ->check(CLI::Range(8, 16384));
  cmd->add_option("--fps", a->fps, "Frames per second of GIF/WebP/Lottie (default 24)")
      ->check(CLI::Range(0.1, 240.0));
  AddInbetweenFlags(cmd, &a->flags);
  cmd->add_option("--fill", a->fill,
                  "Fill colour (#rrggbb) instead of the drawings' own fill colours");
  cmd->add_option("--render", a->render,
                  "art (default): the drawings' art; silhouette: the shape in one colour "
                  "(the default with --fill)")
      ->check(CLI::IsMember({"art", "silhouette"}));
  cmd->add_flag("--mesh", a->mesh, "Draw the triangle mesh over every frame");
  cmd->add_option("--overlay", a->overlay, "mesh: same as --mesh; none: no overlay")
      ->check(CLI::IsMember({"mesh", "none"}));
  cmd->add_flag("--transparent", a->options.transparent, "Transparent background");
  cmd->add_flag("--optimize", a->options.optimize, "Optimize the comesh before inbetweening");
  cmd->add_flag("--auto-topology", a->options.auto_topology,
                "When the drawings' topology differs, propose cuts and write them to "
                "--project (else OUT/project.json)");
  cmd->footer(
      "Examples:\n"
      "  inbetween animate square.svg hexagon.svg --frames 24 --out out/\n"
      "  inbetween animate --project walk.json --out out/ --format gif,webp,lottie --size 640\n"
      "  inbetween --server 127.0.0.1:50051 animate a.svg b.svg c.svg --out out/ --method alexa\n"
      "  inbetween animate a.svg b.svg c.svg --out out/ --key-times 0,0.3,1 --tau 0.05\n"
      "  inbetween animate disc.svg ring.svg --out out/ --auto-topology   (cuts -> "
      "out/project.json)\n"
      "Writes OUT/frames.json, OUT/frame_NNNN.svg, OUT/animation.gif ...; prints the path of "
      "frames.json (and the session id when --server is used).");
}

// The animate options with the flags the user gave applied (drawings or a project given).
inbetween::client::AnimateOptions AnimateOptionsFor(
    const AnimateCommand& a, inbetween::client::InbetweenOverrides overrides) {
  inbetween::client::AnimateOptions out = a.options;
  if (out.inputs.project.empty() && out.inputs.drawings.empty()) return out;
  ApplyInbetweenFlags(*a.cmd, a.flags, &overrides);
  out.overrides = overrides;
  if (a.cmd->count("--fill")) out.fill = a.fill;
  if (a.cmd->count("--render")) out.render = a.render;
  if (!a.formats.empty()) out.formats = a.formats;
  if (a.width != 0) out.width = a.width;
  if (a.fps != 0) out.fps = a.fps;
  if (a.mesh || a.overlay == "mesh") out.mesh_overlay = true;
  if (a.overlay == "none") out.mesh_overlay = false;
  return out;
}

// mesh and optimize: the same inputs and output, optimize also runs comesh optimization.
CLI::App* AddMeshCommand(CLI::App& app, const char* name, const char* help, const char* footer,
                         inbetween::client::MeshOptions* mesh) {
  CLI::App* cmd = app.add_subcommand(name, help);
  AddInputs(cmd, &mesh->inputs);
  cmd->add_option("--out", mesh->out_dir, "Output directory")->required();
  cmd->add_flag("--auto-topology", mesh->auto_topology,
                "Propose cuts when the topology differs (see animate)");
  cmd->footer(footer);
  return cmd;
}

struct RenderCommand {
  CLI::App* cmd = nullptr;
  inbetween::client::RenderOptions options;
  std::string fill, render, overlay;
};

void AddRender(CLI::App& app, RenderCommand* r) {
  CLI::App* cmd = r->cmd = app.add_subcommand("render", "Render a frames.json to images");
  cmd->add_option("frames", r->options.frames_json, "frames.json")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", r->options.out_dir, "Output directory")->required();
  cmd->add_option("--format", r->options.formats, "Comma list (see animate)")
      ->default_val("svg,json,gif");
  cmd->add_option("--size", r->options.width, "Raster width in pixels")
      ->default_val(512)
      ->check(CLI::Range(8, 16384));
  cmd->add_option("--fps", r->options.fps, "Frames per second")->default_val(24);
  cmd->add_option("--fill", r->fill,
                  "Fill colour (#rrggbb); default: the drawings' fills in frames.json, else "
                  "#3b7dd8");
  cmd->add_option("--render", r->render,
                  "art (default, when frames.json has art) | silhouette (see animate)")
      ->check(CLI::IsMember({"art", "silhouette"}));
  cmd->add_flag("--mesh", r->options.mesh_overlay, "Draw the triangle mesh");
  cmd->add_option("--overlay", r->overlay, "mesh: same as --mesh; none: no overlay")
      ->check(CLI::IsMember({"mesh", "none"}));
  cmd->add_flag("--transparent", r->options.transparent, "Transparent background");
  cmd->footer("Examples:\n  inbetween render out/frames.json --out out/ --format png,gif");
}

struct InspectCommand {
  CLI::App* cmd = nullptr;
  std::string session_id;
  inbetween::client::Inputs project;
};

void AddInspect(CLI::App& app, InspectCommand* i) {
  CLI::App* cmd = i->cmd =
      app.add_subcommand("inspect", "Show a session's state, or list your sessions");
  cmd->add_option("session", i->session_id, "Session id (omit to list every session)");
  cmd->add_option("--project", i->project.project,
                  "Inspect a project file instead: classes, multimesh size and energies")
      ->check(CLI::ExistingFile)
      ->excludes(cmd->get_option("session"));
  AddImportFlags(cmd, &i->project.import_flags);
  cmd->footer(
      "Examples:\n  inbetween --server 127.0.0.1:50051 inspect\n"
      "  inbetween --server 127.0.0.1:50051 inspect 4f2a9c...\n"
      "  inbetween inspect --project walk.json");
}

struct InitCommand {
  CLI::App* cmd = nullptr;
  inbetween::client::Inputs inputs;
  std::string out;
  bool force = false;
  InbetweenFlags flags;
};

void AddInit(CLI::App& app, FrameFlags* shared, InitCommand* i) {
  CLI::App* cmd = i->cmd = app.add_subcommand("init", "Write a project file for some drawings");
  cmd->add_option("drawings", i->inputs.drawings, "SVG drawings in key order")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", i->out, "Project file to write")->required();
  cmd->add_option("--frames", shared->frames, "Frames including the keys");
  cmd->add_option("--method", shared->method, "zhu17 | alexa | linear")
      ->check(CLI::IsMember({"linear", "alexa", "zhu17"}));
  AddInbetweenFlags(cmd, &i->flags);
  AddImportFlags(cmd, &i->inputs.import_flags);
  cmd->add_flag("--force", i->force, "Overwrite an existing file");
  cmd->footer("Examples:\n  inbetween init pose*.svg -o walk.json --frames 48");
}

// The embedded service (no --server) or a channel to the server; nullopt after printing why the
// embedded service could not start.
std::optional<std::shared_ptr<grpc::Channel>> Connect(
    const GlobalFlags& g, std::unique_ptr<inbetween::server::InbetweenServer>* embedded) {
  if (!g.server.empty()) {
    return inbetween::client::CreateChannelForServer(g.server, Credentials(g.tls_ca));
  }
  inbetween::server::ServerOptions options;  // no listening port: in-process only
  auto started = inbetween::server::InbetweenServer::Start(options);
  if (!started.ok()) {
    std::fprintf(stderr, "error: cannot start the embedded service: %s\n",
                 std::string(started.status().message()).c_str());
    return std::nullopt;
  }
  *embedded = std::move(*started);
  return (*embedded)->InProcessChannel();
}

// The client options: the token, and unless quiet a line for every retry.
inbetween::client::ClientOptions ClientOptionsFor(const GlobalFlags& g) {
  inbetween::client::ClientOptions client_options;
  client_options.token = g.token;
  if (!g.quiet) {
    // A replica went away mid-call (docs/scale-out.md): say what is retried and from where.
    client_options.on_retry = [](const inbetween::client::RetryEvent& e) {
      const std::string from =
          e.method == "Inbetween" ? absl::StrCat(", resuming at frame ", e.resume_frame) : "";
      std::fprintf(stderr, "retry: %s attempt %d failed (%s); attempt %d in %lld ms%s\n",
                   e.method.c_str(), e.failed_attempt, e.status.ToString().c_str(),
                   e.failed_attempt + 1, static_cast<long long>(e.backoff.count()), from.c_str());
    };
  }
  return client_options;
}

int Report(const absl::Status& status) {
  if (!status.ok()) std::fprintf(stderr, "error: %s\n", std::string(status.message()).c_str());
  return ExitCodeFor(status);
}

// Every subcommand with its flags, bound by AddCommands.
struct Commands {
  GlobalFlags global;
  FrameFlags shared;
  AnimateCommand animate;
  inbetween::client::MeshOptions mesh, optimize;
  CLI::App* mesh_cmd = nullptr;
  CLI::App* optimize_cmd = nullptr;
  RenderCommand render;
  InspectCommand inspect;
  inbetween::client::Inputs validate;
  CLI::App* validate_cmd = nullptr;
  InitCommand init;
};

void AddCommands(CLI::App& app, Commands* c) {
  AddGlobalFlags(app, &c->global);
  AddAnimate(app, &c->shared, &c->animate);
  c->mesh_cmd =
      AddMeshCommand(app, "mesh", "Build the multimesh of 2-16 drawings",
                     "Examples:\n  inbetween mesh mouth_closed.svg mouth_open.svg --out mesh/\n"
                     "  inbetween mesh disc.svg ring.svg --out mesh/ --auto-topology   (writes "
                     "mesh/project.json)\n"
                     "Writes OUT/multimesh.json and OUT/shape_N.svg (each shape with its mesh).",
                     &c->mesh);
  c->optimize.optimize = true;
  c->optimize_cmd =
      AddMeshCommand(app, "optimize", "Build and optimize the multimesh (comesh optimization)",
                     "Examples:\n  inbetween optimize square.svg hexagon.svg --out mesh/\n"
                     "Writes OUT/multimesh.json, OUT/shape_N.svg and OUT/report.json.",
                     &c->optimize);
  AddRender(app, &c->render);
  AddInspect(app, &c->inspect);
  CLI::App* validate_cmd = c->validate_cmd =
      app.add_subcommand("validate", "Check drawings and a project file; report every problem");
  AddInputs(validate_cmd, &c->validate);
  validate_cmd->footer(
      "Examples:\n  inbetween validate --project walk.json\n"
      "  inbetween validate a.svg b.svg");
  AddInit(app, &c->shared, &c->init);
  for (CLI::App* cmd : {c->animate.cmd, c->mesh_cmd, c->optimize_cmd, c->render.cmd, c->inspect.cmd,
                        validate_cmd, c->init.cmd}) {
    cmd->fallthrough();  // global options may also follow the subcommand
  }
}

// Runs the parsed subcommand; the exit code.
int Run(Commands& c) {
  inbetween::client::InbetweenOverrides overrides;
  if (c.shared.frames != 0) overrides.frames = c.shared.frames;
  if (!c.shared.method.empty()) overrides.method = c.shared.method;
  const auto mode = c.global.quiet                ? inbetween::client::ProgressMode::kQuiet
                    : c.global.progress == "json" ? inbetween::client::ProgressMode::kJson
                                                  : inbetween::client::ProgressMode::kAuto;
  inbetween::client::ProgressBar bar(mode);

  // Commands without a service.
  if (*c.render.cmd) {
    if (c.render.cmd->count("--fill")) c.render.options.fill = c.render.fill;
    if (c.render.cmd->count("--render")) c.render.options.render = c.render.render;
    if (c.render.overlay == "mesh") c.render.options.mesh_overlay = true;
    return Report(inbetween::client::RunRender(c.render.options, bar));
  }
  if (*c.init.cmd) {
    ApplyInbetweenFlags(*c.init.cmd, c.init.flags, &overrides);
    return Report(inbetween::client::RunInit(c.init.inputs, c.init.out, overrides, c.init.force));
  }

  std::unique_ptr<inbetween::server::InbetweenServer> embedded;
  const std::optional<std::shared_ptr<grpc::Channel>> channel = Connect(c.global, &embedded);
  if (!channel) return 5;
  inbetween::client::InbetweenClient client(*channel, ClientOptionsFor(c.global));
  StartSignalThread(&client);
  const inbetween::client::RunContext ctx{.client = &client,
                                          .progress = &bar,
                                          .remote = !c.global.server.empty(),
                                          .quiet = c.global.quiet};
  absl::Status status;
  if (*c.animate.cmd) {
    status = inbetween::client::RunAnimate(AnimateOptionsFor(c.animate, overrides), ctx);
  } else if (*c.mesh_cmd) {
    status = inbetween::client::RunMesh(c.mesh, ctx);
  } else if (*c.optimize_cmd) {
    status = inbetween::client::RunMesh(c.optimize, ctx);
  } else if (*c.inspect.cmd) {
    if (!c.inspect.project.project.empty()) {
      status = inbetween::client::RunInspectProject(c.inspect.project, ctx);
    } else if (c.inspect.session_id.empty() && c.global.server.empty()) {
      status = absl::InvalidArgumentError(
          "inspect without a session id lists a server's sessions: give --server HOST:PORT");
    } else {
      status = inbetween::client::RunInspect(c.inspect.session_id, ctx);
    }
  } else if (*c.validate_cmd) {
    status = inbetween::client::RunValidate(c.validate, ctx);
  }
  if (embedded) embedded->Shutdown();
  return Report(status);
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
  Commands commands;
  AddCommands(app, &commands);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kUsageError;
  }
  return Run(commands);
}
