// Stage driver: drawings -> compatible multimesh. Correspondence of the boundaries, quality
// mesh of shape 1 (CGAL), its boundary Steiner points copied into every other boundary at the
// same segment parameter, then an injective map of the mesh into every other shape.
#include "solver/mesh/build_multimesh.h"

#include <chrono>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "solver/geometry/correspondence.h"
#include "solver/mesh/cgal_triangulate.h"
#include "solver/mesh/map_to_boundary.h"
#include "solver/mesh/split_boundary_chords.h"
#include "solver/mesh/validate.h"

namespace inbetween::solver {
namespace {

// Vertex indices of the boundary in order: shape 1's resampled boundary vertices with the
// boundary Steiner points of each segment after its start vertex.
std::vector<int> BoundaryOrder(int n, const std::vector<BoundarySteiner>& steiner) {
  std::vector<int> order;
  size_t next = 0;  // `steiner` is sorted by (segment, t)
  for (int s = 0; s < n; ++s) {
    order.push_back(s);
    for (; next < steiner.size() && steiner[next].segment == s; ++next) {
      order.push_back(steiner[next].vertex);
    }
  }
  return order;
}

}  // namespace

absl::StatusOr<Multimesh> BuildMultimesh(const std::vector<Drawing>& drawings,
                                         const MultimeshOptions& options, const CancelToken* cancel,
                                         const ProgressFn& progress, MultimeshReport* report) {
  const auto start = std::chrono::steady_clock::now();
  auto notify = [&](const std::string& stage, double fraction, const std::string& detail) {
    if (progress) progress(stage, fraction, detail);
  };
  auto cancelled = [&] { return cancel != nullptr && cancel->IsCancelled(); };
  const int num_shapes = static_cast<int>(drawings.size());
  if (num_shapes < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("a multimesh needs at least 2 drawings, got ", num_shapes));
  }
  for (int d = 0; d < num_shapes; ++d) {
    const auto& outlines = drawings[d].outlines;
    for (size_t o = 0; o < outlines.size(); ++o) {
      for (size_t p = 0; p < outlines[o].points.size(); ++p) {
        if (!outlines[o].points[p].allFinite()) {
          return absl::InvalidArgumentError(
              absl::StrCat("drawing ", d, ", outline ", o, ", point ", p, " is not finite"));
        }
      }
    }
  }

  if (cancelled()) return absl::CancelledError("BuildMultimesh cancelled");
  notify("correspondence", 0.0, absl::StrCat(num_shapes, " drawings"));
  CorrespondenceOptions correspondence_options;
  correspondence_options.vertices = options.boundary_vertices;
  absl::StatusOr<Correspondence> correspondence =
      ComputeCorrespondence(drawings, correspondence_options);
  if (!correspondence.ok()) return correspondence.status();
  const std::vector<Points>& boundaries = correspondence->boundaries;
  const int n = static_cast<int>(boundaries[0].size());

  if (cancelled()) return absl::CancelledError("BuildMultimesh cancelled");
  notify("triangulate", 0.1, absl::StrCat("drawing 0, ", n, " boundary vertices"));
  TriangulateOptions triangulate_options;
  triangulate_options.shape_bound = options.shape_bound;
  if (options.max_edge_relative > 0) {
    Point lo = boundaries[0][0], hi = lo;
    for (const Point& p : boundaries[0]) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    triangulate_options.max_edge = options.max_edge_relative * (hi - lo).norm();
  } else {
    // Automatic: interior edges about as long as the boundary spacing.
    double perimeter = 0.0;
    for (int i = 0; i < n; ++i) perimeter += (boundaries[0][(i + 1) % n] - boundaries[0][i]).norm();
    triangulate_options.max_edge = 1.5 * perimeter / n;
  }
  absl::StatusOr<PolygonTriangulation> triangulation =
      CgalTriangulate(boundaries[0], triangulate_options);
  if (!triangulation.ok()) {
    return absl::Status(triangulation.status().code(),
                        absl::StrCat("drawing 0: ", triangulation.status().message()));
  }

  Multimesh mesh;
  mesh.boundary = BoundaryOrder(n, triangulation->boundary_steiner);
  mesh.triangles = std::move(triangulation->triangles);
  Points vertices = std::move(triangulation->vertices);
  std::vector<bool> is_boundary(vertices.size(), false);
  for (int b : mesh.boundary) is_boundary[b] = true;
  SplitBoundaryChords(&vertices, &mesh.triangles, &is_boundary);
  mesh.shapes.push_back(vertices);

  for (int d = 1; d < num_shapes; ++d) {
    if (cancelled()) return absl::CancelledError("BuildMultimesh cancelled");
    notify("map", 0.2 + 0.75 * (d - 1) / (num_shapes - 1), absl::StrCat("drawing ", d));
    // Steiner points go to the same segment parameter of this drawing's boundary.
    Points target(vertices.size());
    for (int i = 0; i < n; ++i) target[i] = boundaries[d][i];
    for (const BoundarySteiner& s : triangulation->boundary_steiner) {
      target[s.vertex] =
          (1 - s.t) * boundaries[d][s.segment] + s.t * boundaries[d][(s.segment + 1) % n];
    }
    Points target_boundary;
    for (int b : mesh.boundary) target_boundary.push_back(target[b]);
    absl::StatusOr<Points> mapped =
        MapToBoundary(vertices, mesh.triangles, mesh.boundary, target_boundary, {}, cancel);
    if (!mapped.ok()) {
      if (absl::IsCancelled(mapped.status())) return mapped.status();
      return absl::FailedPreconditionError(
          absl::StrCat("cannot map mesh into drawing ", d, ": ", mapped.status().message()));
    }
    mesh.shapes.push_back(*std::move(mapped));
  }

  notify("validate", 0.95, absl::StrCat(mesh.num_vertices(), " vertices"));
  if (absl::Status valid = ValidateMultimesh(mesh); !valid.ok()) {
    return absl::InternalError(absl::StrCat("built multimesh is invalid: ", valid.message()));
  }
  if (report != nullptr) {
    report->vertices = mesh.num_vertices();
    report->triangles = static_cast<int>(mesh.triangles.size());
    report->seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  notify("done", 1.0,
         absl::StrCat(mesh.num_vertices(), " vertices, ", mesh.triangles.size(), " triangles"));
  return mesh;
}

}  // namespace inbetween::solver
