// Boundary correspondence against a known truth. Each case is a drawing and its image under a
// known smooth map f (a bend up to a half ring, a twist, a stretch of one part, an affine map;
// the examples' first keys bent and sheared), so the true correspondence is f itself. Every case
// is built three times in one run: "arc" (no marks, the legacy sampling and arc-length
// correspondence: the baseline), "auto" (no marks: today's defaults) and "true" (marks
// at f's images of points spread along every loop, corners included: the correspondence f
// gives), each followed by comesh optimization (default options) and a 25-frame inbetween.
// Printed per case and mode:
//   corr_mean, corr_max  boundary correspondence error: for every boundary vertex, the distance
//                        along drawing 2's outline between where the mesh puts it and where f
//                        puts its drawing-1 position, relative to that loop's length;
//   mid_distort          the middle frame's worst isometric distortion max(sigma_1, 1/sigma_2)
//                        measured from drawing 1 (as bench quality does);
//   key_distort          the same between the two keys (the map the mesh gives between them);
//   key_tol              worst Hausdorff distance (both ways) between a key's mesh boundary and
//                        its drawing's outline, relative to the drawing's bounding-box diagonal;
//   *                    the build fell back to corner matching or the overlay
//                        (MultimeshReport);
//   ratio                mid_distort / true mid_distort (the summary counts auto's cases
//                        within 1.10 and 1.25, and arc's).
// Unless --no-examples, also every example as a project (all keys, its own options), built with
// the legacy sampling and correspondence and with today's: the outline tolerance the build
// achieved (MultimeshReport::achieved_tolerance).
// With --icons DIR (SVG files; e.g. an npm icon set), also pairs of icons of the same topology
// (each with the next of its class in C-sorted name order, up to --pairs N), each built in one
// run with the legacy boundary sampling and correspondence ("legacy"), with today's defaults
// ("today"), and with each change alone ("align": the feature alignment, even sampling; "tol":
// arc length, sampling refined to the tolerance): build share, median build seconds and vertex
// counts, and the keys' outline tolerance (measured on the built multimesh).
// Usage: correspondence [--json FILE] [--no-examples] [--no-synthetic] [--only NAME]
//                       [--no-optimize] [--icons DIR] [--pairs N]
// and, to diagnose the comesh run: [--slide-window W] [--map-weight W] [--no-boundary-sliding]
// [--no-outline-sliding] [--no-topology] [--no-boundary-collapses] [--no-boundary-splits]
// [--no-corner-swaps]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "solver/comesh/comesh_optimizer.h"
#include "solver/geometry/polygon.h"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "solver/io/svg_import.h"
#include "solver/mesh/build_multimesh.h"
#include "tests/bench/distortion.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program
using inbetween::bench::MaxDistortion;

constexpr double kPi = std::numbers::pi;
using Map = std::function<Point(const Point&)>;

struct Box {
  Point lo, hi;
  Point centre() const { return 0.5 * (lo + hi); }
  double diagonal() const { return (hi - lo).norm(); }
};

Box BoxOf(const Drawing& d) {
  Box b{d.outlines[0].points[0], d.outlines[0].points[0]};
  for (const Outline& o : d.outlines) {
    for (const Point& p : o.points) b.lo = b.lo.cwiseMin(p), b.hi = b.hi.cwiseMax(p);
  }
  return b;
}

// Points every `step` along the closed polyline (its own vertices kept).
Points Densify(const Points& p, double step) {
  Points out;
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const Point a = p[i], b = p[(i + 1) % n];
    const int k = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int j = 0; j < k; ++j) out.push_back(a + (b - a) * (static_cast<double>(j) / k));
  }
  return out;
}

Points OpenDensify(const Points& p, double step) {
  Points out;
  for (size_t i = 0; i + 1 < p.size(); ++i) {
    const Point a = p[i], b = p[i + 1];
    const int k = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int j = 0; j < k; ++j) out.push_back(a + (b - a) * (static_cast<double>(j) / k));
  }
  if (!p.empty()) out.push_back(p.back());
  return out;
}

// Drawing 1 densified (so that f's image of it is f's image of the outline, up to the step).
Drawing Dense(const Drawing& d, double step) {
  Drawing out;
  for (const Outline& o : d.outlines) out.outlines.push_back(Outline{Densify(o.points, step)});
  for (const Points& c : d.cuts) out.cuts.push_back(OpenDensify(c, step));
  for (const Points& c : d.openings) out.openings.push_back(OpenDensify(c, step));
  return out;
}

