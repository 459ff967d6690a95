// The union of a drawing's paint and its cleaning (paint_union.h), over Clipper 6.
//
// Every layer is evaluated on its own first (its fill under its fill-rule, its stroke offset
// from its subpaths), so that the final union sees positively wound regions only and unites
// them under the "positive" rule. Cleaning is a morphological closing by half the gap width
// (grow, then shrink, with miter joins so that corners come back where they were), then islands
// and holes below the area threshold are dropped from the polygon tree.
#include "solver/io/paint_union.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <polyclipping/clipper.hpp>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "solver/geometry/polygon.h"

namespace inbetween::solver {
namespace {

namespace cl = ::ClipperLib;

// Coordinates are quantized into |c| <= kRange, inside Clipper's 32-bit fast range (its 128-bit
// products are only used beyond 2^30).
constexpr double kRange = 5.0e8;
// Miter limit of the closing's joins (in half gap widths): a corner sharper than about 1 degree
// loses its tip by at most the gap width.
constexpr double kClosingMiterLimit = 100.0;

// Maps user units to Clipper's integers and back.
class Quantizer {
 public:
  Quantizer(const Point& lo, const Point& hi) : origin_(0.5 * (lo + hi)) {
    const double half = 0.5 * (hi - lo).maxCoeff();
    scale_ = half > 0 ? kRange / half : 1.0;
  }
  cl::IntPoint ToInt(const Point& p) const {
    const Point q = (p - origin_) * scale_;
    return cl::IntPoint(static_cast<cl::cInt>(std::llround(q.x())),
                        static_cast<cl::cInt>(std::llround(q.y())));
  }
  Point ToPoint(const cl::IntPoint& p) const {
    return origin_ + Point(static_cast<double>(p.X), static_cast<double>(p.Y)) / scale_;
  }
  cl::Path ToPath(const Points& points) const {
    cl::Path path;
    path.reserve(points.size());
    for (const Point& p : points) {
      const cl::IntPoint q = ToInt(p);
      if (path.empty() || !(q == path.back())) path.push_back(q);
    }
    return path;
  }
  double Length(double user) const { return user * scale_; }
  double Area(double clipper_area) const { return clipper_area / (scale_ * scale_); }

