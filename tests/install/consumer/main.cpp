// Uses both halves of an installed Inbetween: the solver directly (a multimesh of a square and a
// hexagon, then the frame halfway between them) and the gRPC client, against the service started
// in-process (no port), for one session round trip. Prints one line per check; exits 1 on failure.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "client/inbetween_client.h"
#include "server/inbetween_server.h"
#include "solver/interp/inbetweener.h"
#include "solver/mesh/build_multimesh.h"

namespace sv = inbetween::solver;

namespace {

// A regular polygon of `sides` corners on a circle of radius 10, counter-clockwise.
sv::Drawing RegularPolygon(int sides) {
  sv::Outline outline;
  for (int k = 0; k < sides; ++k) {
    const double angle = 2 * std::numbers::pi * k / sides + std::numbers::pi / sides;
    outline.points.emplace_back(10 * std::cos(angle), 10 * std::sin(angle));
  }
  sv::Drawing drawing;
  drawing.outlines.push_back(outline);
  return drawing;
}

int Fail(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "%s: %s\n", what, status.ToString().c_str());
  return 1;
}

}  // namespace

int main() {
  absl::StatusOr<sv::Multimesh> mesh =
      sv::BuildMultimesh({RegularPolygon(4), RegularPolygon(6)}, sv::MultimeshOptions{});
  if (!mesh.ok()) return Fail("BuildMultimesh", mesh.status());
  absl::StatusOr<sv::Inbetweener> inbetweener =
      sv::Inbetweener::Create(*mesh, sv::InbetweenOptions{});
  if (!inbetweener.ok()) return Fail("Inbetweener::Create", inbetweener.status());
  absl::StatusOr<sv::Frame> frame = inbetweener->Solve({0.5, 0.5}, sv::Frame{});
  if (!frame.ok()) return Fail("Solve", frame.status());
  int inverted = 0;
  for (const sv::Triangle& t : mesh->triangles) {
    const sv::Point& a = frame->vertices[t[0]];
    const sv::Point e1 = frame->vertices[t[1]] - a;
    const sv::Point e2 = frame->vertices[t[2]] - a;
    if (e1.x() * e2.y() - e1.y() * e2.x() <= 0) ++inverted;
  }
  std::printf("solver: multimesh of %d vertices, %zu triangles; halfway frame: %d inverted\n",
              mesh->num_vertices(), mesh->triangles.size(), inverted);
  if (mesh->triangles.empty() || inverted != 0) return 1;

  inbetween::server::ServerOptions options;  // no listening port: in-process only
  auto server = inbetween::server::InbetweenServer::Start(options);
  if (!server.ok()) return Fail("InbetweenServer::Start", server.status());
  inbetween::client::InbetweenClient client((*server)->InProcessChannel());
  absl::StatusOr<inbetween::v1::Session> session = client.CreateSession("consumer");
  if (!session.ok()) return Fail("CreateSession", session.status());
  absl::StatusOr<std::vector<inbetween::v1::Session>> sessions = client.ListSessions();
  if (!sessions.ok()) return Fail("ListSessions", sessions.status());
  const bool listed = sessions->size() == 1 && (*sessions)[0].id() == session->id();
  std::printf("client: created session \"%s\", listed: %s\n",
              session->display_name().c_str(), listed ? "yes" : "no");
  return listed ? 0 : 1;
}
