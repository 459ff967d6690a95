// Runs the bad-input catalogue (tests/data/bad/*.json, docs/bad-input.md) against a live
// inbetween-server while a healthy session of the same server keeps streaming frames.
//
// Each case: an optional setup (a session in some stage), then steps; a step sends one RPC whose
// request is written in the proto's JSON mapping (placeholders ${session}, ${version},
// ${stale_version}, ${svg:NAME}) or made by a named generator (huge inputs), and expects a gRPC
// status code plus a fragment of its message. After every case the server must still answer and
// the healthy session must be untouched; the frames streamed by the healthy session during the
// whole catalogue must equal, bit for bit, the frames of the same job run alone before it.
//
// Usage: bad_input_runner --server HOST:PORT --token T --other-token T2 --healthy-token T3
//                         --cases DIR --examples DIR [--only NAME] [--deadline-seconds S]
// (S: each call's deadline unless its step sets deadline_ms; 60 by default, longer for the
// sanitizer builds, whose server runs several times slower)
#include <grpcpp/create_channel.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/impl/codegen/client_unary_call.h>
#include <grpcpp/impl/codegen/sync_stream.h>
#include <grpcpp/support/byte_buffer.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "google/protobuf/util/json_util.h"
#include "inbetween/v1/inbetween.grpc.pb.h"
#include "nlohmann/json.hpp"

namespace {

namespace v1 = ::inbetween::v1;
namespace fs = std::filesystem;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

struct Config {
  std::string server, token, other_token, healthy_token, cases, examples, only;
  int deadline_seconds = 60;
};

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void ReplaceAll(std::string* s, const std::string& from, const std::string& to) {
  for (size_t pos = 0; (pos = s->find(from, pos)) != std::string::npos; pos += to.size()) {
    s->replace(pos, from.size(), to);
  }
}

// JSON string escaping for text substituted into a JSON document.
std::string JsonQuoted(const std::string& text) { return json(text).dump(); }

std::string CodeName(grpc::StatusCode code) {
  static const std::map<grpc::StatusCode, std::string> names = {
      {grpc::OK, "OK"},
      {grpc::CANCELLED, "CANCELLED"},
      {grpc::UNKNOWN, "UNKNOWN"},
      {grpc::INVALID_ARGUMENT, "INVALID_ARGUMENT"},
      {grpc::DEADLINE_EXCEEDED, "DEADLINE_EXCEEDED"},
      {grpc::NOT_FOUND, "NOT_FOUND"},
      {grpc::ALREADY_EXISTS, "ALREADY_EXISTS"},
      {grpc::PERMISSION_DENIED, "PERMISSION_DENIED"},
      {grpc::UNAUTHENTICATED, "UNAUTHENTICATED"},
      {grpc::RESOURCE_EXHAUSTED, "RESOURCE_EXHAUSTED"},
      {grpc::FAILED_PRECONDITION, "FAILED_PRECONDITION"},
      {grpc::ABORTED, "ABORTED"},
      {grpc::OUT_OF_RANGE, "OUT_OF_RANGE"},
      {grpc::UNIMPLEMENTED, "UNIMPLEMENTED"},
      {grpc::INTERNAL, "INTERNAL"},
      {grpc::UNAVAILABLE, "UNAVAILABLE"},
      {grpc::DATA_LOSS, "DATA_LOSS"},
  };
  auto it = names.find(code);
  return it == names.end() ? "CODE_" + std::to_string(code) : it->second;
}

// ---------------------------------------------------------------------------------------------
// Generators for inputs too large (or too binary) to write in a case file.

// A closed regular polygon of n points (an outline with positive area, y down).
void FillCircle(int64_t n, double radius, v1::Polyline* polyline) {
  polyline->mutable_points()->Reserve(static_cast<int>(n));
  for (int64_t i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    v1::Point* p = polyline->add_points();
    p->set_x(radius * std::cos(a));
    p->set_y(radius * std::sin(a));
  }
}

// Appends a protobuf varint.
void PutVarint(uint64_t v, std::string* out) {
  while (v >= 0x80) {
    out->push_back(static_cast<char>(v | 0x80));
    v >>= 7;
  }
  out->push_back(static_cast<char>(v));
}
void PutTag(int field, int wire_type, std::string* out) {
  PutVarint((field << 3) | wire_type, out);
}
void PutBytesField(int field, const std::string& bytes, std::string* out) {
  PutTag(field, 2, out);
  PutVarint(bytes.size(), out);
  out->append(bytes);
}

// PutDrawingRequest{session_id, expected_version, drawing{polylines{elements{kind OUTLINE,
// polyline{n points}}}}} serialized directly: building 10M Point messages would take ~1 GB.
std::string RawHugePolylineRequest(const std::string& session, uint64_t version, int64_t n) {
  std::string points;
  points.reserve(static_cast<size_t>(n) * 20);
  for (int64_t i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    const double x = 1000 * std::cos(a), y = 1000 * std::sin(a);
    points.push_back(static_cast<char>((1 << 3) | 2));  // Polyline.points
    points.push_back(18);                               // two fixed64 fields
    points.push_back(static_cast<char>((1 << 3) | 1));
    points.append(reinterpret_cast<const char*>(&x), 8);
    points.push_back(static_cast<char>((2 << 3) | 1));
    points.append(reinterpret_cast<const char*>(&y), 8);
  }
  std::string polyline;
  PutBytesField(1, points, &polyline);  // wrapped below as TopologyElement.polyline = 3
  points.clear();
  points.shrink_to_fit();
  std::string element;
  PutTag(2, 0, &element);
  PutVarint(v1::ELEMENT_KIND_OUTLINE, &element);
  PutBytesField(3, polyline.substr(0), &element);
  polyline.clear();
  std::string polylines;
  PutBytesField(1, element, &polylines);
  element.clear();
  std::string drawing;
  PutBytesField(4, polylines, &drawing);
  polylines.clear();
  std::string request;
  PutBytesField(1, session, &request);
  PutTag(2, 0, &request);
  PutVarint(version, &request);
  PutBytesField(3, drawing, &request);
  return request;
}

std::string SvgNestedGroups(int depth) {
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\">";
  for (int i = 0; i < depth; ++i) s += "<g>";
  s += "<rect x=\"0\" y=\"0\" width=\"10\" height=\"10\"/>";
  for (int i = 0; i < depth; ++i) s += "</g>";
  return s + "</svg>";
}

std::string SvgHugeAttribute(size_t bytes) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\"><rect x=\"0\" y=\"0\" width=\"10\" "
         "height=\"10\" class=\"" +
         std::string(bytes, 'a') + "\"/></svg>";
}

