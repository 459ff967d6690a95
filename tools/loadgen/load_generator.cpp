// inbetween-loadgen's engine (see load_generator.h). The studios are state machines on the gRPC
// callback API: each step starts one call (`stub->async()->Method(...)`, or a ClientReadReactor
// for the server streams) and its completion, on one of gRPC's threads, starts the next step.
// Waits (busy-pool backoff, failover backoff, the pause after a failed project) are entries of one
// timer thread, so N studios need no thread of their own.
#include "tools/loadgen/load_generator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <type_traits>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/inbetween_client.h"
#include "nlohmann/json.hpp"

namespace inbetween::loadgen {
namespace {

using Clock = std::chrono::steady_clock;
using Done = std::function<void(absl::Status)>;

bool IsUnary(const std::string& rpc) {
  return rpc != "BuildMultimesh" && rpc != "OptimizeComesh" && rpc != "Inbetween";
}

// Runs callbacks at their time on one thread: every studio's waits, none of them sleeping.
class Timer {
 public:
  Timer() : thread_([this] { Loop(); }) {}
  ~Timer() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      stopping_ = true;
    }
    cv_.notify_one();
    thread_.join();
  }
  void After(std::chrono::milliseconds wait, std::function<void()> f) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      queue_.emplace(Clock::now() + wait, std::move(f));
    }
    cv_.notify_one();
  }

 private:
  void Loop() {
    std::unique_lock<std::mutex> lock(mu_);
    while (!stopping_) {
      if (queue_.empty()) {
        cv_.wait(lock);
      } else if (queue_.begin()->first > Clock::now()) {
        cv_.wait_until(lock, queue_.begin()->first);
      } else {
        std::function<void()> f = std::move(queue_.begin()->second);
        queue_.erase(queue_.begin());
        lock.unlock();
        f();  // starts a call or ends a studio; never blocks
        lock.lock();
      }
    }
  }

  std::mutex mu_;
  std::condition_variable cv_;
  std::multimap<Clock::time_point, std::function<void()>> queue_;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once the members above exist
};

// What every studio shares: the request budget, the deadline and the measurements.
class Run {
 public:
  Run(const LoadGenOptions& options)
      : options_(options), deadline_(Clock::now() + options.duration), running_(options.studios) {}

  // Claims one request of the budget; false once the budget or the time is used up.
  bool Claim() {
    if (Clock::now() >= deadline_) return false;
    if (claimed_.fetch_add(1) >= options_.max_requests) return false;
    const int64_t now = in_flight_.fetch_add(1) + 1;
    int64_t peak = peak_in_flight_.load();
    while (now > peak && !peak_in_flight_.compare_exchange_weak(peak, now)) {
    }
    return true;
  }

  // Records the outcome of one claimed call (one RPC, or one whole stream with its retries).
  void Record(const std::string& rpc, Clock::time_point start, const absl::Status& status) {
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    in_flight_.fetch_sub(1);
    std::lock_guard<std::mutex> lock(mu_);
    ++requests_;
    Samples& s = samples_[rpc];
    ++s.calls;
    if (status.ok()) {
      s.ms.push_back(ms);
    } else {
      ++s.errors;
      ++s.errors_by_code[absl::StatusCodeToString(status.code())];
      ++errors_by_code_[absl::StatusCodeToString(status.code())];
    }
  }

  // Sessions created and not deleted by the studio that made them.
  void AddSession(const std::string& id) {
    std::lock_guard<std::mutex> lock(mu_);
    ++sessions_created_;
    alive_.insert(id);
  }
  void DeletedSession(const std::string& id) {
    std::lock_guard<std::mutex> lock(mu_);
    alive_.erase(id);
  }
  void LostSession() {
    std::lock_guard<std::mutex> lock(mu_);
    ++lost_;
  }
  void AddFrames(const std::string& digest) {
    std::lock_guard<std::mutex> lock(mu_);
    ++streams_completed_;
    if (first_frames_.empty()) first_frames_ = digest;
    if (digest != first_frames_) frames_identical_ = false;
  }
  void AddRetry() { retries_.fetch_add(1); }
  std::vector<std::string> alive_sessions() {
    std::lock_guard<std::mutex> lock(mu_);
    return {alive_.begin(), alive_.end()};
  }

