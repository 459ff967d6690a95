// Per-triangle stiffness from regions: centroid-in-polygon in drawing 1's coordinates.
#include "server/stiffness_field.h"

#include "solver/geometry/polygon.h"

namespace inbetween::server {

std::vector<double> StiffnessPerTriangle(
    const solver::Multimesh& mesh,
    const google::protobuf::RepeatedPtrField<inbetween::v1::StiffnessRegion>& regions) {
  if (regions.empty() || mesh.shapes.empty()) return {};
  std::vector<solver::Points> polygons;
  for (const inbetween::v1::StiffnessRegion& region : regions) {
    solver::Points& polygon = polygons.emplace_back();
    for (const inbetween::v1::Point& p : region.polygon().points())
      polygon.emplace_back(p.x(), p.y());
  }
  const solver::Points& x = mesh.shapes[0];
  std::vector<double> kappa(mesh.triangles.size(), 1.0);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const solver::Triangle& tri = mesh.triangles[t];
    const solver::Point centroid = (x[tri[0]] + x[tri[1]] + x[tri[2]]) / 3.0;
    for (int r = regions.size() - 1; r >= 0; --r) {  // the last matching region wins
      if (solver::PolygonContains(polygons[r], centroid)) {
        kappa[t] = regions[r].kappa();
        break;
      }
    }
  }
  return kappa;
}

}  // namespace inbetween::server
