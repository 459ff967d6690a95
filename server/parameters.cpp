// Parameter ranges and defaults exactly as documented in proto/inbetween/v1/inbetween.proto.
#include "server/parameters.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"

namespace inbetween::server {
namespace {

// `value` must lie in [lo, hi] (or (lo, hi] when lo_open); non-finite values never do.
absl::Status CheckRange(double value, double lo, double hi, bool lo_open, absl::string_view field,
                        absl::string_view name) {
  const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi;
  if (ok) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(field, ".", name, " = ", value, " is not in ",
                                                 lo_open ? "(" : "[", lo, ", ", hi, "]"));
}

}  // namespace

absl::Status ValidateComesh(const inbetween::v1::ComeshParameters& comesh,
                            absl::string_view field) {
  if (comesh.has_map_weight()) {
    if (auto s = CheckRange(comesh.map_weight(), 0, 1, false, field, "map_weight"); !s.ok()) {
      return s;
    }
  }
  if (comesh.max_outer_iterations() > 1000) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ".max_outer_iterations = ", comesh.max_outer_iterations(), " is not in [1, 1000]"));
  }
  if (comesh.max_inner_iterations() > 100000) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".max_inner_iterations = ", comesh.max_inner_iterations(),
                     " is not in [1, 100000]"));
  }
  if (comesh.has_outer_tolerance()) {
    if (!(std::isfinite(comesh.outer_tolerance()) && comesh.outer_tolerance() >= 0 &&
          comesh.outer_tolerance() < 1)) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".outer_tolerance = ", comesh.outer_tolerance(), " is not in [0, 1)"));
    }
  }
  if (comesh.has_outline_corner_degrees()) {
    if (auto s = CheckRange(comesh.outline_corner_degrees(), 0, 180, false, field,
                            "outline_corner_degrees");
        !s.ok()) {
      return s;
    }
  }
  if (comesh.has_slide_window()) {
    if (auto s = CheckRange(comesh.slide_window(), 0, 100, false, field, "slide_window"); !s.ok()) {
      return s;
    }
  }
  if (comesh.has_min_quality()) {
    if (!(std::isfinite(comesh.min_quality()) && comesh.min_quality() >= 0 &&
          comesh.min_quality() < 1)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".min_quality = ", comesh.min_quality(), " is not in [0, 1)"));
    }
  }
  if (comesh.tolerance() != 0) {
    if (!(std::isfinite(comesh.tolerance()) && comesh.tolerance() > 0 && comesh.tolerance() < 1)) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".tolerance = ", comesh.tolerance(), " is not in (0, 1)"));
    }
  }
  return absl::OkStatus();
}

absl::Status ValidateMeshing(const inbetween::v1::MeshingParameters& meshing,
                             absl::string_view field) {
  const uint32_t n = meshing.boundary_vertices();
  if (n != 0 && (n < 8 || n > 100000)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".boundary_vertices = ", n, " is not in [8, 100000]"));
  }
  if (meshing.max_edge_relative() != 0) {
    if (auto s = CheckRange(meshing.max_edge_relative(), 0, 1, true, field, "max_edge_relative");
        !s.ok()) {
      return s;
    }
  }
  if (meshing.shape_bound() != 0) {
    if (auto s = CheckRange(meshing.shape_bound(), 0, 0.125, true, field, "shape_bound"); !s.ok()) {
      return s;
    }
  }
  if (!inbetween::v1::CornerMatching_IsValid(meshing.corner_matching())) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".corner_matching = ",
                                                   meshing.corner_matching(),
                                                   " is not a known CornerMatching"));
  }
  if (meshing.has_boundary_tolerance() && meshing.boundary_tolerance() != 0) {
    if (auto s =
            CheckRange(meshing.boundary_tolerance(), 0, 0.1, true, field, "boundary_tolerance");
        !s.ok()) {
      return s;
    }
  }
  if (!inbetween::v1::BoundaryAlignment_IsValid(meshing.boundary_alignment())) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".boundary_alignment = ", meshing.boundary_alignment(),
                     " is not a known BoundaryAlignment"));
  }
  return absl::OkStatus();
}