std::string SvgHugePath(size_t commands) {
  std::string d = "M0 0";
  d.reserve(commands * 6);
  for (size_t i = 0; i < commands; ++i) d += (i % 2 == 0) ? " h1" : " v1";
  return "<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"" + d + " z\"/></svg>";
}

// A few hundred bytes that flatten to millions of points: huge circles, tiny tolerance.
std::string SvgFlattenBomb(int circles, double radius) {
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\">";
  for (int i = 0; i < circles; ++i) {
    s += "<circle cx=\"" + std::to_string(3 * radius * i) + "\" cy=\"0\" r=\"" +
         std::to_string(radius) + "\"/>";
  }
  return s + "</svg>";
}

// `layers` painted layers: small squares on a grid, each drawn over its neighbours (a layered
// drawing: every one is an art layer and the union has work to do).
std::string SvgManyLayers(int layers) {
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\">";
  s.reserve(static_cast<size_t>(layers) * 44 + 64);
  for (int i = 0; i < layers; ++i) {
    s += "<rect x=\"" + std::to_string(i % 1000) + "\" y=\"" + std::to_string(i / 1000) +
         "\" width=\"2\" height=\"2\"/>";
  }
  return s + "</svg>";
}

// <use> fan-out: level k holds `fanout` uses of level k-1 (fanout^levels copies of one rect).
std::string SvgUseBomb(int levels, int fanout) {
  std::string s =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">"
      "<defs><rect id=\"l0\" x=\"0\" y=\"0\" width=\"1\" height=\"1\"/>";
  for (int k = 1; k <= levels; ++k) {
    s += "<g id=\"l" + std::to_string(k) + "\">";
    for (int j = 0; j < fanout; ++j) s += "<use href=\"#l" + std::to_string(k - 1) + "\"/>";
    s += "</g>";
  }
  return s + "</defs><use href=\"#l" + std::to_string(levels) + "\"/></svg>";
}

