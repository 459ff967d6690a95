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
  out.mutable_art()->Reserve(static_cast<int>(mesh.art.size()));
  for (const solver::EmbeddedArt& art : mesh.art) ToProto(art, out.add_art());
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
  out.art.reserve(mesh.art_size());
  for (int k = 0; k < mesh.art_size(); ++k) {
    absl::StatusOr<solver::EmbeddedArt> art = EmbeddedArtFromProto(
        mesh.art(k), out.triangles, num_vertices, absl::StrCat(field, ".art[", k, "]"));
    if (!art.ok()) return art.status();
    out.art.push_back(*std::move(art));
  }
  return out;
}

solver::Points FromProto(const google::protobuf::RepeatedPtrField<inbetween::v1::Point>& points) {
  solver::Points out;
  out.reserve(points.size());
  for (const inbetween::v1::Point& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

void ToProto(const solver::ArtLayer& layer, inbetween::v1::ArtLayer* out) {
  out->set_id(layer.id);
  out->set_name(layer.name);
  out->mutable_paths()->Reserve(static_cast<int>(layer.paths.size()));
  for (const solver::ArtPath& path : layer.paths) {
    inbetween::v1::ArtPath* p = out->add_paths();
    ToProto(path.points, p->mutable_points());
    p->set_closed(path.closed);
  }
  if (layer.fill) {
    inbetween::v1::FillPaint* fill = out->mutable_fill();
    fill->set_rgb(layer.fill->rgb);
    fill->set_opacity(layer.fill->opacity);
    fill->set_even_odd(layer.fill->even_odd);
  }
  if (layer.stroke) {
    const solver::StrokePaint& s = *layer.stroke;
    inbetween::v1::StrokePaint* stroke = out->mutable_stroke();
    stroke->set_rgb(s.rgb);
    stroke->set_opacity(s.opacity);
    stroke->set_width(s.width);
    switch (s.cap) {
      case solver::LineCap::kButt:
        stroke->set_cap(inbetween::v1::LINE_CAP_BUTT);
        break;
      case solver::LineCap::kRound:
        stroke->set_cap(inbetween::v1::LINE_CAP_ROUND);
        break;
      case solver::LineCap::kSquare:
        stroke->set_cap(inbetween::v1::LINE_CAP_SQUARE);
        break;
    }
    switch (s.join) {
      case solver::LineJoin::kMiter:
        stroke->set_join(inbetween::v1::LINE_JOIN_MITER);
        break;
      case solver::LineJoin::kRound:
        stroke->set_join(inbetween::v1::LINE_JOIN_ROUND);
        break;
      case solver::LineJoin::kBevel:
        stroke->set_join(inbetween::v1::LINE_JOIN_BEVEL);
        break;
    }
    stroke->set_miter_limit(s.miter_limit);
    stroke->mutable_dashes()->Add(s.dashes.begin(), s.dashes.end());
    stroke->set_dash_offset(s.dash_offset);
  }
  out->set_opacity(layer.opacity);
}

void ToProto(const std::vector<solver::ArtLayer>& art,
             google::protobuf::RepeatedPtrField<inbetween::v1::ArtLayer>* out) {
  out->Reserve(out->size() + static_cast<int>(art.size()));
  for (const solver::ArtLayer& layer : art) ToProto(layer, out->Add());
}

void ToProto(const solver::EmbeddedArt& art, inbetween::v1::KeyArt* out) {
  out->set_key(static_cast<uint32_t>(art.key));
  out->mutable_layers()->Reserve(static_cast<int>(art.layers.size()));
  for (const solver::EmbeddedLayer& layer : art.layers) ToProto(layer, out->add_layers());
}

void ToProto(const solver::EmbeddedLayer& layer, inbetween::v1::EmbeddedArtLayer* out) {
  ToProto(layer.paint, out->mutable_paint());
  out->mutable_paint()->clear_paths();
  out->mutable_paths()->Reserve(static_cast<int>(layer.paths.size()));
  for (const solver::EmbeddedPath& path : layer.paths) {
    inbetween::v1::EmbeddedArtPath* p = out->add_paths();
    p->mutable_triangles()->Reserve(static_cast<int>(path.points.size()));
    p->mutable_barycentric()->Reserve(3 * static_cast<int>(path.points.size()));
    for (const solver::EmbeddedPoint& point : path.points) {
      p->add_triangles(static_cast<uint32_t>(point.triangle));
      for (int c = 0; c < 3; ++c) p->add_barycentric(point.barycentric[c]);
    }
    p->set_closed(path.closed);
  }
}

absl::StatusOr<solver::EmbeddedArt> EmbeddedArtFromProto(
    const inbetween::v1::KeyArt& art, const std::vector<solver::Triangle>& triangles,
    int num_vertices, absl::string_view field) {
  solver::EmbeddedArt out;
  out.key = static_cast<int>(art.key());
  out.num_vertices = num_vertices;
  out.layers.reserve(art.layers_size());
  for (int l = 0; l < art.layers_size(); ++l) {
    const inbetween::v1::EmbeddedArtLayer& layer = art.layers(l);
    solver::EmbeddedLayer& embedded = out.layers.emplace_back();
    embedded.paint = FromProto(layer.paint());
    embedded.paint.paths.clear();
    embedded.paths.reserve(layer.paths_size());
    for (int p = 0; p < layer.paths_size(); ++p) {
      const inbetween::v1::EmbeddedArtPath& path = layer.paths(p);
      const std::string where = absl::StrCat(field, ".layers[", l, "].paths[", p, "]");
      if (path.barycentric_size() != 3 * path.triangles_size()) {
        return absl::InvalidArgumentError(
            absl::StrCat(where, " has ", path.barycentric_size(), " barycentric coordinates for ",
                         path.triangles_size(), " points (3 per point)"));
      }
      solver::EmbeddedPath& e = embedded.paths.emplace_back();
      e.closed = path.closed();
      e.points.reserve(path.triangles_size());
      for (int i = 0; i < path.triangles_size(); ++i) {
        const uint32_t t = path.triangles(i);
        if (t >= triangles.size()) {
          return absl::InvalidArgumentError(absl::StrCat(
              where, ".triangles[", i, "] refers to triangle ", t, " of ", triangles.size()));
        }
        solver::EmbeddedPoint& point = e.points.emplace_back();
        point.triangle = static_cast<int>(t);
        point.corners = triangles[t];
        point.barycentric = {path.barycentric(3 * i), path.barycentric(3 * i + 1),
                             path.barycentric(3 * i + 2)};
      }
    }
  }
  return out;
}

solver::ArtLayer FromProto(const inbetween::v1::ArtLayer& layer) {
  solver::ArtLayer out;
  out.id = layer.id();
  out.name = layer.name();
  out.paths.reserve(layer.paths_size());
  for (const inbetween::v1::ArtPath& path : layer.paths()) {
    out.paths.push_back({FromProto(path.points()), path.closed()});
  }
  if (layer.has_fill()) {
    out.fill = solver::FillPaint{.rgb = layer.fill().rgb(),
                                 .opacity = layer.fill().opacity(),
                                 .even_odd = layer.fill().even_odd()};
  }
  if (layer.has_stroke()) {
    const inbetween::v1::StrokePaint& s = layer.stroke();
    solver::StrokePaint& stroke = out.stroke.emplace();
    stroke.rgb = s.rgb();
    stroke.opacity = s.opacity();
    stroke.width = s.width();
    stroke.cap = s.cap() == inbetween::v1::LINE_CAP_ROUND    ? solver::LineCap::kRound
                 : s.cap() == inbetween::v1::LINE_CAP_SQUARE ? solver::LineCap::kSquare
                                                             : solver::LineCap::kButt;
    stroke.join = s.join() == inbetween::v1::LINE_JOIN_ROUND   ? solver::LineJoin::kRound
                  : s.join() == inbetween::v1::LINE_JOIN_BEVEL ? solver::LineJoin::kBevel
                                                               : solver::LineJoin::kMiter;
    stroke.miter_limit = s.miter_limit();
    stroke.dashes.assign(s.dashes().begin(), s.dashes().end());
    stroke.dash_offset = s.dash_offset();
  }
  out.opacity = layer.opacity();
  return out;
}

std::vector<solver::ArtLayer> FromProto(
    const google::protobuf::RepeatedPtrField<inbetween::v1::ArtLayer>& art) {
  std::vector<solver::ArtLayer> out;
  out.reserve(art.size());
  for (const inbetween::v1::ArtLayer& layer : art) out.push_back(FromProto(layer));
  return out;
}

inbetween::v1::ImportReport ToProto(const solver::SvgImportInfo& info, int art_layers) {
  inbetween::v1::ImportReport out;
  switch (info.source) {
    case solver::SilhouetteSource::kElements:
      out.set_silhouette_source(inbetween::v1::SILHOUETTE_SOURCE_ELEMENTS);
      break;
    case solver::SilhouetteSource::kUnion:
      out.set_silhouette_source(inbetween::v1::SILHOUETTE_SOURCE_UNION);
      break;
    case solver::SilhouetteSource::kOutlineClass:
      out.set_silhouette_source(inbetween::v1::SILHOUETTE_SOURCE_OUTLINE_CLASS);
      break;
  }
  const solver::PaintCleaning& c = info.cleaning;
  out.set_gaps_closed(static_cast<uint32_t>(c.gaps_closed));
  out.set_slits_closed(static_cast<uint32_t>(c.slits_closed));
  out.set_islands_dropped(static_cast<uint32_t>(c.islands_dropped));
  out.set_holes_dropped(static_cast<uint32_t>(c.holes_dropped));
  out.set_gap_width(c.gap_width);
  out.set_min_area(c.min_area);
  for (const std::string& warning : info.warnings) out.add_warnings(warning);
  out.set_art_layers(static_cast<uint32_t>(art_layers));
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
