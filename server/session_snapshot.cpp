// Snapshot encoding. The parsed solver drawings are rebuilt from the stored elements, marks and
// art (they are the same numbers), the multimesh from the archive plus its loops and closed
// cohesive edges.
#include "server/session_snapshot.h"

#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "server/drawing_import.h"
#include "server/proto_convert.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;

constexpr absl::string_view kMagic = "INBSNAP1";
constexpr absl::string_view kEnd = "INBSEND1";
constexpr absl::string_view kCheckpoint = "INBCKPT1";
constexpr absl::string_view kCheckpointEnd = "INBCKEND";
constexpr absl::string_view kCheckpointStage = "INBCKST1";

void PutU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void PutU64(std::string& out, uint64_t v) {
  PutU32(out, static_cast<uint32_t>(v & 0xffffffffu));
  PutU32(out, static_cast<uint32_t>(v >> 32));
}

void PutF64(std::string& out, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  PutU64(out, bits);
}

void PutBytes(std::string& out, absl::string_view bytes) {
  PutU32(out, static_cast<uint32_t>(bytes.size()));
  out.append(bytes.data(), bytes.size());
}

void PutLists(std::string& out, const std::vector<std::vector<int>>& lists) {
  PutU32(out, static_cast<uint32_t>(lists.size()));
  for (const std::vector<int>& list : lists) {
    PutU32(out, static_cast<uint32_t>(list.size()));
    for (int v : list) PutU32(out, static_cast<uint32_t>(v));
  }
}

class Reader {
 public:
  Reader(absl::string_view bytes, absl::string_view where) : bytes_(bytes), where_(where) {}

  absl::Status Expect(absl::string_view magic) {
    if (bytes_.substr(at_, magic.size()) != magic) return Error("bad marker");
    at_ += magic.size();
    return absl::OkStatus();
  }
  absl::StatusOr<uint32_t> U32() {
    if (bytes_.size() - at_ < 4) return Error("truncated");
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
      v |= static_cast<uint32_t>(static_cast<unsigned char>(bytes_[at_ + i])) << (8 * i);
    at_ += 4;
    return v;
  }
  absl::StatusOr<uint64_t> U64() {
    absl::StatusOr<uint32_t> low = U32();
    if (!low.ok()) return low.status();
    absl::StatusOr<uint32_t> high = U32();
    if (!high.ok()) return high.status();
    return static_cast<uint64_t>(*high) << 32 | *low;
  }
  absl::StatusOr<double> F64() {
    absl::StatusOr<uint64_t> bits = U64();
    if (!bits.ok()) return bits.status();
    double v;
    std::memcpy(&v, &*bits, sizeof v);
    return v;
  }
  absl::StatusOr<int> Int() {
    absl::StatusOr<uint32_t> v = U32();
    if (!v.ok()) return v.status();
    if (*v > static_cast<uint32_t>(std::numeric_limits<int>::max())) return Error("bad count");
    return static_cast<int>(*v);
  }
  // Skips `magic` if the bytes continue with it.
  bool Consume(absl::string_view magic) {
    if (bytes_.substr(at_, magic.size()) != magic) return false;
    at_ += magic.size();
    return true;
  }
  absl::StatusOr<absl::string_view> Bytes() {
    absl::StatusOr<uint32_t> n = U32();
    if (!n.ok()) return n.status();
    if (bytes_.size() - at_ < *n) return Error("truncated");
    absl::string_view out = bytes_.substr(at_, *n);
    at_ += *n;
    return out;
  }
  absl::StatusOr<std::vector<std::vector<int>>> Lists(uint32_t max_value) {
    absl::StatusOr<uint32_t> count = U32();
    if (!count.ok()) return count.status();
    if (*count > bytes_.size()) return Error("bad list count");
    std::vector<std::vector<int>> lists(*count);
    for (std::vector<int>& list : lists) {
      absl::StatusOr<uint32_t> n = U32();
      if (!n.ok()) return n.status();
      if (*n > (bytes_.size() - at_) / 4) return Error("truncated list");
      list.resize(*n);
      for (int& v : list) {
        absl::StatusOr<uint32_t> x = U32();
        if (!x.ok()) return x.status();
        if (*x >= max_value) return Error("index out of range");
        v = static_cast<int>(*x);
      }
    }
    return lists;
  }
  absl::Status Error(absl::string_view what) const {
    return absl::DataLossError(
        absl::StrCat("session snapshot ", where_, " is damaged (", what, " at byte ", at_, ")"));
  }

 private:
  absl::string_view bytes_;
  absl::string_view where_;
  size_t at_ = 0;
};

