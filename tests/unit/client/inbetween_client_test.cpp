// Tests InbetweenClient's failover (client/inbetween_client.cpp): a fake front service forwards
// calls to a real in-process InbetweenServer and breaks them as scripted (a replica dying
// mid-stream behind a proxy). The client must resume Inbetween at the next frame not received,
// deliver exactly the frames of an uninterrupted run, resume OptimizeComesh from the server's
// checkpoint with the result of an uninterrupted run, retry GetSession/ListSessions, stop after
// the attempts run out, never retry a non-transient error, and refuse to splice frames of two
// session versions.
#include "client/inbetween_client.h"

#include <gmock/gmock.h>
#include <google/protobuf/util/message_differencer.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/inbetween_server.h"
#include "server/status_mapping.h"
#include "solver/core/error_reason.h"
#include "tests/unit/server/many_layers_svg.h"

namespace inbetween::client {
namespace {

using ::testing::Each;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

// How the front breaks one call: forward `after_frames` frames (Inbetween; the header always
// goes through) or iterations (OptimizeComesh), then end the call with `status` instead of the
// rest.
struct Fault {
  grpc::Status status;
  int after_frames = 0;
  int after_art = -1;  // >= 0: Inbetween breaks after this many art messages instead
};

const grpc::Status kUnavailable(grpc::StatusCode::UNAVAILABLE, "Socket closed");
// What gRPC reports when nginx resets a stream whose replica died.
const grpc::Status kProxyReset(grpc::StatusCode::INTERNAL, "Received RST_STREAM with error code 2");

// Forwards GetSession, ListSessions, Inbetween and OptimizeComesh to `backend`, failing calls
// per `faults`
// (consumed in call order, shared by all methods) and recording what the client sent.
class FlakyFront final : public v1::Inbetween::Service {
 public:
  explicit FlakyFront(std::shared_ptr<grpc::Channel> backend)
      : backend_(v1::Inbetween::NewStub(std::move(backend))) {}

  std::deque<Fault> faults;
  std::vector<uint32_t> start_frames;       // of every Inbetween call
  std::vector<bool> resumes;                // `resume` of every OptimizeComesh call
  std::vector<uint64_t> expected_versions;  // of every OptimizeComesh call
  std::vector<uint64_t> build_versions;     // expected_version of every BuildMultimesh call
  std::vector<std::string> session_ids;     // x-session-id of every call ("" when absent)
  int unary_calls = 0;

  grpc::Status GetSession(grpc::ServerContext* context, const v1::GetSessionRequest* request,
                          v1::GetSessionResponse* response) override {
    Record(*context);
    ++unary_calls;
    if (auto fault = NextFault()) return fault->status;
    grpc::ClientContext upstream;
    return backend_->GetSession(&upstream, *request, response);
  }

  grpc::Status ListSessions(grpc::ServerContext* context, const v1::ListSessionsRequest* request,
                            v1::ListSessionsResponse* response) override {
    Record(*context);
    ++unary_calls;
    if (auto fault = NextFault()) return fault->status;
    grpc::ClientContext upstream;
    return backend_->ListSessions(&upstream, *request, response);
  }

  grpc::Status Inbetween(grpc::ServerContext* context, const v1::InbetweenRequest* request,
                         grpc::ServerWriter<v1::InbetweenResponse>* writer) override {
    Record(*context);
    start_frames.push_back(request->start_frame());
    std::optional<Fault> fault = NextFault();
    grpc::ClientContext upstream;
    auto reader = backend_->Inbetween(&upstream, *request);
    v1::InbetweenResponse response;
    int frames = 0;
    int art = 0;
    while (reader->Read(&response)) {
      const bool break_here =
          fault && (fault->after_art >= 0
                        ? response.has_art() && art++ == fault->after_art
                        : response.has_frame() && frames++ == fault->after_frames);
      if (break_here) {
        upstream.TryCancel();
        reader->Finish();
        return fault->status;
      }
      writer->Write(response);
    }
    grpc::Status status = reader->Finish();
    return fault && status.ok() ? fault->status : status;
  }

