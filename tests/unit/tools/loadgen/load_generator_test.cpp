// Tests inbetween-loadgen's engine (tools/loadgen/load_generator.cpp): loopback-only targets,
// nearest-rank percentiles, a bounded run against a real in-process server that stops at
// exactly the request budget, exercises every RPC of the studio loop without errors, loses no
// session and gets the same frames from every stream, the failover of the client library (through
// a front that breaks Inbetween streams, an optimization and a GetSession as a dying replica
// behind a proxy would: resumed at the next frame or the checkpoint, frames identical,
// x-session-id on every call), and 64 studios against
// a real inbetween-server process running on far fewer than 64 threads of this process (the
// callback API), with the same guarantees.
#include "tools/loadgen/load_generator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <deque>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>
#include <thread>

#include "absl/status/statusor.h"
#include "nlohmann/json.hpp"
#include "server/inbetween_server.h"

namespace inbetween::loadgen {
namespace {

using ::testing::HasSubstr;

std::string ReadExample(const std::string& relative) {
  std::ifstream in(std::string(INBETWEEN_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Forwards every call of the studio loop to `backend`, recording each call's x-session-id against
// its request's session id and breaking calls as scripted: the Inbetween streams in `faults`
// (forward `after_frames` frames, then end with `status`), the OptimizeComesh streams in
// `optimize_faults` (`after_frames` iterations) and `get_session_faults` GetSessions.
class FlakyFront final : public v1::Inbetween::Service {
 public:
  struct Fault {
    grpc::Status status;
    int after_frames = 0;
  };
  explicit FlakyFront(std::shared_ptr<grpc::Channel> backend)
      : backend_(v1::Inbetween::NewStub(std::move(backend))) {}

  std::mutex mu;                         // guards the fields below
  std::deque<Fault> faults;              // Inbetween
  std::deque<Fault> optimize_faults;     // OptimizeComesh: `after_frames` iterations
  std::deque<Fault> build_faults;        // BuildMultimesh: `after_frames` progress messages
  std::vector<uint64_t> build_versions;  // expected_version of every BuildMultimesh call
  int get_session_faults = 0;
  std::vector<bool> resumes;                    // `resume` of every OptimizeComesh call
  std::vector<uint64_t> expected_versions;      // of every OptimizeComesh call
  std::vector<uint32_t> start_frames;           // of every Inbetween call
  std::vector<std::string> missing_session_id;  // methods called without the right x-session-id

  grpc::Status CreateSession(grpc::ServerContext* c, const v1::CreateSessionRequest* q,
                             v1::CreateSessionResponse* r) override {
    return Forward(c, *q, r, &v1::Inbetween::Stub::CreateSession);
  }
  grpc::Status PutDrawing(grpc::ServerContext* c, const v1::PutDrawingRequest* q,
                          v1::PutDrawingResponse* r) override {
    return Forward(c, *q, r, &v1::Inbetween::Stub::PutDrawing);
  }
  grpc::Status GetSession(grpc::ServerContext* c, const v1::GetSessionRequest* q,
                          v1::GetSessionResponse* r) override {
    {
      std::lock_guard<std::mutex> lock(mu);
      if (get_session_faults > 0) {
        --get_session_faults;
        return grpc::Status(grpc::StatusCode::UNAVAILABLE, "Socket closed");
      }
    }
    return Forward(c, *q, r, &v1::Inbetween::Stub::GetSession);
  }
  grpc::Status ListSessions(grpc::ServerContext* c, const v1::ListSessionsRequest* q,
                            v1::ListSessionsResponse* r) override {
    return Forward(c, *q, r, &v1::Inbetween::Stub::ListSessions);
  }
  grpc::Status DeleteSession(grpc::ServerContext* c, const v1::DeleteSessionRequest* q,
                             v1::DeleteSessionResponse* r) override {
    return Forward(c, *q, r, &v1::Inbetween::Stub::DeleteSession);
  }
  grpc::Status BuildMultimesh(grpc::ServerContext* c, const v1::BuildMultimeshRequest* q,
                              grpc::ServerWriter<v1::BuildMultimeshResponse>* w) override {
    std::optional<Fault> fault;
    {
      std::lock_guard<std::mutex> lock(mu);
      build_versions.push_back(q->expected_version());
      if (!build_faults.empty()) {
        fault = build_faults.front();
        build_faults.pop_front();
      }
    }
    if (!fault) return ForwardStream(c, *q, w, &v1::Inbetween::Stub::BuildMultimesh);
    CheckSessionId(*c, q->session_id(), "BuildMultimesh");
    grpc::ClientContext upstream;
    auto reader = backend_->BuildMultimesh(&upstream, *q);
    v1::BuildMultimeshResponse response;
    int messages = 0;
    while (reader->Read(&response)) {
      if (response.has_progress() && messages++ == fault->after_frames) break;
      w->Write(response);
    }
    upstream.TryCancel();  // the replica is gone before it stored the multimesh
    reader->Finish();
    return fault->status;
  }
  grpc::Status OptimizeComesh(grpc::ServerContext* c, const v1::OptimizeComeshRequest* q,
                              grpc::ServerWriter<v1::OptimizeComeshResponse>* w) override {
    std::optional<Fault> fault;
    {
      std::lock_guard<std::mutex> lock(mu);
      resumes.push_back(q->resume());
      expected_versions.push_back(q->expected_version());
      if (!optimize_faults.empty()) {
        fault = optimize_faults.front();
        optimize_faults.pop_front();
      }
    }
    if (!fault) return ForwardStream(c, *q, w, &v1::Inbetween::Stub::OptimizeComesh);
    CheckSessionId(*c, q->session_id(), "OptimizeComesh");
    grpc::ClientContext upstream;
    auto reader = backend_->OptimizeComesh(&upstream, *q);
    v1::OptimizeComeshResponse response;
    int iterations = 0;
    while (reader->Read(&response)) {
      if (response.has_iteration() && iterations++ == fault->after_frames) break;
      w->Write(response);
    }
    upstream.TryCancel();  // the replica is gone: its run stops
    reader->Finish();
    return fault->status;
  }
  grpc::Status Inbetween(grpc::ServerContext* c, const v1::InbetweenRequest* q,
                         grpc::ServerWriter<v1::InbetweenResponse>* w) override {
    std::optional<Fault> fault;
    {
      std::lock_guard<std::mutex> lock(mu);
      start_frames.push_back(q->start_frame());
      if (!faults.empty()) {
        fault = faults.front();
        faults.pop_front();
      }
    }
    if (!fault) return ForwardStream(c, *q, w, &v1::Inbetween::Stub::Inbetween);
    CheckSessionId(*c, q->session_id(), "Inbetween");
    grpc::ClientContext upstream;
    auto reader = backend_->Inbetween(&upstream, *q);
    v1::InbetweenResponse response;
    int frames = 0;
    while (reader->Read(&response)) {
      if (response.has_frame() && frames++ == fault->after_frames) break;
      w->Write(response);
    }
    upstream.TryCancel();  // the replica is gone
    reader->Finish();
    return fault->status;
  }

 private:
  template <class Request>
  static std::string SessionOf(const Request& request) {
    if constexpr (requires { request.session_id(); }) {
      return request.session_id();
    } else {
      return "";
    }
  }
  void CheckSessionId(const grpc::ServerContext& context, const std::string& want,
                      const std::string& method) {
    auto it = context.client_metadata().find("x-session-id");
    const std::string got = it == context.client_metadata().end()
                                ? std::string()
                                : std::string(it->second.data(), it->second.size());
    std::lock_guard<std::mutex> lock(mu);
    if (got != want) missing_session_id.push_back(method);
  }
  template <class Request, class Response, class Method>
  grpc::Status Forward(grpc::ServerContext* context, const Request& request, Response* response,
                       Method method) {
    CheckSessionId(*context, SessionOf(request), Request::descriptor()->name());
    grpc::ClientContext upstream;
    return ((*backend_).*method)(&upstream, request, response);
  }
  template <class Request, class Response, class Method>
  grpc::Status ForwardStream(grpc::ServerContext* context, const Request& request,
                             grpc::ServerWriter<Response>* writer, Method method) {
    CheckSessionId(*context, SessionOf(request), Request::descriptor()->name());
    grpc::ClientContext upstream;
    auto reader = ((*backend_).*method)(&upstream, request);
    Response response;
    while (reader->Read(&response)) writer->Write(response);
    return reader->Finish();
  }

  std::unique_ptr<v1::Inbetween::Stub> backend_;
};

// Threads of this process, from /proc/self/status.
int ThreadCount() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

// inbetween-server as a child process on a free loopback port (its threads are not ours).
class ServerProcess {
 public:
  ~ServerProcess() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
    if (out_ != nullptr) fclose(out_);
  }
  // Starts it with `flags`; the address it listens on, or an error.
  absl::StatusOr<std::string> Start(const std::vector<std::string>& flags) {
    const std::string bin = std::string(INBETWEEN_BINARY_DIR) + "/server/inbetween-server";
    std::vector<std::string> args = {bin, "--listen", "127.0.0.1:0"};
    args.insert(args.end(), flags.begin(), flags.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    int pipe_fds[2];
    if (pipe(pipe_fds) != 0) return absl::InternalError("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
    const int rc = posix_spawn(&pid_, bin.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(pipe_fds[1]);
    out_ = fdopen(pipe_fds[0], "r");
    if (rc != 0) {
      pid_ = 0;
      return absl::NotFoundError("cannot run " + bin);
    }
    char line[512];
    const std::regex listening("inbetween-server listening on (127\\.0\\.0\\.1:[0-9]+)");
    while (fgets(line, sizeof line, out_) != nullptr) {
      std::cmatch m;
      if (std::regex_search(line, m, listening)) return m[1].str();
    }
    return absl::UnavailableError(bin + " exited without listening");
  }

 private:
  pid_t pid_ = 0;
  FILE* out_ = nullptr;
};

TEST(LoadGeneratorTest, OnlyLoopbackTargets) {
  for (const char* ok : {"127.0.0.1:50051", "127.1.2.3:1", "localhost:8080", "[::1]:443"}) {
    EXPECT_TRUE(CheckLoopbackTarget(ok).ok()) << ok;
  }
  for (const char* bad : {"10.0.0.1:50051", "example.com:443", "0.0.0.0:1", "[2001:db8::1]:1",
                          "127.0.0.1", "127.0.0.1:0", "127.0.0.1:99999", "128.0.0.1:1"}) {
    EXPECT_FALSE(CheckLoopbackTarget(bad).ok()) << bad;
  }
  EXPECT_THAT(CheckLoopbackTarget("192.168.1.2:50051").message(), HasSubstr("not a loopback"));
}

TEST(LoadGeneratorTest, NearestRankPercentiles) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // 1..100, unsorted
  EXPECT_EQ(Percentile(v, 50), 50);
  EXPECT_EQ(Percentile(v, 95), 95);
  EXPECT_EQ(Percentile(v, 99), 99);
  EXPECT_EQ(Percentile(v, 100), 100);
  EXPECT_EQ(Percentile({7}, 99), 7);
  EXPECT_EQ(Percentile({}, 50), 0);
}

TEST(LoadGeneratorTest, BoundedRunAgainstARealServer) {
  // Room for every studio's heavy call at once: no RESOURCE_EXHAUSTED back-pressure here.
  server::ServerOptions server_options;
  server_options.service.heavy.max_running = 3;
  server_options.service.heavy.max_per_owner = 3;
  auto server = server::InbetweenServer::Start(server_options);
  ASSERT_TRUE(server.ok()) << server.status();
  LoadGenOptions options;
  options.studios = 3;
  options.duration = std::chrono::seconds(600);  // the request budget ends the run
  options.max_requests = 60;
  options.frames = 6;
  options.drawings_svg = {ReadExample("examples/square_hexagon/square.svg"),
                          ReadExample("examples/square_hexagon/hexagon.svg")};
  auto report = RunLoad((*server)->InProcessChannel(), options);
  ASSERT_TRUE(report.ok()) << report.status();

  EXPECT_EQ(report->requests, 60);
  EXPECT_EQ(report->errors, 0) << FormatTable(*report);
  EXPECT_TRUE(report->errors_by_code.empty());
  for (const char* rpc : {"CreateSession", "PutDrawing", "BuildMultimesh", "OptimizeComesh",
                          "Inbetween", "GetSession", "ListSessions", "DeleteSession"}) {
    ASSERT_TRUE(report->rpcs.count(rpc)) << rpc << "\n" << FormatTable(*report);
    EXPECT_GT(report->rpcs.at(rpc).calls, 0) << rpc;
    EXPECT_LE(report->rpcs.at(rpc).p50_ms, report->rpcs.at(rpc).p99_ms) << rpc;
  }
  int64_t calls = 0;
  for (const auto& [rpc, s] : report->rpcs) calls += s.calls;
  EXPECT_EQ(calls, 60);
  EXPECT_EQ(report->sessions, report->rpcs.at("CreateSession").calls);
  EXPECT_EQ(report->lost_sessions, 0);
  EXPECT_EQ(report->streams_completed, report->rpcs.at("Inbetween").calls);
  EXPECT_TRUE(report->frames_identical);

  // The JSON carries the fields scripts and dashboards read.
  nlohmann::json j = nlohmann::json::parse(FormatJson(*report));
  EXPECT_EQ(j["studios"], 3);
  EXPECT_EQ(j["requests"], 60);
  EXPECT_EQ(j["lost_sessions"], 0);
  EXPECT_EQ(j["frames_identical"], true);
  EXPECT_TRUE(j["errors_by_code"].is_object());
  EXPECT_TRUE(j["rpcs"].contains("Inbetween"));
  EXPECT_GT(j["unary_p99_ms"].get<double>(), 0.0);
}

TEST(LoadGeneratorTest, UnreachableTargetIsCountedByCode) {
  LoadGenOptions options;
  options.studios = 1;
  options.max_requests = 3;
  options.drawings_svg = {"<svg/>", "<svg/>"};
  // A port nobody listens on: 127.0.0.1:1 (privileged, unused).
  auto report =
      RunLoad(grpc::CreateChannel("127.0.0.1:1", grpc::InsecureChannelCredentials()), options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->requests, 3);
  EXPECT_EQ(report->errors_by_code["UNAVAILABLE"], 3);
  EXPECT_EQ(report->rpcs["CreateSession"].errors_by_code["UNAVAILABLE"], 3);
  EXPECT_EQ(report->sessions, 0);
}

TEST(LoadGeneratorTest, StreamsFailOverLikeTheClientLibrary) {
  auto backend = server::InbetweenServer::Start(server::ServerOptions{});
  ASSERT_TRUE(backend.ok()) << backend.status();
  FlakyFront front((*backend)->InProcessChannel());
  const grpc::Status proxy_reset(grpc::StatusCode::INTERNAL,
                                 "Received RST_STREAM with error code 2");
  front.faults = {{grpc::Status(grpc::StatusCode::UNAVAILABLE, "Socket closed"), 5},
                  {proxy_reset, 3}};
  front.optimize_faults = {{proxy_reset, 1}};
  front.build_faults = {{grpc::Status(grpc::StatusCode::UNAVAILABLE, "Socket closed"), 1}};
  front.get_session_faults = 1;
  grpc::ServerBuilder builder;
  builder.RegisterService(&front);
  std::unique_ptr<grpc::Server> front_server = builder.BuildAndStart();
  ASSERT_NE(front_server, nullptr);

  LoadGenOptions options;
  options.studios = 1;
  options.duration = std::chrono::seconds(600);
  options.max_requests = 20;  // two projects: the first one broken, the second one not
  options.frames = 12;
  options.drawings_svg = {ReadExample("examples/square_hexagon/square.svg"),
                          ReadExample("examples/square_hexagon/hexagon.svg")};
  auto report = RunLoad(front_server->InProcessChannel({}), options);
  front_server->Shutdown();
  ASSERT_TRUE(report.ok()) << report.status();
  const std::string table = FormatTable(*report);

  EXPECT_EQ(report->requests, 20);
  EXPECT_EQ(report->errors, 0) << table;
  // Two stream resumes, one optimization, one build, one GetSession.
  EXPECT_EQ(report->retries, 5) << table;
  EXPECT_EQ(report->rpcs.at("Inbetween").calls, 2);  // a stream is one request, retries included
  EXPECT_EQ(report->streams_completed, 2);
  // Resumed frames, and the frames of a resumed optimization's multimesh, equal the second
  // project's unbroken ones.
  EXPECT_TRUE(report->frames_identical);
  EXPECT_EQ(report->lost_sessions, 0);
  EXPECT_EQ(report->sessions, 2);
  EXPECT_EQ(front.start_frames, (std::vector<uint32_t>{0, 5, 8, 0}));
  EXPECT_EQ(front.resumes, (std::vector<bool>{false, true, false}));
  ASSERT_EQ(front.expected_versions.size(), 3u);
  EXPECT_EQ(front.expected_versions[0], front.expected_versions[1]);  // the first attempt's
  ASSERT_EQ(front.build_versions.size(), 3u);  // broken, sent again, the second project's
  EXPECT_EQ(front.build_versions[0], front.build_versions[1]);
  EXPECT_TRUE(front.missing_session_id.empty())
      << ::testing::PrintToString(front.missing_session_id);
}

TEST(LoadGeneratorTest, ManyStudiosRunOnFewThreads) {
  // Heavy calls wait in the server's queue rather than being refused: no back-pressure errors.
  ServerProcess server;
  absl::StatusOr<std::string> address =
      server.Start({"--solver-threads", "1", "--max-heavy-jobs", "2", "--heavy-queue", "200",
                    "--max-heavy-jobs-per-token", "202", "--log-level", "warn"});
  ASSERT_TRUE(address.ok()) << address.status();
  LoadGenOptions options;
  options.studios = 64;
  options.duration = std::chrono::seconds(240);  // the request budget ends the run
  options.max_requests = 64 * 10;                // about one project per studio
  options.frames = 6;
  options.drawings_svg = {ReadExample("examples/square_hexagon/square.svg"),
                          ReadExample("examples/square_hexagon/hexagon.svg")};

  const int before = ThreadCount();
  std::atomic<bool> stop{false};
  std::atomic<int> peak_threads{0};
  std::thread sampler([&] {  // one more thread of ours, counted too
    while (!stop) {
      peak_threads = std::max(peak_threads.load(), ThreadCount());
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  auto report = RunLoad(grpc::CreateChannel(*address, grpc::InsecureChannelCredentials()), options);
  stop = true;
  sampler.join();
  ASSERT_TRUE(report.ok()) << report.status();
  const std::string table = FormatTable(*report);
  std::printf("%s threads: %d before the run, at most %d during it\n", table.c_str(), before,
              peak_threads.load());

  // Every studio had a call outstanding at once, on a handful of threads.
  EXPECT_GE(report->peak_in_flight, 48) << table;
  EXPECT_LE(peak_threads.load(), 24) << table;
  EXPECT_LT(peak_threads.load(), report->peak_in_flight) << table;
  // And the results hold: the whole budget, no error, no lost session, identical frames.
  EXPECT_EQ(report->requests, 640);
  EXPECT_EQ(report->errors, 0) << table;
  EXPECT_GE(report->sessions, 64) << table;
  EXPECT_EQ(report->lost_sessions, 0);
  EXPECT_GT(report->streams_completed, 0) << table;
  EXPECT_EQ(report->streams_completed, report->rpcs.at("Inbetween").calls);
  EXPECT_TRUE(report->frames_identical);
}

}  // namespace
}  // namespace inbetween::loadgen
