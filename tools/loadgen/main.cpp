// inbetween-loadgen: N virtual studios against one inbetween-server (or a proxy in front of
// replicas), loopback targets only; prints a table of per-RPC latencies and errors by code, and
// writes the same as JSON with --json. See docs/scale-out.md. A server with --tokens needs
// --token TOKEN or --token-file PATH (one or the other; the file keeps it out of argv).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "tools/loadgen/load_generator.h"

int main(int argc, char** argv) {
  CLI::App app{"Load generator for inbetween-server (loopback targets only)"};
  std::string target, json_path;
  std::vector<std::string> drawings;
  int seconds = 30;
  inbetween::loadgen::LoadGenOptions options;
  app.add_option("--target", target, "HOST:PORT of a server or proxy (loopback)")->required();
  app.add_option("--studios", options.studios, "Concurrent virtual studios")
      ->check(CLI::Range(1, 1024));
  app.add_option("--seconds", seconds, "Stop starting calls after this long")
      ->check(CLI::Range(1, 3600));
  app.add_option("--max-requests", options.max_requests, "Stop after this many calls in total")
      ->check(CLI::Range(int64_t{1}, int64_t{10000000}));
  app.add_option("--drawings", drawings, "Key drawings (SVG files, 2-16) every studio uploads")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--frames", options.frames, "Frames per Inbetween stream")
      ->check(CLI::Range(2, 100000));
  app.add_option("--optimize-iterations", options.optimize_outer_iterations,
                 "OptimizeComesh outer iterations per session (0 = no OptimizeComesh)");
  std::string token_file;
  CLI::Option* token_opt = app.add_option("--token", options.token, "Bearer token");
  // A file keeps the token out of argv (visible to every user); the same file as the server's
  // --tokens works, so one secret serves both (docker/compose.yaml).
  app.add_option("--token-file", token_file,
                 "Read the bearer token from this file: the first word of its first line that is "
                 "neither empty nor a # comment (a --tokens file's TOKEN [NAME] lines work)")
      ->check(CLI::ExistingFile)
      ->excludes(token_opt);
  app.add_option("--json", json_path, "Also write the report as JSON here");
  CLI11_PARSE(app, argc, argv);

  if (absl::Status ok = inbetween::loadgen::CheckLoopbackTarget(target); !ok.ok()) {
    std::fprintf(stderr, "error: %s\n", std::string(ok.message()).c_str());
    return 2;
  }
  if (!token_file.empty()) {
    std::ifstream in(token_file);
    std::string line, word;
    while (std::getline(in, line)) {
      std::istringstream words(line);
      if (words >> word && word[0] != '#') break;
      word.clear();
    }
    if (word.empty()) {
      std::fprintf(stderr, "error: --token-file %s holds no token\n", token_file.c_str());
      return 2;
    }
    options.token = word;
  }
  options.duration = std::chrono::seconds(seconds);
  for (const std::string& path : drawings) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    options.drawings_svg.push_back(text.str());
  }
  auto report = inbetween::loadgen::RunLoad(
      grpc::CreateChannel(target, grpc::InsecureChannelCredentials()), options);
  if (!report.ok()) {
    std::fprintf(stderr, "error: %s\n", report.status().ToString().c_str());
    return 1;
  }
  std::fputs(inbetween::loadgen::FormatTable(*report).c_str(), stdout);
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    out << inbetween::loadgen::FormatJson(*report) << "\n";
    if (!out) {
      std::fprintf(stderr, "error: cannot write %s\n", json_path.c_str());
      return 1;
    }
  }
  return 0;
}
