// StiffnessRegion list (API) -> per-triangle material stiffness kappa (S-eq.3) for the solver.
#pragma once

#include <vector>

#include "inbetween/v1/inbetween.pb.h"
#include "solver/mesh/multimesh.h"

namespace inbetween::server {

// kappa per triangle of `mesh`: 1 by default; a triangle whose centroid in drawing 1 (shape 0)
// lies inside a region's polygon gets that region's kappa, later regions overriding earlier
// ones. Empty `regions` = an empty vector (the solver's "1 everywhere"). Regions must have been
// validated (ValidateInbetween).
std::vector<double> StiffnessPerTriangle(
    const solver::Multimesh& mesh,
    const google::protobuf::RepeatedPtrField<inbetween::v1::StiffnessRegion>& regions);

}  // namespace inbetween::server