  // A studio has stopped (budget or time used up); the last one wakes WaitForStudios().
  void StudioDone() {
    std::lock_guard<std::mutex> lock(mu_);
    if (--running_ == 0) studios_done_.notify_all();
  }
  void WaitForStudios() {
    std::unique_lock<std::mutex> lock(mu_);
    studios_done_.wait(lock, [this] { return running_ == 0; });
  }

  LoadReport Report(double seconds) {
    std::lock_guard<std::mutex> lock(mu_);
    LoadReport r;
    r.studios = options_.studios;
    r.seconds = seconds;
    r.requests = requests_;
    r.errors_by_code = errors_by_code_;
    for (const auto& [code, n] : errors_by_code_) r.errors += n;
    std::vector<double> unary;
    for (const auto& [rpc, s] : samples_) {
      RpcSummary& out = r.rpcs[rpc];
      out.calls = s.calls;
      out.errors = s.errors;
      out.errors_by_code = s.errors_by_code;
      out.p50_ms = Percentile(s.ms, 50);
      out.p95_ms = Percentile(s.ms, 95);
      out.p99_ms = Percentile(s.ms, 99);
      out.max_ms = Percentile(s.ms, 100);
      if (IsUnary(rpc)) unary.insert(unary.end(), s.ms.begin(), s.ms.end());
    }
    r.unary_p99_ms = Percentile(unary, 99);
    r.retries = retries_.load();
    r.sessions = sessions_created_;
    r.lost_sessions = lost_;
    r.streams_completed = streams_completed_;
    r.frames_identical = frames_identical_;
    r.peak_in_flight = peak_in_flight_.load();
    return r;
  }

 private:
  struct Samples {
    int64_t calls = 0, errors = 0;
    std::map<std::string, int64_t> errors_by_code;
    std::vector<double> ms;
  };
  const LoadGenOptions& options_;
  const Clock::time_point deadline_;
  std::atomic<int64_t> claimed_{0};
  std::atomic<int64_t> retries_{0};
  std::atomic<int64_t> in_flight_{0};
  std::atomic<int64_t> peak_in_flight_{0};
  std::mutex mu_;
  std::condition_variable studios_done_;
  int running_;
  int64_t requests_ = 0;
  std::map<std::string, Samples> samples_;
  std::map<std::string, int64_t> errors_by_code_;
  int64_t sessions_created_ = 0;
  int64_t lost_ = 0;
  std::set<std::string> alive_;
  int64_t streams_completed_ = 0;
  std::string first_frames_;
  bool frames_identical_ = true;
};

// One server stream on the callback API: every message goes to `on_message` (a non-OK status
// cancels the call and becomes its result), then `done` gets the final status. Deletes itself
// when gRPC is done with it.
template <class Response>
class StreamCall : public grpc::ClientReadReactor<Response> {
 public:
  using OnMessage = std::function<absl::Status(Response&)>;
  StreamCall(std::unique_ptr<grpc::ClientContext> context, OnMessage on_message, Done done)
      : context_(std::move(context)), on_message_(std::move(on_message)), done_(std::move(done)) {}
  grpc::ClientContext* context() { return context_.get(); }

  // After the stub bound this reactor (stub->async()->Method(context(), &request, this)).
  void Go() {
    this->StartRead(&response_);
    this->StartCall();  // may complete at once: nothing touches `this` after it
  }
  void OnReadDone(bool ok) override {
    if (!ok) return;  // the stream ended; OnDone follows
    if (absl::Status status = on_message_(response_); !status.ok()) {
      stopped_ = std::move(status);
      context_->TryCancel();
      return;
    }
    this->StartRead(&response_);
  }
  void OnDone(const grpc::Status& status) override {
    done_(stopped_.ok() ? client::FromGrpcStatus(status) : stopped_);
    delete this;
  }

 private:
  std::unique_ptr<grpc::ClientContext> context_;
  OnMessage on_message_;
  Done done_;
  Response response_;
  absl::Status stopped_;
};

