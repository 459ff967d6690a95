// Session snapshots (server/session_snapshot.cpp): a comesh checkpoint comes back bit for bit,
// a snapshot without one is unchanged, the checkpoint section after the end marker is what an
// older reader skips, and a damaged section is DATA_LOSS; drawings keep their art and import
// report, and the parsed drawings get the art back.
#include "server/session_snapshot.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "server/proto_convert.h"
#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

SessionState WithCheckpoint() {
  SessionState state = StoredSessionState("alice");
  state.session.set_id("0123456789abcdef");
  state.session.set_version(9);
  auto stored = std::make_shared<StoredComeshCheckpoint>();
  stored->input_version = 7;
  stored->stored_version = 9;
  stored->parameters = "\x08\x03";
  solver::ComeshCheckpoint& c = stored->checkpoint;
  c.mesh = *state.multimesh;
  c.mesh.shapes[1][2] = solver::Point(0.1 + 0.2, 1.0 / 3.0);  // not exactly decimal
  c.mesh.cohesive_edges = {{0, 1, 3, 2}};
  c.mesh.cohesive_closed = {{0}, {}};
  c.mesh.pinned = {1, 3};
  c.outer = 2;
  c.inner = 41;
  c.energy_evaluations = 97;
  c.flips = 3;
  c.collapses = 1;
  c.splits = 0;
  c.pass_start_objective = 1.0 / 7.0;
  c.objective_trace = {2.5, 1.0 / 3.0, 0.1 + 0.2};
  state.comesh_checkpoint = stored;
  return state;
}

TEST(SessionSnapshotTest, ComeshCheckpointRoundTripsBitForBit) {
  const SessionState state = WithCheckpoint();
  auto decoded = DecodeSnapshot(EncodeSnapshot(state), "test");
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ASSERT_NE(decoded->comesh_checkpoint, nullptr);
  const StoredComeshCheckpoint& want = *state.comesh_checkpoint;
  const StoredComeshCheckpoint& got = *decoded->comesh_checkpoint;
  EXPECT_EQ(got.input_version, want.input_version);
  EXPECT_EQ(got.stored_version, want.stored_version);
  EXPECT_EQ(got.parameters, want.parameters);
  const solver::ComeshCheckpoint& a = got.checkpoint;
  const solver::ComeshCheckpoint& b = want.checkpoint;
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.mesh.shapes, b.mesh.shapes);  // exact doubles
  EXPECT_EQ(a.mesh.boundary, b.mesh.boundary);
  EXPECT_EQ(a.mesh.cohesive_edges, b.mesh.cohesive_edges);
  EXPECT_EQ(a.mesh.boundary_loops, b.mesh.boundary_loops);
  EXPECT_EQ(a.mesh.cohesive_closed, b.mesh.cohesive_closed);
  EXPECT_EQ(a.mesh.pinned, b.mesh.pinned);
  EXPECT_EQ(a.outer, b.outer);
  EXPECT_EQ(a.inner, b.inner);
  EXPECT_EQ(a.energy_evaluations, b.energy_evaluations);
  EXPECT_EQ(a.flips, b.flips);
  EXPECT_EQ(a.collapses, b.collapses);
  EXPECT_EQ(a.splits, b.splits);
  EXPECT_EQ(a.pass_start_objective, b.pass_start_objective);
  EXPECT_EQ(a.objective_trace, b.objective_trace);
  // The session's own multimesh is the input, not the checkpoint's.
  ASSERT_TRUE(decoded->multimesh);
  EXPECT_EQ(decoded->multimesh->shapes, state.multimesh->shapes);
}