absl::Status ValidateInbetween(const inbetween::v1::InbetweenParameters& p,
                               absl::string_view field) {
  if (!inbetween::v1::Method_IsValid(p.method())) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".method = ", p.method(), " is not a known Method"));
  }
  if (p.frames() > static_cast<uint32_t>(kMaxFrames)) {
    return absl::ResourceExhaustedError(
        absl::StrCat(field, ".frames = ", p.frames(), " exceeds the limit of ", kMaxFrames));
  }
  if (p.frames() == 1) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".frames = 1 is not in [2, ", kMaxFrames, "]"));
  }
  if (!inbetween::v1::TimingCurve_IsValid(p.timing())) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".timing = ", p.timing(), " is not a known TimingCurve"));
  }
  for (int i = 0; i < p.ease_size(); ++i) {
    if (auto s = CheckRange(p.ease(i), 0, 1, false, field, absl::StrCat("ease[", i, "]"));
        !s.ok()) {
      return s;
    }
  }
  for (int i = 0; i < p.stiffness_size(); ++i) {
    const inbetween::v1::StiffnessRegion& region = p.stiffness(i);
    const std::string name = absl::StrCat("stiffness[", i, "]");
    if (region.polygon().points_size() < 3) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".", name, ".polygon needs at least 3 points"));
    }
    for (const inbetween::v1::Point& q : region.polygon().points()) {
      if (!std::isfinite(q.x()) || !std::isfinite(q.y())) {
        return absl::InvalidArgumentError(
            absl::StrCat(field, ".", name, ".polygon has a non-finite point"));
      }
    }
    if (auto s = CheckRange(region.kappa(), 0, 1e6, true, field, name + ".kappa"); !s.ok()) {
      return s;
    }
  }
  if (p.has_lambda()) {
    if (auto s = CheckRange(p.lambda(), 0, 1e9, false, field, "lambda"); !s.ok()) return s;
  }
  if (p.has_tau()) {
    if (auto s = CheckRange(p.tau(), 0, 1e9, false, field, "tau"); !s.ok()) return s;
  }
  if (p.has_alpha()) {
    if (auto s = CheckRange(p.alpha(), 0, 1, false, field, "alpha"); !s.ok()) return s;
  }
  if (auto s = CheckRange(p.epsilon(), 0, 1e6, false, field, "epsilon"); !s.ok()) return s;
  if (p.has_rho()) {
    if (auto s = CheckRange(p.rho(), 0, 1e9, true, field, "rho"); !s.ok()) return s;
  }
  if (p.has_timestep()) {
    if (auto s = CheckRange(p.timestep(), 0, 10, true, field, "timestep"); !s.ok()) return s;
  }
  for (int i = 0; i < p.key_times_size(); ++i) {
    if (auto s = CheckRange(p.key_times(i), 0, 1, false, field, absl::StrCat("key_times[", i, "]"));
        !s.ok()) {
      return s;
    }
  }
  if (p.max_iterations() > 10000) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".max_iterations = ", p.max_iterations(), " is not in [1, 10000]"));
  }
  return absl::OkStatus();
}

absl::Status ValidateParameters(const inbetween::v1::Parameters& parameters,
                                absl::string_view field) {
  if (auto s = ValidateMeshing(parameters.meshing(), absl::StrCat(field, ".meshing")); !s.ok()) {
    return s;
  }
  if (auto s = ValidateComesh(parameters.comesh(), absl::StrCat(field, ".comesh")); !s.ok()) {
    return s;
  }
  return ValidateInbetween(parameters.inbetween(), absl::StrCat(field, ".inbetween"));
}

solver::MultimeshOptions ToMultimeshOptions(const inbetween::v1::MeshingParameters& meshing) {
  solver::MultimeshOptions options;
  options.boundary_vertices = static_cast<int>(meshing.boundary_vertices());
  options.max_edge_relative = meshing.max_edge_relative();
  if (meshing.shape_bound() != 0) options.shape_bound = meshing.shape_bound();
  switch (meshing.corner_matching()) {
    case inbetween::v1::CORNER_MATCHING_NEVER:
      options.corner_matching = solver::MultimeshOptions::CornerMatching::kNever;
      break;
    case inbetween::v1::CORNER_MATCHING_ALWAYS:
      options.corner_matching = solver::MultimeshOptions::CornerMatching::kAlways;
      break;
    default:  // unspecified or when arc length fails (validated before)
      options.corner_matching = solver::MultimeshOptions::CornerMatching::kWhenArcLengthFails;
      break;
  }
  if (meshing.has_boundary_tolerance()) options.boundary_tolerance = meshing.boundary_tolerance();
  options.correspondence =
      meshing.boundary_alignment() == inbetween::v1::BOUNDARY_ALIGNMENT_ARC_LENGTH
          ? solver::MultimeshOptions::Correspondence::kArcLength
          : solver::MultimeshOptions::Correspondence::kFeatures;
  return options;
}