Drawing Mapped(const Drawing& dense, const Map& f) {
  Drawing out = dense;
  for (Outline& o : out.outlines) {
    for (Point& p : o.points) p = f(p);
  }
  for (Points& c : out.cuts) {
    for (Point& p : c) p = f(p);
  }
  for (Points& c : out.openings) {
    for (Point& p : c) p = f(p);
  }
  return out;
}

// Bends the box about its horizontal centre line by `angle` in all (a half ring at pi): column x
// goes onto the arc of radius R = width / angle, the top side outside.
Map Bend(const Box& box, double angle) {
  const Point c = box.centre();
  const double radius = (box.hi.x() - box.lo.x()) / angle;
  return [=](const Point& p) {
    const double phi = (p.x() - c.x()) / radius, r = radius + (p.y() - c.y());
    return Point(c.x() + r * std::sin(phi), c.y() - radius + r * std::cos(phi));
  };
}

// Turns points about the centre by `angle` at the centre, fading out as exp(-(r / rho)^2).
Map Twist(const Box& box, double angle) {
  const Point c = box.centre();
  const double rho = 0.35 * box.diagonal();
  return [=](const Point& p) {
    const Point d = p - c;
    const double a = angle * std::exp(-d.squaredNorm() / (rho * rho));
    return Point(c.x() + std::cos(a) * d.x() - std::sin(a) * d.y(),
                 c.y() + std::sin(a) * d.x() + std::cos(a) * d.y());
  };
}

// Stretches the part right of the centre along x by `factor` (smoothly switched on over a fifth
// of the width), the rest as it is.
Map StretchPart(const Box& box, double factor) {
  const double xm = box.centre().x(), w = 0.1 * (box.hi.x() - box.lo.x());
  return [=](const Point& p) {
    // x' = x + (factor - 1) * integral of a smooth step from xm - w to xm + w.
    const double u = (p.x() - xm) / w;
    const double ramp = u <= -1 ? 0.0 : u >= 1 ? u : (u + 1) * (u + 1) * (u + 1) * (3 - u) / 16.0;
    return Point(p.x() + (factor - 1) * w * ramp, p.y());
  };
}

// Squashes vertically by a factor growing from 1 (left) to `factor` (right), about the centre.
Map Squash(const Box& box, double factor) {
  const Point c = box.centre();
  const double width = box.hi.x() - box.lo.x();
  return [=](const Point& p) {
    const double s = 1 + (factor - 1) * std::clamp((p.x() - box.lo.x()) / width, 0.0, 1.0);
    return Point(p.x(), c.y() + s * (p.y() - c.y()));
  };
}

Map Affine(const Box& box) {
  const Point c = box.centre();
  Eigen::Matrix2d m;
  m << 1.2, -0.25, 0.35, 1.1;
  return [=](const Point& p) { return Point(c + m * (p - c) + Point(30, -4)); };
}

Drawing Polygon(const Points& p) {
  Drawing d;
  d.outlines.push_back(Outline{p});
  return d;
}

Drawing Bar() { return Polygon({{0, 0}, {400, 0}, {400, 100}, {0, 100}}); }

Drawing Arrow() {
  return Polygon({{0, 40}, {220, 40}, {220, 0}, {320, 70}, {220, 140}, {220, 100}, {0, 100}});
}

Drawing Star() {
  Points p;
  for (int k = 0; k < 10; ++k) {
    const double a = kPi / 2 + k * kPi / 5, r = k % 2 ? 40.0 : 100.0;
    p.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return Polygon(p);
}

// A droplet: a round end and a sharp tip (a cusp-free smooth curve with one corner).
Drawing Droplet() {
  Points p;
  const int n = 180;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * kPi * k / n;
    p.emplace_back(100 * std::cos(t), 60 * std::sin(t) * std::pow(std::sin(t / 2), 1.5));
  }
  return Polygon(p);
}

// An L: a vertical stem and a foot.
Drawing Ell() { return Polygon({{0, 0}, {300, 0}, {300, 80}, {80, 80}, {80, 300}, {0, 300}}); }

