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

// The solver drawing of an imported drawing: its OUTLINE elements, in element order.
solver::Drawing DrawingFromElements(const inbetween::v1::Drawing& drawing);

}  // namespace inbetween::server