// The frames' content without the wall-clock seconds, as bytes to compare between streams.
void AppendFrame(v1::InbetweenFrame frame, std::string* digest) {
  frame.mutable_stats()->clear_seconds();
  *digest += frame.SerializeAsString();
}

// One studio: the animator's loop until the budget or the time runs out; a project ends with
// DeleteSession. A failed call ends the current project (after a short pause; its session is
// kept and checked at the end) and the studio starts a new one. One call at a time: each step
// runs in the completion of the previous one, so the state below needs no lock.
class Studio {
 public:
  Studio(int index, v1::Inbetween::Stub& stub, const LoadGenOptions& options,
         const client::RetryOptions& retry, Run& run, Timer& timer)
      : index_(index), stub_(stub), options_(options), retry_(retry), run_(run), timer_(timer) {
    // The optimization's bound lives in the session's parameters.
    parameters_.mutable_comesh()->set_max_outer_iterations(options.optimize_outer_iterations);
    parameters_.mutable_comesh()->set_max_inner_iterations(20);
  }

  void Start() { NewProject(); }

 private:
  // --- the studio's steps, in order ---
  void NewProject() {
    session_.Clear();
    first_drawing_ = 0;
    Measure(
        "CreateSession",
        [this](Done done) {
          v1::CreateSessionRequest request;
          request.set_display_name(absl::StrCat("loadgen studio ", index_, " #", project_++));
          *request.mutable_parameters() = parameters_;
          Unary<v1::CreateSessionRequest, v1::CreateSessionResponse>(
              "", std::move(request),
              [this](auto* c, auto* q, auto* r, auto f) {
                stub_.async()->CreateSession(c, q, r, std::move(f));
              },
              [this, done](const grpc::Status& status, v1::CreateSessionResponse& response) {
                if (status.ok()) {
                  session_ = response.session();
                  run_.AddSession(session_.id());
                }
                done(client::FromGrpcStatus(status));
              });
        },
        [this](absl::Status status) { Then(status, [this] { PutKey(0); }); });
  }

  void PutKey(size_t d) {
    if (d == options_.drawings_svg.size()) return Build();
    Measure(
        "PutDrawing",
        [this, d](Done done) {
          v1::PutDrawingRequest request;
          request.set_session_id(session_.id());
          request.set_expected_version(session_.version());
          request.mutable_drawing()->set_name(absl::StrCat("key", d + 1, ".svg"));
          request.mutable_drawing()->set_svg(options_.drawings_svg[d]);
          PutDrawing(std::move(request), done);
        },
        [this, d](absl::Status status) { Then(status, [this, d] { PutKey(d + 1); }); });
  }

  void Build() {
    MeasureHeavy(
        "BuildMultimesh", [this](Done done) { BuildAttempt(1, std::move(done)); },
        [this](absl::Status status) {
          Then(status, [this] { options_.optimize_outer_iterations > 0 ? Optimize() : Frames(); });
        });
  }

  // BuildMultimesh with the client library's failover: after a transient failure the same
  // request (same expected_version) is sent again; a build that died before storing left the
  // session unchanged.
  void BuildAttempt(int attempt, Done done) {
    v1::BuildMultimeshRequest request;
    request.set_session_id(session_.id());
    request.set_expected_version(session_.version());
    WritingStream<v1::BuildMultimeshResponse>(
        "BuildMultimesh", std::move(request),
        [this](auto* c, auto* q, auto* r) { stub_.async()->BuildMultimesh(c, q, r); }, attempt,
        [this](int next, Done d) { BuildAttempt(next, std::move(d)); }, std::move(done));
  }

