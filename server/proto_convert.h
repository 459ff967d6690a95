// Conversions between the API's proto messages and the solver's value types.
#pragma once

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/art/art_embedding.h"
#include "solver/core/types.h"
#include "solver/io/svg_import.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::server {

void ToProto(const solver::Point& point, inbetween::v1::Point* out);
void ToProto(const solver::Points& points,
             google::protobuf::RepeatedPtrField<inbetween::v1::Point>* out);
inbetween::v1::Multimesh ToProto(const solver::Multimesh& mesh);

// Checks indices and sizes, the art's too (the caller validates geometry with
// solver::ValidateMultimesh).
// Errors are INVALID_ARGUMENT naming `field`.
absl::StatusOr<solver::Multimesh> MultimeshFromProto(const inbetween::v1::Multimesh& mesh,
                                                     absl::string_view field);

// The solver drawing of a drawing's elements: OUTLINE -> outlines, CUT -> cuts, OPENING ->
// openings, each in element order (what ImportDrawing produced from the same elements).
solver::Drawing SolverDrawing(
    const google::protobuf::RepeatedPtrField<inbetween::v1::TopologyElement>& elements);

solver::Points FromProto(const google::protobuf::RepeatedPtrField<inbetween::v1::Point>& points);

// A drawing's art (Drawing.art), both ways. FromProto reads UNSPECIFIED cap and join as SVG's
// initial values (butt, miter), as it reads any value it does not know; it checks nothing
// (CheckArt in drawing_import.h does).
void ToProto(const solver::ArtLayer& layer, inbetween::v1::ArtLayer* out);
void ToProto(const std::vector<solver::ArtLayer>& art,
             google::protobuf::RepeatedPtrField<inbetween::v1::ArtLayer>* out);
solver::ArtLayer FromProto(const inbetween::v1::ArtLayer& layer);
std::vector<solver::ArtLayer> FromProto(
    const google::protobuf::RepeatedPtrField<inbetween::v1::ArtLayer>& art);

// A key's art embedded in the multimesh (InbetweenHeader.art): paint as in ToProto(ArtLayer)
// without paths, each path's points packed as triangle indices and barycentric triples.
void ToProto(const solver::EmbeddedArt& art, inbetween::v1::KeyArt* out);
void ToProto(const solver::EmbeddedLayer& layer, inbetween::v1::EmbeddedArtLayer* out);
// And back, for a mesh of `triangles` and `num_vertices` vertices (the inserted-point flags are
// not carried: every point reads as drawn). Checks indices and sizes; errors are
// INVALID_ARGUMENT naming `field`.
absl::StatusOr<solver::EmbeddedArt> EmbeddedArtFromProto(
    const inbetween::v1::KeyArt& art, const std::vector<solver::Triangle>& triangles,
    int num_vertices, absl::string_view field);

// What ImportSvg saw, as the API reports it; `art_layers` is the size of the drawing's art.
inbetween::v1::ImportReport ToProto(const solver::SvgImportInfo& info, int art_layers);

}  // namespace inbetween::server