  grpc::Status BuildMultimesh(grpc::ServerContext* context,
                              const v1::BuildMultimeshRequest* request,
                              grpc::ServerWriter<v1::BuildMultimeshResponse>* writer) override {
    Record(*context);
    build_versions.push_back(request->expected_version());
    std::optional<Fault> fault = NextFault();
    grpc::ClientContext upstream;
    auto reader = backend_->BuildMultimesh(&upstream, *request);
    v1::BuildMultimeshResponse response;
    int messages = 0;
    while (reader->Read(&response)) {
      if (response.has_progress() && fault && messages++ == fault->after_frames) {
        upstream.TryCancel();  // the replica is gone before it stored anything
        reader->Finish();
        return fault->status;
      }
      writer->Write(response);
    }
    grpc::Status status = reader->Finish();
    return fault && status.ok() ? fault->status : status;
  }

  grpc::Status OptimizeComesh(grpc::ServerContext* context,
                              const v1::OptimizeComeshRequest* request,
                              grpc::ServerWriter<v1::OptimizeComeshResponse>* writer) override {
    Record(*context);
    resumes.push_back(request->resume());
    expected_versions.push_back(request->expected_version());
    std::optional<Fault> fault = NextFault();
    grpc::ClientContext upstream;
    auto reader = backend_->OptimizeComesh(&upstream, *request);
    v1::OptimizeComeshResponse response;
    int iterations = 0;
    while (reader->Read(&response)) {
      if (response.has_iteration() && fault && iterations++ == fault->after_frames) {
        upstream.TryCancel();  // the replica is gone: its run stops
        reader->Finish();
        return fault->status;
      }
      writer->Write(response);
    }
    grpc::Status status = reader->Finish();
    return fault && status.ok() ? fault->status : status;
  }

 private:
  std::optional<Fault> NextFault() {
    if (faults.empty()) return std::nullopt;
    Fault f = faults.front();
    faults.pop_front();
    return f;
  }
  void Record(const grpc::ServerContext& context) {
    auto it = context.client_metadata().find("x-session-id");
    session_ids.push_back(it == context.client_metadata().end()
                              ? std::string()
                              : std::string(it->second.data(), it->second.size()));
  }

