// Boundary correspondence for single-outline drawings: arc-length resampling to a common vertex
// count, then the cyclic shift minimising the squared distance between normalised boundaries
// (centred on their vertex mean, scaled to unit RMS radius). O(N^2) per drawing.
#include "solver/geometry/correspondence.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

constexpr int kDefaultVertices = 64;
constexpr int kMaxAutoVertices = 4096;

std::string Where(const Point& p) { return absl::StrCat("(", p.x(), ", ", p.y(), ")"); }

Points WithoutRepeats(const Points& points) {
  Points out;
  for (const Point& p : points) {
    if (out.empty() || p != out.back()) out.push_back(p);
  }
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  return out;
}

Points Normalized(const Points& points) {
  Point mean = Point::Zero();
  for (const Point& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const Point& p : points) sum += (p - mean).squaredNorm();
  const double rms = std::sqrt(sum / points.size());
  Points out;
  for (const Point& p : points) out.push_back((p - mean) / (rms > 0 ? rms : 1.0));
  return out;
}

int BestShift(const Points& reference, const Points& candidate) {
  const Points a = Normalized(reference);
  const Points b = Normalized(candidate);
  const int n = static_cast<int>(a.size());
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int s = 0; s < n; ++s) {
    double cost = 0.0;
    for (int k = 0; k < n && cost < best_cost; ++k) cost += (a[k] - b[(k + s) % n]).squaredNorm();
    if (cost < best_cost) best_cost = cost, best = s;
  }
  return best;
}

}  // namespace

absl::Status CheckSimplePolygon(const Points& polygon, const std::string& what) {
  for (size_t i = 0; i < polygon.size(); ++i) {
    if (!polygon[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": point ", i, " is not finite"));
    }
  }
  const Points p = WithoutRepeats(polygon);
  Points distinct = p;
  std::sort(distinct.begin(), distinct.end(), [](const Point& a, const Point& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  if (distinct.size() < 3) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": outline has only ", distinct.size(), " distinct point(s)",
                     distinct.empty() ? "" : absl::StrCat(" near ", Where(distinct[0]))));
  }
  if (auto hit = FindSelfIntersection(p)) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": outline crosses itself at ",
                                                   Where(hit->location), " (segments ",
                                                   hit->segment_a, " and ", hit->segment_b, ")"));
  }
  Point lo = p[0], hi = p[0];
  for (const Point& q : p) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  const double area = PolygonSignedArea(p);
  if (std::abs(area) <= 1e-12 * (hi - lo).squaredNorm()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": outline encloses no area (from ", Where(lo), " to ", Where(hi), ")"));
  }
  return absl::OkStatus();
}

absl::StatusOr<Correspondence> ComputeCorrespondence(const std::vector<Drawing>& drawings,
                                                     const CorrespondenceOptions& options) {
  if (drawings.empty()) return absl::InvalidArgumentError("no drawings");
  std::vector<Points> outlines;
  for (size_t d = 0; d < drawings.size(); ++d) {
    const auto& list = drawings[d].outlines;
    if (list.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("drawing ", d, " has no outline"));
    }
    if (list.size() > 1) {
      int holes = 0;
      for (const Outline& o : list) holes += PolygonSignedArea(o.points) < 0 ? 1 : 0;
      return absl::UnimplementedError(
          absl::StrCat("drawing ", d, " has ", list.size(), " outlines (", list.size() - holes,
                       " components, ", holes,
                       " holes); shapes of different topology need cuts/openings "
                       "(not yet supported)"));
    }
    const std::string what = absl::StrCat("drawing ", d);
    if (absl::Status s = CheckSimplePolygon(list[0].points, what); !s.ok()) return s;
    Points p = WithoutRepeats(list[0].points);
    // A single outline is the outer boundary whatever its direction: make it positive.
    if (PolygonSignedArea(p) < 0) std::reverse(p.begin() + 1, p.end());
    outlines.push_back(std::move(p));
  }

  int count = options.vertices;
  if (count <= 0) {
    count = kDefaultVertices;
    for (const Points& p : outlines) {
      const int corners =
          static_cast<int>(FindCorners(p, options.resample.corner_angle_degrees).size());
      count = std::max(count, std::min(2 * corners, kMaxAutoVertices));
    }
  }
  if (count < 3) {
    return absl::InvalidArgumentError(absl::StrCat("boundary vertex count ", count, " is < 3"));
  }

  Correspondence out;
  for (size_t d = 0; d < outlines.size(); ++d) {
    Points resampled = ResampleOutline(outlines[d], count, options.resample);
    int shift = 0;
    if (d > 0) {
      shift = BestShift(out.boundaries[0], resampled);
      std::rotate(resampled.begin(), resampled.begin() + shift, resampled.end());
    }
    const std::string what =
        absl::StrCat("drawing ", d, " resampled to ", count, " boundary vertices");
    if (absl::Status s = CheckSimplePolygon(resampled, what); !s.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(s.message(),
                       "; the outline has features thinner than the spacing, "
                       "use more boundary vertices"));
    }
    if (WithoutRepeats(resampled).size() != resampled.size()) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": repeated vertices"));
    }
    out.boundaries.push_back(std::move(resampled));
    out.shifts.push_back(shift);
  }
  return out;
}

}  // namespace inbetween::solver
