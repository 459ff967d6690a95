// Snapshot encoding. The parsed solver drawings are rebuilt from the stored elements (they are
// the same numbers), the multimesh from the archive plus its loops and closed cohesive edges.
#include "server/session_snapshot.h"

#include <cstdint>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "server/drawing_import.h"
#include "server/proto_convert.h"

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;

constexpr absl::string_view kMagic = "INBSNAP1";
constexpr absl::string_view kEnd = "INBSEND1";

void PutU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
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

}  // namespace

v1::Session SessionSummary(const v1::Session& session) {
  v1::Session out;
  out.set_id(session.id());
  out.set_version(session.version());
  out.set_display_name(session.display_name());
  out.set_stage(session.stage());
  out.set_created_unix_ms(session.created_unix_ms());
  out.set_updated_unix_ms(session.updated_unix_ms());
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
  return state;
}

}  // namespace inbetween::server