  std::unique_ptr<v1::Inbetween::Stub> backend_;
};

std::string ReadExample(const std::string& relative) {
  std::ifstream in(std::string(INBETWEEN_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Frames without their wall-clock seconds (the only field that may differ between two runs).
std::vector<v1::InbetweenFrame> WithoutSeconds(std::vector<v1::InbetweenFrame> frames) {
  for (v1::InbetweenFrame& f : frames) f.mutable_stats()->clear_seconds();
  return frames;
}

class InbetweenClientFailoverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto started = server::InbetweenServer::Start(server::ServerOptions{});
    ASSERT_TRUE(started.ok()) << started.status();
    backend_ = *std::move(started);
    direct_ = std::make_unique<InbetweenClient>(backend_->InProcessChannel());

    // A built square -> hexagon session on the real server.
    session_ = BuiltSession("failover");
    ASSERT_FALSE(session_.id().empty());
    parameters_.set_frames(40);
    parameters_.set_method(v1::METHOD_ZHU17);

    front_ = std::make_unique<FlakyFront>(backend_->InProcessChannel());
    grpc::ServerBuilder builder;
    builder.RegisterService(front_.get());
    front_server_ = builder.BuildAndStart();
    ASSERT_NE(front_server_, nullptr);
  }

  void TearDown() override {
    if (front_server_) front_server_->Shutdown();
  }

  // A new square -> hexagon session on the real server, built.
  v1::Session BuiltSession(const std::string& name) {
    auto session = direct_->CreateSession(name);
    EXPECT_TRUE(session.ok()) << session.status();
    if (!session.ok()) return {};
    for (const char* drawing : {"square", "hexagon"}) {
      v1::PutDrawingRequest request;
      request.set_session_id(session->id());
      request.set_expected_version(session->version());
      request.mutable_drawing()->set_name(drawing);
      request.mutable_drawing()->set_svg(
          ReadExample(std::string("examples/square_hexagon/") + drawing + ".svg"));
      auto put = direct_->PutDrawing(request);
      EXPECT_TRUE(put.ok()) << put.status();
      if (!put.ok()) return {};
      *session = put->session();
    }
    auto built = direct_->BuildMultimesh(*session, nullptr);
    EXPECT_TRUE(built.ok()) << built.status();
    return built.ok() ? built->session() : v1::Session();
  }

  // A client through the flaky front; backoff of 1, 2, 4 ... ms so the test stays short.
  std::unique_ptr<InbetweenClient> FrontClient(int max_attempts = 5) {
    ClientOptions options;
    options.retry.max_attempts = max_attempts;
    options.retry.initial_backoff = std::chrono::milliseconds(1);
    options.on_retry = [this](const RetryEvent& e) { retries_.push_back(e); };
    return std::make_unique<InbetweenClient>(front_server_->InProcessChannel({}), options);
  }

  std::unique_ptr<server::InbetweenServer> backend_;
  std::unique_ptr<InbetweenClient> direct_;
  v1::Session session_;
  v1::InbetweenParameters parameters_;
  std::unique_ptr<FlakyFront> front_;
  std::unique_ptr<grpc::Server> front_server_;
  std::vector<RetryEvent> retries_;
};

// A build whose replica dies after its first progress message (before it stored anything) is
// sent again with the same expected_version and builds the same multimesh; a non-transient
// error is not repeated.
TEST_F(InbetweenClientFailoverTest, BrokenBuildIsSentAgainAndBuildsTheSameMultimesh) {
  auto fresh = [&](const std::string& name) {
    auto session = direct_->CreateSession(name);
    EXPECT_TRUE(session.ok());
    for (const char* drawing : {"square", "hexagon"}) {
      v1::PutDrawingRequest request;
      request.set_session_id(session->id());
      request.set_expected_version(session->version());
      request.mutable_drawing()->set_svg(
          ReadExample(std::string("examples/square_hexagon/") + drawing + ".svg"));
      auto put = direct_->PutDrawing(request);
      EXPECT_TRUE(put.ok()) << put.status();
      *session = put->session();
    }
    return *session;
  };
  const v1::Session reference_session = fresh("build reference");
  auto reference = direct_->BuildMultimesh(reference_session, nullptr);
  ASSERT_TRUE(reference.ok()) << reference.status();

  const v1::Session session = fresh("build broken");
  front_->faults = {{kUnavailable, 0}, {kProxyReset, 1}};
  auto client = FrontClient();
  auto built = client->BuildMultimesh(session, nullptr);
  ASSERT_TRUE(built.ok()) << built.status();
  // Two injected faults; on a loaded machine the third attempt may also meet the server still
  // winding down the broken attempts' jobs (--max-heavy-jobs-per-token), retried as well.
  ASSERT_GE(retries_.size(), 2u);
  EXPECT_EQ(retries_[0].method, "BuildMultimesh");
  for (size_t i = 2; i < retries_.size(); ++i) {
    EXPECT_THAT(retries_[i].status.message(), HasSubstr("--max-heavy-jobs-per-token"));
  }
  EXPECT_EQ(front_->build_versions.size(), retries_.size() + 1);
  EXPECT_THAT(front_->build_versions, Each(session.version()));
  EXPECT_EQ(built->session().version(), session.version() + 1);  // built once
  EXPECT_EQ(built->session().multimesh_stats().vertices(),
            reference->session().multimesh_stats().vertices());
  auto mine = direct_->GetSession(session.id(), /*full=*/true);
  auto theirs = direct_->GetSession(reference_session.id(), /*full=*/true);
  ASSERT_TRUE(mine.ok() && theirs.ok());
  ASSERT_GT(mine->multimesh().triangles_size(), 0);
  EXPECT_EQ(mine->multimesh().SerializeAsString(), theirs->multimesh().SerializeAsString());

  // FAILED_PRECONDITION (not transient) goes straight back.
  retries_.clear();
  front_->faults = {{grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, "no"), 0}};
  auto refused = client->BuildMultimesh(fresh("build refused"), nullptr);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(retries_.empty());
}

// The art that follows the header in messages of its own is appended to the header's, also when
// the connection breaks in the middle of it.
TEST_F(InbetweenClientFailoverTest, ArtMessagesAreAppendedToTheHeaderAcrossABrokenStream) {
  auto session = direct_->CreateSession("many layers");
  ASSERT_TRUE(session.ok()) << session.status();
  for (double dx : {0.0, 5.0}) {
    v1::PutDrawingRequest request;
    request.set_session_id(session->id());
    request.set_expected_version(session->version());
    request.mutable_drawing()->set_svg(server::testing::ManyLayersSvg(2000, dx));
    auto put = direct_->PutDrawing(request);
    ASSERT_TRUE(put.ok()) << put.status();
    *session = put->session();
  }
  auto built = direct_->BuildMultimesh(*session, nullptr);
  ASSERT_TRUE(built.ok()) << built.status();
  ASSERT_EQ(built->multimesh().art_size(), 2);
  v1::InbetweenParameters parameters;
  parameters.set_frames(3);

  auto direct = direct_->Inbetween(session->id(), parameters, nullptr);
  ASSERT_TRUE(direct.ok()) << direct.status();
  ASSERT_GT(direct->header.art_messages(), 1u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(direct->header.art(k),
                                                                   built->multimesh().art(k)))
        << "key " << k;
  }