void EncodeCheckpoint(const StoredComeshCheckpoint& stored, std::string& out) {
  const solver::ComeshCheckpoint& c = stored.checkpoint;
  out.append(kCheckpoint.data(), kCheckpoint.size());
  PutU64(out, stored.input_version);
  PutU64(out, stored.stored_version);
  PutBytes(out, stored.parameters);
  PutBytes(out, ToProto(c.mesh).SerializeAsString());
  PutLists(out, c.mesh.boundary_loops);
  PutLists(out, c.mesh.cohesive_closed);
  for (int v : {c.outer, c.inner, c.energy_evaluations, c.flips, c.collapses, c.splits}) {
    PutU32(out, static_cast<uint32_t>(v));
  }
  PutF64(out, c.pass_start_objective);
  PutU32(out, static_cast<uint32_t>(c.objective_trace.size()));
  for (double f : c.objective_trace) PutF64(out, f);
  out.append(kCheckpointEnd.data(), kCheckpointEnd.size());
  if (c.stage != 0) {  // a later section: older servers skip it (and resume in stage 0)
    out.append(kCheckpointStage.data(), kCheckpointStage.size());
    PutU32(out, static_cast<uint32_t>(c.stage));
  }
}

// The checkpoint section after the end marker (the reader is just past "INBCKPT1").
absl::StatusOr<StoredComeshCheckpoint> DecodeCheckpoint(Reader& reader, absl::string_view where) {
  StoredComeshCheckpoint stored;
  solver::ComeshCheckpoint& c = stored.checkpoint;
  absl::StatusOr<uint64_t> input = reader.U64();
  if (!input.ok()) return input.status();
  absl::StatusOr<uint64_t> version = reader.U64();
  if (!version.ok()) return version.status();
  stored.input_version = *input;
  stored.stored_version = *version;
  absl::StatusOr<absl::string_view> parameters = reader.Bytes();
  if (!parameters.ok()) return parameters.status();
  stored.parameters = std::string(*parameters);
  absl::StatusOr<absl::string_view> mesh_bytes = reader.Bytes();
  if (!mesh_bytes.ok()) return mesh_bytes.status();
  v1::Multimesh proto;
  if (!proto.ParseFromArray(mesh_bytes->data(), static_cast<int>(mesh_bytes->size()))) {
    return reader.Error("bad checkpoint multimesh");
  }
  absl::StatusOr<solver::Multimesh> mesh = MultimeshFromProto(proto, where);
  if (!mesh.ok()) return reader.Error(mesh.status().message());
  c.mesh = *std::move(mesh);
  absl::StatusOr<std::vector<std::vector<int>>> loops =
      reader.Lists(static_cast<uint32_t>(c.mesh.num_vertices()));
  if (!loops.ok()) return loops.status();
  absl::StatusOr<std::vector<std::vector<int>>> closed =
      reader.Lists(static_cast<uint32_t>(c.mesh.cohesive_edges.size()));
  if (!closed.ok()) return closed.status();
  c.mesh.boundary_loops = *std::move(loops);
  c.mesh.cohesive_closed = *std::move(closed);
  for (int* v : {&c.outer, &c.inner, &c.energy_evaluations, &c.flips, &c.collapses, &c.splits}) {
    absl::StatusOr<int> n = reader.Int();
    if (!n.ok()) return n.status();
    *v = *n;
  }
  absl::StatusOr<double> pass_start = reader.F64();
  if (!pass_start.ok()) return pass_start.status();
  c.pass_start_objective = *pass_start;
  absl::StatusOr<int> trace = reader.Int();
  if (!trace.ok()) return trace.status();
  for (int i = 0; i < *trace; ++i) {
    absl::StatusOr<double> f = reader.F64();
    if (!f.ok()) return f.status();
    c.objective_trace.push_back(*f);
  }
  if (absl::Status s = reader.Expect(kCheckpointEnd); !s.ok()) return s;
  if (reader.Consume(kCheckpointStage)) {
    absl::StatusOr<int> stage = reader.Int();
    if (!stage.ok()) return stage.status();
    if (*stage > 1) return reader.Error("bad checkpoint stage");
    c.stage = *stage;
  }
  return stored;
}

}  // namespace

v1::Session SessionSummary(const v1::Session& session) {
  v1::Session out;
  out.set_id(session.id());
  out.set_version(session.version());
  out.set_display_name(session.display_name());
  out.set_stage(session.stage());
  out.set_created_unix_ms(session.created_unix_ms());
  out.set_updated_unix_ms(session.updated_unix_ms());
  // A summary of a summary (a store's listing) keeps the count it carries.
  if (session.drawings_size() > 0 || !session.has_drawing_count()) {
    out.set_drawing_count(static_cast<uint32_t>(session.drawings_size()));
  } else {
    out.set_drawing_count(session.drawing_count());
  }
  return out;
}

