// Proto <-> solver value types. Pure data shuffling; validation of geometry lives elsewhere.
#include "server/proto_convert.h"

#include <string>

#include "absl/strings/str_cat.h"

namespace inbetween::server {

void ToProto(const solver::Point& point, inbetween::v1::Point* out) {
  out->set_x(point.x());
  out->set_y(point.y());
}

void ToProto(const solver::Points& points,
             google::protobuf::RepeatedPtrField<inbetween::v1::Point>* out) {
  out->Reserve(out->size() + static_cast<int>(points.size()));
  for (const solver::Point& p : points) ToProto(p, out->Add());
}

inbetween::v1::Multimesh ToProto(const solver::Multimesh& mesh) {
  inbetween::v1::Multimesh out;
  out.mutable_triangles()->Reserve(static_cast<int>(mesh.triangles.size()));
  for (const solver::Triangle& t : mesh.triangles) {
    inbetween::v1::Triangle* triangle = out.add_triangles();
    triangle->set_a(t[0]);
    triangle->set_b(t[1]);
    triangle->set_c(t[2]);
  }
  for (const solver::Points& shape : mesh.shapes) {
    ToProto(shape, out.add_shapes()->mutable_vertices());
  }
  for (int v : mesh.boundary) out.add_boundary(v);
  for (const auto& e : mesh.cohesive_edges) {
    inbetween::v1::CohesiveEdgePair* pair = out.add_cohesive_edges();
    pair->set_a(e[0]);
    pair->set_b(e[1]);
    pair->set_c(e[2]);
    pair->set_d(e[3]);
  }
  for (int v : mesh.pinned) out.add_pinned(v);
  return out;
}

absl::StatusOr<solver::Multimesh> MultimeshFromProto(const inbetween::v1::Multimesh& mesh,
                                                     absl::string_view field) {
  solver::Multimesh out;
  if (mesh.shapes_size() == 0) {
    return absl::InvalidArgumentError(absl::StrCat(field, " has no shapes"));
  }
  const int num_vertices = mesh.shapes(0).vertices_size();
  for (int i = 0; i < mesh.shapes_size(); ++i) {
    const auto& vertices = mesh.shapes(i).vertices();
    if (vertices.size() != num_vertices) {
      return absl::InvalidArgumentError(absl::StrCat(field, ".shapes[", i, "] has ",
                                                     vertices.size(), " vertices, shapes[0] has ",
                                                     num_vertices));
    }
    solver::Points& shape = out.shapes.emplace_back();
    shape.reserve(num_vertices);
    for (const inbetween::v1::Point& p : vertices) shape.emplace_back(p.x(), p.y());
  }
  auto check_index = [&](uint32_t index, absl::string_view what, int i) -> absl::Status {
    if (index >= static_cast<uint32_t>(num_vertices)) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".", what, "[", i, "] refers to vertex ", index, " of ", num_vertices));
    }
    return absl::OkStatus();
  };
  for (int i = 0; i < mesh.triangles_size(); ++i) {
    const inbetween::v1::Triangle& t = mesh.triangles(i);
    for (uint32_t v : {t.a(), t.b(), t.c()}) {
      if (absl::Status s = check_index(v, "triangles", i); !s.ok()) return s;
    }
    out.triangles.push_back(
        {static_cast<int>(t.a()), static_cast<int>(t.b()), static_cast<int>(t.c())});
  }
  for (int i = 0; i < mesh.boundary_size(); ++i) {
    if (absl::Status s = check_index(mesh.boundary(i), "boundary", i); !s.ok()) return s;
    out.boundary.push_back(static_cast<int>(mesh.boundary(i)));
  }
  for (int i = 0; i < mesh.cohesive_edges_size(); ++i) {
    const inbetween::v1::CohesiveEdgePair& e = mesh.cohesive_edges(i);
    for (uint32_t v : {e.a(), e.b(), e.c(), e.d()}) {
      if (absl::Status s = check_index(v, "cohesive_edges", i); !s.ok()) return s;
    }
    out.cohesive_edges.push_back({static_cast<int>(e.a()), static_cast<int>(e.b()),
                                  static_cast<int>(e.c()), static_cast<int>(e.d())});
  }
  for (int i = 0; i < mesh.pinned_size(); ++i) {
    if (absl::Status s = check_index(mesh.pinned(i), "pinned", i); !s.ok()) return s;
    if (i > 0 && !(mesh.pinned(i - 1) < mesh.pinned(i))) {
      return absl::InvalidArgumentError(absl::StrCat(field, ".pinned[", i, "] (", mesh.pinned(i),
                                                     ") is not above the one before it"));
    }
    out.pinned.push_back(static_cast<int>(mesh.pinned(i)));
  }
  return out;
}

solver::Points FromProto(const google::protobuf::RepeatedPtrField<inbetween::v1::Point>& points) {
  solver::Points out;
  out.reserve(points.size());
  for (const inbetween::v1::Point& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

solver::Drawing SolverDrawing(
    const google::protobuf::RepeatedPtrField<inbetween::v1::TopologyElement>& elements) {
  solver::Drawing out;
  for (const inbetween::v1::TopologyElement& element : elements) {
    solver::Points points = FromProto(element.polyline().points());
    switch (element.kind()) {
      case inbetween::v1::ELEMENT_KIND_OUTLINE:
        out.outlines.push_back({std::move(points)});
        break;
      case inbetween::v1::ELEMENT_KIND_CUT:
        out.cuts.push_back(std::move(points));
        break;
      case inbetween::v1::ELEMENT_KIND_OPENING:
        out.openings.push_back(std::move(points));
        break;
      default:
        break;
    }
  }
  return out;
}

}  // namespace inbetween::server