  // One attempt of a stream that writes the session and ends with a `result` holding it: the
  // result is the last message, sent after the session was written, so the call is done once it
  // arrived, even if the connection broke after it; otherwise a transient failure is retried by
  // `again(attempt + 1, done)` after the client library's backoff.
  template <class Response, class Request, class Start>
  void WritingStream(const char* rpc, Request request, Start start, int attempt,
                     std::function<void(int, Done)> again, Done done) {
    using Result = std::decay_t<decltype(std::declval<Response>().result())>;
    auto result = std::make_shared<std::optional<Result>>();
    Stream<Request, Response>(
        std::move(request), std::move(start),
        [result](Response& response) {
          if (response.has_result()) *result = std::move(*response.mutable_result());
          return absl::OkStatus();
        },
        [this, rpc, attempt, again = std::move(again), result, done](absl::Status status) {
          if (*result) {
            session_ = (*result)->session();
            return done(absl::OkStatus());
          }
          if (status.ok()) {
            return done(absl::InternalError(absl::StrCat(rpc, " stream ended without a result")));
          }
          const grpc::Status as_grpc(static_cast<grpc::StatusCode>(status.code()),
                                     std::string(status.message()));
          std::optional<std::chrono::milliseconds> backoff = Backoff(attempt, as_grpc);
          if (!backoff) return done(status);
          timer_.After(*backoff, [attempt, again, done] { again(attempt + 1, done); });
        });
  }

  void Optimize() {
    MeasureHeavy(
        "OptimizeComesh", [this](Done done) { OptimizeAttempt(1, std::move(done)); },
        [this](absl::Status status) { Then(status, [this] { Frames(); }); });
  }

  // OptimizeComesh with the client library's failover: after a transient failure it is sent
  // again with resume = true and the version the first attempt started from (the server goes on
  // from the run's last checkpoint).
  void OptimizeAttempt(int attempt, Done done) {
    v1::OptimizeComeshRequest request;
    request.set_session_id(session_.id());
    request.set_expected_version(session_.version());
    request.set_resume(attempt > 1);
    WritingStream<v1::OptimizeComeshResponse>(
        "OptimizeComesh", std::move(request),
        [this](auto* c, auto* q, auto* r) { stub_.async()->OptimizeComesh(c, q, r); }, attempt,
        [this](int next, Done d) { OptimizeAttempt(next, std::move(d)); }, std::move(done));
  }

  void Frames() {
    MeasureHeavy(
        "Inbetween",
        [this](Done done) {
          frames_ = FramesState{};
          FramesAttempt(1, std::move(done));
        },
        [this](absl::Status status) {
          if (status.ok()) run_.AddFrames(frames_.digest);
          Then(status, [this] { Read(); });
        });
  }

  void Read() {
    Measure(
        "GetSession",
        [this](Done done) {
          v1::GetSessionRequest request;
          request.set_session_id(session_.id());
          request.set_full(false);
          UnaryWithRetry<v1::GetSessionRequest, v1::GetSessionResponse>(
              session_.id(), std::move(request),
              [this](auto* c, auto* q, auto* r, auto f) {
                stub_.async()->GetSession(c, q, r, std::move(f));
              },
              [this, done](absl::Status status, v1::GetSessionResponse& response) {
                if (status.ok()) session_ = response.session();
                if (absl::IsNotFound(status)) run_.LostSession();
                done(status);
              });
        },
        [this](absl::Status status) { Then(status, [this] { Edit(); }); });
  }

  void Edit() {  // drawing 1 replaced (its multimesh is dropped)
    Measure(
        "PutDrawing",
        [this](Done done) {
          v1::PutDrawingRequest request;
          request.set_session_id(session_.id());
          request.set_expected_version(session_.version());
          request.mutable_drawing()->set_id(first_drawing_);
          request.mutable_drawing()->set_name("key1-edited.svg");
          request.mutable_drawing()->set_svg(options_.drawings_svg[0]);
          PutDrawing(std::move(request), done);
        },
        [this](absl::Status status) { Then(status, [this] { List(); }); });
  }

  void List() {
    Measure(
        "ListSessions",
        [this](Done done) {
          v1::ListSessionsRequest request;
          request.set_page_size(1000);
          ListPage(std::move(request), std::move(done));
        },
        [this](absl::Status status) { Then(status, [this] { Delete(); }); });
  }

  void Delete() {
    Measure(
        "DeleteSession",
        [this](Done done) {
          v1::DeleteSessionRequest request;
          request.set_session_id(session_.id());
          request.set_expected_version(session_.version());
          Unary<v1::DeleteSessionRequest, v1::DeleteSessionResponse>(
              session_.id(), std::move(request),
              [this](auto* c, auto* q, auto* r, auto f) {
                stub_.async()->DeleteSession(c, q, r, std::move(f));
              },
              [this, done](const grpc::Status& status, v1::DeleteSessionResponse&) {
                if (status.ok()) run_.DeletedSession(session_.id());
                done(client::FromGrpcStatus(status));
              });
        },
        [this](absl::Status status) { Then(status, [this] { NewProject(); }); });
  }

