// SVG in: parses a document with libxml2 (no network, no entity expansion, no DTD loading) and
// walks it with SVG++, which resolves relative/shorthand path commands, arcs and quadratics to
// absolute cubic Beziers, turns basic shapes into paths and composes `transform` attributes.
// Filled subpaths are flattened adaptively and oriented by even-odd nesting depth.
//
// This is the only translation unit that instantiates SVG++ templates (compile time).
#include "solver/io/svg_import.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// SVG++'s arc-to-Bezier iterator trips GCC's -Wmaybe-uninitialized at -O2 (false positive in the
// library's own code, reported at instantiation in this file).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Geometry>
#include <svgpp/policy/xml/libxml2.hpp>
#include <svgpp/svgpp.hpp>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "solver/core/error_reason.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"
#include "solver/io/paint_union.h"

namespace inbetween::solver {
namespace {

namespace sv = ::svgpp;
using Affine = Eigen::Matrix<double, 2, 3>;  // [A | t]

constexpr char kSvgNamespace[] = "http://www.w3.org/2000/svg";
constexpr int kMaxSubdivisionDepth = 18;
constexpr int kMaxUseDepth = 8;
constexpr size_t kMaxElements = 100'000;  // elements after <use> expansion (fan-out bombs)
constexpr double kInf = std::numeric_limits<double>::infinity();

// Our own error raised from inside SVG++ callbacks; SVG++ attaches the element to it.
struct ImportError : virtual boost::exception, virtual std::exception {
  explicit ImportError(std::string m) : message(std::move(m)) {}
  const char* what() const noexcept override { return message.c_str(); }
  std::string message;
};

// The document needs more than SvgImportOptions::max_points points.
struct TooManyPoints : ImportError {
  explicit TooManyPoints(std::string m) : ImportError(std::move(m)) {}
};

using ElementInfo = boost::error_info<sv::tag::error_info::xml_element, xmlNode*>;

std::string Describe(const xmlNode* node) {
  if (node == nullptr) return "document";
  std::string out = absl::StrCat("<", reinterpret_cast<const char*>(node->name));
  if (xmlChar* id = xmlGetProp(node, reinterpret_cast<const xmlChar*>("id"))) {
    absl::StrAppend(&out, " id=\"", reinterpret_cast<const char*>(id), "\"");
    xmlFree(id);
  }
  absl::StrAppend(&out, "> (line ", xmlGetLineNo(node), ")");
  return out;
}

Point Apply(const Affine& m, double x, double y) {
  return m.leftCols<2>() * Point(x, y) + m.col(2);
}

// Appends the flattening of a cubic Bezier (p0 excluded) to `out`: subdivide until the control
// points are within `tolerance` of the chord (the curve lies in their convex hull).
void FlattenCubic(const Point& p0, const Point& p1, const Point& p2, const Point& p3,
                  double tolerance, int depth, Points* out) {
  const Point chord = p3 - p0;
  const double len = chord.norm();
  auto distance = [&](const Point& p) {
    if (len < 1e-300) return (p - p0).norm();
    return std::abs(Cross(chord, p - p0)) / len;
  };
  if (depth >= kMaxSubdivisionDepth || std::max(distance(p1), distance(p2)) <= tolerance) {
    out->push_back(p3);
    return;
  }
  const Point p01 = 0.5 * (p0 + p1), p12 = 0.5 * (p1 + p2), p23 = 0.5 * (p2 + p3);
  const Point p012 = 0.5 * (p01 + p12), p123 = 0.5 * (p12 + p23);
  const Point mid = 0.5 * (p012 + p123);
  FlattenCubic(p0, p01, p012, mid, tolerance, depth + 1, out);
  FlattenCubic(mid, p123, p23, p3, tolerance, depth + 1, out);
}

// The document has more than SvgImportOptions::max_layers painted layers.
struct TooManyLayers : ImportError {
  explicit TooManyLayers(std::string m) : ImportError(std::move(m)) {}
};

// The mean colour of a gradient's stops (the art model keeps plain colours), or nullopt when
// it has none (SVG paints a gradient without stops as "none").
struct GradientColour {
  std::optional<uint32_t> rgb;
  double opacity = 1.0;
};

// Where finished outlines and layers go, in document order.
struct Collector {
  double tolerance = 0.05;
  size_t max_points = 1'000'000;
  size_t max_layers = 100'000;
  size_t raw_points = 0;   // points written in path data so far
  size_t flat_points = 0;  // points after flattening so far
  // The filled elements' own outlines (the one-colour convention: SilhouetteSource::kElements).
  std::vector<Outline> outlines;
  std::vector<ArtLayer> art;              // painted elements, in paint order
  std::vector<ArtLayer> outline_class;    // class="outline" elements, as filled shapes
  std::vector<Points> cuts, openings;     // from class="cut" / class="opening" elements
  std::vector<CorrespondenceMark> marks;  // from data-corr="N" elements
  // The explicit fill of the filled element with the largest outline (SvgImportInfo::fill_rgb).
  double largest_area = 0;
  std::optional<uint32_t> largest_fill;
  std::vector<std::string> warnings;
  // Elements by id (paint servers are looked up here) and the gradients resolved so far.
  std::map<std::string, xmlNode*> by_id;
  std::map<std::string, GradientColour> gradients;
};

// The value of attribute `name`, or nullopt.
std::optional<std::string> Attribute(xmlNode* node, const char* name) {
  xmlChar* value = xmlGetProp(node, reinterpret_cast<const xmlChar*>(name));
  if (value == nullptr) return std::nullopt;
  std::string out = reinterpret_cast<const char*>(value);
  xmlFree(value);
  return out;
}

// A <use>'s or gradient's href (or xlink:href).
std::optional<std::string> UseHref(xmlNode* use) {
  std::optional<std::string> href = Attribute(use, "href");
  if (!href) {
    xmlChar* x = xmlGetNsProp(use, reinterpret_cast<const xmlChar*>("href"),
                              reinterpret_cast<const xmlChar*>("http://www.w3.org/1999/xlink"));
    if (x != nullptr) href = reinterpret_cast<const char*>(x), xmlFree(x);
  }
  return href;
}

// Whether the element's class attribute lists `token` (whitespace-separated).
bool HasClass(xmlNode* node, const std::string& token) {
  xmlChar* value = xmlGetProp(node, reinterpret_cast<const xmlChar*>("class"));
  if (value == nullptr) return false;
  const std::string classes = reinterpret_cast<const char*>(value);
  xmlFree(value);
  size_t pos = 0;
  while (pos < classes.size()) {
    const size_t begin = classes.find_first_not_of(" \t\n\r", pos);
    if (begin == std::string::npos) break;
    size_t end = classes.find_first_of(" \t\n\r", begin);
    if (end == std::string::npos) end = classes.size();
    if (classes.compare(begin, end - begin, token) == 0) return true;
    pos = end;
  }
  return false;
}

// The value of a presentation property: its attribute, or its declaration in style="" (which
// takes precedence, as CSS does over presentation attributes), split by SVG++'s own style
// tokenizer, the one its attribute traversal reads style="" with.
std::optional<std::string> Property(xmlNode* node, const char* name) {
  std::optional<std::string> value = Attribute(node, name);
  if (std::optional<std::string> style = Attribute(node, "style")) {
    for (sv::css_style_iterator<std::string::const_iterator> it(style->cbegin(), style->cend());
         !it.eof(); ++it) {
      if (std::string(it->first.begin(), it->first.end()) == name) {
        value = std::string(it->second.begin(), it->second.end());
      }
    }
  }
  return value;
}

// Receives one colour from SVG++'s colour grammar.
struct ColourSink {
  std::optional<uint32_t> rgb;
  void set(sv::tag::attribute::stop_color, int value) {
    rgb = static_cast<uint32_t>(value) & 0xffffffu;
  }
  template <class... Args>
  void set(sv::tag::attribute::stop_color, Args&&...) {}
};

// A colour written as SVG writes it (#rgb, #rrggbb, rgb(), a colour keyword), parsed by SVG++.
std::optional<uint32_t> ParseColour(const std::string& text) {
  ColourSink sink;
  try {
    sv::value_parser<sv::tag::type::color>::parse(sv::tag::attribute::stop_color(), sink, text,
                                                  sv::tag::source::attribute());
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return sink.rgb;
}

// A gradient's stops, following href to the gradient that holds them (up to kMaxUseDepth).
GradientColour MeanOfStops(xmlNode* gradient, const std::map<std::string, xmlNode*>& by_id) {
  for (int depth = 0; gradient != nullptr && depth < kMaxUseDepth; ++depth) {
    double r = 0, g = 0, b = 0, weight = 0, opacity = 0;
    int stops = 0;
    for (xmlNode* child = gradient->children; child != nullptr; child = child->next) {
      if (child->type != XML_ELEMENT_NODE ||
          xmlStrcmp(child->name, reinterpret_cast<const xmlChar*>("stop")) != 0) {
        continue;
      }
      ++stops;
      const uint32_t rgb = ParseColour(Property(child, "stop-color").value_or("black")).value_or(0);
      double alpha = 1.0;
      if (std::optional<std::string> a = Property(child, "stop-opacity")) {
        if (!absl::SimpleAtod(*a, &alpha) || !std::isfinite(alpha)) alpha = 1.0;
      }
      alpha = std::clamp(alpha, 0.0, 1.0);
      // Colours averaged weighted by their opacity (a transparent stop adds no colour).
      const double w = std::max(alpha, 1e-6);
      r += w * ((rgb >> 16) & 0xff), g += w * ((rgb >> 8) & 0xff), b += w * (rgb & 0xff);
      weight += w;
      opacity += alpha;
    }
    if (stops > 0) {
      auto channel = [&](double v) {
        return static_cast<uint32_t>(std::clamp(std::lround(v / weight), 0L, 255L));
      };
      return {(channel(r) << 16) | (channel(g) << 8) | channel(b), opacity / stops};
    }
    std::optional<std::string> href = UseHref(gradient);
    if (!href || href->size() < 2 || (*href)[0] != '#') break;
    auto it = by_id.find(href->substr(1));
    gradient = it == by_id.end() ? nullptr : it->second;
  }
  return {};
}

// A paint as written (fill or stroke); resolved to a colour when the layer is emitted.
struct PaintSpec {
  enum class Kind { kNone, kColour, kCurrentColour, kServer };
  Kind kind = Kind::kColour;
  uint32_t rgb = 0;                  // kColour
  std::string server;                // kServer: the referenced id
  std::optional<uint32_t> fallback;  // kServer: the fallback colour, if given
  bool fallback_none = false;        // kServer: "url(#x) none"
  bool given = false;                // set by the document (not SVG's initial black)

  static PaintSpec Of(Kind kind, uint32_t rgb = 0) {
    PaintSpec paint;
    paint.kind = kind;
    paint.rgb = rgb;
    paint.given = true;
    return paint;
  }
};

// A subpath as the pen drew it, in the element's local coordinates. A cubic segment is stored
// as its three points, the two control points flagged.
struct Subpath {
  Points points;
  std::vector<bool> is_control;
  bool closed = false;
};

// One context per SVG element (created on the stack by SVG++): inherits the transform and the
// fill state of its parent. Shape data is buffered and emitted in on_exit_element, because the
// attributes (d, transform, fill) may come in any order.
class Context {
 public:
  Context(Collector* collector, xmlNode* node) : collector_(collector), node_(node) {
    ctm_.setZero();
    ctm_(0, 0) = ctm_(1, 1) = 1.0;
  }
  // Inherited properties are copied; opacity is not inherited but multiplies into the
  // children's (group opacity), display:none hides the subtree.
  Context(const Context& parent, xmlNode* node)
      : collector_(parent.collector_),
        node_(node),
        ctm_(parent.ctm_),
        fill_(parent.fill_),
        stroke_(parent.stroke_),
        evenodd_(parent.evenodd_),
        colour_(parent.colour_),
        fill_opacity_(parent.fill_opacity_),
        stroke_opacity_(parent.stroke_opacity_),
        stroke_width_(parent.stroke_width_),
        cap_(parent.cap_),
        join_(parent.join_),
        miter_limit_(parent.miter_limit_),
        dashes_(parent.dashes_),
        dash_offset_(parent.dash_offset_),
        group_opacity_(parent.group_opacity_ * parent.opacity_),
        displayed_(parent.displayed_),
        visible_(parent.visible_),
        outline_class_(parent.outline_class_ || (node != nullptr && HasClass(node, "outline"))) {}

  // Transform (SVG++ composes the attribute's list into one matrix [a b c d e f]).
  void transform_matrix(const boost::array<double, 6>& m) {
    for (double v : m) CheckFinite(v, "transform");
    Affine local;
    local << m[0], m[2], m[4], m[1], m[3], m[5];
    Affine composed;
    composed.leftCols<2>() = ctm_.leftCols<2>() * local.leftCols<2>();
    composed.col(2) = ctm_.leftCols<2>() * local.col(2) + ctm_.col(2);
    ctm_ = composed;
  }

  // fill-rule (inherited; SVG's initial value is nonzero).
  void set(sv::tag::attribute::fill_rule, sv::tag::value::nonzero) { evenodd_ = false; }
  void set(sv::tag::attribute::fill_rule, sv::tag::value::evenodd) { evenodd_ = true; }
  void set(sv::tag::attribute::fill_rule, sv::tag::value::inherit) {}
  // Opacities (clamped to [0, 1], as CSS does).
  void set(sv::tag::attribute::opacity, double v) { opacity_ = Unit(v, "opacity"); }
  void set(sv::tag::attribute::fill_opacity, double v) { fill_opacity_ = Unit(v, "fill-opacity"); }
  void set(sv::tag::attribute::stroke_opacity, double v) {
    stroke_opacity_ = Unit(v, "stroke-opacity");
  }
  void set(sv::tag::attribute::color, int rgb) { colour_ = static_cast<uint32_t>(rgb) & 0xffffffu; }
  void set(sv::tag::attribute::stroke_width, double v) {
    CheckFinite(v, "stroke-width");
    if (v < 0) throw ImportError("stroke-width is negative");
    stroke_width_ = v;
  }
  void set(sv::tag::attribute::stroke_miterlimit, double v) {
    CheckFinite(v, "stroke-miterlimit");
    miter_limit_ = std::max(1.0, v);  // below 1 is an error in SVG; treated as 1
  }
  void set(sv::tag::attribute::stroke_dashoffset, double v) {
    CheckFinite(v, "stroke-dashoffset");
    dash_offset_ = v;
  }
  void set(sv::tag::attribute::stroke_dasharray, sv::tag::value::none) { dashes_.clear(); }
  void set(sv::tag::attribute::stroke_dasharray, sv::tag::value::inherit) {}
  template <class Range>
  void set(sv::tag::attribute::stroke_dasharray, const Range& values) {
    dashes_.clear();
    for (double v : values) {
      CheckFinite(v, "stroke-dasharray");
      if (v < 0) throw ImportError("stroke-dasharray has a negative length");
      dashes_.push_back(v);
    }
  }
  void set(sv::tag::attribute::stroke_linecap, sv::tag::value::butt) { cap_ = LineCap::kButt; }
  void set(sv::tag::attribute::stroke_linecap, sv::tag::value::round) { cap_ = LineCap::kRound; }
  void set(sv::tag::attribute::stroke_linecap, sv::tag::value::square) { cap_ = LineCap::kSquare; }
  void set(sv::tag::attribute::stroke_linejoin, sv::tag::value::miter) { join_ = LineJoin::kMiter; }
  void set(sv::tag::attribute::stroke_linejoin, sv::tag::value::round) { join_ = LineJoin::kRound; }
  void set(sv::tag::attribute::stroke_linejoin, sv::tag::value::bevel) { join_ = LineJoin::kBevel; }
  void set(sv::tag::attribute::display, sv::tag::value::none) { displayed_ = false; }
  void set(sv::tag::attribute::visibility, sv::tag::value::visible) { visible_ = true; }
  void set(sv::tag::attribute::visibility, sv::tag::value::hidden) { visible_ = false; }
  void set(sv::tag::attribute::visibility, sv::tag::value::collapse) { visible_ = false; }
  // Paint (fill, stroke): none, a colour, currentColor or a paint server; anything else (inherit
  // and the other values of the properties above) keeps the inherited state.
  template <class Tag, class... Args>
  void set(Tag, Args&&... args) {
    if constexpr (std::is_same_v<Tag, sv::tag::attribute::fill>) {
      SetPaint(&fill_, std::forward<Args>(args)...);
    } else if constexpr (std::is_same_v<Tag, sv::tag::attribute::stroke>) {
      SetPaint(&stroke_, std::forward<Args>(args)...);
    }
  }

  // Path events, absolute coordinates only (policy::path::minimal).
  void path_move_to(double x, double y, sv::tag::coordinate::absolute) {
    CheckFinite(x, "path data"), CheckFinite(y, "path data");
    subpaths_.emplace_back();
    Add(x, y, false);
    open_ = true;
  }
  void path_line_to(double x, double y, sv::tag::coordinate::absolute) {
    CheckFinite(x, "path data"), CheckFinite(y, "path data");
    StartIfNeeded();
    Add(x, y, false);
  }
  void path_cubic_bezier_to(double x1, double y1, double x2, double y2, double x, double y,
                            sv::tag::coordinate::absolute) {
    for (double v : {x1, y1, x2, y2, x, y}) CheckFinite(v, "path data");
    StartIfNeeded();
    Add(x1, y1, true);
    Add(x2, y2, true);
    Add(x, y, false);
  }
  // Elliptical arc (SVG 1.1 F.6.5, endpoint to centre parameterization), as cubic Beziers of at
  // most a quarter turn each. Done here rather than by SVG++ (policy ArcsOurs below): its
  // converter turns some valid arcs (a zero radius, which SVG draws as a straight line) into NaN.
  void path_elliptical_arc_to(double rx, double ry, double rotation_degrees, bool large_arc,
                              bool sweep, double x, double y, sv::tag::coordinate::absolute) {
    for (double v : {rx, ry, rotation_degrees, x, y}) CheckFinite(v, "path data");
    StartIfNeeded();
    const Point p1 = pen_, p2(x, y);
    if (p1 == p2) return;  // F.6.2: an arc to the current point is omitted
    rx = std::abs(rx), ry = std::abs(ry);
    if (rx == 0 || ry == 0) {  // F.6.2: a zero radius is a straight line
      Add(x, y, false);
      return;
    }
    const double phi = rotation_degrees * std::numbers::pi / 180.0;
    const double c = std::cos(phi), s = std::sin(phi);
    const Point h = 0.5 * (p1 - p2);
    const Point q(c * h.x() + s * h.y(), -s * h.x() + c * h.y());  // (x1', y1')
    const double lambda = (q.x() * q.x()) / (rx * rx) + (q.y() * q.y()) / (ry * ry);
    if (lambda > 1) rx *= std::sqrt(lambda), ry *= std::sqrt(lambda);  // F.6.6: scale up
    const double num = rx * rx * ry * ry - rx * rx * q.y() * q.y() - ry * ry * q.x() * q.x();
    const double den = rx * rx * q.y() * q.y() + ry * ry * q.x() * q.x();
    double coef = den > 0 ? std::sqrt(std::max(0.0, num / den)) : 0.0;
    if (large_arc == sweep) coef = -coef;
    const Point cq(coef * rx * q.y() / ry, -coef * ry * q.x() / rx);  // (cx', cy')
    const Point center(c * cq.x() - s * cq.y() + 0.5 * (p1.x() + p2.x()),
                       s * cq.x() + c * cq.y() + 0.5 * (p1.y() + p2.y()));
    auto angle = [](const Point& u, const Point& v) { return std::atan2(Cross(u, v), u.dot(v)); };
    const Point u((q.x() - cq.x()) / rx, (q.y() - cq.y()) / ry);
    const Point v((-q.x() - cq.x()) / rx, (-q.y() - cq.y()) / ry);
    const double theta1 = angle(Point(1, 0), u);
    double delta = angle(u, v);
    if (!sweep && delta > 0) delta -= 2 * std::numbers::pi;
    if (sweep && delta < 0) delta += 2 * std::numbers::pi;
    if (!std::isfinite(theta1) || !std::isfinite(delta)) {
      throw ImportError("path data has an arc that cannot be evaluated");
    }
    auto at = [&](double t) {  // point and derivative of the ellipse at angle t
      const Point e(rx * std::cos(t), ry * std::sin(t)), d(-rx * std::sin(t), ry * std::cos(t));
      return std::pair<Point, Point>{Point(c * e.x() - s * e.y(), s * e.x() + c * e.y()) + center,
                                     Point(c * d.x() - s * d.y(), s * d.x() + c * d.y())};
    };
    const int n =
        std::max(1, static_cast<int>(std::ceil(std::abs(delta) / (std::numbers::pi / 2))));
    const double step = delta / n, k = 4.0 / 3.0 * std::tan(step / 4);
    for (int i = 0; i < n; ++i) {
      const auto [a, da] = at(theta1 + i * step);
      auto [b, db] = at(theta1 + (i + 1) * step);
      if (i + 1 == n) b = p2;  // land exactly on the end point
      const Point c1 = a + k * da, c2 = b - k * db;
      for (double w : {c1.x(), c1.y(), c2.x(), c2.y(), b.x(), b.y()}) {
        CheckFinite(w, "path data");
      }
      Add(c1.x(), c1.y(), true);
      Add(c2.x(), c2.y(), true);
      Add(b.x(), b.y(), false);
    }
  }
  void path_close_subpath() {
    // The pen returns to the subpath start; a further drawing command starts a new subpath.
    if (!subpaths_.empty()) {
      pen_ = subpaths_.back().points.front();
      subpaths_.back().closed = true;
    }
    open_ = false;
  }
  void path_exit() {}

  void on_exit_element() {
    // Correspondence marks (docs/svg-convention.md): the centre of the element's bounding box.
    if (node_ != nullptr) {
      if (std::optional<std::string> corr = Attribute(node_, "data-corr")) {
        int id = 0;
        if (!absl::SimpleAtoi(*corr, &id) || id < 0) {
          throw ImportError(absl::StrCat("data-corr=\"", *corr, "\" is not a mark number"))
              << ElementInfo(node_);
        }
        Point lo(kInf, kInf), hi(-kInf, -kInf);
        for (const Subpath& subpath : subpaths_) {
          for (const Point& p : Flatten(subpath)) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
        }
        if (!(lo.x() <= hi.x())) {
          throw ImportError("a data-corr mark needs some geometry") << ElementInfo(node_);
        }
        collector_->marks.push_back({id, 0.5 * (lo + hi)});
        return;
      }
    }
    // Topology edits (docs/svg-convention.md): class="cut" / class="opening" elements are open
    // polylines whatever their paint; they never become outlines.
    const bool cut = node_ != nullptr && HasClass(node_, "cut");
    const bool opening = node_ != nullptr && !cut && HasClass(node_, "opening");
    if (cut || opening) {
      for (const Subpath& subpath : subpaths_) {
        Points line = Flatten(subpath);
        if (subpath.closed && line.size() > 1 && line.back() != line.front()) {
          line.push_back(line.front());
        }
        if (line.size() >= 2) (cut ? collector_->cuts : collector_->openings).push_back(line);
      }
      return;
    }
    if (subpaths_.empty()) return;  // a group, or a shape without geometry
    const bool shown = displayed_ && visible_ && group_opacity_ * opacity_ > 0;
    std::optional<FillPaint> fill = shown ? ResolveFill() : std::nullopt;
    std::optional<StrokePaint> stroke = shown ? ResolveStroke() : std::nullopt;
    if (outline_class_) {  // the silhouette, whatever its paint (docs/svg-convention.md)
      ArtLayer shape = MakeLayer();
      shape.fill = FillPaint{0, 1.0, evenodd_};
      if (stroke) shape.stroke = stroke;
      collector_->outline_class.push_back(std::move(shape));
    }
    if (!fill && !stroke) return;
    if (collector_->art.size() >= collector_->max_layers) {
      throw TooManyLayers(absl::StrCat("more than ", collector_->max_layers, " painted layers"));
    }
    ArtLayer layer = MakeLayer();
    layer.fill = fill;
    layer.stroke = stroke;
    layer.opacity = group_opacity_ * opacity_;
    collector_->art.push_back(std::move(layer));
    if (!fill) return;
    // The element's own outlines, as the one-colour convention reads them.
    std::vector<Outline> outlines;
    for (const Subpath& subpath : subpaths_) Emit(subpath, &outlines);
    if (!evenodd_) DropNonzeroInnerBoundaries(&outlines);
    for (Outline& o : outlines) {
      const double area = std::abs(PolygonSignedArea(o.points));
      if (area > collector_->largest_area) {
        collector_->largest_area = area;
        collector_->largest_fill = fill_.kind == PaintSpec::Kind::kColour && fill_.given
                                       ? std::optional<uint32_t>(fill_.rgb)
                                       : std::nullopt;
      }
      collector_->outlines.push_back(std::move(o));
    }
  }

 private:
  void CheckFinite(double v, const char* what) const {
    if (!std::isfinite(v)) throw ImportError(absl::StrCat(what, " has a non-finite coordinate"));
  }
  void StartIfNeeded() {
    if (!open_) {  // after 'Z' a new subpath begins where the previous one started
      subpaths_.emplace_back();
      subpaths_.back().points.push_back(pen_);
      subpaths_.back().is_control.push_back(false);
      open_ = true;
    }
  }
  void Add(double x, double y, bool control) {
    if (++collector_->raw_points > collector_->max_points) {
      throw TooManyPoints(
          absl::StrCat("more than ", collector_->max_points, " points in its path data"));
    }
    subpaths_.back().points.emplace_back(x, y);
    subpaths_.back().is_control.push_back(control);
    if (!control) pen_ = Point(x, y);
  }

  // Transforms and flattens one subpath (consecutive duplicates removed).
  Points Flatten(const Subpath& subpath) const {
    const Points& raw = subpath.points;
    Points flat = {Apply(ctm_, raw[0].x(), raw[0].y())};
    for (size_t i = 1; i < raw.size();) {
      if (subpath.is_control[i] && i + 2 < raw.size()) {
        const Point p0 = flat.back();
        FlattenCubic(p0, Apply(ctm_, raw[i].x(), raw[i].y()),
                     Apply(ctm_, raw[i + 1].x(), raw[i + 1].y()),
                     Apply(ctm_, raw[i + 2].x(), raw[i + 2].y()), collector_->tolerance, 0, &flat);
        i += 3;
      } else {
        flat.push_back(Apply(ctm_, raw[i].x(), raw[i].y()));
        ++i;
      }
      if (collector_->flat_points + flat.size() > collector_->max_points) {
        throw TooManyPoints(absl::StrCat(
            "more than ", collector_->max_points,
            " points once its curves are flattened (raise the flatten tolerance or simplify "
            "the drawing)"));
      }
    }
    collector_->flat_points += flat.size();
    Points out;
    for (const Point& p : flat) {
      if (!p.allFinite()) throw ImportError("the transformed coordinates are not finite");
      if (out.empty() || p != out.back()) out.push_back(p);
    }
    return out;
  }

  // Whether outline `a` lies inside outline `b`, for outlines that do not cross but may touch
  // (share a vertex, or run along each other): decided at the midpoint of the first of a's
  // edges (at most 16 tried) that is not on b's boundary, not at a's first point, which may be
  // a vertex of b (bootstrap-icons' dropbox: the answer there went either way).
  static bool NestedIn(const Points& a, const Points& b) {
    Point lo = b[0], hi = b[0];
    for (const Point& p : b) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double eps = 1e-9 * (hi - lo).norm();
    const size_t n = a.size(), m = b.size();
    for (size_t k = 0; k < std::min<size_t>(n, 16); ++k) {
      const Point q = 0.5 * (a[k] + a[(k + 1) % n]);
      if (q.x() < lo.x() - eps || q.y() < lo.y() - eps || q.x() > hi.x() + eps ||
          q.y() > hi.y() + eps) {
        return false;  // a point of a outside b's box: a is not inside b
      }
      double distance = kInf;
      for (size_t j = 0; j < m && distance > eps; ++j) {
        distance = std::min(distance, DistanceToSegment(q, b[j], b[(j + 1) % m]));
      }
      if (distance > eps) return PolygonContains(b, q);
    }
    return PolygonContains(b, a[0]);
  }

  // fill-rule nonzero: a subpath nested in this element's others is a boundary only if the
  // winding number changes between zero and non-zero across it (a same-direction subpath inside
  // a filled one is filled on both sides and dropped). Subpaths that cross are left as they
  // are (the boundary builder reports crossing outlines).
  static void DropNonzeroInnerBoundaries(std::vector<Outline>* outlines) {
    const size_t n = outlines->size();
    if (n < 2) return;
    std::vector<int> sign(n);
    for (size_t i = 0; i < n; ++i) sign[i] = PolygonSignedArea((*outlines)[i].points) > 0 ? 1 : -1;
    std::vector<bool> boundary(n);
    for (size_t i = 0; i < n; ++i) {
      int winding = sign[i];  // just inside outline i
      for (size_t j = 0; j < n; ++j) {
        if (j != i && NestedIn((*outlines)[i].points, (*outlines)[j].points)) winding += sign[j];
      }
      boundary[i] = (winding != 0) != (winding - sign[i] != 0);
    }
    std::vector<Outline> kept;
    for (size_t i = 0; i < n; ++i) {
      if (boundary[i]) kept.push_back(std::move((*outlines)[i]));
    }
    *outlines = std::move(kept);
  }

  // Whether the closed polyline has an area that is not zero up to rounding: above 1e-9 of its
  // bounding box's diagonal squared (a width above 1e-9 of its length). Three collinear points
  // (bootstrap-icons' emoji-kiss has such a subpath) have an area of about 1e-17 from rounding,
  // or exactly 0 depending on the transform: the icon and its rotated copy differed by a hole.
  static bool EnclosesArea(const Points& points) {
    // Measured on the points scaled into [-1, 1]: huge coordinates (1e308, refused later with
    // their own message) would overflow the area and the diagonal to inf.
    double scale = 0.0;
    for (const Point& p : points) scale = std::max(scale, p.cwiseAbs().maxCoeff());
    if (!(scale > 0) || !std::isfinite(scale)) return scale > 0;
    Points unit;
    unit.reserve(points.size());
    for (const Point& p : points) unit.push_back(p / scale);
    Point lo = unit[0], hi = unit[0];
    for (const Point& p : unit) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return std::abs(PolygonSignedArea(unit)) > 1e-9 * (hi - lo).squaredNorm();
  }

  // Flattens and closes one subpath; keeps it when it encloses some area.
  void Emit(const Subpath& subpath, std::vector<Outline>* outlines) const {
    // A fill closes every subpath implicitly; drop the repeated closing point.
    Outline outline;
    outline.points = Flatten(subpath);
    while (outline.points.size() > 1 && outline.points.back() == outline.points.front()) {
      outline.points.pop_back();
    }
    // A subpath that ends a hair short of its start (path data rounded to three decimals:
    // "...h-.668z" stopping 0.001 before the first point) would close with a segment folding
    // back along its neighbours, far below what the flattening resolves: the last point is
    // dropped while it lies within the flatten tolerance and within 1e-3 of the subpath's size
    // of the first (docs/svg-convention.md).
    if (outline.points.size() > 3) {
      Point lo = outline.points[0], hi = lo;
      for (const Point& p : outline.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      const double gap = std::min(collector_->tolerance, 1e-3 * (hi - lo).norm());
      while (outline.points.size() > 3 &&
             (outline.points.back() - outline.points.front()).norm() <= gap) {
        outline.points.pop_back();
      }
    }
    if (outline.points.size() >= 3 && EnclosesArea(outline.points)) {
      outlines->push_back(std::move(outline));
    }
  }

  static double Unit(double v, const char* what) {
    if (!std::isfinite(v)) throw ImportError(absl::StrCat(what, " is not a number"));
    return std::clamp(v, 0.0, 1.0);
  }

  void SetPaint(PaintSpec* paint, sv::tag::value::none) {
    *paint = PaintSpec::Of(PaintSpec::Kind::kNone);
  }
  void SetPaint(PaintSpec* paint, sv::tag::value::currentColor) {
    *paint = PaintSpec::Of(PaintSpec::Kind::kCurrentColour);
  }
  void SetPaint(PaintSpec*, sv::tag::value::inherit) {}
  void SetPaint(PaintSpec* paint, int rgb) {
    *paint = PaintSpec::Of(PaintSpec::Kind::kColour, static_cast<uint32_t>(rgb) & 0xffffffu);
  }
  template <class Icc>
  void SetPaint(PaintSpec* paint, int rgb, const Icc&) {
    SetPaint(paint, rgb);
  }
  // url(#id) with an optional fallback.
  template <class Range, class... Fallback>
  void SetPaint(PaintSpec* paint, sv::tag::iri_fragment, const Range& id, Fallback&&... fallback) {
    *paint = PaintSpec::Of(PaintSpec::Kind::kServer);
    paint->server.assign(boost::begin(id), boost::end(id));
    SetFallback(paint, std::forward<Fallback>(fallback)...);
  }
  // url(other-document#id): never fetched; its fallback, or none.
  template <class Range, class... Fallback>
  void SetPaint(PaintSpec* paint, const Range&, Fallback&&... fallback) {
    *paint = PaintSpec::Of(PaintSpec::Kind::kServer);
    SetFallback(paint, std::forward<Fallback>(fallback)...);
  }
  void SetFallback(PaintSpec*) {}
  void SetFallback(PaintSpec* paint, sv::tag::value::none) { paint->fallback_none = true; }
  void SetFallback(PaintSpec* paint, sv::tag::value::currentColor) { paint->fallback = colour_; }
  void SetFallback(PaintSpec* paint, int rgb) {
    paint->fallback = static_cast<uint32_t>(rgb) & 0xffffffu;
  }
  template <class Icc>
  void SetFallback(PaintSpec* paint, int rgb, const Icc&) {
    SetFallback(paint, rgb);
  }

  void Warn(const std::string& what) const {
    collector_->warnings.push_back(absl::StrCat(Describe(node_), ": ", what));
  }

  // A paint's colour and opacity factor, or nullopt when it paints nothing.
  std::optional<std::pair<uint32_t, double>> Resolve(const PaintSpec& paint, const char* what) {
    switch (paint.kind) {
      case PaintSpec::Kind::kNone:
        return std::nullopt;
      case PaintSpec::Kind::kColour:
        return std::make_pair(paint.rgb, 1.0);
      case PaintSpec::Kind::kCurrentColour:
        return std::make_pair(colour_, 1.0);
      case PaintSpec::Kind::kServer:
        break;
    }
    auto it = collector_->by_id.find(paint.server);
    const bool gradient =
        it != collector_->by_id.end() &&
        (xmlStrcmp(it->second->name, reinterpret_cast<const xmlChar*>("linearGradient")) == 0 ||
         xmlStrcmp(it->second->name, reinterpret_cast<const xmlChar*>("radialGradient")) == 0);
    if (gradient) {
      auto [cached, inserted] = collector_->gradients.emplace(paint.server, GradientColour{});
      if (inserted) cached->second = MeanOfStops(it->second, collector_->by_id);
      if (!cached->second.rgb) {
        Warn(absl::StrCat(what, " gradient \"", paint.server, "\" has no stops: painted as none"));
        return std::nullopt;
      }
      Warn(absl::StrCat(what, " gradient \"", paint.server,
                        "\" is drawn as the mean colour of its stops"));
      return std::make_pair(*cached->second.rgb, cached->second.opacity);
    }
    if (paint.fallback_none) return std::nullopt;
    if (paint.fallback) {
      Warn(absl::StrCat(what, " paint server \"", paint.server, "\" drawn as its fallback"));
      return std::make_pair(*paint.fallback, 1.0);
    }
    if (it == collector_->by_id.end()) {  // an error in SVG; drawn as it always was here
      Warn(absl::StrCat(what, " references unknown paint server \"", paint.server,
                        "\": drawn black"));
      return std::make_pair(0u, 1.0);
    }
    Warn(absl::StrCat(what, " paint server \"", paint.server, "\" (a pattern) is drawn black"));
    return std::make_pair(0u, 1.0);
  }

  std::optional<FillPaint> ResolveFill() {
    std::optional<std::pair<uint32_t, double>> paint = Resolve(fill_, "fill");
    if (!paint || fill_opacity_ * paint->second <= 0) return std::nullopt;
    return FillPaint{paint->first, fill_opacity_ * paint->second, evenodd_};
  }

  std::optional<StrokePaint> ResolveStroke() {
    if (stroke_.kind == PaintSpec::Kind::kNone) return std::nullopt;
    if (stroke_width_ <= 0) {
      Warn("stroke-width 0: the stroke is not painted");
      return std::nullopt;
    }
    std::optional<std::pair<uint32_t, double>> paint = Resolve(stroke_, "stroke");
    if (!paint || stroke_opacity_ * paint->second <= 0) return std::nullopt;
    // Widths in the drawing's units: scaled by the transform's mean scale sqrt|det|.
    const double scale = std::sqrt(std::abs(ctm_.leftCols<2>().determinant()));
    StrokePaint out;
    out.rgb = paint->first;
    out.opacity = stroke_opacity_ * paint->second;
    out.width = stroke_width_ * scale;
    if (!(out.width > 0) || !std::isfinite(out.width)) return std::nullopt;
    out.cap = cap_;
    out.join = join_;
    out.miter_limit = miter_limit_;
    double period = 0;
    for (double d : dashes_) period += d;
    if (period > 0) {  // SVG: an odd count repeats; all zeros draw a solid line
      out.dashes = dashes_;
      if (out.dashes.size() % 2 == 1)
        out.dashes.insert(out.dashes.end(), dashes_.begin(), dashes_.end());
      for (double& d : out.dashes) d *= scale;
      out.dash_offset = dash_offset_ * scale;
    }
    return out;
  }

  // The element's geometry as a layer without paint: flattened, transformed subpaths.
  ArtLayer MakeLayer() const {
    ArtLayer layer;
    layer.id = Attribute(node_, "id").value_or("");
    for (xmlNode* n = node_; n != nullptr && n->type == XML_ELEMENT_NODE; n = n->parent) {
      if (std::optional<std::string> name = Attribute(n, "data-layer")) {
        layer.name = *name;
        break;
      }
    }
    for (const Subpath& subpath : subpaths_) {
      ArtPath path;
      path.points = Flatten(subpath);
      path.closed = subpath.closed;
      while (path.closed && path.points.size() > 1 && path.points.back() == path.points.front()) {
        path.points.pop_back();
      }
      if (!path.points.empty()) layer.paths.push_back(std::move(path));
    }
    return layer;
  }

  Collector* collector_;
  xmlNode* node_;
  Affine ctm_;
  PaintSpec fill_;  // SVG's initial fill: black, not given
  PaintSpec stroke_ = PaintSpec::Of(PaintSpec::Kind::kNone);  // and its initial stroke none
  bool evenodd_ = false;                                      // SVG's initial fill-rule is nonzero
  uint32_t colour_ = 0;                                       // the color property (currentColor)
  double fill_opacity_ = 1.0, stroke_opacity_ = 1.0;          // inherited
  double stroke_width_ = 1.0;
  LineCap cap_ = LineCap::kButt;
  LineJoin join_ = LineJoin::kMiter;
  double miter_limit_ = 4.0;
  std::vector<double> dashes_;
  double dash_offset_ = 0.0;
  double opacity_ = 1.0;        // this element's own opacity (not inherited)
  double group_opacity_ = 1.0;  // the product of its ancestors' opacities
  bool displayed_ = true;       // false under display:none (the whole subtree)
  bool visible_ = true;         // visibility (inherited, a child may override)
  bool outline_class_ = false;  // class="outline" on it or an ancestor
  std::vector<Subpath> subpaths_;
  Point pen_ = Point::Zero();
  bool open_ = false;
};

struct ContextFactories {
  template <class ParentContext, class ElementTag>
  struct apply {
    using type = sv::factory::context::on_stack_with_xml_element<Context>;
  };
};

// Raise SVG++'s exceptions for bad values, but skip elements and attributes it does not know
// (editor metadata such as data-* attributes or sodipodi:* elements).
struct ErrorPolicy : sv::policy::error::raise_exception<Context> {
  template <class XMLElement, class ElementName>
  static bool unknown_element(const Context&, const XMLElement&, const ElementName&) {
    return true;  // continue with the next sibling
  }
  template <class XMLAttribute, class AttributeName>
  static bool unknown_attribute(const Context&, const XMLAttribute&, const AttributeName&,
                                BOOST_SCOPED_ENUM(sv::detail::namespace_id),
                                sv::tag::source::attribute) {
    return true;
  }
  template <class XMLAttribute, class AttributeName>
  static bool unknown_attribute(const Context&, const XMLAttribute&, const AttributeName&,
                                sv::tag::source::css) {
    return true;
  }
};

using ProcessedElements =
    boost::mpl::set<sv::tag::element::svg, sv::tag::element::g, sv::tag::element::path,
                    sv::tag::element::rect, sv::tag::element::circle, sv::tag::element::ellipse,
                    sv::tag::element::polygon, sv::tag::element::polyline,
                    sv::tag::element::line>::type;
// The geometry's attributes, the transform and every property of the art model.
template <class Set, class... Tags>
struct InsertAll {
  using type = Set;
};
template <class Set, class Tag, class... Tags>
struct InsertAll<Set, Tag, Tags...> {
  using type = typename InsertAll<typename boost::mpl::insert<Set, Tag>::type, Tags...>::type;
};
using ProcessedAttributesWithFillRule =
    InsertAll<sv::traits::shapes_attributes_by_element, sv::tag::attribute::transform,
              sv::tag::attribute::fill, sv::tag::attribute::fill_rule,
              sv::tag::attribute::fill_opacity, sv::tag::attribute::stroke,
              sv::tag::attribute::stroke_width, sv::tag::attribute::stroke_opacity,
              sv::tag::attribute::stroke_linecap, sv::tag::attribute::stroke_linejoin,
              sv::tag::attribute::stroke_miterlimit, sv::tag::attribute::stroke_dasharray,
              sv::tag::attribute::stroke_dashoffset, sv::tag::attribute::opacity,
              sv::tag::attribute::color, sv::tag::attribute::display,
              sv::tag::attribute::visibility>::type;

// SVG++'s minimal path policy, except that arcs come to Context::path_elliptical_arc_to.
struct PathPolicy : sv::policy::path::minimal {
  static const bool arc_as_cubic_bezier = false;
};

using Traversal =
    sv::document_traversal<sv::processed_elements<ProcessedElements>,
                           sv::processed_attributes<ProcessedAttributesWithFillRule>,
                           sv::context_factories<ContextFactories>, sv::path_policy<PathPolicy>,
                           sv::basic_shapes_policy<sv::policy::basic_shapes::all_to_path>,
                           sv::error_policy<ErrorPolicy>>;

// libxml2 reports some errors without the parser's context (an input encoding conversion that
// fails, the I/O layer's "encoder error"), to the thread's generic error handler, which prints
// them on stderr whatever XML_PARSE_NOERROR says: in the server, user input would write to the
// log. While one is alive, this thread's handler (libxml2 keeps one per thread) ignores them;
// the failure still comes back through the parser (xmlCtxtGetLastError). Restores the previous
// handler.
void IgnoreXmlError(void* /*context*/, const char* /*format*/, ...) {}
class QuietXmlErrors {
 public:
  QuietXmlErrors() : handler_(xmlGenericError), context_(xmlGenericErrorContext) {
    xmlSetGenericErrorFunc(nullptr, IgnoreXmlError);
  }
  ~QuietXmlErrors() { xmlSetGenericErrorFunc(context_, handler_); }
  QuietXmlErrors(const QuietXmlErrors&) = delete;
  QuietXmlErrors& operator=(const QuietXmlErrors&) = delete;

 private:
  xmlGenericErrorFunc handler_;
  void* context_;
};

struct DocDeleter {
  void operator()(xmlDoc* doc) const { xmlFreeDoc(doc); }
};
struct ParserDeleter {
  void operator()(xmlParserCtxt* ctxt) const { xmlFreeParserCtxt(ctxt); }
};

// Entities are never expanded (XML_PARSE_NOENT is off), but libxml2 would still substitute them
// when SVG++ reads an attribute value; refuse any reference instead of reading it.
const xmlNode* FindEntityReference(const xmlNode* node) {
  for (; node != nullptr; node = node->next) {
    if (node->type == XML_ENTITY_REF_NODE) return node;
    if (node->type == XML_ELEMENT_NODE) {
      for (const xmlAttr* attr = node->properties; attr != nullptr; attr = attr->next) {
        for (const xmlNode* child = attr->children; child; child = child->next) {
          if (child->type == XML_ENTITY_REF_NODE) return node;
        }
      }
      if (const xmlNode* found = FindEntityReference(node->children)) return found;
    }
  }
  return nullptr;
}

// The first element with a non-ASCII byte in an attribute SVG++ parses (Boost.Spirit asserts on
// such characters in its case-insensitive keyword matching: svg_import_fuzz finding), with the
// attribute's name.
std::optional<std::pair<const xmlNode*, std::string>> FindNonAsciiParsedAttribute(
    const xmlNode* root) {
  static const std::set<std::string> kParsed = {"d",
                                                "points",
                                                "transform",
                                                "style",
                                                "fill",
                                                "fill-rule",
                                                "x",
                                                "y",
                                                "width",
                                                "height",
                                                "cx",
                                                "cy",
                                                "r",
                                                "rx",
                                                "ry",
                                                "x1",
                                                "y1",
                                                "x2",
                                                "y2",
                                                "stroke",
                                                "stroke-width",
                                                "stroke-opacity",
                                                "stroke-linecap",
                                                "stroke-linejoin",
                                                "stroke-miterlimit",
                                                "stroke-dasharray",
                                                "stroke-dashoffset",
                                                "opacity",
                                                "fill-opacity",
                                                "color",
                                                "display",
                                                "visibility",
                                                "stop-color",
                                                "stop-opacity"};
  std::vector<const xmlNode*> stack = {root};
  while (!stack.empty()) {
    const xmlNode* node = stack.back();
    stack.pop_back();
    if (node->type != XML_ELEMENT_NODE) continue;
    for (const xmlAttr* attr = node->properties; attr != nullptr; attr = attr->next) {
      const std::string name = reinterpret_cast<const char*>(attr->name);
      if (!kParsed.count(name)) continue;
      for (const xmlNode* child = attr->children; child; child = child->next) {
        if (child->content == nullptr) continue;
        for (const xmlChar* c = child->content; *c; ++c) {
          if (*c >= 0x80) return std::make_pair(node, name);
        }
      }
    }
    for (const xmlNode* child = node->children; child; child = child->next) stack.push_back(child);
  }
  return std::nullopt;
}

// Documents written without xmlns still mean SVG; SVG++ only reads elements in its namespace.
void AdoptSvgNamespace(xmlNode* root) {
  if (root->ns != nullptr) return;
  xmlNs* ns = xmlNewNs(root, reinterpret_cast<const xmlChar*>(kSvgNamespace), nullptr);
  std::vector<xmlNode*> stack = {root};
  while (!stack.empty()) {
    xmlNode* node = stack.back();
    stack.pop_back();
    if (node->type != XML_ELEMENT_NODE || node->ns != nullptr) continue;
    xmlSetNs(node, ns);
    for (xmlNode* child = node->children; child; child = child->next) stack.push_back(child);
  }
}

// Replaces every <use href="#id" x y transform> by a <g transform="... translate(x y)"> holding
// a deep copy of the referenced element (ids dropped from the copy), repeatedly so that copies
// holding <use> expand too. Returns the <use> that cannot be expanded, with the reason.
struct UseError {
  xmlNode* use;
  std::string reason;
  absl::StatusCode code = absl::StatusCode::kInvalidArgument;
};

// Element nodes in the subtree of `node` (itself included).
size_t CountElements(const xmlNode* node) {
  size_t n = 0;
  std::vector<const xmlNode*> stack = {node};
  while (!stack.empty()) {
    const xmlNode* e = stack.back();
    stack.pop_back();
    if (e->type != XML_ELEMENT_NODE) continue;
    ++n;
    for (const xmlNode* child = e->children; child; child = child->next) stack.push_back(child);
  }
  return n;
}

std::optional<UseError> ExpandUses(xmlDoc* doc, xmlNode* root) {
  for (int depth = 0;; ++depth) {
    std::map<std::string, xmlNode*> by_id;
    std::vector<xmlNode*> uses, stack = {root};
    size_t elements = 0;
    while (!stack.empty()) {
      xmlNode* node = stack.back();
      stack.pop_back();
      if (node->type != XML_ELEMENT_NODE) continue;
      ++elements;
      if (std::optional<std::string> id = Attribute(node, "id")) by_id.emplace(*id, node);
      if (xmlStrcmp(node->name, reinterpret_cast<const xmlChar*>("use")) == 0) {
        uses.push_back(node);
        continue;
      }
      for (xmlNode* child = node->children; child; child = child->next) stack.push_back(child);
    }
    if (uses.empty()) return std::nullopt;
    if (depth >= kMaxUseDepth) {
      return UseError{uses[0], "<use> nested too deeply (or referencing itself)"};
    }
    // Each round multiplies the copies of what the uses reference (fan-out, like entity
    // expansion): refuse a round that would grow the document past kMaxElements.
    std::map<const xmlNode*, size_t> sizes;
    for (xmlNode* use : uses) {
      std::optional<std::string> href = UseHref(use);
      if (!href || href->size() < 2 || (*href)[0] != '#') {
        return UseError{use, "<use> needs href=\"#id\" of an element in the document"};
      }
      auto it = by_id.find(href->substr(1));
      if (it == by_id.end()) {
        return UseError{use, absl::StrCat("<use> references unknown id \"", *href, "\"")};
      }
      auto [size, inserted] = sizes.emplace(it->second, 0);
      if (inserted) size->second = CountElements(it->second);
      elements += size->second;
      if (elements > kMaxElements) {
        return UseError{use,
                        absl::StrCat("<use> expansion makes more than ", kMaxElements, " elements"),
                        absl::StatusCode::kResourceExhausted};
      }
    }
    // Copies are taken from the round's starting state: copying a node that an earlier use of
    // the same round already grew would double it per use (2^uses in one round; fuzzer OOM).
    std::map<const xmlNode*, xmlNode*> snapshot;
    for (const auto& [node, size] : sizes) {
      snapshot[node] = xmlDocCopyNode(const_cast<xmlNode*>(node), doc, 1);
    }
    for (xmlNode* use : uses) {
      const std::string href = *UseHref(use);  // checked above
      auto it = by_id.find(href.substr(1));
      std::string transform = Attribute(use, "transform").value_or("");
      const std::string x = Attribute(use, "x").value_or("0"),
                        y = Attribute(use, "y").value_or("0");
      absl::StrAppend(&transform, " translate(", x, " ", y, ")");
      xmlNode* group = xmlNewDocNode(doc, use->ns, reinterpret_cast<const xmlChar*>("g"), nullptr);
      xmlSetProp(group, reinterpret_cast<const xmlChar*>("transform"),
                 reinterpret_cast<const xmlChar*>(transform.c_str()));
      for (const char* inherited : {"fill", "fill-rule", "class", "style"}) {
        if (std::optional<std::string> v = Attribute(use, inherited)) {
          xmlSetProp(group, reinterpret_cast<const xmlChar*>(inherited),
                     reinterpret_cast<const xmlChar*>(v->c_str()));
        }
      }
      xmlNode* copy = xmlDocCopyNode(snapshot.at(it->second), doc, 1);
      std::vector<xmlNode*> strip = {copy};
      while (!strip.empty()) {
        xmlNode* node = strip.back();
        strip.pop_back();
        if (node->type != XML_ELEMENT_NODE) continue;
        xmlUnsetProp(node, reinterpret_cast<const xmlChar*>("id"));
        for (xmlNode* child = node->children; child; child = child->next) strip.push_back(child);
      }
      xmlAddChild(group, copy);
      xmlReplaceNode(use, group);
      xmlFreeNode(use);
    }
    for (const auto& [node, copy] : snapshot) xmlFreeNode(copy);
  }
}

// Warnings for what is drawn but not imported: text, images, embedded documents, filters, clip
// paths, masks and style sheets (the subtrees of definitions are not drawn and not visited).
void WarnUnsupported(xmlNode* root, std::vector<std::string>* warnings) {
  static const std::set<std::string> kNotDrawn = {
      "defs",     "symbol",         "clipPath",       "mask",  "marker", "pattern",
      "metadata", "linearGradient", "radialGradient", "title", "desc"};
  static const std::map<std::string, std::string> kIgnored = {
      {"text", "text is not imported (convert it to paths)"},
      {"image", "images are not imported"},
      {"foreignObject", "embedded documents are not imported"},
      {"video", "video is not imported"},
      {"style", "style sheets are not applied (use attributes or style=\"...\")"}};
  std::vector<xmlNode*> stack = {root};
  while (!stack.empty()) {
    xmlNode* node = stack.back();
    stack.pop_back();
    if (node->type != XML_ELEMENT_NODE) continue;
    const std::string name = reinterpret_cast<const char*>(node->name);
    if (kNotDrawn.count(name)) continue;
    if (auto it = kIgnored.find(name); it != kIgnored.end()) {
      warnings->push_back(absl::StrCat(Describe(node), ": ", it->second));
      continue;
    }
    for (const char* property : {"filter", "clip-path", "mask"}) {
      std::optional<std::string> value = Property(node, property);
      if (value && *value != "none") {
        warnings->push_back(absl::StrCat(Describe(node), ": ", property, " is ignored"));
      }
    }
    std::vector<xmlNode*> children;
    for (xmlNode* child = node->children; child; child = child->next) children.push_back(child);
    stack.insert(stack.end(), children.rbegin(), children.rend());  // document order
  }
}

// The root's viewBox (min-x, min-y, width, height), when it has a valid one.
std::optional<Eigen::AlignedBox2d> ViewBox(xmlNode* root) {
  std::optional<std::string> text = Attribute(root, "viewBox");
  if (!text) return std::nullopt;
  std::vector<double> v;
  for (absl::string_view part :
       absl::StrSplit(*text, absl::ByAnyChar(" ,\t\n\r"), absl::SkipEmpty())) {
    double x = 0;
    if (!absl::SimpleAtod(part, &x) || !std::isfinite(x)) return std::nullopt;
    v.push_back(x);
  }
  if (v.size() != 4 || !(v[2] > 0) || !(v[3] > 0)) return std::nullopt;
  return Eigen::AlignedBox2d(Point(v[0], v[1]), Point(v[0] + v[2], v[1] + v[3]));
}

// The one-colour convention: filled elements only, all of one colour and opacity, none
// overlapping another (each layer's own area adds up to the union's). Its outlines are the
// elements' own, as written; touching elements and specks stay as they always were. Elements
// that share a curved edge overlap by slivers of the flattening's width (each flattens the curve
// its own way): overlaps up to half the flatten tolerance along the outlines are not overlaps.
// OneFill: the paint half of the test; NoOverlaps: the geometry half.
bool OneFill(const std::vector<ArtLayer>& art) {
  for (const ArtLayer& layer : art) {
    if (layer.stroke || !layer.fill || layer.fill->rgb != art[0].fill->rgb ||
        layer.fill->opacity != art[0].fill->opacity || layer.opacity != art[0].opacity) {
      return false;
    }
  }
  return !art.empty();
}
bool NoOverlaps(const std::vector<Outline>& outlines, const PaintRegion& region,
                double flatten_tolerance) {
  double perimeter = 0;
  for (const Outline& o : outlines) {
    for (size_t i = 0; i < o.points.size(); ++i) {
      perimeter += (o.points[(i + 1) % o.points.size()] - o.points[i]).norm();
    }
  }
  const double slivers = 0.5 * flatten_tolerance * perimeter;
  return std::abs(region.layers_area - region.raw_area) <= 1e-6 * region.raw_area + slivers;
}

// The document parsed and checked: well-formed XML with an <svg> root, no entity references,
// ASCII in the attributes we parse, <use> elements expanded (libxml2 errors are kept quiet by
// the caller's QuietXmlErrors).
absl::StatusOr<std::unique_ptr<xmlDoc, DocDeleter>> ParseSvgDocument(std::string_view svg_text) {
  std::unique_ptr<xmlParserCtxt, ParserDeleter> ctxt(xmlNewParserCtxt());
  if (ctxt == nullptr) return absl::ResourceExhaustedError("SVG import: out of memory");
  // No network, no entity substitution, no DTD loading or validation; keep errors quiet.
  const int flags = XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING;
  std::unique_ptr<xmlDoc, DocDeleter> doc(xmlCtxtReadMemory(ctxt.get(), svg_text.data(),
                                                            static_cast<int>(svg_text.size()),
                                                            "drawing.svg", nullptr, flags));
  if (doc == nullptr) {
    const xmlError* error = xmlCtxtGetLastError(ctxt.get());
    std::string reason = error && error->message ? error->message : "unknown error";
    while (!reason.empty() && (reason.back() == '\n' || reason.back() == ' ')) reason.pop_back();
    return absl::InvalidArgumentError(
        absl::StrCat("SVG is not well-formed XML (line ", error ? error->line : 0, "): ", reason));
  }
  xmlNode* root = xmlDocGetRootElement(doc.get());
  if (root == nullptr || xmlStrcmp(root->name, reinterpret_cast<const xmlChar*>("svg")) != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("SVG root element must be <svg>, found ", Describe(root)));
  }
  if (const xmlNode* ref = FindEntityReference(root)) {
    const xmlNode* element = ref->type == XML_ELEMENT_NODE ? ref : ref->parent;
    return absl::InvalidArgumentError(
        absl::StrCat("SVG element ", Describe(element),
                     ": entity references are not supported (never expanded)"));
  }
  if (auto bad = FindNonAsciiParsedAttribute(root)) {
    return absl::InvalidArgumentError(absl::StrCat("SVG element ", Describe(bad->first),
                                                   ": attribute \"", bad->second,
                                                   "\" has a non-ASCII character"));
  }
  AdoptSvgNamespace(root);
  if (auto bad = ExpandUses(doc.get(), root)) {
    return absl::Status(bad->code,
                        absl::StrCat("SVG element ", Describe(bad->use), ": ", bad->reason));
  }
  return doc;
}

// Walks the document under `root` into `collector` (paint, outlines, cuts, openings, marks,
// warnings): the ids first, in document order (the first one wins), then the elements. A limit
// reached or an element that cannot be read ends the walk with its status.
absl::Status CollectPaint(xmlNode* root, Collector* collector) {
  for (xmlNode* n = root; n != nullptr;) {
    if (n->type == XML_ELEMENT_NODE) {
      if (std::optional<std::string> id = Attribute(n, "id")) collector->by_id.emplace(*id, n);
      if (n->children != nullptr) {
        n = n->children;
        continue;
      }
    }
    while (n != nullptr && n != root && n->next == nullptr) n = n->parent;
    n = (n == nullptr || n == root) ? nullptr : n->next;
  }
  try {
    Context context(collector, root);
    Traversal::load_document(root, context);
  } catch (const TooManyPoints& e) {
    return WithReason(absl::ResourceExhaustedError(absl::StrCat("SVG has ", e.message)),
                      kReasonDrawingPointLimit);
  } catch (const TooManyLayers& e) {
    return absl::ResourceExhaustedError(absl::StrCat("SVG has ", e.message));
  } catch (const boost::exception& e) {
    xmlNode* const* element = boost::get_error_info<ElementInfo>(e);
    const auto* std_error = dynamic_cast<const std::exception*>(&e);
    return absl::InvalidArgumentError(
        absl::StrCat("SVG element ", Describe(element ? *element : nullptr), ": ",
                     std_error ? std_error->what() : "invalid content"));
  } catch (const std::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat("SVG import failed: ", e.what()));
  }
  return absl::OkStatus();
}

// The drawing's outlines: the union of all paint (or of the class="outline" elements), or the
// elements' own outlines when the drawing is one fill whose elements do not overlap; `report`
// gets the source and the cleaning, `collector` a warning for paint outside the viewBox.
absl::StatusOr<std::vector<Outline>> SilhouetteOutlines(xmlNode* root,
                                                        const SvgImportOptions& options,
                                                        bool by_class, Collector* collector,
                                                        SvgImportInfo* report) {
  // The silhouette: the union of all paint, or of the class="outline" elements.
  std::vector<const ArtLayer*> silhouette;
  for (const ArtLayer& layer : by_class ? collector->outline_class : collector->art) {
    silhouette.push_back(&layer);
  }
  Point lo(kInf, kInf), hi(-kInf, -kInf);
  for (const ArtLayer* layer : silhouette) {
    for (const ArtPath& path : layer->paths) {
      for (const Point& p : path.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
  }
  // Coordinates beyond what the service accepts (|x| <= 1e9) are refused downstream, naming the
  // point; the union (quantized over the paint's extent) is not attempted for them.
  if (!(lo.cwiseAbs().maxCoeff() <= 1e9 && hi.cwiseAbs().maxCoeff() <= 1e9)) {
    OrientByNesting(&collector->outlines);
    return std::move(collector->outlines);
  }
  PaintUnionOptions union_options;
  union_options.arc_tolerance = options.tolerance;
  if (lo.x() <= hi.x()) {
    union_options.gap_width = std::max(0.0, options.gap_tolerance) * (hi - lo).norm();
    union_options.min_area =
        std::max(0.0, options.min_area_fraction) * (hi - lo).x() * (hi - lo).y();
  }
  // A drawing of one fill is united without cleaning first: when its elements do not overlap it
  // keeps its own outlines and the cleaning would be wasted (benchmark "import").
  const bool one_fill = !by_class && OneFill(collector->art);
  PaintUnionOptions first = union_options;
  if (one_fill) first.gap_width = first.min_area = 0;
  absl::StatusOr<PaintRegion> region = UnionOfPaint(silhouette, first);
  const bool one_colour =
      one_fill && region.ok() && NoOverlaps(collector->outlines, *region, options.tolerance);
  if (one_fill && !one_colour && region.ok()) region = UnionOfPaint(silhouette, union_options);
  if (!region.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("SVG ", by_class ? "class=\"outline\" elements" : "paint", ": ",
                     region.status().message()));
  }
  // Paint that lies entirely outside the viewBox is imported all the same (coordinates are the
  // user units as written, and the animation is framed by the drawings' boxes), with a warning:
  // a browser would show nothing.
  if (std::optional<Eigen::AlignedBox2d> view = ViewBox(root)) {
    bool seen = false;
    for (const Outline& o : region->outlines) {
      Eigen::AlignedBox2d box;
      for (const Point& p : o.points) box.extend(p);
      seen = seen || view->intersects(box);
    }
    if (!seen) {
      collector->warnings.push_back(
          "<svg>: all paint lies outside the viewBox (a browser would show nothing)");
    }
  }

  if (one_colour) {
    OrientByNesting(&collector->outlines);
    // The one-colour convention: the elements' own outlines, exactly as written.
    report->source = SilhouetteSource::kElements;
    report->cleaning.gap_width = union_options.gap_width;
    report->cleaning.min_area = union_options.min_area;
    return std::move(collector->outlines);
  }
  if (region->hairline) {
    return absl::InvalidArgumentError(absl::StrCat(
        "SVG ", by_class ? "class=\"outline\" elements are" : "paint is",
        " nowhere wider than the gap tolerance (", region->cleaning.gap_width,
        " user units): it is all hairlines; lower the gap tolerance or paint wider shapes"));
  }
  if (region->outlines.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("SVG ", by_class ? "class=\"outline\" elements" : "paint",
                     ": every piece is smaller than the minimum area (", region->cleaning.min_area,
                     " square user units; SvgImportOptions::min_area_fraction)"));
  }
  report->source = by_class ? SilhouetteSource::kOutlineClass : SilhouetteSource::kUnion;
  report->cleaning = region->cleaning;
  return std::move(region->outlines);
}

}  // namespace

absl::StatusOr<Drawing> ImportSvg(std::string_view svg_text, const SvgImportOptions& options,
                                  SvgImportInfo* info) {
  if (!(options.tolerance > 0) || !std::isfinite(options.tolerance)) {
    return absl::InvalidArgumentError("SVG import: tolerance must be a positive number");
  }
  if (options.max_points < 1) {
    return absl::InvalidArgumentError("SVG import: max_points must be positive");
  }
  const QuietXmlErrors quiet;
  absl::StatusOr<std::unique_ptr<xmlDoc, DocDeleter>> doc = ParseSvgDocument(svg_text);
  if (!doc.ok()) return doc.status();
  xmlNode* root = xmlDocGetRootElement(doc->get());
  Collector collector;
  collector.tolerance = options.tolerance;
  collector.max_points = static_cast<size_t>(options.max_points);
  collector.max_layers = static_cast<size_t>(options.max_layers);
  if (absl::Status s = CollectPaint(root, &collector); !s.ok()) return s;
  WarnUnsupported(root, &collector.warnings);
  const bool by_class = !collector.outline_class.empty();
  if (collector.art.empty() && !by_class) {
    return absl::InvalidArgumentError(
        "SVG has no filled shape and no stroke: nothing is painted (elements with fill=\"none\" "
        "and no stroke, hidden or fully transparent elements and empty paths are ignored)");
  }

  SvgImportInfo report;
  report.fill_rgb = collector.largest_fill;
  absl::StatusOr<std::vector<Outline>> outlines =
      SilhouetteOutlines(root, options, by_class, &collector, &report);
  if (!outlines.ok()) return outlines.status();
  report.warnings = std::move(collector.warnings);
  if (info != nullptr) *info = std::move(report);
  Drawing drawing;
  drawing.outlines = *std::move(outlines);
  drawing.cuts = std::move(collector.cuts);
  drawing.openings = std::move(collector.openings);
  drawing.marks = std::move(collector.marks);
  drawing.art = std::move(collector.art);
  return drawing;
}

}  // namespace inbetween::solver