TEST(SessionSnapshotTest, ArtAndImportReportRoundTrip) {
  SessionState state = StoredSessionState("alice");
  state.session.set_id("0123456789abcdef");
  v1::Drawing& drawing = *state.session.mutable_drawings(0);
  ToProto(SampleArt(), drawing.mutable_art());
  drawing.mutable_import_report()->set_silhouette_source(v1::SILHOUETTE_SOURCE_UNION);
  drawing.mutable_import_report()->set_islands_dropped(3);
  drawing.mutable_import_report()->set_min_area(0.1 + 0.2);
  drawing.mutable_import_report()->add_warnings("a gradient became its mean colour");
  drawing.mutable_import_report()->set_art_layers(2);
  state.parsed[0].art = SampleArt();
  absl::StatusOr<SessionState> decoded = DecodeSnapshot(EncodeSnapshot(state), "test");
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  ASSERT_EQ(decoded->session.drawings_size(), 1);
  EXPECT_EQ(decoded->session.drawings(0).SerializeAsString(), drawing.SerializeAsString());
  ASSERT_EQ(decoded->parsed.size(), 1u);
  ExpectSameArt(decoded->parsed[0].art, SampleArt());
}

TEST(SessionSnapshotTest, WithoutACheckpointTheLayoutIsUnchanged) {
  SessionState state = WithCheckpoint();
  const std::string with = EncodeSnapshot(state);
  state.comesh_checkpoint.reset();
  const std::string without = EncodeSnapshot(state);
  // The checkpoint is a section after the end marker: an older reader stops before it.
  ASSERT_LT(without.size(), with.size());
  EXPECT_EQ(with.substr(0, without.size()), without);
  EXPECT_EQ(without.substr(without.size() - 8), "INBSEND1");
  auto decoded = DecodeSnapshot(without, "test");
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_EQ(decoded->comesh_checkpoint, nullptr);
}

// A checkpoint of the optimizer's outline-sliding stage carries its stage in a section after the
// checkpoint's end marker; a stage-0 checkpoint is laid out as before that section existed.
TEST(SessionSnapshotTest, CheckpointStageRoundTrips) {
  SessionState state = WithCheckpoint();
  const std::string stage0 = EncodeSnapshot(state);
  EXPECT_EQ(stage0.substr(stage0.size() - 8), "INBCKEND");
  auto stored = std::make_shared<StoredComeshCheckpoint>(*state.comesh_checkpoint);
  stored->checkpoint.stage = 1;
  state.comesh_checkpoint = stored;
  const std::string stage1 = EncodeSnapshot(state);
  EXPECT_EQ(stage1.substr(0, stage0.size()), stage0);
  for (int stage : {0, 1}) {
    auto decoded = DecodeSnapshot(stage == 0 ? stage0 : stage1, "test");
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    ASSERT_NE(decoded->comesh_checkpoint, nullptr);
    EXPECT_EQ(decoded->comesh_checkpoint->checkpoint.stage, stage);
  }
  auto cut = DecodeSnapshot(stage1.substr(0, stage1.size() - 1), "file 9");
  EXPECT_EQ(cut.status().code(), absl::StatusCode::kDataLoss);
  std::string bad = stage1;
  bad[bad.size() - 4] = 2;  // stage 2 does not exist
  EXPECT_EQ(DecodeSnapshot(bad, "file 9").status().code(), absl::StatusCode::kDataLoss);
}

TEST(SessionSnapshotTest, DamagedCheckpointIsDataLoss) {
  const std::string bytes = EncodeSnapshot(WithCheckpoint());
  for (size_t cut : {bytes.size() - 1, bytes.size() - 12, bytes.size() - 60}) {
    auto decoded = DecodeSnapshot(bytes.substr(0, cut), "file 9");
    EXPECT_EQ(decoded.status().code(), absl::StatusCode::kDataLoss) << cut;
  }
  // A later version's section after the end marker is skipped.
  SessionState plain = WithCheckpoint();
  plain.comesh_checkpoint.reset();
  auto later = DecodeSnapshot(EncodeSnapshot(plain) + "INBLATER-and-more", "file 9");
  ASSERT_TRUE(later.ok()) << later.status();
  EXPECT_EQ(later->comesh_checkpoint, nullptr);
}

}  // namespace
}  // namespace inbetween::server::testing
