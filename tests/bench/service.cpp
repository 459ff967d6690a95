// Service overhead: the same Inbetween job (square -> hexagon meshed to ~1.6k vertices,
// zhu17, N frames) streamed from one InbetweenServer over its in-process channel (what the
// embedded CLI uses) and over loopback TCP gRPC, alternating runs in one process. Per transport:
// frames per second (frames / time from the request to the last frame) and per-frame latency
// (time between consecutive frames at the client, p50/p99). Then the unary latency while every
// heavy slot runs an Inbetween stream: GetSession p50/p99 over loopback TCP. The solver alone
// (the handler's work without RPC) is printed for reference. Last, cancellation latency: a long
// Inbetween stream and an OptimizeComesh run are cancelled by the client after 200 ms; the time
// from TryCancel to the server's handler returning CANCELLED (its RPC counted in the metrics,
// i.e. the solver stopped and the heavy slot freed), per trial (target: within 100 ms).
// Usage: service [--json FILE] [--frames N] [--runs R] [--max-edge E] [--boundary B]
//                [--unary-calls N]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "inbetween/v1/inbetween.grpc.pb.h"
#include "nlohmann/json.hpp"
#include "server/inbetween_server.h"
#include "server/parameters.h"
#include "server/stiffness_field.h"
#include "solver/core/cancel.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"

namespace {

namespace v1 = ::inbetween::v1;
using Clock = std::chrono::steady_clock;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5));
  return values[i];
}

[[noreturn]] void Fail(const std::string& what, const grpc::Status& status) {
  std::fprintf(stderr, "bench_service: %s: %s\n", what.c_str(), status.error_message().c_str());
  std::exit(1);
}

// Creates the session, uploads the two drawings and builds the multimesh; returns it.
v1::Session Prepare(v1::Inbetween::Stub& stub, const std::string& examples, double max_edge,
                    uint32_t boundary) {
  v1::Session session;
  {
    grpc::ClientContext context;
    v1::CreateSessionRequest request;
    request.set_display_name("bench-service");
    request.mutable_parameters()->mutable_meshing()->set_max_edge_relative(max_edge);
    request.mutable_parameters()->mutable_meshing()->set_boundary_vertices(boundary);
    v1::CreateSessionResponse response;
    if (auto s = stub.CreateSession(&context, request, &response); !s.ok()) Fail("create", s);
    session = response.session();
  }
  for (const char* name : {"square.svg", "hexagon.svg"}) {
    grpc::ClientContext context;
    v1::PutDrawingRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    request.mutable_drawing()->set_name(name);
    request.mutable_drawing()->set_svg(ReadFile(examples + "/" + name));
    v1::PutDrawingResponse response;
    if (auto s = stub.PutDrawing(&context, request, &response); !s.ok()) Fail(name, s);
    session = response.session();
  }
  grpc::ClientContext context;
  v1::BuildMultimeshRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  auto reader = stub.BuildMultimesh(&context, request);
  v1::BuildMultimeshResponse response;
  while (reader->Read(&response)) {
    if (response.has_result()) session = response.result().session();
  }
  if (auto s = reader->Finish(); !s.ok()) Fail("build", s);
  return session;
}

// The session's version now (GetSession).
uint64_t CurrentVersion(v1::Inbetween::Stub& stub, const std::string& session_id) {
  grpc::ClientContext context;
  v1::GetSessionRequest request;
  request.set_session_id(session_id);
  v1::GetSessionResponse response;
  if (auto s = stub.GetSession(&context, request, &response); !s.ok()) Fail("get", s);
  return response.session().version();
}

// inbetween_rpcs_total{code="CANCELLED",method=METHOD} in the server's metrics text (label names
// in sorted order, as prometheus-cpp writes them).
uint64_t CancelledCount(const inbetween::server::InbetweenServer& server,
                        const std::string& method) {
  const std::string text = server.RenderMetrics();
  const std::string key = "inbetween_rpcs_total{code=\"CANCELLED\",method=\"" + method + "\"} ";
  const size_t at = text.find(key);
  return at == std::string::npos ? 0 : std::strtoull(text.c_str() + at + key.size(), nullptr, 10);
}

