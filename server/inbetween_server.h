// The Inbetween gRPC server: the service, the session store, health and reflection, an optional
// listening port and an in-process channel (used by the embedded CLI and the tests).
#pragma once

#include <grpcpp/channel.h>
#include <grpcpp/server.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <string>

#include "absl/status/statusor.h"

namespace inbetween::server {

class InbetweenService;
class SessionStore;

inline constexpr int kMaxMessageBytes = 64 * 1024 * 1024;

struct ServerOptions {
  // "host:port"; empty = no listening port (in-process only); port 0 = pick a free port.
  std::string listen;
  // Only "memory" for now; anything else -> InvalidArgument naming the flag (--store).
  std::string store = "memory";
  bool reflection = true;
  std::chrono::milliseconds shutdown_grace{5000};
};

class InbetweenServer {
 public:
  // Errors: INVALID_ARGUMENT naming the flag (--store, --listen), UNAVAILABLE when the address
  // cannot be bound. Note: gRPC's reflection plugin is process-wide; once a server in this
  // process started with reflection, later servers have it too.
  static absl::StatusOr<std::unique_ptr<InbetweenServer>> Start(const ServerOptions& options);
  ~InbetweenServer();  // Shutdown() + Wait()

  std::shared_ptr<grpc::Channel> InProcessChannel();  // same service, no network
  int port() const;                                   // the bound port (0 if not listening)
  // Stop accepting, let running streams finish up to shutdown_grace, then cancel them (the
  // handlers see the cancellation and stop their solver work). Idempotent, thread-safe.
  void Shutdown();
  void Wait();  // blocks until the server has shut down

 private:
  InbetweenServer() = default;

  ServerOptions options_;
  int port_ = 0;
  std::shared_ptr<SessionStore> store_;
  std::unique_ptr<InbetweenService> service_;  // must outlive server_
  std::unique_ptr<grpc::Server> server_;
  std::once_flag shutdown_once_;
};

}  // namespace inbetween::server
