// `inbetween`: the animator's command-line tool. Without --server the service runs embedded
// in this process and is reached over an in-process gRPC channel (the same code path as remote).
#include <grpcpp/grpcpp.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <thread>

#include "client/animate_command.h"
#include "client/inbetween_client.h"
#include "server/inbetween_server.h"

namespace {

constexpr int kUsageError = 2;

// Ctrl-C / SIGTERM cancel the RPC in flight; the command then exits with code 130.
void StartSignalThread(inbetween::client::InbetweenClient* client) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  std::thread([set, client]() {
    int sig = 0;
    if (sigwait(&set, &sig) == 0) {
      std::fprintf(stderr, "\ninterrupted: cancelling...\n");
      client->CancelInFlight();
    }
  }).detach();
}

}  // namespace

int main(int argc, char** argv) {
  // Block the signals before any thread starts so only the signal thread receives them.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);

  CLI::App app{"inbetween: 2D inbetween animation from a few key drawings"};
  app.require_subcommand(1);
  std::string server;
  app.add_option("--server", server,
                 "HOST:PORT of an inbetween-server; without it the service runs embedded");

  inbetween::client::AnimateOptions animate;
  CLI::App* cmd = app.add_subcommand("animate", "Inbetween frames from 2-16 SVG drawings");
  cmd->fallthrough();  // global options (--server) may also follow the subcommand
  cmd->footer(
      "Examples:\n"
      "  inbetween animate square.svg hexagon.svg --frames 24 --out out/\n"
      "  inbetween --server 127.0.0.1:50051 animate a.svg b.svg c.svg --out out/ --method alexa\n"
      "Writes OUT/frames.json and OUT/frame_0000.svg ...; prints the path of frames.json.\n"
      "Exit codes: 0 ok, 2 usage, 3 bad input, 4 server unreachable, 5 server failure, "
      "130 interrupted.");
  cmd->add_option("drawings", animate.drawings, "SVG drawings in key order (2 to 16)")
      ->required()
      ->check(CLI::ExistingFile)
      ->expected(2, 16);
  cmd->add_option("--frames", animate.frames, "Frames including the keys")
      ->default_val(24)
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--out", animate.out_dir, "Output directory")->required();
  cmd->add_option("--method", animate.method, "linear | alexa | zhu17")
      ->default_val("zhu17")
      ->check(CLI::IsMember({"linear", "alexa", "zhu17"}));
  cmd->add_flag("--mesh", animate.mesh_overlay, "Draw the mesh over each SVG frame");
  cmd->add_flag("-q,--quiet", animate.quiet, "No progress output");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kUsageError;
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
    channel = grpc::CreateChannel(server, grpc::InsecureChannelCredentials());
  }

  inbetween::client::InbetweenClient client(channel);
  StartSignalThread(&client);
  absl::Status status = inbetween::client::RunAnimate(animate, client);
  if (embedded) embedded->Shutdown();
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", std::string(status.message()).c_str());
  }
  return inbetween::client::ExitCodeFor(status);
}