struct Case {
  std::string name;
  Drawing a;  // drawing 1 as drawn
  Drawing dense;
  Drawing b;  // f(dense)
  Map f;
};

Case MakeCase(const std::string& name, const Drawing& a,
              const std::function<Map(const Box&)>& make_map) {
  const Box box = BoxOf(a);
  Case c{name, a, Dense(a, box.diagonal() / 600.0), {}, make_map(box)};
  c.b = Mapped(c.dense, c.f);
  return c;
}

std::vector<Case> SyntheticCases() {
  std::vector<Case> cases;
  cases.push_back(MakeCase("bar_half_ring", Bar(), [](const Box& b) { return Bend(b, kPi); }));
  cases.push_back(MakeCase("bar_quarter", Bar(), [](const Box& b) { return Bend(b, kPi / 2); }));
  cases.push_back(MakeCase("bar_stretch", Bar(), [](const Box& b) { return StretchPart(b, 2.0); }));
  cases.push_back(MakeCase("bar_squash", Bar(), [](const Box& b) { return Squash(b, 0.4); }));
  cases.push_back(MakeCase("arrow_bend", Arrow(), [](const Box& b) { return Bend(b, 0.6 * kPi); }));
  cases.push_back(
      MakeCase("arrow_stretch", Arrow(), [](const Box& b) { return StretchPart(b, 1.8); }));
  cases.push_back(MakeCase("arrow_affine", Arrow(), [](const Box& b) { return Affine(b); }));
  cases.push_back(MakeCase("star_twist", Star(), [](const Box& b) { return Twist(b, kPi / 3); }));
  cases.push_back(
      MakeCase("star_stretch", Star(), [](const Box& b) { return StretchPart(b, 1.6); }));
  cases.push_back(MakeCase("star_affine", Star(), [](const Box& b) { return Affine(b); }));
  cases.push_back(
      MakeCase("droplet_bend", Droplet(), [](const Box& b) { return Bend(b, 0.5 * kPi); }));
  cases.push_back(
      MakeCase("droplet_squash", Droplet(), [](const Box& b) { return Squash(b, 0.5); }));
  cases.push_back(MakeCase("ell_stretch", Ell(), [](const Box& b) { return StretchPart(b, 2.0); }));
  cases.push_back(MakeCase("ell_twist", Ell(), [](const Box& b) { return Twist(b, kPi / 4); }));
  return cases;
}

// Each example's first key, bent by a third of a half turn (where that folds no part: every
// point stays above a fifth of the bend's radius from its centre) and mapped affinely. Examples
// whose first key has cuts or openings are left out (their loops are not the outlines), and
// so are repeats of a first key already taken (pentagon_star's variants).
std::vector<Case> ExampleCases() {
  std::vector<Case> cases;
  std::vector<std::string> seen;
  for (const std::string& name : example_projects::List()) {
    absl::StatusOr<example_projects::Example> ex;
    try {
      ex = example_projects::Load(name);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "example %s: %s\n", name.c_str(), e.what());
      continue;
    }
    if (!ex.ok() || ex->drawings.empty() || ex->files.empty()) continue;
    Drawing a = ex->drawings[0];
    if (!a.cuts.empty() || !a.openings.empty()) continue;
    const std::string first = example_projects::ReadFile(
        std::filesystem::path(INBETWEEN_SOURCE_DIR) / "examples" / name / ex->files[0]);
    if (std::find(seen.begin(), seen.end(), first) != seen.end()) continue;
    seen.push_back(first);
    a.marks.clear();
    a.art.clear();
    const Box box = BoxOf(a);
    const double angle = kPi / 3, radius = (box.hi.x() - box.lo.x()) / angle;
    if (0.5 * (box.hi.y() - box.lo.y()) < 0.8 * radius) {
      cases.push_back(MakeCase(name + "/bend", a, [&](const Box& b) { return Bend(b, angle); }));
    }
    cases.push_back(MakeCase(name + "/affine", a, [](const Box& b) { return Affine(b); }));
  }
  return cases;
}

// Closest point on closed polylines: (loop, arc length) and distance.
struct Projection {
  int loop = -1;
  double arc = 0, distance = std::numeric_limits<double>::infinity();
};