  // After a step: `next` on success; the end of the studio when the budget is used up; else a
  // new project after a short pause.
  void Then(const absl::Status& status, std::function<void()> next) {
    if (status.ok()) return next();
    if (budget_spent_) return run_.StudioDone();  // last statement: the studio may be destroyed
    timer_.After(std::chrono::milliseconds(50), [this] { NewProject(); });
  }

  // --- measuring ---
  // Claims a request of the budget, runs `call` and records its outcome when it reports, then
  // `then`. Nothing is sent (CANCELLED "budget", budget_spent_) when the budget is used up.
  void Measure(const std::string& rpc, std::function<void(Done)> call, Done then) {
    if (!run_.Claim()) {
      budget_spent_ = true;
      return then(absl::CancelledError("budget"));
    }
    const Clock::time_point start = Clock::now();
    call([this, rpc, start, then = std::move(then)](absl::Status status) {
      run_.Record(rpc, start, status);
      then(std::move(status));
    });
  }

  // A heavy call (a slot of the server's bounded pool): RESOURCE_EXHAUSTED is the server's
  // documented back-pressure, so the studio waits (100 ms, doubling up to 1.6 s) and asks again,
  // up to 6 times; every attempt is a request in the report.
  void MeasureHeavy(const std::string& rpc, std::function<void(Done)> call, Done then,
                    int attempt = 1,
                    std::chrono::milliseconds wait = std::chrono::milliseconds(100)) {
    Measure(rpc, call, [=, this](absl::Status status) {
      if (!absl::IsResourceExhausted(status) || attempt == 6) return then(std::move(status));
      timer_.After(wait, [=, this] {
        MeasureHeavy(rpc, call, then, attempt + 1,
                     std::min(wait * 2, std::chrono::milliseconds(1600)));
      });
    });
  }

  // --- calls on the callback API ---
  // A context carrying the token and the session id (for proxies' session affinity).
  std::unique_ptr<grpc::ClientContext> Context(const std::string& session_id) const {
    auto context = std::make_unique<grpc::ClientContext>();
    if (!options_.token.empty()) {
      context->AddMetadata("authorization", absl::StrCat("Bearer ", options_.token));
    }
    if (!session_id.empty()) context->AddMetadata("x-session-id", session_id);
    return context;
  }

  // One unary call: `start(context, &request, &response, callback)` is the stub's async method;
  // `done` sees the status and the response.
  template <class Request, class Response, class Start>
  void Unary(const std::string& session_id, Request request, Start start,
             std::function<void(const grpc::Status&, Response&)> done) {
    struct Call {
      std::unique_ptr<grpc::ClientContext> context;
      Request request;
      Response response;
    };
    auto call = std::make_shared<Call>(Call{Context(session_id), std::move(request), {}});
    start(call->context.get(), &call->request, &call->response,
          [call, done = std::move(done)](grpc::Status status) { done(status, call->response); });
  }

  // A read-only unary call, sent again after a transient failure (client::IsTransient) with the
  // client library's backoff (RetryOptions), each retry counted in the report.
  template <class Request, class Response, class Start>
  void UnaryWithRetry(const std::string& session_id, Request request, Start start,
                      std::function<void(absl::Status, Response&)> done, int attempt = 1) {
    Unary<Request, Response>(
        session_id, request, start, [=, this](const grpc::Status& status, Response& response) {
          std::optional<std::chrono::milliseconds> backoff = Backoff(attempt, status);
          if (!backoff) return done(client::FromGrpcStatus(status), response);
          timer_.After(*backoff, [=, this] {
            UnaryWithRetry<Request, Response>(session_id, request, start, done, attempt + 1);
          });
        });
  }

