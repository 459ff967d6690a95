// Conversions between the API's proto messages and the solver's value types.
#pragma once

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/types.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::server {

void ToProto(const solver::Point& point, inbetween::v1::Point* out);
void ToProto(const solver::Points& points,
             google::protobuf::RepeatedPtrField<inbetween::v1::Point>* out);
inbetween::v1::Multimesh ToProto(const solver::Multimesh& mesh);

// Checks indices and sizes (the caller validates geometry with solver::ValidateMultimesh).
// Errors are INVALID_ARGUMENT naming `field`.
absl::StatusOr<solver::Multimesh> MultimeshFromProto(const inbetween::v1::Multimesh& mesh,
                                                     absl::string_view field);

// The solver drawing of a drawing's elements: OUTLINE -> outlines, CUT -> cuts, OPENING ->
// openings, each in element order (what ImportDrawing produced from the same elements).
solver::Drawing SolverDrawing(
    const google::protobuf::RepeatedPtrField<inbetween::v1::TopologyElement>& elements);

solver::Points FromProto(const google::protobuf::RepeatedPtrField<inbetween::v1::Point>& points);

}  // namespace inbetween::server