Projection Project(const std::vector<Points>& loops, const std::vector<std::vector<double>>& cum,
                   const Point& q) {
  Projection best;
  for (size_t l = 0; l < loops.size(); ++l) {
    const Points& p = loops[l];
    for (size_t i = 0; i < p.size(); ++i) {
      const Point a = p[i], d = p[(i + 1) % p.size()] - a;
      const double t =
          d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      const double dist = (a + t * d - q).norm();
      if (dist < best.distance) {
        best = {static_cast<int>(l), cum[l][i] + t * (cum[l][i + 1] - cum[l][i]), dist};
      }
    }
  }
  return best;
}

std::vector<std::vector<double>> Cumulative(const std::vector<Points>& loops) {
  std::vector<std::vector<double>> out;
  for (const Points& p : loops) {
    std::vector<double> c(p.size() + 1, 0.0);
    for (size_t i = 0; i < p.size(); ++i) c[i + 1] = c[i] + (p[(i + 1) % p.size()] - p[i]).norm();
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<Points> LoopsOf(const Drawing& d) {
  std::vector<Points> out;
  for (const Outline& o : d.outlines) out.push_back(o.points);
  return out;
}

// Mean and max over boundary vertices of the distance along drawing 2's outline between the
// vertex's position there and f of its position in drawing 1, relative to the loop's length.
std::pair<double, double> CorrespondenceError(const Multimesh& mesh, const Case& c) {
  const std::vector<Points> loops = LoopsOf(c.b);
  const auto cum = Cumulative(loops);
  double sum = 0, worst = 0;
  int n = 0;
  for (int v : mesh.boundary) {
    const Projection got = Project(loops, cum, mesh.shapes[1][v]);
    const Projection want = Project(loops, cum, c.f(mesh.shapes[0][v]));
    double e = 0.5;
    if (got.loop == want.loop && got.loop >= 0) {
      const double len = cum[got.loop].back();
      const double gap = std::abs(got.arc - want.arc);
      e = std::min(gap, len - gap) / len;
    }
    sum += e, worst = std::max(worst, e), ++n;
  }
  return {n ? sum / n : 0.0, worst};
}

// Distance from q to the closed polylines.
double DistanceTo(const std::vector<Points>& loops, const Point& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Points& p : loops) {
    for (size_t i = 0; i < p.size(); ++i) {
      const Point a = p[i], d = p[(i + 1) % p.size()] - a;
      const double t =
          d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      best = std::min(best, (a + t * d - q).norm());
    }
  }
  return best;
}

// Points along the closed polylines, at most `step` apart (vertices included).
Points Samples(const std::vector<Points>& loops, double step) {
  Points out;
  for (const Points& p : loops) {
    const Points d = Densify(p, step);
    out.insert(out.end(), d.begin(), d.end());
  }
  return out;
}

// Hausdorff distance (both ways) between shape s's mesh boundary loops and the drawing's outlines,
// relative to the drawing's bounding-box diagonal (sampled at 1e-4 of the diagonal).
double KeyTolerance(const Multimesh& mesh, int s, const Drawing& d) {
  std::vector<Points> boundary;
  for (const std::vector<int>& loop : mesh.boundary_loops) {
    Points p;
    for (int v : loop) p.push_back(mesh.shapes[s][v]);
    boundary.push_back(std::move(p));
  }
  const std::vector<Points> outline = LoopsOf(d);
  const double diagonal = BoxOf(d).diagonal();
  const double step = 2e-4 * diagonal;
  double worst = 0;
  for (const Point& q : Samples(boundary, step)) worst = std::max(worst, DistanceTo(outline, q));
  for (const Point& q : Samples(outline, step)) worst = std::max(worst, DistanceTo(boundary, q));
  return worst / diagonal;
}


// Marks at f's images: every corner of drawing 1 (turning by more than 30 degrees) and points
// spread evenly by arc length, at least 16 per loop, all taken from the densified outline (whose
// image is drawing 2's outline exactly).
std::vector<std::vector<Point>> TrueMarks(const Case& c) {
  std::vector<std::vector<Point>> marks;
  for (size_t l = 0; l < c.dense.outlines.size(); ++l) {
    const Points& p = c.dense.outlines[l].points;
    const int n = static_cast<int>(p.size());
    std::vector<bool> pick(n, false);
    for (int i = 0; i < n; ++i) {
      const Point a = p[i] - p[(i + n - 1) % n], b = p[(i + 1) % n] - p[i];
      const double turn = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
      if (std::abs(turn) > kPi / 6) pick[i] = true;
    }
    const int spread = 16;
    for (int k = 0; k < spread; ++k) pick[(static_cast<long>(k) * n) / spread] = true;
    // Never two marks on neighbouring samples (a sliver interval).
    for (int i = 0; i < n; ++i) {
      if (pick[i] && pick[(i + 1) % n] && (i + 1) % n != 0) pick[(i + 1) % n] = false;
    }
    for (int i = 0; i < n; ++i) {
      if (pick[i]) marks.push_back({p[i], c.f(p[i])});
    }
  }
  return marks;
}

struct Result {
  bool ok = false;
  bool fallback = false;  // built by corner matching or the overlay (MultimeshReport)
  std::string error;
  int vertices = 0, boundary = 0;
  double corr_mean = 0, corr_max = 0, mid = 0, keys = 0, key_tol = 0, seconds = 0;
};

Result RunOnce(const Case& c, const MultimeshOptions& options, bool optimize);

// The comesh options every run starts from (switches on the command line change them).
ComeshOptions& BaseComeshOptions() {
  static ComeshOptions options;
  return options;
}

Result Run(const Case& c, const MultimeshOptions& options, bool optimize) {
  const auto start = std::chrono::steady_clock::now();
  Result r;
  try {
    r = RunOnce(c, options, optimize);
  } catch (const std::exception& e) {
    r.ok = false;
    r.error = std::string("exception: ") + e.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Result RunOnce(const Case& c, const MultimeshOptions& options, bool optimize) {
  Result r;
  MultimeshReport report;
  absl::StatusOr<Multimesh> mesh = BuildMultimesh({c.a, c.b}, options, nullptr, nullptr, &report);
  r.fallback = report.corner_matched_loops > 0 || report.overlays > 0;
  if (mesh.ok() && optimize) {
    ComeshOptions co = BaseComeshOptions();
    co.threads = 1;
    // The guard measures against the drawings, as the server's OptimizeComesh does; the legacy
    // row (boundary_tolerance 0) runs without it, as before the guard.
    co.outline_tolerance = options.boundary_tolerance;
    co.outline_reference = {LoopsOf(c.a), LoopsOf(c.b)};
    mesh = OptimizeComesh(*mesh, co, nullptr, nullptr, nullptr);
  }
  if (!mesh.ok()) {
    r.error = std::string(mesh.status().message());
    return r;
  }
  r.vertices = mesh->num_vertices();
  r.boundary = static_cast<int>(mesh->boundary.size());
  std::tie(r.corr_mean, r.corr_max) = CorrespondenceError(*mesh, c);
  r.keys = MaxDistortion(*mesh, mesh->shapes[0], mesh->shapes[1]);
  r.key_tol = std::max(KeyTolerance(*mesh, 0, c.a), KeyTolerance(*mesh, 1, c.b));
  const int frames = 25;
  absl::StatusOr<Schedule> schedule = MakeSchedule(2, frames);
  InbetweenOptions io;
  absl::StatusOr<Inbetweener> ib = schedule.ok() ? Inbetweener::Create(*mesh, io)
                                                 : absl::StatusOr<Inbetweener>(schedule.status());
  if (!ib.ok()) {
    r.error = std::string(ib.status().message());
    return r;
  }
  Frame previous;
  for (int k = 0; k <= frames / 2; ++k) {
    absl::StatusOr<Frame> f = ib->Solve(schedule->frames[k].weights, previous, nullptr);
    if (!f.ok()) {
      r.error = std::string(f.status().message());
      return r;
    }
    previous = *std::move(f);
  }
  r.mid = MaxDistortion(*mesh, mesh->shapes[0], previous.vertices);
  r.ok = true;
  return r;
}

nlohmann::json Finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Icon pairs: SVGs of DIR imported, grouped by topology, each paired with the next of its group.
struct IconPair {
  std::string name;
  Drawing a, b;
};

std::vector<IconPair> IconPairs(const std::string& dir, int max_pairs) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() == ".svg") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::map<std::string, std::vector<std::pair<std::string, Drawing>>> by_class;
  std::vector<IconPair> pairs;
  for (const auto& path : files) {
    absl::StatusOr<Drawing> d = ImportSvg(example_projects::ReadFile(path));
    if (!d.ok() || d->outlines.empty()) continue;
    d->art.clear();
    int outer = 0, holes = 0;
    for (const Outline& o : d->outlines) (PolygonSignedArea(o.points) > 0 ? outer : holes)++;
    // Keep it to one component: several components pair by position, which is another question.
    if (outer != 1) continue;
    const std::string key = std::to_string(outer) + "/" + std::to_string(holes);
    by_class[key].push_back({path.stem().string(), *std::move(d)});
  }
  // Interleave the classes so that a small --pairs still sees several topologies.
  for (size_t i = 0;; ++i) {
    bool any = false;
    for (auto& [key, list] : by_class) {
      if (i + 1 >= list.size()) continue;
      any = true;
      if (static_cast<int>(pairs.size()) >= max_pairs) return pairs;
      pairs.push_back(
          {list[i].first + "->" + list[i + 1].first, list[i].second, list[i + 1].second});
    }
    if (!any) break;
  }
  return pairs;
}

struct IconResult {
  bool ok = false;
  int vertices = 0, boundary = 0;
  double seconds = 0, key_tol = 0;
};

IconResult BuildIcons(const IconPair& p, const MultimeshOptions& options) {
  IconResult r;
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Multimesh> mesh = BuildMultimesh({p.a, p.b}, options);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!mesh.ok()) return r;
  r.ok = true;
  r.vertices = mesh->num_vertices();
  r.boundary = static_cast<int>(mesh->boundary.size());
  r.key_tol = std::max(KeyTolerance(*mesh, 0, p.a), KeyTolerance(*mesh, 1, p.b));
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::string json_path, only, icons;
  bool examples = true, synthetic = true, optimize = true;
  int max_pairs = 200;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--json" && a + 1 < argc) {
      json_path = argv[++a];
    } else if (arg == "--only" && a + 1 < argc) {
      only = argv[++a];
    } else if (arg == "--icons" && a + 1 < argc) {
      icons = argv[++a];
    } else if (arg == "--pairs" && a + 1 < argc) {
      max_pairs = std::atoi(argv[++a]);
    } else if (arg == "--no-examples") {
      examples = false;
    } else if (arg == "--no-synthetic") {
      synthetic = false;
    } else if (arg == "--no-optimize") {
      optimize = false;
    } else if (arg == "--no-boundary-sliding") {
      BaseComeshOptions().slide_boundary = false;
    } else if (arg == "--no-outline-sliding") {
      BaseComeshOptions().slide_outline = false;
    } else if (arg == "--no-boundary-collapses") {
      BaseComeshOptions().topology.boundary_collapses = false;
    } else if (arg == "--no-boundary-splits") {
      BaseComeshOptions().topology.boundary_splits = false;
    } else if (arg == "--no-corner-swaps") {
      BaseComeshOptions().topology.corner_swaps = false;
    } else if (arg == "--slide-window" && a + 1 < argc) {
      BaseComeshOptions().slide_window = std::atof(argv[++a]);
    } else if (arg == "--map-weight" && a + 1 < argc) {
      BaseComeshOptions().map_weight = std::atof(argv[++a]);
    } else if (arg == "--no-topology") {
      BaseComeshOptions().max_outer = 0;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--json FILE] [--no-examples] [--no-synthetic] [--only NAME] "
                   "[--no-optimize] [--no-boundary-sliding] [--no-outline-sliding] [--icons DIR] "
                   "[--pairs N]\n",
                   argv[0]);
      return 2;
    }
  }
  nlohmann::json out = {{"cases", nlohmann::json::array()}, {"icons", nlohmann::json::array()}};
  std::vector<Case> cases;
  if (synthetic) cases = SyntheticCases();
  if (examples) {
    for (Case& c : ExampleCases()) cases.push_back(std::move(c));
  }
  if (!only.empty()) {
    std::erase_if(cases, [&](const Case& c) { return c.name.find(only) == std::string::npos; });
  }
  std::printf("%-40s %-5s %8s %8s %9s %9s %11s %11s %9s %7s %7s\n", "case", "mode", "vertices",
              "boundary", "corr_mean", "corr_max", "mid_distort", "key_distort", "key_tol",
              "seconds", "ratio");
  int within10 = 0, within25 = 0, compared = 0, arc_within10 = 0, arc_within25 = 0;
  for (const Case& c : cases) {
    MultimeshOptions legacy_options;
    legacy_options.correspondence = MultimeshOptions::Correspondence::kArcLength;
    legacy_options.boundary_tolerance = 0.0;
    MultimeshOptions auto_options;
    MultimeshOptions true_options;
    true_options.marks = TrueMarks(c);
    const Result legacy = Run(c, legacy_options, optimize);
    const Result automatic = Run(c, auto_options, optimize);
    const Result truth = Run(c, true_options, optimize);
    double legacy_ratio = std::numeric_limits<double>::quiet_NaN();
    if (legacy.ok && truth.ok) legacy_ratio = legacy.mid / truth.mid;
    double ratio = std::numeric_limits<double>::quiet_NaN();
    if (automatic.ok && truth.ok) {
      ratio = automatic.mid / truth.mid;
      ++compared;
      within10 += ratio <= 1.10;
      within25 += ratio <= 1.25;
      arc_within10 += legacy_ratio <= 1.10;
      arc_within25 += legacy_ratio <= 1.25;
    }
    for (const auto& [mode, r] :
         {std::pair{"arc", legacy}, std::pair{"auto", automatic}, std::pair{"true", truth}}) {
      if (!r.ok) {
        std::printf("%-40s %-5s failed (%.2f s): %s\n", c.name.c_str(), mode, r.seconds,
                    r.error.c_str());
      } else {
        std::printf("%-40s %-5s %8d %8d %9.4f %9.4f %11.3f %11.3f %9.5f %7.2f %7.3f%s\n",
                    c.name.c_str(), mode, r.vertices, r.boundary, r.corr_mean, r.corr_max, r.mid,
                    r.keys, r.key_tol, r.seconds,
                    std::string(mode) == "auto"  ? ratio
                    : std::string(mode) == "arc" ? legacy_ratio
                                                 : 1.0,
                    r.fallback ? " *" : "");
      }
      out["cases"].push_back({{"case", c.name},
                              {"mode", mode},
                              {"ok", r.ok},
                              {"error", r.error},
                              {"vertices", r.vertices},
                              {"boundary_vertices", r.boundary},
                              {"correspondence_error_mean", r.corr_mean},
                              {"correspondence_error_max", r.corr_max},
                              {"middle_max_distortion", Finite(r.mid)},
                              {"key_max_distortion", Finite(r.keys)},
                              {"key_tolerance", r.key_tol},
                              {"seconds", r.seconds},
                              {"fallback", r.fallback}});
    }
    std::fflush(stdout);
  }
  if (compared > 0) {
    std::printf(
        "\n%d cases with both modes built: auto within 10%% of true in %d (%.0f%%), "
        "within 25%% in %d (%.0f%%)\n",
        compared, within10, 100.0 * within10 / compared, within25, 100.0 * within25 / compared);
    std::printf("arc (legacy): within 10%% in %d (%.0f%%), within 25%% in %d (%.0f%%)\n",
                arc_within10, 100.0 * arc_within10 / compared, arc_within25,
                100.0 * arc_within25 / compared);
  }
  out["summary"] = {{"compared", compared},
                    {"within_10", within10},
                    {"within_25", within25},
                    {"arc_within_10", arc_within10},
                    {"arc_within_25", arc_within25}};

  if (examples) {
    // The examples as projects (all keys, their own meshing options and marks): the outline
    // tolerance the build achieved (MultimeshReport), legacy sampling against today's.
    std::printf("\n%-40s %-7s %8s %8s %9s %8s\n", "example (all keys)", "mode", "vertices",
                "boundary", "achieved", "seconds");
    for (const std::string& name : example_projects::List()) {
      absl::StatusOr<example_projects::Example> ex = example_projects::Load(name);
      if (!ex.ok()) continue;
      for (int m = 0; m < 2; ++m) {
        MultimeshOptions o = ex->options;
        if (m == 0) {
          o.boundary_tolerance = 0.0;
          o.correspondence = MultimeshOptions::Correspondence::kArcLength;
        }
        MultimeshReport report;
        const auto start = std::chrono::steady_clock::now();
        absl::StatusOr<Multimesh> mesh = BuildMultimesh(ex->drawings, o, nullptr, nullptr, &report);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const char* mode = m == 0 ? "legacy" : "today";
        if (!mesh.ok()) {
          std::printf("%-40s %-7s failed: %s\n", name.c_str(), mode,
                      std::string(mesh.status().message()).c_str());
          continue;
        }
        std::printf("%-40s %-7s %8d %8zu %9.5f %8.3f%s\n", name.c_str(), mode, mesh->num_vertices(),
                    mesh->boundary.size(), report.achieved_tolerance, seconds,
                    ex->options.boundary_vertices > 0 ? "  (fixed boundary_vertices)" : "");
        out["examples"].push_back({{"example", name},
                                   {"mode", mode},
                                   {"vertices", mesh->num_vertices()},
                                   {"boundary_vertices", mesh->boundary.size()},
                                   {"achieved_tolerance", report.achieved_tolerance},
                                   {"seconds", seconds}});
      }
      std::fflush(stdout);
    }
  }

  if (!icons.empty()) {
    const std::vector<IconPair> pairs = IconPairs(icons, max_pairs);
    MultimeshOptions legacy;
    legacy.boundary_tolerance = 0.0;
    legacy.correspondence = MultimeshOptions::Correspondence::kArcLength;
    const MultimeshOptions today;
    // Each change alone, to attribute the cost: the feature alignment with the even sampling,
    // and arc length with the refinement to the tolerance.
    MultimeshOptions features_only = today;
    features_only.boundary_tolerance = 0.0;
    MultimeshOptions tolerance_only = today;
    tolerance_only.correspondence = MultimeshOptions::Correspondence::kArcLength;
    const MultimeshOptions* modes[] = {&legacy, &today, &features_only, &tolerance_only};
    const char* mode_names[] = {"legacy", "today", "align", "tol"};
    constexpr int kModes = 4;
    std::vector<double> secs[kModes], verts[kModes], tol[kModes];
    int built[kModes] = {}, within[kModes] = {};
    std::printf("\n%-44s %-7s %8s %8s %9s %8s\n", "icon pair", "mode", "vertices", "boundary",
                "key_tol", "seconds");
    for (const IconPair& p : pairs) {
      for (int m = 0; m < kModes; ++m) {
        const IconResult r = BuildIcons(p, *modes[m]);
        const char* mode = mode_names[m];
        if (r.ok) {
          ++built[m];
          secs[m].push_back(r.seconds), verts[m].push_back(r.vertices), tol[m].push_back(r.key_tol);
          within[m] += r.key_tol <= 1e-3 * 1.0001;
          std::printf("%-44s %-7s %8d %8d %9.5f %8.3f\n", p.name.c_str(), mode, r.vertices,
                      r.boundary, r.key_tol, r.seconds);
        } else {
          std::printf("%-44s %-7s failed\n", p.name.c_str(), mode);
        }
        out["icons"].push_back({{"pair", p.name},
                                {"mode", mode},
                                {"ok", r.ok},
                                {"vertices", r.vertices},
                                {"boundary_vertices", r.boundary},
                                {"key_tolerance", r.key_tol},
                                {"seconds", r.seconds}});
      }
      std::fflush(stdout);
    }
    std::printf("\n%-7s %7s %7s %14s %15s %12s %14s\n", "mode", "pairs", "built", "median_secs",
                "median_vertices", "max_key_tol", "within_0.1%");
    for (int m = 0; m < kModes; ++m) {
      const double worst = tol[m].empty() ? 0 : *std::max_element(tol[m].begin(), tol[m].end());
      std::printf("%-7s %7zu %7d %14.4f %15.1f %12.5f %14d\n", mode_names[m], pairs.size(),
                  built[m], Median(secs[m]), Median(verts[m]), worst, within[m]);
      out["icon_summary"].push_back({{"mode", mode_names[m]},
                                     {"pairs", pairs.size()},
                                     {"built", built[m]},
                                     {"median_seconds", Median(secs[m])},
                                     {"median_vertices", Median(verts[m])},
                                     {"max_key_tolerance", worst},
                                     {"within_tolerance", within[m]}});
    }
    if (!secs[0].empty() && !secs[1].empty()) {
      std::printf("median build time ratio today/legacy %.2f, median vertices ratio %.2f\n",
                  Median(secs[1]) / Median(secs[0]), Median(verts[1]) / Median(verts[0]));
    }
  }
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}