  // The wait before attempt `failed_attempt + 1` of a call that may be repeated; none when
  // `status` is not transient or the attempts are used up (client::InbetweenClient's rules).
  std::optional<std::chrono::milliseconds> Backoff(int failed_attempt, const grpc::Status& status) {
    if (status.ok() || !client::IsTransient(status) || failed_attempt >= retry_.max_attempts) {
      return std::nullopt;
    }
    const double ms =
        std::min(static_cast<double>(retry_.max_backoff.count()),
                 retry_.initial_backoff.count() * std::pow(retry_.multiplier, failed_attempt - 1));
    run_.AddRetry();
    return std::chrono::milliseconds(static_cast<int64_t>(ms));
  }

  // One server stream: `start(context, &request, reactor)` is the stub's async method.
  template <class Request, class Response, class Start>
  void Stream(Request request, Start start, typename StreamCall<Response>::OnMessage on_message,
              Done done) {
    auto owned = std::make_shared<Request>(std::move(request));  // lives until the call is done
    auto* call = new StreamCall<Response>(
        Context(owned->session_id()), std::move(on_message),
        [owned, done = std::move(done)](absl::Status status) { done(std::move(status)); });
    start(call->context(), owned.get(), call);
    call->Go();
  }

  void PutDrawing(v1::PutDrawingRequest request, Done done) {
    const std::string id = request.session_id();
    Unary<v1::PutDrawingRequest, v1::PutDrawingResponse>(
        id, std::move(request),
        [this](auto* c, auto* q, auto* r, auto f) {
          stub_.async()->PutDrawing(c, q, r, std::move(f));
        },
        [this, done](const grpc::Status& status, v1::PutDrawingResponse& response) {
          if (status.ok()) {
            session_ = response.session();
            if (first_drawing_ == 0) first_drawing_ = response.drawing().id();
          }
          done(client::FromGrpcStatus(status));
        });
  }

  // Every page of ListSessions, each page retried like GetSession.
  void ListPage(v1::ListSessionsRequest request, Done done) {
    UnaryWithRetry<v1::ListSessionsRequest, v1::ListSessionsResponse>(
        "", request,
        [this](auto* c, auto* q, auto* r, auto f) {
          stub_.async()->ListSessions(c, q, r, std::move(f));
        },
        [this, request, done](absl::Status status, v1::ListSessionsResponse& response) mutable {
          if (!status.ok() || response.next_page_token().empty()) return done(status);
          request.set_page_token(response.next_page_token());
          ListPage(std::move(request), std::move(done));
        });
  }

  // Inbetween with the client library's failover: after a transient failure the stream is sent
  // again from the first frame not received yet (start_frame); a resumed stream of another
  // session version is ABORTED, never mixed in. Frames are taken once each, in order.
  struct FramesState {
    bool have_header = false;
    v1::InbetweenHeader header;
    uint32_t received = 0;
    std::string digest;  // header and frames without seconds (AppendFrame)
  };

  void FramesAttempt(int attempt, Done done) {
    v1::InbetweenRequest request;
    request.set_session_id(session_.id());
    request.mutable_parameters()->set_frames(options_.frames);
    request.set_start_frame(frames_.received);
    Stream<v1::InbetweenRequest, v1::InbetweenResponse>(
        std::move(request),
        [this](auto* c, auto* q, auto* r) { stub_.async()->Inbetween(c, q, r); },
        [this](v1::InbetweenResponse& response) { return TakeFrames(response); },
        [this, attempt, done](absl::Status status) {
          FramesState& f = frames_;
          if (mismatch_) {  // a wrong header or frame (ABORTED, INTERNAL): never retried
            mismatch_ = false;
            return done(status);
          }
          // Every frame arrived before the connection broke: nothing to resume.
          const bool complete = f.have_header && f.received == f.header.frames();
          if (!status.ok() && !complete) {
            const grpc::Status as_grpc(static_cast<grpc::StatusCode>(status.code()),
                                       std::string(status.message()));
            std::optional<std::chrono::milliseconds> backoff = Backoff(attempt, as_grpc);
            if (!backoff) return done(status);
            timer_.After(*backoff, [this, attempt, done] { FramesAttempt(attempt + 1, done); });
            return;
          }
          if (!f.have_header)
            return done(absl::InternalError("Inbetween stream ended without a header"));
          if (f.received != f.header.frames()) {
            return done(
                absl::InternalError(absl::StrCat("Inbetween stream sent ", f.received,
                                                 " frames, header announced ", f.header.frames())));
          }
          done(absl::OkStatus());
        });
  }

