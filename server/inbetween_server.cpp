// InbetweenServer: grpc::ServerBuilder set-up, health status and graceful shutdown.
#include "server/inbetween_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server_builder.h>
#include <grpcpp/support/channel_arguments.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/dir_session_store.h"
#include "server/inbetween_service.h"
#include "server/metrics.h"
#include "server/request_parse_errors.h"
#include "server/redis_session_store.h"
#include "server/session_store.h"

namespace inbetween::server {

namespace {

absl::StatusOr<std::string> ReadPem(const std::string& path, absl::string_view flag) {
  std::ifstream in(path);
  if (!in) return absl::InvalidArgumentError(absl::StrCat(flag, ": cannot read '", path, "'"));
  std::stringstream text;
  text << in.rdbuf();
  if (text.str().find("-----BEGIN") == std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat(flag, ": '", path, "' is not a PEM file"));
  }
  return text.str();
}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> Credentials(const ServerOptions& options) {
  if (options.tls_cert.empty() && options.tls_key.empty()) {
    if (!options.tls_client_ca.empty()) {
      return absl::InvalidArgumentError("--tls-client-ca needs --tls-cert and --tls-key");
    }
    return grpc::InsecureServerCredentials();
  }
  if (options.tls_cert.empty() || options.tls_key.empty()) {
    return absl::InvalidArgumentError("--tls-cert and --tls-key go together");
  }
  absl::StatusOr<std::string> cert = ReadPem(options.tls_cert, "--tls-cert");
  if (!cert.ok()) return cert.status();
  absl::StatusOr<std::string> key = ReadPem(options.tls_key, "--tls-key");
  if (!key.ok()) return key.status();
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*key, *cert});
  if (!options.tls_client_ca.empty()) {
    absl::StatusOr<std::string> ca = ReadPem(options.tls_client_ca, "--tls-client-ca");
    if (!ca.ok()) return ca.status();
    ssl.pem_root_certs = *ca;
    ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(ssl);
}

// The first line of --redis-password-file (a trailing newline is not part of the password).
absl::StatusOr<std::string> ReadPasswordFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!in || !std::getline(in, line)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--redis-password-file: cannot read a line from '", path, "'"));
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--redis-password-file: '", path, "' holds an empty password"));
  }
  return line;
}

absl::StatusOr<std::shared_ptr<SessionStore>> OpenStore(const ServerOptions& options) {
  if (options.store == "memory") {
    return std::make_shared<MemorySessionStore>(options.max_sessions);
  }
  if (absl::StartsWith(options.store, "dir:")) {
    DirStoreOptions dir;
    dir.max_sessions = options.max_sessions;
    absl::StatusOr<std::unique_ptr<DirSessionStore>> store =
        DirSessionStore::Open(options.store.substr(4), dir);
    if (!store.ok()) return store.status();
    return std::shared_ptr<SessionStore>(*std::move(store));
  }
  if (absl::StartsWith(options.store, "redis://")) {
    RedisStoreOptions redis;
    redis.max_sessions = options.max_sessions;
    redis.session_ttl = options.session_ttl;
    if (!options.redis_password_file.empty()) {
      absl::StatusOr<std::string> password = ReadPasswordFile(options.redis_password_file);
      if (!password.ok()) return password.status();
      redis.password = *std::move(password);
    }
    absl::StatusOr<std::unique_ptr<RedisSessionStore>> store =
        RedisSessionStore::Open(options.store, redis);
    if (!store.ok()) return store.status();
    return std::shared_ptr<SessionStore>(*std::move(store));
  }
  return absl::InvalidArgumentError(
      absl::StrCat("--store: '", options.store,
                   "' is not supported (use 'memory', 'dir:PATH' or 'redis://HOST:PORT[/DB]')"));
}

}  // namespace