  front_->faults = {{kUnavailable, 0, /*after_art=*/1}};
  auto resumed = FrontClient()->Inbetween(session->id(), parameters, nullptr);
  ASSERT_TRUE(resumed.ok()) << resumed.status();
  EXPECT_EQ(front_->start_frames.size(), 2u);
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(resumed->header, direct->header));
}

TEST_F(InbetweenClientFailoverTest, ResumedStreamDeliversTheFramesOfAnUninterruptedRun) {
  auto uninterrupted = direct_->Inbetween(session_.id(), parameters_, nullptr);
  ASSERT_TRUE(uninterrupted.ok()) << uninterrupted.status();
  ASSERT_EQ(uninterrupted->frames.size(), 40u);

  // Three failures: after 7 frames, after the header only, after 13 more frames.
  front_->faults = {{kUnavailable, 7}, {kProxyReset, 0}, {kUnavailable, 13}};
  auto client = FrontClient();
  std::vector<uint32_t> seen;
  auto resumed = client->Inbetween(session_.id(), parameters_,
                                   [&](const v1::InbetweenFrame& f, uint32_t total) {
                                     EXPECT_EQ(total, 40u);
                                     seen.push_back(f.index());
                                   });
  ASSERT_TRUE(resumed.ok()) << resumed.status();

  EXPECT_THAT(front_->start_frames, ElementsAre(0u, 7u, 7u, 20u));
  ASSERT_EQ(seen.size(), 40u);  // each frame once, in order
  for (uint32_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i);
  EXPECT_TRUE(
      google::protobuf::util::MessageDifferencer::Equals(resumed->header, uninterrupted->header));
  const auto expected = WithoutSeconds(uninterrupted->frames);
  const auto got = WithoutSeconds(resumed->frames);
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(got[i], expected[i]))
        << "frame " << i;
  }
  // Exponential backoff, the resume point reported with each retry.
  ASSERT_EQ(retries_.size(), 3u);
  EXPECT_EQ(retries_[0].backoff.count(), 1);
  EXPECT_EQ(retries_[1].backoff.count(), 2);
  EXPECT_EQ(retries_[2].backoff.count(), 4);
  EXPECT_EQ(retries_[0].resume_frame, 7u);
  EXPECT_EQ(retries_[1].resume_frame, 7u);
  EXPECT_EQ(retries_[2].resume_frame, 20u);
  EXPECT_EQ(retries_[1].status.code(), absl::StatusCode::kInternal);
  // Every attempt carried the session id for the proxy's affinity.
  EXPECT_THAT(front_->session_ids, Each(session_.id()));
}

