// The API's Parameters: range checks, merging request over session values, and translation to
// the solver's option structs with the documented defaults.
#pragma once

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inbetween/v1/inbetween.pb.h"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "solver/mesh/build_multimesh.h"

namespace inbetween::server {

inline constexpr int kDefaultFrames = 24;
inline constexpr int kMaxFrames = 100000;
// ComeshParameters defaults (inbetween.proto) where the service's differ from, or predate, the
// solver's; max_inner_iterations and tolerance take ComeshOptions' own defaults.
inline constexpr double kDefaultMapWeight = 0.5;
inline constexpr int kDefaultMaxOuterIterations = 50;

// Range checks of every field (the ranges in inbetween.proto). Errors are INVALID_ARGUMENT
// naming `field`.subfield, or RESOURCE_EXHAUSTED for frames above kMaxFrames.
absl::Status ValidateParameters(const inbetween::v1::Parameters& parameters,
                                absl::string_view field);
absl::Status ValidateMeshing(const inbetween::v1::MeshingParameters& meshing,
                             absl::string_view field);
absl::Status ValidateComesh(const inbetween::v1::ComeshParameters& comesh, absl::string_view field);
absl::Status ValidateInbetween(const inbetween::v1::InbetweenParameters& inbetween,
                               absl::string_view field);

// Validated meshing parameters -> solver options (zero fields take the solver's defaults).
solver::MultimeshOptions ToMultimeshOptions(const inbetween::v1::MeshingParameters& meshing);

// Validated comesh parameters -> solver options with the proto's defaults (w 0.5, 50 outer and
// 200 inner iterations, relative decrease 1e-6); other options keep the solver's defaults.
solver::ComeshOptions ToComeshOptions(const inbetween::v1::ComeshParameters& comesh);
// The outline guard's bound for an optimization (ComeshOptions::outline_tolerance): the
// tolerance the session's outlines are built to (MeshingParameters.boundary_tolerance), or the
// build's default when that is unset or 0 (even sampling, which promises none).
double ComeshOutlineTolerance(const inbetween::v1::MeshingParameters& meshing);

// Request fields that are set (non-zero, present or non-empty) override the session's.
inbetween::v1::InbetweenParameters MergeInbetween(
    const inbetween::v1::InbetweenParameters& session,
    const inbetween::v1::InbetweenParameters& request);

struct InbetweenPlan {
  int frames = kDefaultFrames;
  solver::InbetweenOptions options;
};

// Validated, merged parameters -> what the server runs. Stiffness regions need the mesh: the
// caller fills options.stiffness with StiffnessPerTriangle; the timing needs the number of
// drawings: the caller uses ToTimingOptions.
absl::StatusOr<InbetweenPlan> ToInbetweenPlan(const inbetween::v1::InbetweenParameters& params,
                                              absl::string_view field);

// The validated timing curve for `num_drawings` keys: LINEAR (and UNSPECIFIED) = piecewise
// linear, CATMULL_ROM = smooth through the keys, EASE_IN_OUT = every segment eased at both ends
// by its `ease` amount (all 1 when `ease` is empty). `ease` is ignored by the other curves; a
// non-empty `ease` of the wrong length is INVALID_ARGUMENT naming `field`.ease.
absl::StatusOr<solver::TimingOptions> ToTimingOptions(
    const inbetween::v1::InbetweenParameters& params, int num_drawings, absl::string_view field);

// The frames of one Inbetween stream: how many, and each frame's time and key weights.
// Key times are parameters.key_times when set, else the drawings' key_time when every drawing
// has one, else evenly spaced keys. Errors name what is wrong: fewer frames than drawings or
// start_frame past the end (INVALID_ARGUMENT), more frames than `max_frames` (RESOURCE_EXHAUSTED,
// --max-frames), key_time set on some drawings only, or a schedule the key times or timing
// curve cannot make (prefixed with the field it came from).
absl::StatusOr<solver::Schedule> ScheduleFrames(const inbetween::v1::InbetweenParameters& params,
                                                const inbetween::v1::Session& session, int frames,
                                                uint32_t start_frame, int max_frames);

}  // namespace inbetween::server
