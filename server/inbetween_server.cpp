// InbetweenServer: grpc::ServerBuilder set-up, health status and graceful shutdown.
#include "server/inbetween_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/security/server_credentials.h>
#include <grpcpp/server_builder.h>
#include <grpcpp/support/channel_arguments.h>
#include <spdlog/spdlog.h>

#include <utility>

#include "absl/strings/str_cat.h"
#include "server/inbetween_service.h"
#include "server/session_store.h"

namespace inbetween::server {

absl::StatusOr<std::unique_ptr<InbetweenServer>> InbetweenServer::Start(
    const ServerOptions& options) {
  if (options.store != "memory") {
    return absl::InvalidArgumentError(absl::StrCat(
        "--store: '", options.store, "' is not supported (this version has only 'memory')"));
  }
  if (!options.listen.empty() && options.listen.find(':') == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("--listen: '", options.listen, "' is not HOST:PORT"));
  }
  std::unique_ptr<InbetweenServer> server(new InbetweenServer());
  server->options_ = options;
  server->store_ = std::make_shared<MemorySessionStore>();
  server->service_ = std::make_unique<InbetweenService>(server->store_);

  // Both switches are process-wide in gRPC and must be set before the builder is created.
  grpc::EnableDefaultHealthCheckService(true);
  if (options.reflection) grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  grpc::ServerBuilder builder;
  if (!options.listen.empty()) {
    builder.AddListeningPort(options.listen, grpc::InsecureServerCredentials(), &server->port_);
  }
  // gRPC sets SO_REUSEPORT by default: a second server on a taken port would start and silently
  // share the traffic. Fail instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.SetMaxReceiveMessageSize(kMaxMessageBytes);
  builder.SetMaxSendMessageSize(kMaxMessageBytes);
  builder.RegisterService(server->service_.get());
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
  return server;
}

InbetweenServer::~InbetweenServer() {
  if (server_) {
    Shutdown();
    Wait();
  }
}

std::shared_ptr<grpc::Channel> InbetweenServer::InProcessChannel() {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(kMaxMessageBytes);
  args.SetMaxSendMessageSize(kMaxMessageBytes);
  return server_->InProcessChannel(args);
}

int InbetweenServer::port() const { return port_; }

void InbetweenServer::Shutdown() {
  std::call_once(shutdown_once_, [this] {
    spdlog::info("shutting down (grace {} ms)", options_.shutdown_grace.count());
    if (grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService()) {
      health->Shutdown();  // every service reports NOT_SERVING from now on
    }
    server_->Shutdown(std::chrono::system_clock::now() + options_.shutdown_grace);
  });
}

void InbetweenServer::Wait() { server_->Wait(); }

}  // namespace inbetween::server