 private:
  Point origin_;
  double scale_ = 1.0;
};

cl::JoinType JoinOf(LineJoin join) {
  switch (join) {
    case LineJoin::kRound:
      return cl::jtRound;
    case LineJoin::kBevel:
      return cl::jtSquare;  // Clipper's nearest: squared off at the half width
    case LineJoin::kMiter:
      break;
  }
  return cl::jtMiter;
}

cl::EndType EndOf(LineCap cap) {
  switch (cap) {
    case LineCap::kRound:
      return cl::etOpenRound;
    case LineCap::kSquare:
      return cl::etOpenSquare;
    case LineCap::kButt:
      break;
  }
  return cl::etOpenButt;
}

// The area a layer's stroke covers.
cl::Paths StrokeArea(const ArtLayer& layer, const Quantizer& q, double arc_tolerance) {
  const StrokePaint& stroke = *layer.stroke;
  // SVG's miter limit is the miter length over the width: the tip's distance from the vertex
  // over the half width, which is what Clipper's MiterLimit measures (Clipper's least is 2).
  cl::ClipperOffset offset(std::max(2.0, stroke.miter_limit), q.Length(arc_tolerance));
  const cl::JoinType join = JoinOf(stroke.join);
  for (const ArtPath& path : layer.paths) {
    if (stroke.dashes.empty()) {
      cl::Path p = q.ToPath(path.points);
      if (path.closed && p.size() >= 3) {
        offset.AddPath(p, join, cl::etClosedLine);
      } else if (p.size() >= 2 || (p.size() == 1 && stroke.cap != LineCap::kButt)) {
        // A zero-length subpath is drawn only by round and square caps (SVG 1.1, 11.4).
        offset.AddPath(p, join, EndOf(stroke.cap));
      }
      continue;
    }
    for (const Points& dash :
         DashPolyline(path.points, path.closed, stroke.dashes, stroke.dash_offset)) {
      cl::Path p = q.ToPath(dash);
      if (p.size() >= 2 || (p.size() == 1 && stroke.cap != LineCap::kButt)) {
        offset.AddPath(p, join, EndOf(stroke.cap));
      }
    }
  }
  cl::Paths out;
  offset.Execute(out, q.Length(0.5 * stroke.width));
  return out;
}

// The area a layer's fill covers, under its fill-rule.
cl::Paths FillArea(const ArtLayer& layer, const Quantizer& q) {
  cl::Clipper clipper;
  for (const ArtPath& path : layer.paths) {
    cl::Path p = q.ToPath(path.points);  // a fill closes every subpath
    if (p.size() >= 3) clipper.AddPath(p, cl::ptSubject, true);
  }
  cl::Paths out;
  clipper.Execute(cl::ctUnion, out, layer.fill->even_odd ? cl::pftEvenOdd : cl::pftNonZero);
  return out;
}

// Counts of outer loops and holes in a polygon tree.
struct LoopCounts {
  int outers = 0, holes = 0;
};
LoopCounts Count(const cl::PolyTree& tree) {
  LoopCounts c;
  for (const cl::PolyNode* n = tree.GetFirst(); n != nullptr; n = n->GetNext()) {
    (n->IsHole() ? c.holes : c.outers) += 1;
  }
  return c;
}

cl::Paths Offset(const cl::Paths& paths, double delta, double arc_tolerance) {
  cl::ClipperOffset offset(kClosingMiterLimit, arc_tolerance);
  offset.AddPaths(paths, cl::jtMiter, cl::etClosedPolygon);
  cl::Paths out;
  offset.Execute(out, delta);
  return out;
}

void UniteToTree(const cl::Paths& paths, cl::PolyTree* tree) {
  cl::Clipper clipper;
  clipper.AddPaths(paths, cl::ptSubject, true);
  clipper.Execute(cl::ctUnion, *tree, cl::pftNonZero, cl::pftNonZero);
}

}  // namespace

std::vector<Points> DashPolyline(const Points& points, bool closed,
                                 const std::vector<double>& dashes, double offset) {
  std::vector<Points> out;
  double period = 0;
  for (double d : dashes) period += d;
  if (points.empty() || dashes.empty() || !(period > 0)) return out;
  Points path = points;
  if (closed && path.size() > 1) path.push_back(path.front());
  // Position in the pattern at the path's start: SVG's offset shifts the pattern backwards.
  double phase = std::fmod(offset, period);
  if (phase < 0) phase += period;
  size_t index = 0;
  // The element of the pattern holding the start (a zero-length dash there is drawn).
  while (phase > dashes[index] || (phase == dashes[index] && dashes[index] > 0)) {
    phase -= dashes[index];
    index = (index + 1) % dashes.size();
  }
  double left = dashes[index] - phase;  // length remaining in the current dash or gap
  bool on = index % 2 == 0;
  Points current;
  if (on) current.push_back(path[0]);
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    Point a = path[i];
    const Point b = path[i + 1];
    double segment = (b - a).norm();
    while (segment > left) {
      const Point cut = a + (b - a) * (left / segment);
      if (on) {
        current.push_back(cut);
        out.push_back(std::move(current));
        current.clear();
      } else {
        current = {cut};
      }
      segment -= left;
      a = cut;
      on = !on;
      index = (index + 1) % dashes.size();
      left = dashes[index];
      // Zero-length dashes are single points; zero-length gaps join their dashes.
      while (left == 0) {
        if (on) out.push_back({a});
        on = !on;
        index = (index + 1) % dashes.size();
        left = dashes[index];
        if (on) current = {a};
      }
    }
    left -= segment;
    if (on) current.push_back(b);
  }
  if (on && !current.empty()) out.push_back(std::move(current));
  return out;
}