solver::ComeshOptions ToComeshOptions(const inbetween::v1::ComeshParameters& comesh) {
  solver::ComeshOptions options;
  options.map_weight = comesh.has_map_weight() ? comesh.map_weight() : kDefaultMapWeight;
  options.max_outer = comesh.max_outer_iterations() == 0
                          ? kDefaultMaxOuterIterations
                          : static_cast<int>(comesh.max_outer_iterations());
  // Unset (0): the solver's defaults, which the proto documents (200 inner iterations, 1e-5).
  if (comesh.max_inner_iterations() != 0) {
    options.max_iterations = static_cast<int>(comesh.max_inner_iterations());
  }
  if (comesh.tolerance() != 0) options.relative_decrease_tolerance = comesh.tolerance();
  if (comesh.has_outer_tolerance()) options.outer_tolerance = comesh.outer_tolerance();
  // Unset: the solver's default (outline sliding at 25 degrees); 0: off.
  if (comesh.has_outline_corner_degrees()) {
    options.slide_outline = comesh.outline_corner_degrees() > 0.0;
    if (options.slide_outline) options.outline_corner_degrees = comesh.outline_corner_degrees();
  }
  if (comesh.has_min_quality()) options.min_quality = comesh.min_quality();  // unset: 0.02
  if (comesh.has_slide_window()) options.slide_window = comesh.slide_window();  // unset: 0
  return options;
}

double ComeshOutlineTolerance(const inbetween::v1::MeshingParameters& meshing) {
  return meshing.has_boundary_tolerance() && meshing.boundary_tolerance() > 0.0
             ? meshing.boundary_tolerance()
             : solver::MultimeshOptions{}.boundary_tolerance;
}

inbetween::v1::InbetweenParameters MergeInbetween(
    const inbetween::v1::InbetweenParameters& session,
    const inbetween::v1::InbetweenParameters& request) {
  inbetween::v1::InbetweenParameters out = session;
  if (request.method() != 0) out.set_method(request.method());
  if (request.frames() != 0) out.set_frames(request.frames());
  if (request.timing() != 0) out.set_timing(request.timing());
  if (request.ease_size() > 0) *out.mutable_ease() = request.ease();
  if (request.stiffness_size() > 0) *out.mutable_stiffness() = request.stiffness();
  if (request.has_lambda()) out.set_lambda(request.lambda());
  if (request.has_tau()) out.set_tau(request.tau());
  if (request.has_alpha()) out.set_alpha(request.alpha());
  if (request.epsilon() != 0) out.set_epsilon(request.epsilon());
  if (request.has_rho()) out.set_rho(request.rho());
  if (request.has_timestep()) out.set_timestep(request.timestep());
  if (request.max_iterations() != 0) out.set_max_iterations(request.max_iterations());
  if (request.key_times_size() > 0) *out.mutable_key_times() = request.key_times();
  return out;
}

