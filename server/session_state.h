// What the server keeps per session: the API-visible Session plus the solver-side data derived
// from it (parsed drawings, the multimesh), so heavy stages need no re-parsing.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "inbetween/v1/inbetween.pb.h"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::server {

// The last checkpoint of an OptimizeComesh run (docs/api.md "Resuming OptimizeComesh"). It
// belongs to one run: the session version the run started from (its input multimesh) and its
// effective comesh parameters. Stored without moving the version (SessionStore::PutSameVersion),
// so any later write makes it stale.
struct StoredComeshCheckpoint {
  uint64_t input_version = 0;   // the request's expected_version
  uint64_t stored_version = 0;  // the session version it was stored at (== input_version)
  std::string parameters;       // the effective v1::ComeshParameters, serialized
  solver::ComeshCheckpoint checkpoint;
};

struct SessionState {
  // The session as the API shows it, drawings with their source (SVG text) and elements.
  inbetween::v1::Session session;
  // parsed[i] = the solver drawing of session.drawings(i) (its outlines), same order.
  std::vector<solver::Drawing> parsed;
  // The stored multimesh when session.stage() >= STAGE_MULTIMESH, else null. Shared and
  // immutable so that copying a state out of the store is cheap.
  std::shared_ptr<const solver::Multimesh> multimesh;
  // Next drawing id to hand out; ids are never reused within a session.
  uint32_t next_drawing_id = 1;
  // Who may see the session: the caller's token name (auth.h), "" when the server has no tokens.
  std::string owner;
  // The running or interrupted optimization's last checkpoint, or null. Stored with the session
  // (snapshots, Redis), never exported (ExportSession).
  std::shared_ptr<const StoredComeshCheckpoint> comesh_checkpoint;
};

}  // namespace inbetween::server
