// inbetween-loadgen's engine: N virtual studios, each a state machine on the gRPC callback API
// running the animator's loop (create a session, upload drawings, build, optimize, stream frames,
// read it back, edit a drawing, list sessions, delete it) against one target until a duration or a
// total request count is reached; per-RPC latencies and errors by status code, then a check that
// every session created is still there. The studios share gRPC's callback threads and one timer
// thread, however many there are. Calls fail over like the client library's (Inbetween resumed
// at the next frame and OptimizeComesh from its checkpoint after a replica dies; GetSession and
// ListSessions sent again), so a stream's latency includes its retries.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace inbetween::loadgen {

struct LoadGenOptions {
  int studios = 4;                         // concurrent virtual studios
  std::chrono::seconds duration{30};       // stop starting RPCs after this long
  int64_t max_requests = 1000;             // stop after this many RPCs in total (all studios)
  std::vector<std::string> drawings_svg;   // the key drawings every studio uploads (>= 2)
  uint32_t frames = 12;                    // frames per Inbetween stream
  uint32_t optimize_outer_iterations = 1;  // OptimizeComesh bound; 0 = no OptimizeComesh
  std::string token;                       // bearer token, empty = none
};

// Latency percentiles of one RPC (milliseconds, nearest rank), successes only.
struct RpcSummary {
  int64_t calls = 0;
  int64_t errors = 0;
  double p50_ms = 0, p95_ms = 0, p99_ms = 0, max_ms = 0;
  std::map<std::string, int64_t> errors_by_code;
};

struct LoadReport {
  int studios = 0;
  double seconds = 0;    // wall time of the run (without the final session check)
  int64_t requests = 0;  // RPCs sent (a stream once; a busy-pool retry again)
  int64_t errors = 0;
  std::map<std::string, int64_t> errors_by_code;  // "UNAVAILABLE" -> count
  std::map<std::string, RpcSummary> rpcs;         // "Inbetween" -> summary
  double unary_p99_ms = 0;                        // over every successful unary call
  int64_t retries = 0;                            // failover retries (the library's rules)
  int64_t sessions = 0;                           // sessions created
  int64_t lost_sessions = 0;                      // created, not deleted, then NOT_FOUND
  int64_t streams_completed = 0;                  // Inbetween streams with every frame
  bool frames_identical = true;                   // every completed stream gave the same frames
  int64_t peak_in_flight = 0;                     // most calls outstanding at once
};

// Targets must be loopback addresses (127.0.0.0/8, ::1, localhost) with a port.
absl::Status CheckLoopbackTarget(const std::string& target);

// Nearest-rank percentile (p in [0, 100]) of `values`; 0 when empty.
double Percentile(std::vector<double> values, double p);

absl::StatusOr<LoadReport> RunLoad(std::shared_ptr<grpc::Channel> channel,
                                   const LoadGenOptions& options);

std::string FormatTable(const LoadReport& report);
std::string FormatJson(const LoadReport& report);

}  // namespace inbetween::loadgen
