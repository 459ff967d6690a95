// inbetween-server: runs the Inbetween gRPC service until SIGTERM/SIGINT, then shuts down
// gracefully (running streams get --shutdown-grace-ms, then are cancelled) and exits 0.
//
// On start it prints exactly one plain line to stdout, then flushes:
//   inbetween-server listening on HOST:PORT
// with the real bound port (useful with --listen 127.0.0.1:0); e2e tests parse this line.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>

#include "server/inbetween_server.h"
#include "server/logging.h"
#include "server/redis_session_store.h"
#include "server/stop_signals.h"
#include "solver/core/retain_memory.h"

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
  app.add_option("--store", store,
                 "session store: memory | dir:PATH (one snapshot file per session version) | "
                 "redis://HOST:PORT[/DB] (shared by replicas)")
      ->capture_default_str();
  int64_t idle_evict_seconds = 600;
  inbetween::server::ServerOptions options;
  inbetween::server::ServiceLimits& limits = options.service.limits;
  inbetween::server::HeavyJobOptions& heavy = options.service.heavy;
  app.add_option("--max-heavy-jobs", heavy.max_running,
                 "heavy jobs (build, optimize, inbetween) running at once; 0 = hardware threads")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  app.add_option("--heavy-queue", heavy.max_queued,
                 "heavy jobs waiting for a slot before RESOURCE_EXHAUSTED; -1 = 4 x max-heavy-jobs")
      ->capture_default_str()
      ->check(CLI::Range(-1, 100000));
  app.add_option("--solver-threads", options.service.solver_threads,
                 "threads per heavy job's solver; results are identical for every value")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_option("--max-heavy-jobs-per-token", heavy.max_per_owner,
                 "heavy jobs running or waiting per token; 0 = max-heavy-jobs")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  app.add_option("--max-message-bytes", options.max_message_bytes,
                 "largest request or response message")
      ->capture_default_str()
      ->check(CLI::Range(1024, 1 << 30));
  app.add_option("--max-drawing-points", limits.max_drawing_points, "points per drawing")
      ->capture_default_str()
      ->check(CLI::Range(3, 100'000'000));
  app.add_option("--max-drawings", limits.max_drawings, "drawings (shapes) per session, 2..16")
      ->capture_default_str()
      ->check(CLI::Range(2, 16));
  app.add_option("--max-mesh-vertices", limits.max_mesh_vertices, "multimesh vertices")
      ->capture_default_str()
      ->check(CLI::Range(3, 100'000'000));
  app.add_option("--max-frames", limits.max_frames, "frames per Inbetween request")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000));
  app.add_option("--max-sessions", options.max_sessions, "sessions in the whole server")
      ->capture_default_str();
  app.add_option("--max-sessions-per-token", limits.max_sessions_per_token,
                 "sessions per bearer token (with --tokens)")
      ->capture_default_str();
  app.add_option("--tokens", options.tokens_file,
                 "file of bearer tokens, one per line: TOKEN [NAME]; required on every call")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-cert", options.tls_cert, "PEM certificate chain: serve TLS")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", options.tls_key, "PEM private key of --tls-cert")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-client-ca", options.tls_client_ca,
                 "PEM CA: require client certificates it signed (mTLS)")
      ->check(CLI::ExistingFile);
  app.add_option("--metrics-listen", options.metrics_listen,
                 "HOST:PORT for Prometheus GET /metrics (off when empty)");
  app.add_option("--idle-evict-seconds", idle_evict_seconds,
                 "dir/redis stores: drop sessions unused this long from memory (they reload from "
                 "the store on next use); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{30'000'000}));
  int64_t session_ttl_seconds = options.session_ttl.count();
  app.add_option("--session-ttl-seconds", session_ttl_seconds,
                 "redis store: a session expires this long after its last use (create, write, "
                 "read); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{10} * 365 * 24 * 3600));
  app.add_option("--redis-password-file", options.redis_password_file,
                 "redis store: file whose first line is Redis' AUTH password (requirepass)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->capture_default_str();
  app.add_option("--log-format", log_format, "text|json")->capture_default_str();
  app.add_flag("--no-reflection", no_reflection, "disable gRPC server reflection");
  bool retain_freed_memory = false;
  app.add_flag("--retain-freed-memory", retain_freed_memory,
               "keep freed memory for reuse (faster comesh optimization; the resident size "
               "stays near its peak): solver/core/retain_memory.h");
  app.add_option("--shutdown-grace-ms", grace_ms,
                 "on SIGTERM/SIGINT, how long running streams may finish before they are cancelled")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{3'600'000}));
  CLI11_PARSE(app, argc, argv);
  if (retain_freed_memory) inbetween::solver::RetainFreedMemory();

  if (absl::Status s = inbetween::server::ConfigureLogging(log_level, log_format); !s.ok()) {
    std::cerr << "inbetween-server: " << s.message() << "\n";
    return 2;
  }
  if (listen.empty()) {
    std::cerr << "inbetween-server: --listen must not be empty\n";
    return 2;
  }

  // SIGTERM / SIGINT: a handler writes to a pipe the main thread reads (server/stop_signals.h).
  if (!inbetween::server::InstallStopSignals()) {
    std::cerr << "inbetween-server: cannot install the SIGTERM/SIGINT handler\n";
    return 1;
  }

  options.listen = listen;
  options.service.log_ok_rpcs_at_info = true;
  options.store = store;
  options.idle_evict = std::chrono::seconds(idle_evict_seconds);
  options.session_ttl = std::chrono::seconds(session_ttl_seconds);
  options.reflection = !no_reflection;
  options.shutdown_grace = std::chrono::milliseconds(grace_ms);
  auto server = inbetween::server::InbetweenServer::Start(options);
  if (!server.ok()) {
    std::cerr << "inbetween-server: " << server.status().message() << "\n";
    return server.status().code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
  }
  const std::string address = HostOf(listen) + ":" + std::to_string((*server)->port());
  spdlog::info("listening on {} (store {}, reflection {}, tls {}, tokens {})", address,
               inbetween::server::RedactRedisUrl(store),
               no_reflection ? "off" : "on", options.tls_cert.empty() ? "off" : "on",
               options.tokens_file.empty() ? "off" : "on");
  if ((*server)->metrics_port() != 0) {
    spdlog::info("metrics on {}:{}/metrics", HostOf(options.metrics_listen),
                 (*server)->metrics_port());
  }
  std::cout << "inbetween-server listening on " << address << std::endl;  // endl flushes

  const int signal_number = inbetween::server::WaitForStopSignal();
  spdlog::info("received {}, shutting down", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  (*server)->Shutdown();
  (*server)->Wait();
  server->reset();
  spdlog::info("stopped");
  return 0;
}