// ---------------------------------------------------------------------------------------------

class Runner {
 public:
  explicit Runner(Config config) : config_(std::move(config)) {
    grpc::ChannelArguments args;
    args.SetMaxSendMessageSize(-1);
    args.SetMaxReceiveMessageSize(-1);
    channel_ = grpc::CreateCustomChannel(config_.server, grpc::InsecureChannelCredentials(), args);
    stub_ = v1::Inbetween::NewStub(channel_);
    for (const char* name : {"square", "hexagon"}) {
      svgs_[name] =
          ReadFile(fs::path(config_.examples) / "square_hexagon" / (std::string(name) + ".svg"));
    }
  }

  int Run();

 private:
  struct Session {
    std::string id;
    uint64_t version = 0;
  };

  std::unique_ptr<grpc::ClientContext> Context(const std::string& who,
                                               const std::string& session = "") {
    auto ctx = std::make_unique<grpc::ClientContext>();
    const std::string& token = who == "other"     ? config_.other_token
                               : who == "healthy" ? config_.healthy_token
                                                  : config_.token;
    if (who == "bogus") {
      ctx->AddMetadata("authorization", "Bearer not-a-token");
    } else if (who != "none") {
      ctx->AddMetadata("authorization", "Bearer " + token);
    }
    if (!session.empty()) ctx->AddMetadata("x-session-id", session);
    ctx->set_deadline(std::chrono::system_clock::now() +
                      std::chrono::seconds(config_.deadline_seconds));
    return ctx;
  }

  // Setup stages: none | empty | one_drawing | two_drawings | meshed.
  Session Setup(const std::string& stage, const std::string& who);
  void Check(const grpc::Status& s, const std::string& what) {
    if (!s.ok()) {
      throw std::runtime_error(what + " failed: " + CodeName(s.error_code()) + ": " +
                               s.error_message());
    }
  }
  uint64_t Version(const std::string& session, const std::string& who = "main") {
    v1::GetSessionRequest req;
    req.set_session_id(session);
    v1::GetSessionResponse resp;
    auto ctx = Context(who, session);
    Check(stub_->GetSession(ctx.get(), req, &resp), "GetSession");
    return resp.session().version();
  }
  std::string Substitute(std::string text, const Session& s) {
    ReplaceAll(&text, "${session}", s.id);
    ReplaceAll(&text, "\"${version}\"", std::to_string(s.version));
    ReplaceAll(&text, "\"${stale_version}\"", std::to_string(s.version + 7));
    for (const auto& [name, svg] : svgs_)
      ReplaceAll(&text, "\"${svg:" + name + "}\"", JsonQuoted(svg));
    return text;
  }
  template <typename Message>
  void ParseInto(const json& request, const Session& s, Message* out) {
    const std::string text = Substitute(request.dump(), s);
    auto status = google::protobuf::util::JsonStringToMessage(text, out);
    if (!status.ok()) throw std::runtime_error("bad request JSON in case: " + status.ToString());
  }
  void ApplyGenerator(const json& gen, const Session& s, v1::PutDrawingRequest* req);

  // One step; returns the status. `replies` counts the stream messages received.
  grpc::Status RunStep(const json& step, Session* s, int* replies, std::string* note);
  grpc::Status RunRaw(const std::string& method, const std::string& bytes, bool server_stream,
                      const std::string& who, const std::string& session, int* replies);
  grpc::Status RunConcurrent(const json& step, Session* s, std::string* note);

  // The healthy job: Inbetween on a meshed session, every frame serialized.
  std::vector<std::string> HealthyFrames(const std::string& session, grpc::Status* status);