namespace {

// The fixed-point frame of the paint: its bounding box grown by the widest stroke's reach (a
// miter reaches at most miter_limit half widths from its vertex, a square cap sqrt(2)) and the gap
// width; INVALID_ARGUMENT when nothing is painted.
absl::StatusOr<Quantizer> PaintFrame(const std::vector<const ArtLayer*>& layers, double gap_width) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Point lo(kInf, kInf), hi(-kInf, -kInf);
  double margin = 0;
  for (const ArtLayer* layer : layers) {
    for (const ArtPath& path : layer->paths) {
      for (const Point& p : path.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
    if (layer->stroke) {
      margin = std::max(margin, 0.5 * layer->stroke->width *
                                    std::max({std::sqrt(2.0), layer->stroke->miter_limit, 2.0}));
    }
  }
  if (!(lo.x() <= hi.x())) return absl::InvalidArgumentError("nothing is painted");
  margin += gap_width;
  const Point pad(margin, margin);
  return Quantizer(lo - pad, hi + pad);
}

// One layer's paint: its fill and its stroke's area, united.
cl::Paths LayerPaint(const ArtLayer& layer, const Quantizer& q, double arc_tolerance) {
  cl::Paths fill, stroke;
  if (layer.fill) fill = FillArea(layer, q);
  if (layer.stroke && layer.stroke->width > 0) stroke = StrokeArea(layer, q, arc_tolerance);
  if (!fill.empty() && !stroke.empty()) {  // the layer's own paint, for its area
    cl::Clipper clipper;
    clipper.AddPaths(fill, cl::ptSubject, true);
    clipper.AddPaths(stroke, cl::ptSubject, true);
    clipper.Execute(cl::ctUnion, fill, cl::pftPositive, cl::pftPositive);
  } else if (fill.empty()) {
    fill = std::move(stroke);
  }
  return fill;
}

// Cascaded union: neighbours in paint order united pairwise, level by level, so that edges
// hidden under later paint leave early instead of crossing every other layer's in one sweep
// (benchmark "import" in docs/benchmarks.md).
cl::Paths CascadedUnion(std::vector<cl::Paths> pieces) {
  while (pieces.size() > 1) {
    std::vector<cl::Paths> next((pieces.size() + 1) / 2);
    for (size_t i = 0; i < next.size(); ++i) {
      if (2 * i + 1 == pieces.size()) {
        next[i] = std::move(pieces[2 * i]);
        continue;
      }
      cl::Clipper clipper;
      clipper.AddPaths(pieces[2 * i], cl::ptSubject, true);
      clipper.AddPaths(pieces[2 * i + 1], cl::ptSubject, true);
      clipper.Execute(cl::ctUnion, next[i], cl::pftPositive, cl::pftPositive);
    }
    pieces = std::move(next);
  }
  return pieces.empty() ? cl::Paths() : std::move(pieces[0]);
}

// Walks the tree into region->outlines: an outer loop below `min_area` goes with everything
// inside it; a hole below it is filled, and so covers whatever lies in it.
void CollectOutlines(const cl::PolyTree& tree, const Quantizer& q, double min_area,
                     PaintRegion* region) {
  std::vector<const cl::PolyNode*> stack;
  for (const cl::PolyNode* n : tree.Childs) stack.push_back(n);
  while (!stack.empty()) {
    const cl::PolyNode* node = stack.back();
    stack.pop_back();
    const double area = std::abs(cl::Area(node->Contour));
    const bool small = area < min_area;
    if (node->IsHole()) {
      if (small) {
        ++region->cleaning.holes_dropped;
        continue;
      }
      Outline hole;
      for (const cl::IntPoint& p : node->Contour) hole.points.push_back(q.ToPoint(p));
      if (PolygonSignedArea(hole.points) > 0) std::reverse(hole.points.begin(), hole.points.end());
      region->outlines.push_back(std::move(hole));
      for (const cl::PolyNode* child : node->Childs) stack.push_back(child);
      continue;
    }
    if (small) {
      ++region->cleaning.islands_dropped;
      continue;  // with its holes and whatever lies in them
    }
    Outline outer;
    for (const cl::IntPoint& p : node->Contour) outer.points.push_back(q.ToPoint(p));
    if (PolygonSignedArea(outer.points) < 0) std::reverse(outer.points.begin(), outer.points.end());
    region->outlines.push_back(std::move(outer));
    for (const cl::PolyNode* child : node->Childs) stack.push_back(child);
  }
}

}  // namespace

absl::StatusOr<PaintRegion> UnionOfPaint(const std::vector<const ArtLayer*>& layers,
                                         const PaintUnionOptions& options) {
  absl::StatusOr<Quantizer> frame = PaintFrame(layers, options.gap_width);
  if (!frame.ok()) return frame.status();
  const Quantizer& q = *frame;
  std::vector<cl::Paths> pieces;
  double layers_area = 0;
  for (const ArtLayer* layer : layers) {
    cl::Paths paint = LayerPaint(*layer, q, options.arc_tolerance);
    for (const cl::Path& p : paint) layers_area += cl::Area(p);
    if (!paint.empty()) pieces.push_back(std::move(paint));
  }
  const cl::Paths united = CascadedUnion(std::move(pieces));
  double united_area = 0;
  for (const cl::Path& p : united) united_area += cl::Area(p);
  if (!(std::abs(united_area) > 0)) {
    return absl::InvalidArgumentError(
        "no filled shape or stroke covers any area (subpaths without area, or strokes too thin "
        "to resolve)");
  }

  PaintRegion region;
  region.raw_area = q.Area(std::abs(united_area));
  region.layers_area = q.Area(std::abs(layers_area));
  region.cleaning.gap_width = options.gap_width;
  region.cleaning.min_area = options.min_area;
  const double arc = q.Length(options.arc_tolerance);
  cl::PolyTree tree;
  UniteToTree(united, &tree);
  if (options.gap_width > 0) {
    const double half = q.Length(0.5 * options.gap_width);
    region.hairline = Offset(united, -half, arc).empty();
    const LoopCounts before = Count(tree);
    const cl::Paths closed = Offset(Offset(united, half, arc), -half, arc);
    tree.Clear();
    UniteToTree(closed, &tree);
    const LoopCounts after = Count(tree);
    region.cleaning.gaps_closed = std::max(0, before.outers - after.outers);
    region.cleaning.slits_closed = std::max(0, before.holes - after.holes);
  }
  CollectOutlines(tree, q, q.Length(1.0) * q.Length(1.0) * options.min_area, &region);
  return region;
}

}  // namespace inbetween::solver
