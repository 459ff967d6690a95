// Correspondence marks drawn with the drawings (SVG data-corr elements, Drawing.marks): kept by
// PutDrawing, used by BuildMultimesh while the session has no correspondences, carried through
// export and import, and checked.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "tests/unit/server/test_server.h"

namespace inbetween::server::testing {
namespace {

using ::testing::HasSubstr;

constexpr int kWalkMarks = 18;

class DrawingMarksTest : public ServerTest {
 protected:
  // Four keys of the walk example, each with marks data-corr="1" ... "18" (in the last two the
  // arm hangs over the torso: a cut).
  v1::Session WalkSession() {
    v1::Session session = CreateSession("walk");
    for (const char* name : {"01_contact", "06_up", "07_reach", "08_fall"}) {
      v1::PutDrawingResponse response;
      grpc::Status status = PutSvg(
          session, name, ReadExample(std::string("examples/walk/") + name + ".svg"), &response);
      EXPECT_TRUE(status.ok()) << name << ": " << status.error_message();
      EXPECT_EQ(response.drawing().marks_size(), kWalkMarks) << name;
      session = response.session();
    }
    return session;
  }

  grpc::Status Build(const v1::Session& session, v1::Multimesh* built = nullptr) {
    grpc::ClientContext context;
    v1::BuildMultimeshRequest request;
    request.set_session_id(session.id());
    request.set_expected_version(session.version());
    auto reader = stub_->BuildMultimesh(&context, request);
    v1::BuildMultimeshResponse message;
    while (reader->Read(&message)) {
      if (built != nullptr && message.has_result()) *built = message.result().multimesh();
    }
    return reader->Finish();
  }

  v1::Session Get(const std::string& id) {
    grpc::ClientContext context;
    v1::GetSessionRequest request;
    request.set_session_id(id);
    v1::GetSessionResponse response;
    EXPECT_TRUE(stub_->GetSession(&context, request, &response).ok());
    return response.session();
  }
};

TEST_F(DrawingMarksTest, SvgMarksAreKeptAndPinTheMultimesh) {
  const v1::Session session = WalkSession();
  const v1::Session stored = Get(session.id());
  ASSERT_EQ(stored.drawings_size(), 4);
  for (const v1::Drawing& drawing : stored.drawings()) {
    ASSERT_EQ(drawing.marks_size(), kWalkMarks) << drawing.name();
    for (int k = 0; k < kWalkMarks; ++k) EXPECT_EQ(drawing.marks(k).id(), k + 1u);
  }
  EXPECT_EQ(stored.correspondences_size(), 0);
  // The marks pin the arm's cut tip to the armpit and the limbs' corners to one another; with
  // them the four poses build.
  v1::Multimesh built;
  const grpc::Status status = Build(stored, &built);
  EXPECT_TRUE(status.ok()) << status.error_message();
  // Each mark's vertex is listed as pinned (comesh optimization keeps it in place), ascending.
  EXPECT_EQ(built.pinned_size(), kWalkMarks);
  for (int i = 1; i < built.pinned_size(); ++i) EXPECT_LT(built.pinned(i - 1), built.pinned(i));
}

TEST_F(DrawingMarksTest, MarksSurviveExportAndImport) {
  const v1::Session session = WalkSession();
  grpc::ClientContext context;
  v1::ExportSessionRequest request;
  request.set_session_id(session.id());
  v1::ExportSessionResponse exported;
  ASSERT_TRUE(stub_->ExportSession(&context, request, &exported).ok());
  grpc::ClientContext context2;
  v1::ImportSessionRequest import;
  import.set_data(exported.data());
  v1::ImportSessionResponse imported;
  grpc::Status status = stub_->ImportSession(&context2, import, &imported);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const v1::Session copy = Get(imported.session().id());
  ASSERT_EQ(copy.drawings_size(), 4);
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(copy.drawings(i).marks_size(), kWalkMarks);
    for (int k = 0; k < kWalkMarks; ++k) {
      EXPECT_EQ(copy.drawings(i).marks(k).point().x(),
                Get(session.id()).drawings(i).marks(k).point().x());
    }
  }
}

TEST_F(DrawingMarksTest, BadMarksAreInvalidArgument) {
  v1::Session session = CreateSession();
  grpc::ClientContext context;
  v1::PutDrawingRequest request;
  request.set_session_id(session.id());
  request.set_expected_version(session.version());
  *request.mutable_drawing()->mutable_polylines()->add_elements() = SquareOutline(0, 0, 1);
  v1::DrawingMark* mark = request.mutable_drawing()->add_marks();
  mark->set_id(2);
  mark->mutable_point()->set_y(std::numeric_limits<double>::quiet_NaN());
  v1::PutDrawingResponse response;
  grpc::Status status = stub_->PutDrawing(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("drawing.marks[0].point"));

  mark->mutable_point()->set_y(0.0);
  mark->mutable_point()->set_x(1.0);
  grpc::ClientContext context2;
  status = stub_->PutDrawing(&context2, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.drawing().marks_size(), 1);  // given with polylines: kept as given
  EXPECT_EQ(response.drawing().marks(0).id(), 2u);
}

}  // namespace
}  // namespace inbetween::server::testing
