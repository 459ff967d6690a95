// The `inbetween` subcommands as plain functions over an InbetweenClient (embedded or remote),
// so they can be tested without a process. main.cpp only parses flags and calls these.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "client/inbetween_client.h"
#include "client/progress_bar.h"
#include "client/project_file.h"

namespace inbetween::client {

// Where drawings and parameters come from: `--project FILE` and/or drawings on the command line
// (drawings given on the command line replace the project's).
struct Inputs {
  std::vector<std::filesystem::path> drawings;
  std::filesystem::path project;  // empty = none
  // --gap-tolerance, --min-area-fraction: override the project's "import" settings.
  ImportSettings import_flags;
};

// The project of `inputs`, with the command line's drawings and import flags applied. A flag out
// of range is INVALID_ARGUMENT naming it ("--gap-tolerance: value 0.5 is not in [0, 0.1]").
absl::StatusOr<Project> ResolveProject(const Inputs& inputs);

// Overrides from the command line (unset = the project's value, then the server default).
struct InbetweenOverrides {
  std::optional<uint32_t> frames;
  std::optional<std::string> method;  // linear | alexa | zhu17
  std::optional<std::string> timing;  // linear | catmull-rom | ease-in-out (or with '_')
  std::vector<double> ease;           // one per segment, or one for every segment; [0, 1]
  std::vector<double> key_times;      // one per drawing: first 0, last 1, strictly increasing
  std::optional<double> lambda, tau, alpha, epsilon, rho, timestep;
  std::optional<uint32_t> max_iterations;
};

// Applies the command-line overrides to the project's inbetween parameters (flags win) and
// settles the key times: --key-times, else the drawings' key_time, go to both
// InbetweenParameters.key_times and each drawing's key_time. A single --ease value applies to
// every segment; --ease without --timing means ease-in-out. Errors name the flag
// ("--key-times: ...") and are INVALID_ARGUMENT.
absl::Status ApplyInbetweenOverrides(const InbetweenOverrides& overrides, Project* project);

struct RunContext {
  InbetweenClient* client = nullptr;
  ProgressBar* progress = nullptr;
  bool remote = false;  // print the session id so a studio can come back to it
  bool quiet = false;   // -q: no notes on stderr
};

struct AnimateOptions {
  Inputs inputs;
  std::filesystem::path out_dir;
  InbetweenOverrides overrides;
  std::optional<std::string> formats;  // "svg,json,gif"; unset = project's output.formats
  std::optional<int> width;
  std::optional<double> fps;
  std::optional<bool> mesh_overlay;
  std::optional<std::string> fill;  // unset = output.fill, else the drawings' own fills
  // "art" (the drawings' art) or "silhouette" (one colour); unset = art, unless a fill colour
  // is given (--fill or output.fill), which asks for the one-colour silhouette.
  std::optional<std::string> render;
  bool transparent = false;
  bool optimize = false;  // run comesh optimization before inbetweening
  // Propose cuts when the drawings' topology differs; written to --project, else OUT/project.json.
  bool auto_topology = false;
};
absl::Status RunAnimate(const AnimateOptions& options, const RunContext& ctx);

struct MeshOptions {
  Inputs inputs;
  std::filesystem::path out_dir;
  bool optimize = false;  // `inbetween optimize`: also run comesh optimization, write report.json
  bool auto_topology = false;  // as AnimateOptions::auto_topology
};
// Writes DIR/multimesh.json and DIR/shape_N.svg (mesh drawn), plus report.json when optimizing.
absl::Status RunMesh(const MeshOptions& options, const RunContext& ctx);

struct RenderOptions {
  std::filesystem::path frames_json;
  std::filesystem::path out_dir;
  std::string formats = "svg,json,gif";
  int width = 512;
  double fps = 24;
  std::optional<std::string> fill;    // unset = frames.json's "fills", else the default colour
  std::optional<std::string> render;  // as AnimateOptions::render (art: frames.json's "art")
  bool mesh_overlay = false;
  bool transparent = false;
};
absl::Status RunRender(const RenderOptions& options, ProgressBar& progress);

// With an id: that session's state. Without: every session of the caller, one per line.
absl::Status RunInspect(const std::string& session_id, const RunContext& ctx);

// A project's state without keeping a session: its drawings uploaded (embedded, or to --server,
// which keeps the session and prints its id), each drawing's equivalence class, and the
// multimesh built from them (vertex counts, energies) or why it cannot be.
absl::Status RunInspectProject(const Inputs& inputs, const RunContext& ctx);

// Checks the project file and every drawing and reports every problem at once (stdout, one per
// line); fails with INVALID_ARGUMENT carrying the count when there is any. Each drawing that
// imports is reported first: its silhouette source, art layers, what cleaning did and every
// import warning (ImportReport).
absl::Status RunValidate(const Inputs& inputs, const RunContext& ctx);

// Writes a project file for the drawings (paths relative to the file).
absl::Status RunInit(const Inputs& inputs, const std::filesystem::path& project_out,
                     const InbetweenOverrides& overrides, bool force);

// Process exit code for a final status (documented in docs/cli.md).
int ExitCodeFor(const absl::Status& status);

}  // namespace inbetween::client
