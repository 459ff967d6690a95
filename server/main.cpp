// inbetween-server: runs the Inbetween gRPC service until SIGTERM/SIGINT, then shuts down
// gracefully (running streams get --shutdown-grace-ms, then are cancelled) and exits 0.
//
// On start it prints exactly one plain line to stdout, then flushes:
//   inbetween-server listening on HOST:PORT
// with the real bound port (useful with --listen 127.0.0.1:0); e2e tests parse this line.
#include <pthread.h>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include "server/inbetween_server.h"
#include "server/logging.h"

namespace {

// "host:port" -> "host" (keeps brackets of IPv6 literals).
std::string HostOf(const std::string& listen) {
  const size_t colon = listen.rfind(':');
  return colon == std::string::npos ? listen : listen.substr(0, colon);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"inbetween-server: the Inbetween gRPC service (2D inbetween animation)"};
  std::string listen = "127.0.0.1:50051";
  std::string store = "memory";
  std::string log_level = "info";
  std::string log_format = "text";
  bool no_reflection = false;
  int64_t grace_ms = 5000;
  app.add_option("--listen", listen, "HOST:PORT to listen on; port 0 picks a free port")
      ->capture_default_str();
  app.add_option("--store", store, "session store: memory")->capture_default_str();
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->capture_default_str();
  app.add_option("--log-format", log_format, "text|json")->capture_default_str();
  app.add_flag("--no-reflection", no_reflection, "disable gRPC server reflection");
  app.add_option("--shutdown-grace-ms", grace_ms,
                 "on SIGTERM/SIGINT, how long running streams may finish before they are cancelled")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{3'600'000}));
  CLI11_PARSE(app, argc, argv);

  if (absl::Status s = inbetween::server::ConfigureLogging(log_level, log_format); !s.ok()) {
    std::cerr << "inbetween-server: " << s.message() << "\n";
    return 2;
  }
  if (listen.empty()) {
    std::cerr << "inbetween-server: --listen must not be empty\n";
    return 2;
  }

  // Block the shutdown signals before gRPC starts its threads (they inherit the mask); the main
  // thread then waits for them synchronously with sigwait.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  inbetween::server::ServerOptions options;
  options.listen = listen;
  options.store = store;
  options.reflection = !no_reflection;
  options.shutdown_grace = std::chrono::milliseconds(grace_ms);
  auto server = inbetween::server::InbetweenServer::Start(options);
  if (!server.ok()) {
    std::cerr << "inbetween-server: " << server.status().message() << "\n";
    return server.status().code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
  }
  const std::string address = HostOf(listen) + ":" + std::to_string((*server)->port());
  spdlog::info("listening on {} (store {}, reflection {})", address, store,
               no_reflection ? "off" : "on");
  std::cout << "inbetween-server listening on " << address << std::endl;  // endl flushes

  int signal_number = 0;
  while (sigwait(&signals, &signal_number) != 0) {
  }
  spdlog::info("received {}, shutting down", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  (*server)->Shutdown();
  (*server)->Wait();
  server->reset();
  spdlog::info("stopped");
  return 0;
}