  Config config_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Inbetween::Stub> stub_;
  std::map<std::string, std::string> svgs_;
};

Runner::Session Runner::Setup(const std::string& stage, const std::string& who) {
  Session s;
  if (stage == "none") return s;
  {
    v1::CreateSessionRequest req;
    req.set_display_name("bad-input case");
    v1::CreateSessionResponse resp;
    auto ctx = Context(who);
    Check(stub_->CreateSession(ctx.get(), req, &resp), "setup CreateSession");
    s.id = resp.session().id();
    s.version = resp.session().version();
  }
  if (stage == "empty") return s;
  std::vector<std::string> names = {"square"};
  if (stage != "one_drawing") names.push_back("hexagon");
  for (const std::string& name : names) {
    v1::PutDrawingRequest req;
    req.set_session_id(s.id);
    req.set_expected_version(s.version);
    req.mutable_drawing()->set_name(name + ".svg");
    req.mutable_drawing()->set_svg(svgs_[name]);
    v1::PutDrawingResponse resp;
    auto ctx = Context(who, s.id);
    Check(stub_->PutDrawing(ctx.get(), req, &resp), "setup PutDrawing");
    s.version = resp.session().version();
  }
  if (stage == "one_drawing" || stage == "two_drawings") return s;
  if (stage != "meshed") throw std::runtime_error("unknown setup " + stage);
  v1::BuildMultimeshRequest req;
  req.set_session_id(s.id);
  req.set_expected_version(s.version);
  auto ctx = Context(who, s.id);
  auto reader = stub_->BuildMultimesh(ctx.get(), req);
  v1::BuildMultimeshResponse resp;
  while (reader->Read(&resp)) {
    if (resp.has_result()) s.version = resp.result().session().version();
  }
  Check(reader->Finish(), "setup BuildMultimesh");
  return s;
}

void Runner::ApplyGenerator(const json& gen, const Session& s, v1::PutDrawingRequest* req) {
  const std::string name = gen.at("name");
  v1::Drawing* d = req->mutable_drawing();
  if (name == "polyline_circle") {
    v1::TopologyElement* e = d->mutable_polylines()->add_elements();
    e->set_kind(v1::ELEMENT_KIND_OUTLINE);
    FillCircle(gen.at("points").get<int64_t>(), 1000, e->mutable_polyline());
  } else if (name == "polyline_comb") {
    // A simple polygon whose teeth are long parallel segments: the crossing checks' sweep sees
    // every pair of teeth overlap (O(n^2) without a bound).
    v1::TopologyElement* e = d->mutable_polylines()->add_elements();
    e->set_kind(v1::ELEMENT_KIND_OUTLINE);
    const int teeth = gen.at("teeth");
    auto add = [&](double x, double y) {
      v1::Point* p = e->mutable_polyline()->add_points();
      p->set_x(x);
      p->set_y(y);
    };
    // Walked so that the signed area is positive (y down).
    add(0, 0);
    for (int k = 0; k < teeth; ++k) {
      add(1000, 2.0 * k);
      add(1000, 2.0 * k + 1);
      add(1, 2.0 * k + 1);
      add(1, 2.0 * k + 2);
    }
    add(0, 2.0 * teeth);
  } else if (name == "svg_nested_groups") {
    d->set_svg(SvgNestedGroups(gen.at("depth")));
  } else if (name == "svg_huge_attribute") {
    d->set_svg(SvgHugeAttribute(gen.at("bytes")));
  } else if (name == "svg_huge_path") {
    d->set_svg(SvgHugePath(gen.at("commands")));
  } else if (name == "svg_flatten_bomb") {
    d->set_svg(SvgFlattenBomb(gen.at("circles"), gen.at("radius")));
  } else if (name == "svg_many_layers") {
    d->set_svg(SvgManyLayers(gen.at("layers")));
  } else if (name == "svg_use_bomb") {
    d->set_svg(SvgUseBomb(gen.at("levels"), gen.at("fanout")));
  } else if (name == "long_name") {
    d->set_name(std::string(gen.at("bytes").get<size_t>(), 'n'));
  } else {
    throw std::runtime_error("unknown generator " + name);
  }
}