  absl::Status TakeFrames(v1::InbetweenResponse& response) {
    FramesState& f = frames_;
    if (response.has_header()) {
      if (!f.have_header) {
        f.header = response.header();
        f.have_header = true;
        f.digest = f.header.SerializeAsString();
      } else if (response.header().session_version() != f.header.session_version() ||
                 response.header().frames() != f.header.frames() ||
                 response.header().triangles_size() != f.header.triangles_size()) {
        // Another version would give other frames: a mix of two runs is never returned.
        mismatch_ = true;
        return absl::AbortedError(absl::StrCat(
            "session ", session_.id(), " changed from version ", f.header.session_version(), " to ",
            response.header().session_version(), " while its frames were streamed (", f.received,
            " of ", f.header.frames(), " received); start again"));
      }
    } else if (response.has_frame()) {
      if (response.frame().index() != f.received) {
        mismatch_ = true;
        return absl::InternalError(absl::StrCat(
            "Inbetween stream sent frame ", response.frame().index(), ", expected ", f.received));
      }
      AppendFrame(std::move(*response.mutable_frame()), &f.digest);
      ++f.received;
    }
    return absl::OkStatus();
  }

  const int index_;
  v1::Inbetween::Stub& stub_;
  const LoadGenOptions& options_;
  const client::RetryOptions retry_;
  Run& run_;
  Timer& timer_;
  v1::Parameters parameters_;
  int project_ = 0;
  v1::Session session_;
  uint32_t first_drawing_ = 0;
  FramesState frames_;
  bool mismatch_ = false;      // the last stream was stopped for a wrong header or frame
  bool budget_spent_ = false;  // no request left: the studio ends
};

}  // namespace

absl::Status CheckLoopbackTarget(const std::string& target) {
  std::string host, port;
  if (absl::StartsWith(target, "[")) {
    const size_t close = target.find("]:");
    if (close == std::string::npos) return absl::InvalidArgumentError("target: [HOST]:PORT");
    host = target.substr(1, close - 1);
    port = target.substr(close + 2);
  } else {
    const size_t colon = target.rfind(':');
    if (colon == std::string::npos || target.find(':') != colon) {
      return absl::InvalidArgumentError(
          absl::StrCat("target '", target, "': HOST:PORT or [IPV6]:PORT"));
    }
    host = target.substr(0, colon);
    port = target.substr(colon + 1);
  }
  int port_number = 0;
  if (!absl::SimpleAtoi(port, &port_number) || port_number < 1 || port_number > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("target '", target, "': bad port"));
  }
  bool loopback = host == "localhost" || host == "::1";
  int a = 0, b = 0, c = 0, d = 0;
  char tail = 0;
  if (std::sscanf(host.c_str(), "%d.%d.%d.%d%c", &a, &b, &c, &d, &tail) == 4) {
    loopback = a == 127 && b >= 0 && b <= 255 && c >= 0 && c <= 255 && d >= 0 && d <= 255;
  }
  if (!loopback) {
    return absl::InvalidArgumentError(absl::StrCat(
        "target '", target, "' is not a loopback address (127.0.0.0/8, ::1, localhost)"));
  }
  return absl::OkStatus();
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(p / 100.0 * static_cast<double>(values.size()));
  const size_t index = static_cast<size_t>(std::clamp(rank, 1.0, double(values.size()))) - 1;
  return values[index];
}

