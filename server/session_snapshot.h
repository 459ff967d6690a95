// One session version as one file (the directory store's snapshots): the SessionArchive of the
// contract plus what the archive cannot carry (owner, next drawing id, the multimesh's boundary
// loops and closed cohesive edges). Layout, integers little-endian:
//   "INBSNAP1"  u32 len + owner  u32 len + Session summary  u32 len + SessionArchive
//   u32 next_drawing_id  u32 loops, per loop u32 n + n x u32  u32 shapes, per shape u32 n + n x u32
//   "INBSEND1"
// then, when the session holds a comesh checkpoint (session_state.h), after the end marker (so
// older servers, which stop reading there, still load the session):
//   "INBCKPT1"  u64 input_version  u64 stored_version  u32 len + ComeshParameters
//   u32 len + Multimesh (proto)  loops and closed cohesive edges as above  u32 outer, inner,
//   energy_evaluations, flips, collapses, splits  f64 pass_start_objective  u32 n + n x f64 trace
//   "INBCKEND"  and, for a checkpoint of the outline-sliding stage (stage != 0 only):
//   "INBCKST1"  u32 stage
// (f64: the IEEE-754 bits as a little-endian u64, so the checkpoint comes back bit for bit.)
// Other bytes after "INBSEND1" are skipped (a later version's sections).
// The head (owner and summary) can be read without the rest, for listing at start-up.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/session_state.h"

namespace inbetween::server {

struct SnapshotHead {
  std::string owner;
  inbetween::v1::Session summary;  // SessionSummary: no drawings, their count
};

std::string EncodeSnapshot(const SessionState& state);

// DATA_LOSS naming `where` (the file) when the bytes are not a complete snapshot.
absl::StatusOr<SessionState> DecodeSnapshot(absl::string_view bytes, absl::string_view where);
absl::StatusOr<SnapshotHead> DecodeSnapshotHead(absl::string_view bytes, absl::string_view where);

// The ListSessions summary of a session: id, version, display_name, stage, timestamps and the
// number of drawings.
inbetween::v1::Session SessionSummary(const inbetween::v1::Session& session);

}  // namespace inbetween::server