TEST_F(InbetweenClientFailoverTest, GivesUpAfterTheLastAttempt) {
  front_->faults = {{kUnavailable, 1}, {kUnavailable, 1}, {kUnavailable, 1}, {kUnavailable, 1}};
  auto client = FrontClient(/*max_attempts=*/3);
  auto frames = client->Inbetween(session_.id(), parameters_, nullptr);
  EXPECT_EQ(frames.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(front_->start_frames, ElementsAre(0u, 1u, 2u));
  EXPECT_EQ(retries_.size(), 2u);
}

TEST_F(InbetweenClientFailoverTest, NonTransientErrorsAreNotRetried) {
  front_->faults = {{grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, "no multimesh"), 3},
                    {grpc::Status(grpc::StatusCode::INTERNAL, "frame 3: solver bug"), 0}};
  auto client = FrontClient();
  auto first = client->Inbetween(session_.id(), parameters_, nullptr);
  EXPECT_EQ(first.status().code(), absl::StatusCode::kFailedPrecondition);
  auto second = client->Inbetween(session_.id(), parameters_, nullptr);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kInternal);
  EXPECT_THAT(front_->start_frames, ElementsAre(0u, 0u));
  EXPECT_TRUE(retries_.empty());
}

TEST_F(InbetweenClientFailoverTest, FramesOfAnotherSessionVersionAreNotSpliced) {
  front_->faults = {{kUnavailable, 5}};
  ClientOptions options;
  options.retry.initial_backoff = std::chrono::milliseconds(1);
  // While the client waits to resume, someone rebuilds the session (a new version).
  options.on_retry = [this](const RetryEvent&) {
    auto rebuilt = direct_->BuildMultimesh(session_, nullptr);
    ASSERT_TRUE(rebuilt.ok()) << rebuilt.status();
  };
  InbetweenClient client(front_server_->InProcessChannel({}), options);
  auto frames = client.Inbetween(session_.id(), parameters_, nullptr);
  EXPECT_EQ(frames.status().code(), absl::StatusCode::kAborted);
  EXPECT_THAT(frames.status().message(), HasSubstr("changed from version"));
  EXPECT_THAT(front_->start_frames, ElementsAre(0u, 5u));
}

TEST_F(InbetweenClientFailoverTest, CancelDuringTheBackoffEndsTheCall) {
  front_->faults = {{kUnavailable, 2}};
  ClientOptions options;
  options.retry.initial_backoff = std::chrono::minutes(10);  // only a cancel ends this wait
  InbetweenClient* client_ptr = nullptr;
  options.on_retry = [&](const RetryEvent&) { client_ptr->CancelInFlight(); };  // Ctrl-C
  InbetweenClient client(front_server_->InProcessChannel({}), options);
  client_ptr = &client;
  auto frames = client.Inbetween(session_.id(), parameters_, nullptr);
  EXPECT_EQ(frames.status().code(), absl::StatusCode::kCancelled);
  EXPECT_THAT(front_->start_frames, ElementsAre(0u));
}