absl::StatusOr<InbetweenPlan> ToInbetweenPlan(const inbetween::v1::InbetweenParameters& p,
                                              absl::string_view field) {
  if (auto s = ValidateInbetween(p, field); !s.ok()) return s;
  InbetweenPlan plan;
  if (p.frames() != 0) plan.frames = static_cast<int>(p.frames());
  solver::InbetweenOptions& o = plan.options;
  switch (p.method()) {
    case inbetween::v1::METHOD_LINEAR:
      o.method = solver::InterpMethod::kLinear;
      break;
    case inbetween::v1::METHOD_ALEXA:
      o.method = solver::InterpMethod::kAlexa;
      break;
    default:  // METHOD_UNSPECIFIED = METHOD_ZHU17; unknown values were rejected above.
      o.method = solver::InterpMethod::kZhu17;
      break;
  }
  // Proto defaults are written out here (not taken from the solver struct) because the proto is
  // the contract: a solver default change must not silently change the API.
  o.lambda = p.has_lambda() ? p.lambda() : 1.0;
  o.tau = p.has_tau() ? p.tau() : 0.1;
  o.alpha = p.has_alpha() ? p.alpha() : 0.5;
  o.epsilon = p.epsilon();
  o.rho = p.has_rho() ? p.rho() : 1.0;
  o.h = p.has_timestep() ? p.timestep() : 1.0 / 24;
  o.max_iterations = p.max_iterations() != 0 ? static_cast<int>(p.max_iterations()) : 20;
  return plan;
}

absl::StatusOr<solver::TimingOptions> ToTimingOptions(const inbetween::v1::InbetweenParameters& p,
                                                      int num_drawings, absl::string_view field) {
  solver::TimingOptions timing;
  switch (p.timing()) {
    case inbetween::v1::TIMING_CURVE_CATMULL_ROM:
      timing.curve = solver::TimingCurve::kCatmullRom;
      break;
    case inbetween::v1::TIMING_CURVE_EASE_IN_OUT: {
      const int segments = std::max(num_drawings - 1, 0);
      if (p.ease_size() > 0 && p.ease_size() != segments) {
        return absl::InvalidArgumentError(
            absl::StrCat(field, ".ease has ", p.ease_size(), " values, expected one per segment (",
                         segments, " for ", num_drawings, " drawings) or none"));
      }
      timing.easing.assign(segments, solver::Easing::kEaseInOut);
      timing.ease_amount.assign(p.ease().begin(), p.ease().end());
      break;
    }
    default:  // UNSPECIFIED = LINEAR; unknown values were rejected by ValidateInbetween.
      break;
  }
  return timing;
}

absl::StatusOr<solver::Schedule> ScheduleFrames(const inbetween::v1::InbetweenParameters& params,
                                                const inbetween::v1::Session& session, int frames,
                                                uint32_t start_frame, int max_frames) {
  if (frames > max_frames) {
    return absl::ResourceExhaustedError(absl::StrCat("parameters.frames = ", frames,
                                                     " exceeds the limit of ", max_frames,
                                                     " frames per request (--max-frames)"));
  }
  const int num_drawings = session.drawings_size();
  if (frames < num_drawings) {
    return absl::InvalidArgumentError(absl::StrCat("parameters.frames = ", frames,
                                                   " is fewer than the ", num_drawings,
                                                   " drawings (every drawing is a key frame)"));
  }
  if (start_frame >= static_cast<uint32_t>(frames)) {
    return absl::InvalidArgumentError(
        absl::StrCat("start_frame = ", start_frame, " is not in [0, frames = ", frames, ")"));
  }
  std::vector<double> key_times(params.key_times().begin(), params.key_times().end());
  const bool from_parameters = !key_times.empty();
  if (!from_parameters) {
    for (const inbetween::v1::Drawing& drawing : session.drawings()) {
      if (drawing.has_key_time()) key_times.push_back(drawing.key_time());
    }
    if (!key_times.empty() && static_cast<int>(key_times.size()) != num_drawings) {
      return absl::InvalidArgumentError(
          absl::StrCat("key_time is set on ", key_times.size(), " of ", num_drawings,
                       " drawings: set it on every drawing or on none"));
    }
  }
  absl::StatusOr<solver::TimingOptions> timing =
      ToTimingOptions(params, num_drawings, "parameters");
  if (!timing.ok()) return timing.status();
  absl::StatusOr<solver::Schedule> schedule =
      solver::MakeSchedule(num_drawings, frames, key_times, *timing);
  if (!schedule.ok()) {
    return absl::Status(schedule.status().code(),
                        absl::StrCat(from_parameters     ? "parameters.key_times: "
                                     : key_times.empty() ? "frame schedule: "
                                                         : "drawings' key_time: ",
                                     schedule.status().message()));
  }
  return schedule;
}

}  // namespace inbetween::server