absl::StatusOr<std::unique_ptr<InbetweenServer>> InbetweenServer::Start(
    const ServerOptions& options) {
  if (!options.listen.empty() && options.listen.find(':') == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("--listen: '", options.listen, "' is not HOST:PORT"));
  }
  if (options.max_message_bytes < 1024) {
    return absl::InvalidArgumentError("--max-message-bytes must be at least 1024");
  }
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials = Credentials(options);
  if (!credentials.ok()) return credentials.status();
  std::unique_ptr<InbetweenServer> server(new InbetweenServer());
  server->options_ = options;
  absl::StatusOr<std::shared_ptr<SessionStore>> store = OpenStore(options);
  if (!store.ok()) return store.status();
  server->store_ = *std::move(store);
  ServiceOptions service = options.service;
  if (!options.tokens_file.empty()) {
    absl::StatusOr<TokenTable> tokens = TokenTable::Load(options.tokens_file);
    if (!tokens.ok()) return tokens.status();
    service.tokens = std::make_shared<const TokenTable>(*std::move(tokens));
  }
  server->metrics_ = service.metrics ? service.metrics : std::make_shared<Metrics>();
  service.metrics = server->metrics_;
  server->service_ = std::make_unique<InbetweenService>(server->store_, service);

  // Both switches are process-wide in gRPC and must be set before the builder is created.
  grpc::EnableDefaultHealthCheckService(true);
  if (options.reflection) grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  grpc::ServerBuilder builder;
  if (!options.listen.empty()) {
    builder.AddListeningPort(options.listen, *credentials, &server->port_);
  }
  // gRPC sets SO_REUSEPORT by default: a second server on a taken port would start and silently
  // share the traffic. Fail instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  builder.SetMaxSendMessageSize(options.max_message_bytes);
  builder.RegisterService(server->service_.get());
  builder.experimental().SetInterceptorCreators(RequestParseErrorInterceptors());
  server->server_ = builder.BuildAndStart();
  if (!server->server_) {
    return absl::UnavailableError(
        absl::StrCat("--listen: could not start the server on '", options.listen, "'"));
  }
  if (!options.listen.empty() && server->port_ == 0) {
    server->server_->Shutdown();
    return absl::UnavailableError(absl::StrCat("--listen: could not bind '", options.listen,
                                               "' (address in use or not local?)"));
  }
  grpc::HealthCheckServiceInterface* health = server->server_->GetHealthCheckService();
  if (health != nullptr) {
    health->SetServingStatus("", true);
    health->SetServingStatus("inbetween.v1.Inbetween", true);
  }
  if (options.idle_evict.count() > 0 && options.store != "memory") {
    InbetweenServer* self = server.get();
    server->evictor_ = std::thread([self] { self->EvictIdleLoop(); });
  }
  if (!options.metrics_listen.empty()) {
    InbetweenServer* self = server.get();
    absl::StatusOr<std::unique_ptr<MetricsHttpServer>> http = MetricsHttpServer::Start(
        options.metrics_listen, server->metrics_, [self] { return self->ScrapedGauges(); });
    if (!http.ok()) return http.status();
    server->metrics_server_ = *std::move(http);
  }
  return server;
}

void InbetweenServer::EvictIdleLoop() {
  // Sweep a few times per idle period (at most once a second), so a session leaves memory at
  // most ~1.25 idle periods after its last use.
  const auto idle = options_.idle_evict;
  const auto period = std::clamp<std::chrono::milliseconds>(
      std::chrono::duration_cast<std::chrono::milliseconds>(idle) / 4,
      std::chrono::milliseconds(50), std::chrono::milliseconds(1000));
  std::unique_lock lock(evictor_mutex_);
  while (!evictor_stop_.wait_for(lock, period, [this] { return evictor_stopping_; })) {
    const size_t evicted = store_->EvictIdle(std::chrono::steady_clock::now() - idle);
    if (evicted > 0) spdlog::debug("evicted {} idle sessions from memory", evicted);
  }
}

InbetweenServer::~InbetweenServer() {
  if (evictor_.joinable()) {
    {
      std::lock_guard lock(evictor_mutex_);
      evictor_stopping_ = true;
    }
    evictor_stop_.notify_all();
    evictor_.join();
  }
  if (server_) {
    Shutdown();
    Wait();
  }
  metrics_server_.reset();  // its callback reads the service and the store
}

std::shared_ptr<grpc::Channel> InbetweenServer::InProcessChannel() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(kMaxMessageBytes);
  args.SetMaxSendMessageSize(kMaxMessageBytes);
  return server_->InProcessChannel(args);
}

int InbetweenServer::port() const { return port_; }

int InbetweenServer::metrics_port() const { return metrics_server_ ? metrics_server_->port() : 0; }

std::string InbetweenServer::RenderMetrics() const { return metrics_->Render(ScrapedGauges()); }

std::vector<Metrics::Gauge> InbetweenServer::ScrapedGauges() const {
  const HeavyJobs& heavy = service_->heavy_jobs();
  return {
      {"inbetween_active_sessions", "Sessions in the store.", static_cast<double>(store_->Count())},
      {"inbetween_cached_sessions", "Sessions held in this process's memory.",
       static_cast<double>(store_->CachedCount())},
      {"inbetween_heavy_jobs_running", "Heavy jobs (build, optimize, inbetween) running.",
       static_cast<double>(heavy.running())},
      {"inbetween_heavy_queue_depth", "Heavy jobs waiting for a slot.",
       static_cast<double>(heavy.queued())},
      {"inbetween_heavy_jobs_max", "Heavy-job slots (--max-heavy-jobs).",
       static_cast<double>(heavy.max_running())},
      {"inbetween_serving", "1 while serving, 0 while draining.", draining_ ? 0.0 : 1.0},
  };
}

void InbetweenServer::Shutdown() {
  std::call_once(shutdown_once_, [this] {
    draining_ = true;
    spdlog::info("shutting down (grace {} ms)", options_.shutdown_grace.count());
    if (grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService()) {
      health->Shutdown();  // every service reports NOT_SERVING from now on
    }
    server_->Shutdown(std::chrono::system_clock::now() + options_.shutdown_grace);
  });
}

void InbetweenServer::Wait() { server_->Wait(); }

}  // namespace inbetween::server