// Milliseconds from the client's TryCancel, 200 ms into `method`, to the server's handler having
// returned CANCELLED (polled every 0.2 ms).
template <class Start>
double CancelLatencyMs(const inbetween::server::InbetweenServer& server, const std::string& method,
                       Start start) {
  const uint64_t before = CancelledCount(server, method);
  grpc::ClientContext context;
  std::thread reader([&] { start(&context); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const Clock::time_point cancelled = Clock::now();
  context.TryCancel();
  double ms = -1;
  while (std::chrono::duration<double>(Clock::now() - cancelled).count() < 10.0) {
    if (CancelledCount(server, method) > before) {
      ms = std::chrono::duration<double, std::milli>(Clock::now() - cancelled).count();
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  reader.join();
  return ms;  // -1: the handler did not stop within 10 s (or finished before the cancel)
}

struct Run {
  double seconds = 0;
  std::vector<double> gaps_ms;  // between consecutive frames (the first: request -> frame 0)
  int frames = 0;
};

Run StreamFrames(v1::Inbetween::Stub& stub, const std::string& id, int frames) {
  grpc::ClientContext context;
  v1::InbetweenRequest request;
  request.set_session_id(id);
  request.mutable_parameters()->set_frames(static_cast<uint32_t>(frames));
  Run run;
  const Clock::time_point start = Clock::now();
  Clock::time_point last = start;
  auto reader = stub.Inbetween(&context, request);
  v1::InbetweenResponse response;
  while (reader->Read(&response)) {
    if (!response.has_frame()) continue;
    const Clock::time_point now = Clock::now();
    run.gaps_ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
    last = now;
    ++run.frames;
  }
  if (auto s = reader->Finish(); !s.ok()) Fail("inbetween", s);
  run.seconds = std::chrono::duration<double>(last - start).count();
  return run;
}

// The same job without any RPC: what the Inbetween handler runs (plan, schedule, Inbetweener on
// the stored multimesh, one Solve per frame), timed the same way.
Run SolveDirect(const inbetween::solver::Multimesh& mesh, int num_drawings, int frames) {
  namespace solver = ::inbetween::solver;
  v1::InbetweenParameters parameters;
  parameters.set_frames(static_cast<uint32_t>(frames));
  Run run;
  const Clock::time_point start = Clock::now();
  Clock::time_point last = start;
  auto plan = inbetween::server::ToInbetweenPlan(parameters, "parameters");
  auto timing = inbetween::server::ToTimingOptions(parameters, num_drawings, "parameters");
  if (!plan.ok() || !timing.ok()) std::exit(1);
  plan->options.stiffness = inbetween::server::StiffnessPerTriangle(mesh, parameters.stiffness());
  auto schedule = solver::MakeSchedule(num_drawings, plan->frames, {}, *timing);
  auto inbetweener = solver::Inbetweener::Create(mesh, plan->options);
  if (!schedule.ok() || !inbetweener.ok()) std::exit(1);
  solver::CancelToken token;
  solver::Frame previous;
  for (int i = 0; i < plan->frames; ++i) {
    solver::FrameReport report;
    auto frame = inbetweener->Solve(schedule->frames[i].weights, previous, &token, &report);
    if (!frame.ok()) std::exit(1);
    previous = *std::move(frame);
    const Clock::time_point now = Clock::now();
    run.gaps_ms.push_back(std::chrono::duration<double, std::milli>(now - last).count());
    last = now;
    ++run.frames;
  }
  run.seconds = std::chrono::duration<double>(last - start).count();
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  std::string json_path;
  int frames = 240;
  int runs = 15;
  double max_edge = 0.028;
  uint32_t boundary = 160;
  int unary_calls = 400;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (arg == "--json" && value) {
      json_path = argv[++i];
    } else if (arg == "--frames" && value) {
      frames = std::atoi(argv[++i]);
    } else if (arg == "--runs" && value) {
      runs = std::atoi(argv[++i]);
    } else if (arg == "--max-edge" && value) {
      max_edge = std::atof(argv[++i]);
    } else if (arg == "--boundary" && value) {
      boundary = static_cast<uint32_t>(std::atoi(argv[++i]));
    } else if (arg == "--unary-calls" && value) {
      unary_calls = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr,
                   "usage: service [--json FILE] [--frames N] [--runs R] [--max-edge E] "
                   "[--boundary B] [--unary-calls N]\n");
      return 2;
    }
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  inbetween::server::ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.service.heavy.max_running = static_cast<int>(cores);
  options.shutdown_grace = std::chrono::milliseconds(100);
  auto server = inbetween::server::InbetweenServer::Start(options);
  if (!server.ok()) {
    std::fprintf(stderr, "bench_service: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(inbetween::server::kMaxMessageBytes);
  auto tcp_channel = grpc::CreateCustomChannel("127.0.0.1:" + std::to_string((*server)->port()),
                                               grpc::InsecureChannelCredentials(), args);
  auto inprocess = v1::Inbetween::NewStub((*server)->InProcessChannel());
  auto tcp = v1::Inbetween::NewStub(tcp_channel);

  const v1::Session session =
      Prepare(*inprocess, std::string(INBETWEEN_SOURCE_DIR) + "/examples/square_hexagon", max_edge,
              boundary);
  const uint32_t vertices = session.multimesh_stats().vertices();
  std::printf("multimesh: %u vertices, %u triangles; %d frames (zhu17), %d runs per transport\n",
              vertices, session.multimesh_stats().triangles(), frames, runs);

  // Warm-up (first factorization caches, connection set-up), then alternate the transports so
  // both see the same machine load.
  StreamFrames(*inprocess, session.id(), frames);
  StreamFrames(*tcp, session.id(), frames);
  struct Totals {
    const char* name;
    v1::Inbetween::Stub* stub;
    double seconds = 0;
    int frames = 0;
    std::vector<double> gaps_ms;
  };
  // Plus the solver alone (no RPC; printed, not a JSON row) on the multimesh the server stored.
  auto stored = (*server)->store().Get(session.id());
  if (!stored.ok() || !stored->multimesh) return 1;
  const int num_drawings = session.drawings_size();
  SolveDirect(*stored->multimesh, num_drawings, frames);
  Totals totals[] = {{"inprocess", inprocess.get()}, {"grpc", tcp.get()}, {"solver", nullptr}};
  for (int r = 0; r < runs; ++r) {
    for (Totals& t : totals) {
      Run run = t.stub ? StreamFrames(*t.stub, session.id(), frames)
                       : SolveDirect(*stored->multimesh, num_drawings, frames);
      t.seconds += run.seconds;
      t.frames += run.frames;
      t.gaps_ms.insert(t.gaps_ms.end(), run.gaps_ms.begin(), run.gaps_ms.end());
    }
  }
  nlohmann::json rows = nlohmann::json::array();
  std::printf("\n%-10s %9s %12s %9s %9s\n", "transport", "vertices", "frames/s", "p50 ms",
              "p99 ms");
  for (const Totals& t : totals) {
    const double fps = t.frames / t.seconds;
    const double p50 = Percentile(t.gaps_ms, 0.50);
    const double p99 = Percentile(t.gaps_ms, 0.99);
    std::printf("%-10s %9u %12.1f %9.3f %9.3f\n", t.name, vertices, fps, p50, p99);
    if (t.stub == nullptr) continue;  // the JSON rows are the two transports
    rows.push_back({{"transport", t.name},
                    {"vertices", vertices},
                    {"frames_per_second", fps},
                    {"p50_ms", p50},
                    {"p99_ms", p99}});
  }
  const double fps_in = rows[0]["frames_per_second"].get<double>();
  const double fps_grpc = rows[1]["frames_per_second"].get<double>();
  const double fps_solver = totals[2].frames / totals[2].seconds;
  std::printf("gRPC loopback throughput vs in-process: %+.1f%% (target: no worse than -10%%)\n",
              100.0 * (fps_grpc / fps_in - 1.0));
  std::printf("vs the solver alone: in-process %+.1f%%, gRPC loopback %+.1f%%\n",
              100.0 * (fps_in / fps_solver - 1.0), 100.0 * (fps_grpc / fps_solver - 1.0));

  // Unary latency while every heavy slot (one per core) streams frames over TCP.
  std::atomic<bool> stop{false};
  std::atomic<int> heavy_streams{0};
  std::vector<std::thread> heavy;
  for (unsigned c = 0; c < cores; ++c) {
    heavy.emplace_back([&] {
      auto stub = v1::Inbetween::NewStub(tcp_channel);
      while (!stop) {
        StreamFrames(*stub, session.id(), frames);
        ++heavy_streams;
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let the streams start
  std::vector<double> unary_ms;
  for (int i = 0; i < unary_calls; ++i) {
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(session.id());
    v1::GetSessionResponse response;
    const Clock::time_point start = Clock::now();
    if (auto s = tcp->GetSession(&context, request, &response); !s.ok()) Fail("get", s);
    unary_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  stop = true;
  for (std::thread& t : heavy) t.join();
  const double unary_p50 = Percentile(unary_ms, 0.50);
  const double unary_p99 = Percentile(unary_ms, 0.99);
  std::printf(
      "\nunary GetSession over loopback while %u heavy Inbetween streams run (%d streams "
      "finished meanwhile): p50 %.3f ms, p99 %.3f ms, max %.3f ms (%d calls)\n",
      cores, heavy_streams.load(), unary_p50, unary_p99,
      *std::max_element(unary_ms.begin(), unary_ms.end()), unary_calls);

  // Cancellation latency.
  std::vector<double> cancel_inbetween, cancel_optimize;
  for (int trial = 0; trial < 10; ++trial) {
    cancel_inbetween.push_back(
        CancelLatencyMs(**server, "Inbetween", [&](grpc::ClientContext* context) {
          v1::InbetweenRequest request;
          request.set_session_id(session.id());
          request.mutable_parameters()->set_frames(100000);  // far longer than the 200 ms
          auto reader = inprocess->Inbetween(context, request);
          v1::InbetweenResponse response;
          while (reader->Read(&response)) {
          }
          reader->Finish();
        }));
    // A cancelled run stores its checkpoints (each a new session version): every trial starts
    // from the version the session has now, and its comesh parameters make every topology pass
    // (seconds of work, far longer than the 200 ms).
    const uint64_t version = CurrentVersion(*inprocess, session.id());
    cancel_optimize.push_back(
        CancelLatencyMs(**server, "OptimizeComesh", [&](grpc::ClientContext* context) {
          v1::OptimizeComeshRequest request;
          request.set_session_id(session.id());
          request.set_expected_version(version);
          v1::ComeshParameters* comesh = request.mutable_comesh();
          comesh->set_max_outer_iterations(1000);
          comesh->set_max_inner_iterations(100000);
          comesh->set_tolerance(1e-15);
          comesh->set_outer_tolerance(0.0);
          auto reader = inprocess->OptimizeComesh(context, request);
          v1::OptimizeComeshResponse response;
          while (reader->Read(&response)) {
          }
          reader->Finish();
        }));
  }
  auto summary = [](const std::vector<double>& ms) {
    return nlohmann::json{{"p50_ms", Percentile(ms, 0.5)},
                          {"max_ms", *std::max_element(ms.begin(), ms.end())},
                          {"trials", ms.size()}};
  };
  std::printf(
      "\ncancellation, client TryCancel -> server handler returned CANCELLED (10 trials, target "
      "100 ms): Inbetween p50 %.2f ms, max %.2f ms; OptimizeComesh p50 %.2f ms, max %.2f ms "
      "(-1: did not stop)\n",
      Percentile(cancel_inbetween, 0.5),
      *std::max_element(cancel_inbetween.begin(), cancel_inbetween.end()),
      Percentile(cancel_optimize, 0.5),
      *std::max_element(cancel_optimize.begin(), cancel_optimize.end()));
  rows.push_back({{"cancel", "Inbetween"}, {"latency", summary(cancel_inbetween)}});
  rows.push_back({{"cancel", "OptimizeComesh"}, {"latency", summary(cancel_optimize)}});
  rows.push_back({{"unary", "GetSession"},
                  {"p50_ms", unary_p50},
                  {"p99_ms", unary_p99},
                  {"heavy_streams", cores}});

  if (!json_path.empty()) {
    std::ofstream out(json_path);
    out << rows.dump(2) << "\n";
    std::printf("wrote %s\n", json_path.c_str());
  }
  (*server)->Shutdown();
  (*server)->Wait();
  return 0;
}