std::string EncodeSnapshot(const SessionState& state) {
  v1::SessionArchive archive;
  archive.set_format_version(1);
  *archive.mutable_session() = state.session;
  if (state.multimesh) *archive.mutable_multimesh() = ToProto(*state.multimesh);
  std::string out(kMagic);
  PutBytes(out, state.owner);
  PutBytes(out, SessionSummary(state.session).SerializeAsString());
  PutBytes(out, archive.SerializeAsString());
  PutU32(out, state.next_drawing_id);
  PutLists(out,
           state.multimesh ? state.multimesh->boundary_loops : std::vector<std::vector<int>>{});
  PutLists(out,
           state.multimesh ? state.multimesh->cohesive_closed : std::vector<std::vector<int>>{});
  out.append(kEnd.data(), kEnd.size());
  if (state.comesh_checkpoint) EncodeCheckpoint(*state.comesh_checkpoint, out);
  return out;
}

absl::StatusOr<SnapshotHead> DecodeSnapshotHead(absl::string_view bytes, absl::string_view where) {
  Reader reader(bytes, where);
  if (absl::Status s = reader.Expect(kMagic); !s.ok()) return s;
  SnapshotHead head;
  absl::StatusOr<absl::string_view> owner = reader.Bytes();
  if (!owner.ok()) return owner.status();
  head.owner = std::string(*owner);
  absl::StatusOr<absl::string_view> summary = reader.Bytes();
  if (!summary.ok()) return summary.status();
  if (!head.summary.ParseFromArray(summary->data(), static_cast<int>(summary->size()))) {
    return reader.Error("bad summary");
  }
  return head;
}

absl::StatusOr<SessionState> DecodeSnapshot(absl::string_view bytes, absl::string_view where) {
  Reader reader(bytes, where);
  if (absl::Status s = reader.Expect(kMagic); !s.ok()) return s;
  SessionState state;
  absl::StatusOr<absl::string_view> owner = reader.Bytes();
  if (!owner.ok()) return owner.status();
  state.owner = std::string(*owner);
  if (absl::StatusOr<absl::string_view> summary = reader.Bytes(); !summary.ok()) {
    return summary.status();
  }
  absl::StatusOr<absl::string_view> archive_bytes = reader.Bytes();
  if (!archive_bytes.ok()) return archive_bytes.status();
  v1::SessionArchive archive;
  if (!archive.ParseFromArray(archive_bytes->data(), static_cast<int>(archive_bytes->size()))) {
    return reader.Error("bad archive");
  }
  absl::StatusOr<uint32_t> next_id = reader.U32();
  if (!next_id.ok()) return next_id.status();
  state.next_drawing_id = *next_id;
  state.session = std::move(*archive.mutable_session());
  for (const v1::Drawing& drawing : state.session.drawings()) {
    state.parsed.push_back(SolverDrawing(drawing.elements()));
    state.parsed.back().marks = MarksOf(drawing);
    state.parsed.back().art = FromProto(drawing.art());
  }
  if (archive.has_multimesh() && archive.multimesh().shapes_size() > 0) {
    absl::StatusOr<solver::Multimesh> mesh = MultimeshFromProto(archive.multimesh(), where);
    if (!mesh.ok()) return reader.Error(mesh.status().message());
    const uint32_t vertices = static_cast<uint32_t>(mesh->num_vertices());
    absl::StatusOr<std::vector<std::vector<int>>> loops = reader.Lists(vertices);
    if (!loops.ok()) return loops.status();
    absl::StatusOr<std::vector<std::vector<int>>> closed =
        reader.Lists(static_cast<uint32_t>(mesh->cohesive_edges.size()));
    if (!closed.ok()) return closed.status();
    mesh->boundary_loops = *std::move(loops);
    mesh->cohesive_closed = *std::move(closed);
    state.multimesh = std::make_shared<const solver::Multimesh>(*std::move(mesh));
  } else {
    for (int i = 0; i < 2; ++i) {
      if (absl::StatusOr<std::vector<std::vector<int>>> l = reader.Lists(0); !l.ok()) {
        return l.status();
      }
    }
  }
  if (absl::Status s = reader.Expect(kEnd); !s.ok()) return s;
  // Anything else after the end marker is a later version's section: skipped, as older
  // versions skip the checkpoint.
  if (reader.Consume(kCheckpoint)) {
    absl::StatusOr<StoredComeshCheckpoint> checkpoint = DecodeCheckpoint(reader, where);
    if (!checkpoint.ok()) return checkpoint.status();
    state.comesh_checkpoint =
        std::make_shared<const StoredComeshCheckpoint>(*std::move(checkpoint));
  }
  return state;
}

}  // namespace inbetween::server