TEST_F(InbetweenClientFailoverTest, GetSessionAndListSessionsAreRetried) {
  auto client = FrontClient();
  front_->faults = {{kUnavailable, 0}, {kProxyReset, 0}};
  auto got = client->GetSession(session_.id(), /*full=*/false);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->session().version(), session_.version());
  EXPECT_EQ(front_->unary_calls, 3);
  EXPECT_THAT(front_->session_ids, Each(session_.id()));

  front_->faults = {{kUnavailable, 0}};
  auto listed = client->ListSessions();
  ASSERT_TRUE(listed.ok()) << listed.status();
  ASSERT_EQ(listed->size(), 1u);
  EXPECT_EQ((*listed)[0].id(), session_.id());
  EXPECT_EQ(front_->unary_calls, 5);

  front_->faults = {{grpc::Status(grpc::StatusCode::NOT_FOUND, "no such session"), 0}};
  EXPECT_EQ(client->GetSession("nope", false).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(front_->unary_calls, 6);
  EXPECT_EQ(retries_.size(), 3u);

  // The heavy-job limit is retried only after a transient failure (the broken attempt's job),
  // and no sooner than kOrphanJobBackoff; as the first answer it goes straight back.
  // (As the server sends it: the reason in the status details.)
  const grpc::Status busy = server::ToGrpcStatus(solver::WithReason(
      absl::ResourceExhaustedError("this token already has 2 heavy jobs (build, optimize, "
                                   "inbetween) running or queued, the limit "
                                   "(--max-heavy-jobs-per-token)"),
      solver::kReasonHeavyJobsPerToken));
  front_->faults = {{kUnavailable, 0}, {busy, 0}};
  ASSERT_TRUE(client->GetSession(session_.id(), false).ok());
  EXPECT_EQ(front_->unary_calls, 9);
  ASSERT_EQ(retries_.size(), 5u);
  EXPECT_EQ(retries_[4].status.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_GE(retries_[4].backoff, InbetweenClient::kOrphanJobBackoff);
  front_->faults = {{busy, 0}};
  EXPECT_EQ(client->GetSession(session_.id(), false).status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(front_->unary_calls, 10);
  EXPECT_EQ(retries_.size(), 5u);
}

// Bounded so that the test stays short but makes several topology passes (no outer tolerance:
// passes until one changes nothing or 8 were made).
v1::ComeshParameters ShortComesh() {
  v1::ComeshParameters comesh;
  comesh.set_max_outer_iterations(8);
  comesh.set_outer_tolerance(0.0);
  comesh.set_max_inner_iterations(200);
  return comesh;
}

TEST_F(InbetweenClientFailoverTest, ResumedOptimizationGivesTheMultimeshOfAnUninterruptedRun) {
  // The reference: the same drawings, built and optimized without failures.
  const v1::Session reference_session = BuiltSession("reference");
  const v1::ComeshParameters comesh = ShortComesh();
  std::vector<v1::ComeshIteration> reference_iterations;
  auto reference = direct_->OptimizeComesh(
      reference_session, [&](const v1::ComeshIteration& it) { reference_iterations.push_back(it); },
      nullptr, &comesh);
  ASSERT_TRUE(reference.ok()) << reference.status();
  // Resumed from the checkpoint of pass 1, the run still has a pass (and the outer stops) ahead.
  ASSERT_GE(reference->outer_iterations(), 2u);
  // Break the stream 3 iterations after the first topology pass (its checkpoint is stored by
  // then), and the resumed stream after its first iteration.
  int first_after_pass = -1;
  for (size_t i = 0; i < reference_iterations.size() && first_after_pass < 0; ++i) {
    if (reference_iterations[i].outer() == 1) first_after_pass = static_cast<int>(i);
  }
  ASSERT_GT(first_after_pass, 0);
  ASSERT_GE(std::count_if(reference_iterations.begin(), reference_iterations.end(),
                          [](const v1::ComeshIteration& it) { return it.outer() == 1; }),
            5)
      << "the break must come before pass 2";
  front_->faults = {{kUnavailable, first_after_pass + 3}, {kProxyReset, 1}};

  // A backoff long enough for the broken run's handler to notice it was cancelled.
  ClientOptions options;
  options.retry.initial_backoff = std::chrono::milliseconds(100);
  options.on_retry = [this](const RetryEvent& e) { retries_.push_back(e); };
  InbetweenClient client(front_server_->InProcessChannel({}), options);
  std::vector<v1::ComeshIteration> iterations;
  std::vector<std::string> progress;
  auto optimized = client.OptimizeComesh(
      session_, [&](const v1::ComeshIteration& it) { iterations.push_back(it); },
      [&](const v1::Progress& p) { progress.push_back(p.detail()); }, &comesh);
  ASSERT_TRUE(optimized.ok()) << optimized.status();

  // Sent three times, the retries with resume and the version the first one started from.
  EXPECT_THAT(front_->resumes, ElementsAre(false, true, true));
  EXPECT_THAT(front_->expected_versions, Each(session_.version()));
  EXPECT_THAT(front_->session_ids, Each(session_.id()));
  ASSERT_EQ(retries_.size(), 2u);
  EXPECT_EQ(retries_[0].method, "OptimizeComesh");
  EXPECT_EQ(retries_[0].last_iteration, static_cast<uint32_t>(first_after_pass + 3));
  EXPECT_EQ(retries_[1].status.code(), absl::StatusCode::kInternal);
  // The server resumed from a checkpoint (after pass 1: the second attempt wrote none).
  EXPECT_EQ(optimized->resumed_outer(), 1u);
  EXPECT_GT(optimized->resumed_inner(), 0u);
  EXPECT_EQ(optimized->resumed_inner(), static_cast<uint32_t>(first_after_pass));
  EXPECT_EQ(std::count_if(progress.begin(), progress.end(),
                          [](const std::string& p) {
                            return p.starts_with("resumed after outer 1 at iteration");
                          }),
            2);
  // Each iteration reached on_iter once, in order, equal to the uninterrupted run's.
  ASSERT_EQ(iterations.size(), reference_iterations.size());
  for (size_t i = 0; i < iterations.size(); ++i) {
    EXPECT_TRUE(
        google::protobuf::util::MessageDifferencer::Equals(iterations[i], reference_iterations[i]))
        << "iteration " << i + 1;
  }
  EXPECT_EQ(optimized->inner_iterations(), reference->inner_iterations());
  EXPECT_EQ(optimized->outer_iterations(), reference->outer_iterations());

  // The stored multimesh, fetched after, is the uninterrupted run's, bit for bit.
  auto stored = direct_->GetSession(session_.id(), /*full=*/true);
  auto reference_stored = direct_->GetSession(reference_session.id(), /*full=*/true);
  ASSERT_TRUE(stored.ok() && reference_stored.ok());
  EXPECT_EQ(stored->session().stage(), v1::STAGE_OPTIMIZED);
  EXPECT_EQ(stored->session().version(), optimized->session().version());
  ASSERT_GT(stored->multimesh().shapes_size(), 0);
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(stored->multimesh(),
                                                                 reference_stored->multimesh()));
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(optimized->multimesh(),
                                                                 reference->multimesh()));
  EXPECT_EQ(stored->session().multimesh_stats().map_energy(),
            reference_stored->session().multimesh_stats().map_energy());
}