grpc::Status Runner::RunRaw(const std::string& method, const std::string& bytes, bool server_stream,
                            const std::string& who, const std::string& session, int* replies) {
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1);
  auto ctx = Context(who, session);
  const std::string path = "/inbetween.v1.Inbetween/" + method;
  if (!server_stream) {
    grpc::ByteBuffer response;
    grpc::internal::RpcMethod rpc(path.c_str(), grpc::internal::RpcMethod::NORMAL_RPC);
    grpc::Status st = grpc::internal::BlockingUnaryCall<grpc::ByteBuffer, grpc::ByteBuffer>(
        channel_.get(), rpc, ctx.get(), request, &response);
    if (st.ok()) ++*replies;
    return st;
  }
  grpc::internal::RpcMethod rpc(path.c_str(), grpc::internal::RpcMethod::SERVER_STREAMING);
  std::unique_ptr<grpc::ClientReader<grpc::ByteBuffer>> reader(
      grpc::internal::ClientReaderFactory<grpc::ByteBuffer>::Create(channel_.get(), rpc, ctx.get(),
                                                                    request));
  grpc::ByteBuffer response;
  while (reader->Read(&response)) ++*replies;
  return reader->Finish();
}

// Sends the same mutation `count` times at once; exactly one may win, the rest are ABORTED.
grpc::Status Runner::RunConcurrent(const json& step, Session* s, std::string* note) {
  const int count = step.value("count", 8);
  v1::PutDrawingRequest req;
  ParseInto(step.at("request"), *s, &req);
  std::vector<grpc::Status> results(count);
  std::vector<std::thread> threads;
  std::atomic<bool> go{false};
  for (int i = 0; i < count; ++i) {
    threads.emplace_back([&, i] {
      while (!go.load()) std::this_thread::yield();
      v1::PutDrawingResponse resp;
      auto ctx = Context("main", s->id);
      results[i] = stub_->PutDrawing(ctx.get(), req, &resp);
    });
  }
  go = true;
  for (std::thread& t : threads) t.join();
  int ok = 0;
  grpc::Status other;
  for (const grpc::Status& r : results) {
    if (r.ok()) {
      ++ok;
    } else {
      other = r;
    }
  }
  const uint64_t version = Version(s->id);
  *note = std::to_string(ok) + " of " + std::to_string(count) + " won, version " +
          std::to_string(s->version) + " -> " + std::to_string(version);
  if (ok != 1 || version != s->version + 1) {
    return grpc::Status(grpc::INTERNAL,
                        "concurrent edits: expected exactly one winner and one "
                        "version step, got " +
                            *note);
  }
  s->version = version;
  return other;  // every loser's status (the last one); the case names the expected code
}