absl::StatusOr<LoadReport> RunLoad(std::shared_ptr<grpc::Channel> channel,
                                   const LoadGenOptions& options) {
  if (options.studios < 1) return absl::InvalidArgumentError("studios must be >= 1");
  if (options.drawings_svg.size() < 2) return absl::InvalidArgumentError("need >= 2 drawings");
  if (options.max_requests < 1) return absl::InvalidArgumentError("max_requests must be >= 1");
  // gRPC aborts the process on a metadata value outside printable ASCII.
  if (!std::all_of(options.token.begin(), options.token.end(),
                   [](char c) { return c >= 0x20 && c < 0x7f; })) {
    return absl::InvalidArgumentError("token: printable ASCII only");
  }
  Run run(options);
  client::ClientOptions client_options;  // the library's retry rules, also for the final check
  client_options.token = options.token;
  std::unique_ptr<v1::Inbetween::Stub> stub = v1::Inbetween::NewStub(channel);
  const Clock::time_point start = Clock::now();
  {
    Timer timer;
    std::vector<std::unique_ptr<Studio>> studios;
    for (int i = 0; i < options.studios; ++i) {
      studios.push_back(
          std::make_unique<Studio>(i, *stub, options, client_options.retry, run, timer));
    }
    for (auto& studio : studios) studio->Start();  // each runs on gRPC's and the timer's threads
    run.WaitForStudios();
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  LoadReport report = run.Report(seconds);
  // Every session created and not deleted must still be there (e.g. after replicas were killed).
  client::InbetweenClient checker(channel, client_options);
  for (const std::string& id : run.alive_sessions()) {
    auto got = checker.GetSession(id, /*full=*/false);
    if (!got.ok() && absl::IsNotFound(got.status())) ++report.lost_sessions;
    if (!got.ok() && !absl::IsNotFound(got.status())) {
      return absl::Status(got.status().code(),
                          absl::StrCat("checking session ", id, ": ", got.status().message()));
    }
  }
  return report;
}

std::string FormatTable(const LoadReport& r) {
  std::string out =
      absl::StrFormat("%-16s %8s %7s %10s %10s %10s %10s  %s\n", "rpc", "calls", "errors", "p50 ms",
                      "p95 ms", "p99 ms", "max ms", "errors by code");
  for (const auto& [rpc, s] : r.rpcs) {
    std::string codes;
    for (const auto& [code, n] : s.errors_by_code) absl::StrAppend(&codes, " ", code, "=", n);
    absl::StrAppendFormat(&out, "%-16s %8d %7d %10.2f %10.2f %10.2f %10.2f %s\n", rpc, s.calls,
                          s.errors, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms, codes);
  }
  absl::StrAppendFormat(&out,
                        "%d studios, %.1f s, %d requests (%.1f/s), %d errors, unary p99 %.2f ms, "
                        "%d retries, %d sessions (%d lost), %d streams, frames identical: %s, "
                        "peak %d calls in flight\n",
                        r.studios, r.seconds, r.requests,
                        r.seconds > 0 ? r.requests / r.seconds : 0.0, r.errors, r.unary_p99_ms,
                        r.retries, r.sessions, r.lost_sessions, r.streams_completed,
                        r.frames_identical ? "yes" : "NO", r.peak_in_flight);
  for (const auto& [code, n] : r.errors_by_code) absl::StrAppendFormat(&out, "  %s: %d\n", code, n);
  return out;
}

std::string FormatJson(const LoadReport& r) {
  nlohmann::json j;
  j["studios"] = r.studios;
  j["seconds"] = r.seconds;
  j["requests"] = r.requests;
  j["requests_per_second"] = r.seconds > 0 ? r.requests / r.seconds : 0.0;
  j["errors"] = r.errors;
  j["errors_by_code"] = nlohmann::json::object();
  for (const auto& [code, n] : r.errors_by_code) j["errors_by_code"][code] = n;
  j["unary_p99_ms"] = r.unary_p99_ms;
  j["retries"] = r.retries;
  j["sessions"] = r.sessions;
  j["lost_sessions"] = r.lost_sessions;
  j["streams_completed"] = r.streams_completed;
  j["frames_identical"] = r.frames_identical;
  j["peak_in_flight"] = r.peak_in_flight;
  for (const auto& [rpc, s] : r.rpcs) {
    j["rpcs"][rpc] = {{"calls", s.calls},   {"errors", s.errors}, {"p50_ms", s.p50_ms},
                      {"p95_ms", s.p95_ms}, {"p99_ms", s.p99_ms}, {"max_ms", s.max_ms}};
    j["rpcs"][rpc]["errors_by_code"] = nlohmann::json::object();
    for (const auto& [code, n] : s.errors_by_code) j["rpcs"][rpc]["errors_by_code"][code] = n;
  }
  return j.dump(2);
}

}  // namespace inbetween::loadgen