TEST_F(InbetweenClientFailoverTest, OptimizationIsNotRetriedOnANonTransientError) {
  front_->faults = {{grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "busy"), 0}};
  auto client = FrontClient();
  const v1::ComeshParameters comesh = ShortComesh();
  auto optimized = client->OptimizeComesh(session_, nullptr, nullptr, &comesh);
  EXPECT_EQ(optimized.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(front_->resumes, ElementsAre(false));
  EXPECT_TRUE(retries_.empty());
}

// Refusals by a server limit name the flag: --max-sessions (the store's refusal) and
// --max-message-bytes, which gRPC enforces before any handler with its own text; the client
// translates that (FromGrpcStatus) for a request over the limit and for a reply over it.
TEST(InbetweenClientLimitsTest, RefusalsNameTheServerFlag) {
  server::ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.max_sessions = 1;
  options.max_message_bytes = 4096;
  auto started = server::InbetweenServer::Start(options);
  ASSERT_TRUE(started.ok()) << started.status();
  InbetweenClient client(CreateChannelForServer("127.0.0.1:" + std::to_string((*started)->port()),
                                                grpc::InsecureChannelCredentials()));
  auto session = client.CreateSession("one");
  ASSERT_TRUE(session.ok()) << session.status();

  auto second = client.CreateSession("two");
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(second.status().message(), HasSubstr("maximum of 1 sessions (--max-sessions 1)"));

  v1::PutDrawingRequest request;
  request.set_session_id(session->id());
  request.set_expected_version(session->version());
  request.mutable_drawing()->set_name("big");
  request.mutable_drawing()->set_svg(
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><rect width=\"10\" height=\"10\"/>" +
      std::string(5000, ' ') + "</svg>");
  auto put = client.PutDrawing(request);
  EXPECT_EQ(put.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(put.status().message(), HasSubstr("the request is"));
  EXPECT_THAT(put.status().message(), HasSubstr("over the server's limit of 4096 bytes "
                                                "(inbetween-server --max-message-bytes 4096)"));

  // A small request whose reply (the circle flattened to a few thousand points) is over it.
  request.mutable_drawing()->set_svg(
      "<svg xmlns=\"http://www.w3.org/2000/svg\"><circle r=\"100\"/></svg>");
  request.set_flatten_tolerance(1e-4);
  put = client.PutDrawing(request);
  EXPECT_EQ(put.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(put.status().message(), HasSubstr("the reply is"));
  EXPECT_THAT(put.status().message(), HasSubstr("(inbetween-server --max-message-bytes 4096)"));

  // Other statuses pass unchanged.
  const grpc::Status other(grpc::StatusCode::RESOURCE_EXHAUSTED, "frames = 9 exceeds 8");
  EXPECT_EQ(FromGrpcStatus(other).message(), "frames = 9 exceeds 8");
}

// A reason the service attaches (status details: a google.rpc.ErrorInfo) comes back as the
// status's reason, through a real server: a drawing whose topology differs from the other's.
TEST(InbetweenClientReasonsTest, TheServicesReasonReachesTheClient) {
  const absl::Status sent = solver::WithReason(absl::ResourceExhaustedError("busy"),
                                               solver::kReasonHeavyJobsPerToken);
  const absl::Status back = FromGrpcStatus(server::ToGrpcStatus(sent));
  EXPECT_EQ(back.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(back.message(), "busy");
  EXPECT_EQ(solver::ErrorReason(back), solver::kReasonHeavyJobsPerToken);
  EXPECT_EQ(solver::ErrorReason(FromGrpcStatus(server::ToGrpcStatus(absl::InternalError("x")))),
            "");
  // The offending field and the retry delay come back too.
  const absl::Status field = FromGrpcStatus(
      server::ToGrpcStatus(absl::InvalidArgumentError("parameters.frames = 1 is not in [2, 9]")));
  EXPECT_EQ(solver::ErrorField(field), "parameters.frames");
  const absl::Status retry =
      FromGrpcStatus(server::ToGrpcStatus(solver::WithRetryAfter(sent, 2000)));
  EXPECT_EQ(solver::RetryAfterMs(retry), 2000);
  EXPECT_EQ(solver::ErrorReason(retry), solver::kReasonHeavyJobsPerToken);
  // Details that are not ours are ignored.
  EXPECT_EQ(solver::ErrorReason(FromGrpcStatus(
                grpc::Status(grpc::StatusCode::INTERNAL, "x", std::string("\xff\x01garbage")))),
            "");

  server::ServerOptions options;
  options.listen = "127.0.0.1:0";
  auto started = server::InbetweenServer::Start(options);
  ASSERT_TRUE(started.ok()) << started.status();
  InbetweenClient client(CreateChannelForServer("127.0.0.1:" + std::to_string((*started)->port()),
                                                grpc::InsecureChannelCredentials()));
  auto session = client.CreateSession("topology");
  ASSERT_TRUE(session.ok()) << session.status();
  const std::string disc =
      R"(<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 H10 V10 H0 Z"/></svg>)";
  const std::string ring =
      R"(<svg xmlns="http://www.w3.org/2000/svg"><path fill-rule="evenodd" )"
      R"(d="M0 0 H10 V10 H0 Z M3 3 H7 V7 H3 Z"/></svg>)";
  v1::Session current = *session;
  for (const std::string& svg : {disc, ring}) {
    v1::PutDrawingRequest request;
    request.set_session_id(current.id());
    request.set_expected_version(current.version());
    request.mutable_drawing()->set_svg(svg);
    auto put = client.PutDrawing(request);
    ASSERT_TRUE(put.ok()) << put.status();
    current = put->session();
  }
  auto built = client.BuildMultimesh(current, nullptr);
  ASSERT_FALSE(built.ok());
  EXPECT_EQ(solver::ErrorReason(built.status()), solver::kReasonTopologyDiffers) << built.status();
}

}  // namespace
}  // namespace inbetween::client