grpc::Status Runner::RunStep(const json& step, Session* s, int* replies, std::string* note) {
  const std::string rpc = step.at("rpc");
  const std::string who = step.value("token", "main");
  const std::string session = step.value("session_header", true) ? s->id : "";
  *replies = 0;
  if (step.contains("concurrent")) return RunConcurrent(step, s, note);

  if (step.contains("raw")) {  // serialized request, possibly truncated or generated
    const json& raw = step.at("raw");
    std::string bytes;
    bool server_stream = rpc == "Inbetween" || rpc == "BuildMultimesh" || rpc == "OptimizeComesh";
    if (raw.contains("huge_polyline_points")) {
      bytes = RawHugePolylineRequest(s->id, s->version, raw.at("huge_polyline_points"));
    } else {
      std::unique_ptr<google::protobuf::Message> msg;
      if (rpc == "PutDrawing") msg = std::make_unique<v1::PutDrawingRequest>();
      if (rpc == "Inbetween") msg = std::make_unique<v1::InbetweenRequest>();
      if (rpc == "CreateSession") msg = std::make_unique<v1::CreateSessionRequest>();
      if (rpc == "ImportSession") msg = std::make_unique<v1::ImportSessionRequest>();
      if (!msg) throw std::runtime_error("raw: unsupported rpc " + rpc);
      const std::string text = Substitute(step.at("request").dump(), *s);
      auto st = google::protobuf::util::JsonStringToMessage(text, msg.get());
      if (!st.ok()) throw std::runtime_error("bad request JSON: " + st.ToString());
      bytes = msg->SerializeAsString();
      if (raw.contains("truncate")) bytes.resize(bytes.size() - raw.at("truncate").get<size_t>());
      if (raw.contains("append_hex")) {
        const std::string hex = raw.at("append_hex");
        for (size_t i = 0; i + 1 < hex.size(); i += 2) {
          bytes.push_back(static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16)));
        }
      }
    }
    return RunRaw(rpc, bytes, server_stream, who, session, replies);
  }

  const json request = step.value("request", json::object());
  if (rpc == "CreateSession") {
    v1::CreateSessionRequest req;
    ParseInto(request, *s, &req);
    v1::CreateSessionResponse resp;
    auto ctx = Context(who);
    grpc::Status st = stub_->CreateSession(ctx.get(), req, &resp);
    if (st.ok()) ++*replies;
    return st;
  }
  if (rpc == "GetSession") {
    v1::GetSessionRequest req;
    ParseInto(request, *s, &req);
    v1::GetSessionResponse resp;
    auto ctx = Context(who, session);
    return stub_->GetSession(ctx.get(), req, &resp);
  }
  if (rpc == "DeleteSession") {
    v1::DeleteSessionRequest req;
    ParseInto(request, *s, &req);
    v1::DeleteSessionResponse resp;
    auto ctx = Context(who, session);
    return stub_->DeleteSession(ctx.get(), req, &resp);
  }
  if (rpc == "ListSessions") {
    v1::ListSessionsRequest req;
    ParseInto(request, *s, &req);
    v1::ListSessionsResponse resp;
    auto ctx = Context(who);
    grpc::Status st = stub_->ListSessions(ctx.get(), req, &resp);
    *replies = resp.sessions_size();
    return st;
  }
  if (rpc == "ImportSession") {
    v1::ImportSessionRequest req;
    ParseInto(request, *s, &req);
    v1::ImportSessionResponse resp;
    auto ctx = Context(who);
    return stub_->ImportSession(ctx.get(), req, &resp);
  }
  if (rpc == "PutDrawing") {
    v1::PutDrawingRequest req;
    ParseInto(request, *s, &req);
    if (step.contains("generate")) ApplyGenerator(step.at("generate"), *s, &req);
    v1::PutDrawingResponse resp;
    auto ctx = Context(who, session);
    grpc::Status st = stub_->PutDrawing(ctx.get(), req, &resp);
    if (st.ok()) {
      s->version = resp.session().version();
      *note = "class " + std::to_string(resp.equivalence_class().components()) + " components " +
              std::to_string(resp.equivalence_class().holes()) + " holes";
    }
    return st;
  }
  if (rpc == "RemoveDrawing") {
    v1::RemoveDrawingRequest req;
    ParseInto(request, *s, &req);
    v1::RemoveDrawingResponse resp;
    auto ctx = Context(who, session);
    grpc::Status st = stub_->RemoveDrawing(ctx.get(), req, &resp);
    if (st.ok()) s->version = resp.session().version();
    return st;
  }
  if (rpc == "SetCorrespondences") {
    v1::SetCorrespondencesRequest req;
    ParseInto(request, *s, &req);
    v1::SetCorrespondencesResponse resp;
    auto ctx = Context(who, session);
    grpc::Status st = stub_->SetCorrespondences(ctx.get(), req, &resp);
    if (st.ok()) s->version = resp.session().version();
    return st;
  }
  if (rpc == "EditTopology") {
    auto ctx = Context(who, session);
    auto stream = stub_->EditTopology(ctx.get());
    v1::TopologyState state;
    for (const json& edit_json : step.at("edits")) {
      Session current = *s;
      v1::TopologyEdit edit;
      ParseInto(edit_json, current, &edit);
      if (!stream->Write(edit)) break;
      if (!stream->Read(&state)) break;
      ++*replies;
      s->version = state.version();
      for (const std::string& w : state.warnings()) *note += "warning: " + w + "; ";
    }
    stream->WritesDone();
    while (stream->Read(&state)) ++*replies;
    return stream->Finish();
  }
  if (rpc == "BuildMultimesh" || rpc == "OptimizeComesh" || rpc == "Inbetween") {
    auto ctx = Context(who, session);
    if (step.contains("deadline_ms")) {
      ctx->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::milliseconds(step.at("deadline_ms").get<int>()));
    }
    const int cancel_after = step.value("cancel_after", -1);
    const int abandon_after = step.value("abandon_after", -1);
    auto drive = [&](auto reader, auto response) -> grpc::Status {
      while (reader->Read(&response)) {
        ++*replies;
        if (*replies == cancel_after) ctx->TryCancel();
        if (*replies == abandon_after) {
          // Drop the call without Finish or cancel: the reader and the context go away as a
          // client that crashed mid-stream would leave them.
          reader.reset();
          ctx.reset();
          return grpc::Status(grpc::CANCELLED, "abandoned by the client");
        }
      }
      return reader->Finish();
    };
    if (rpc == "BuildMultimesh") {
      v1::BuildMultimeshRequest req;
      ParseInto(request, *s, &req);
      return drive(stub_->BuildMultimesh(ctx.get(), req), v1::BuildMultimeshResponse());
    }
    if (rpc == "OptimizeComesh") {
      v1::OptimizeComeshRequest req;
      ParseInto(request, *s, &req);
      return drive(stub_->OptimizeComesh(ctx.get(), req), v1::OptimizeComeshResponse());
    }
    v1::InbetweenRequest req;
    ParseInto(request, *s, &req);
    return drive(stub_->Inbetween(ctx.get(), req), v1::InbetweenResponse());
  }
  throw std::runtime_error("unknown rpc " + rpc);
}

