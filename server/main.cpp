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

// What the command line sets: the server's options and the values main turns into them.
struct Flags {
  inbetween::server::ServerOptions options;
  std::string listen = "127.0.0.1:50051";
  std::string store = "memory";
  std::string log_level = "info";
  std::string log_format = "text";
  bool no_reflection = false;
  bool retain_freed_memory = false;
  int64_t grace_ms = 5000;
  int64_t idle_evict_seconds = 600;
  int64_t session_ttl_seconds = options.session_ttl.count();
};

// Heavy-job admission and the per-request limits.
void AddLimitFlags(CLI::App& app, Flags& f) {
  app.add_option("--max-heavy-jobs", f.options.service.heavy.max_running,
                 "heavy jobs (build, optimize, inbetween) running at once; 0 = hardware threads")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  app.add_option("--heavy-queue", f.options.service.heavy.max_queued,
                 "heavy jobs waiting for a slot before RESOURCE_EXHAUSTED; -1 = 4 x max-heavy-jobs")
      ->capture_default_str()
      ->check(CLI::Range(-1, 100000));
  app.add_option("--solver-threads", f.options.service.solver_threads,
                 "threads per heavy job's solver; results are identical for every value")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_option("--max-heavy-jobs-per-token", f.options.service.heavy.max_per_owner,
                 "heavy jobs running or waiting per token; 0 = max-heavy-jobs")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  app.add_option("--max-message-bytes", f.options.max_message_bytes,
                 "largest request or response message")
      ->capture_default_str()
      ->check(CLI::Range(1024, 1 << 30));
  app.add_option("--max-drawing-points", f.options.service.limits.max_drawing_points,
                 "points per drawing")
      ->capture_default_str()
      ->check(CLI::Range(3, 100'000'000));
  app.add_option("--max-drawings", f.options.service.limits.max_drawings,
                 "drawings (shapes) per session, 2..16")
      ->capture_default_str()
      ->check(CLI::Range(2, 16));
  app.add_option("--max-mesh-vertices", f.options.service.limits.max_mesh_vertices,
                 "multimesh vertices")
      ->capture_default_str()
      ->check(CLI::Range(3, 100'000'000));
  app.add_option("--max-frames", f.options.service.limits.max_frames,
                 "frames per Inbetween request")
      ->capture_default_str()
      ->check(CLI::Range(2, 100000));
  app.add_option("--max-sessions", f.options.max_sessions, "sessions in the whole server")
      ->capture_default_str();
  app.add_option("--max-sessions-per-token", f.options.service.limits.max_sessions_per_token,
                 "sessions per bearer token (with --tokens)")
      ->capture_default_str();
}

// Listening, the session store, security, metrics, logging and shutdown.
void AddServerFlags(CLI::App& app, Flags& f) {
  app.add_option("--listen", f.listen, "HOST:PORT to listen on; port 0 picks a free port")
      ->capture_default_str();
  app.add_option("--store", f.store,
                 "session store: memory | dir:PATH (one snapshot file per session version) | "
                 "redis://[[USER]:PASSWORD@]HOST:PORT[/DB] (shared by replicas)")
      ->capture_default_str();
  app.add_option("--tokens", f.options.tokens_file,
                 "file of bearer tokens, one per line: TOKEN [NAME]; required on every call")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-cert", f.options.tls_cert, "PEM certificate chain: serve TLS")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-key", f.options.tls_key, "PEM private key of --tls-cert")
      ->check(CLI::ExistingFile);
  app.add_option("--tls-client-ca", f.options.tls_client_ca,
                 "PEM CA: require client certificates it signed (mTLS)")
      ->check(CLI::ExistingFile);
  app.add_option("--metrics-listen", f.options.metrics_listen,
                 "HOST:PORT for Prometheus GET /metrics (off when empty)");
  app.add_option("--idle-evict-seconds", f.idle_evict_seconds,
                 "dir/redis stores: drop sessions unused this long from memory (they reload from "
                 "the store on next use); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{30'000'000}));
  app.add_option("--session-ttl-seconds", f.session_ttl_seconds,
                 "redis store: a session expires this long after its last use (create, write, "
                 "read); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{10} * 365 * 24 * 3600));
  app.add_option("--redis-password-file", f.options.redis_password_file,
                 "redis store: file whose first line is Redis' AUTH password (requirepass)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-level", f.log_level, "trace|debug|info|warn|error|off")
      ->capture_default_str();
  app.add_option("--log-format", f.log_format, "text|json")->capture_default_str();
  app.add_flag("--no-reflection", f.no_reflection, "disable gRPC server reflection");
  app.add_flag("--retain-freed-memory", f.retain_freed_memory,
               "keep freed memory for reuse (faster comesh optimization; the resident size "
               "stays near its peak): solver/core/retain_memory.h");
  app.add_option("--shutdown-grace-ms", f.grace_ms,
                 "on SIGTERM/SIGINT, how long running streams may finish before they are cancelled")
      ->capture_default_str()
      ->check(CLI::Range(int64_t{0}, int64_t{3'600'000}));
}

// Starts the server from parsed flags and serves until SIGTERM/SIGINT; the exit code.
int Run(Flags& f) {
  if (f.retain_freed_memory) inbetween::solver::RetainFreedMemory();

  if (absl::Status s = inbetween::server::ConfigureLogging(f.log_level, f.log_format); !s.ok()) {
    std::cerr << "inbetween-server: " << s.message() << "\n";
    return 2;
  }
  if (f.listen.empty()) {
    std::cerr << "inbetween-server: --listen must not be empty\n";
    return 2;
  }

  // SIGTERM / SIGINT: a handler writes to a pipe the main thread reads (server/stop_signals.h).
  if (!inbetween::server::InstallStopSignals()) {
    std::cerr << "inbetween-server: cannot install the SIGTERM/SIGINT handler\n";
    return 1;
  }

  inbetween::server::ServerOptions& options = f.options;
  options.listen = f.listen;
  options.service.log_ok_rpcs_at_info = true;
  options.store = f.store;
  options.idle_evict = std::chrono::seconds(f.idle_evict_seconds);
  options.session_ttl = std::chrono::seconds(f.session_ttl_seconds);
  options.reflection = !f.no_reflection;
  options.shutdown_grace = std::chrono::milliseconds(f.grace_ms);
  auto server = inbetween::server::InbetweenServer::Start(options);
  if (!server.ok()) {
    std::cerr << "inbetween-server: " << server.status().message() << "\n";
    return server.status().code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
  }
  const std::string address = HostOf(f.listen) + ":" + std::to_string((*server)->port());
  spdlog::info("listening on {} (store {}, reflection {}, tls {}, tokens {})", address,
               inbetween::server::RedactRedisUrl(f.store), f.no_reflection ? "off" : "on",
               options.tls_cert.empty() ? "off" : "on", options.tokens_file.empty() ? "off" : "on");
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"inbetween-server: the Inbetween gRPC service (2D inbetween animation)"};
  Flags flags;
  AddServerFlags(app, flags);
  AddLimitFlags(app, flags);
  CLI11_PARSE(app, argc, argv);
  return Run(flags);
}