std::vector<std::string> Runner::HealthyFrames(const std::string& session, grpc::Status* status) {
  v1::InbetweenRequest req;
  req.set_session_id(session);
  req.mutable_parameters()->set_frames(48);
  auto ctx = Context("healthy", session);
  auto reader = stub_->Inbetween(ctx.get(), req);
  std::vector<std::string> frames;
  v1::InbetweenResponse resp;
  while (reader->Read(&resp)) {
    if (resp.has_frame()) {
      v1::InbetweenFrame frame = resp.frame();
      frame.mutable_stats()->clear_seconds();  // wall-clock, not part of the result
      frames.push_back(frame.SerializeAsString());
    } else if (resp.has_header()) {
      frames.push_back(resp.header().SerializeAsString());
    }
  }
  *status = reader->Finish();
  return frames;
}

int Runner::Run() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(config_.cases)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());

  // The healthy session, run alone first for the reference frames.
  const Session healthy = Setup("meshed", "healthy");
  grpc::Status st;
  const std::vector<std::string> reference = HealthyFrames(healthy.id, &st);
  Check(st, "healthy Inbetween (alone)");
  std::cout << "healthy session " << healthy.id << ": " << reference.size() - 1
            << " frames alone\n";

  std::atomic<bool> done{false};
  std::atomic<int> healthy_runs{0};
  std::string healthy_error;
  std::thread streamer([&] {
    while (!done.load()) {
      grpc::Status s;
      std::vector<std::string> frames = HealthyFrames(healthy.id, &s);
      if (!s.ok()) {
        healthy_error =
            "healthy stream failed: " + CodeName(s.error_code()) + ": " + s.error_message();
        return;
      }
      if (frames != reference) {
        healthy_error = "healthy stream: frames differ from the run alone";
        return;
      }
      ++healthy_runs;
    }
  });

  int failures = 0, ran = 0;
  for (const fs::path& file : files) {
    const std::string name = file.stem().string();
    if (!config_.only.empty() && name != config_.only) continue;
    ++ran;
    const auto start = Clock::now();
    std::string result = "ok";
    try {
      const json c = json::parse(ReadFile(file));
      Session s = Setup(c.value("setup", "empty"), c.value("setup_token", "main"));
      for (size_t i = 0; i < c.at("steps").size(); ++i) {
        const json& step = c.at("steps")[i];
        int replies = 0;
        std::string note;
        const grpc::Status got = RunStep(step, &s, &replies, &note);
        const json& expect = step.at("expect");
        const std::string want_code = expect.at("code");
        const std::string want_msg = expect.value("message", "");
        std::string got_msg = got.error_message();
        std::string lower_got = got_msg, lower_want = want_msg;
        std::transform(lower_got.begin(), lower_got.end(), lower_got.begin(), ::tolower);
        std::transform(lower_want.begin(), lower_want.end(), lower_want.begin(), ::tolower);
        const bool code_ok = want_code == "ANY" || CodeName(got.error_code()) == want_code;
        const bool msg_ok = lower_got.find(lower_want) != std::string::npos;
        if (expect.contains("note") && note != expect.at("note").get<std::string>()) {
          result = "FAIL step " + std::to_string(i + 1) + ": got [" + note + "], want [" +
                   expect.at("note").get<std::string>() + "]";
          break;
        }
        const bool replies_ok =
            !expect.contains("min_replies") || replies >= expect.at("min_replies").get<int>();
        if (!code_ok || !msg_ok || !replies_ok) {
          result = "FAIL step " + std::to_string(i + 1) + " (" + step.at("rpc").get<std::string>() +
                   "): got " + CodeName(got.error_code()) + " \"" + got_msg + "\" after " +
                   std::to_string(replies) + " replies, want " + want_code + " \"" + want_msg +
                   "\"" + (note.empty() ? "" : " [" + note + "]");
          break;
        }
        if (!note.empty()) result = "ok [" + note + "]";
      }
      // The server still answers, and the case's session (if any) is still readable.
      if (!s.id.empty() && c.value("setup_token", "main") == "main" &&
          !c.value("deletes_session", false)) {
        Version(s.id);
      }
      if (Version(healthy.id, "healthy") != healthy.version) {
        result = "FAIL: the healthy session's version changed";
      }
    } catch (const std::exception& e) {
      result = std::string("FAIL: ") + e.what();
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    if (result.rfind("FAIL", 0) == 0) ++failures;
    std::cout << (result.rfind("FAIL", 0) == 0 ? "FAIL " : "ok   ") << name << " ("
              << static_cast<int>(ms) << " ms)" << (result == "ok" ? "" : ": " + result)
              << std::endl;
  }
  // Let the healthy stream finish at least one full run overlapping the catalogue.
  while (healthy_runs.load() == 0 && healthy_error.empty()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  done = true;
  streamer.join();
  if (!healthy_error.empty()) {
    std::cout << "FAIL " << healthy_error << "\n";
    ++failures;
  }
  std::cout << ran << " cases, " << failures << " failed; healthy session streamed "
            << healthy_runs.load() << " identical runs of " << reference.size() - 1
            << " frames meanwhile\n";
  if (ran < 1) return 1;
  return failures == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Config config;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--server")
      config.server = value;
    else if (flag == "--token")
      config.token = value;
    else if (flag == "--other-token")
      config.other_token = value;
    else if (flag == "--healthy-token")
      config.healthy_token = value;
    else if (flag == "--cases")
      config.cases = value;
    else if (flag == "--examples")
      config.examples = value;
    else if (flag == "--only")
      config.only = value;
    else if (flag == "--deadline-seconds")
      config.deadline_seconds = std::stoi(value);
    else {
      std::cerr << "bad_input_runner: unknown flag " << flag << "\n";
      return 2;
    }
  }
  if (config.server.empty() || config.cases.empty() || config.examples.empty()) {
    std::cerr << "usage: bad_input_runner --server HOST:PORT --token T --other-token T2 "
                 "--healthy-token T3 --cases DIR --examples DIR [--only NAME] "
                 "[--deadline-seconds S]\n";
    return 2;
  }
  try {
    return Runner(config).Run();
  } catch (const std::exception& e) {
    std::cerr << "bad_input_runner: " << e.what() << "\n";
    return 1;
  }
}
