// Inbetweening quality: per case and method (zhu17, alexa, linear) the worst frame's
// inverted triangles and boundary overlaps over a 25-frame sequence (24 frames per key pair,
// solved in order with warm starts), the max isometric distortion max(sigma_1, 1 / sigma_2) of
// the middle frame measured from the straight bar (example 0; the keys' own values are printed
// for scale), the area error of the middle frame against the blended key areas, and the worst
// area error of the sequence. Cases, all a 4 x 1 bar meshed as an 81 x 21 vertex grid:
//   half_circle   bent about its centre line into a half circle;
//   curl_270      curled 270 degrees about its inner (bottom) edge with the curvature growing
//                 along the bar (a spiral that tightens; the inner edge keeps its length);
//   clamped_270   the first quarter clamped straight, the rest curled 270 degrees uniformly
//                 about the inner edge.
// and every example under examples/ (meshed as the examples' test does, default inbetweening
// parameters; 24 frames per pair of keys): there the distortion column is the worst frame's,
// measured from the frame's nearest key, and key_distort the worst between neighbouring keys.
// Usage: quality [--json FILE] [--frames N] [--tolerance T (zhu17 displacement tolerance)]
//                [--no-examples]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "nlohmann/json.hpp"
#include "solver/interp/inbetweener.h"
#include "solver/interp/timing.h"
#include "solver/mesh/build_multimesh.h"
#include "tests/bench/distortion.h"
#include "tests/unit/solver/interp/test_meshes.h"
#include "tests/unit/solver/mesh/example_projects.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program
using inbetween::bench::MaxDistortion;

constexpr double kLength = 4.0;
constexpr double kPi = std::numbers::pi;

// The bar with its bottom edge (y = 0) following the curve of turning angle phi(x), phi(0) = 0,
// and each vertical fibre along the curve's normal: x(s, y) = c(s) + y n(s). With phi' <= 0 the
// curl turns clockwise (in y-up axes) and the bottom edge is the inner edge, which keeps its
// length; the fibre at height y is stretched by 1 - y phi'(s) >= 1.
Points CurlAboutInnerEdge(const Points& rest, const std::function<double(double)>& phi) {
  // c(s) by the midpoint rule on a fine grid.
  const int steps = 4000;
  std::vector<Eigen::Vector2d> curve(steps + 1, Eigen::Vector2d::Zero());
  for (int k = 0; k < steps; ++k) {
    const double s = (k + 0.5) * kLength / steps;
    curve[k + 1] = curve[k] + kLength / steps * Eigen::Vector2d(std::cos(phi(s)), std::sin(phi(s)));
  }
  Points out;
  for (const Point& p : rest) {
    const double u = std::clamp(p.x() / kLength * steps, 0.0, static_cast<double>(steps));
    const int k = std::min(static_cast<int>(u), steps - 1);
    const double f = u - k;
    const Eigen::Vector2d c = (1.0 - f) * curve[k] + f * curve[k + 1];
    const double a = phi(p.x());
    out.push_back(c + p.y() * Eigen::Vector2d(-std::sin(a), std::cos(a)));
  }
  return out;
}

struct Case {
  std::string name;
  Multimesh mesh;
  bool example = false;  // from examples/: distortion from the nearest key, over every frame
};

std::vector<Case> Cases() {
  const Multimesh bar = interp_test::GridMesh(80, 20, kLength / 80);
  std::vector<Case> cases;
  Case half{"half_circle", bar};
  half.mesh.shapes.push_back(interp_test::BentAboutCentre(bar.shapes[0], kLength, kPi));
  cases.push_back(half);
  const double turn = 1.5 * kPi;
  Case curl{"curl_270", bar};
  curl.mesh.shapes.push_back(CurlAboutInnerEdge(
      bar.shapes[0], [&](double s) { return -turn * (s / kLength) * (s / kLength); }));
  cases.push_back(curl);
  Case clamped{"clamped_270", bar};
  clamped.mesh.shapes.push_back(CurlAboutInnerEdge(bar.shapes[0], [&](double s) {
    const double start = 0.25 * kLength;
    return s <= start ? 0.0 : -turn * (s - start) / (kLength - start);
  }));
  cases.push_back(clamped);
  return cases;
}

// The examples' multimeshes; one that does not build is reported and skipped.
std::vector<Case> ExampleCases() {
  std::vector<Case> cases;
  for (const std::string& name : example_projects::List()) {
    absl::StatusOr<example_projects::Example> example = example_projects::Load(name);
    absl::StatusOr<Multimesh> mesh =
        example.ok() ? BuildMultimesh(example->drawings, example->options) : example.status();
    if (!mesh.ok()) {
      std::fprintf(stderr, "example %s: %s\n", name.c_str(),
                   std::string(mesh.status().message()).c_str());
      continue;
    }
    cases.push_back({name, *std::move(mesh), true});
  }
  return cases;
}

int NearestKey(const ExampleWeights& w) {
  return static_cast<int>(std::max_element(w.begin(), w.end()) - w.begin());
}


}  // namespace

int main(int argc, char** argv) {
  std::string json_path;
  int frames = 25;
  bool examples = true;
  InbetweenOptions defaults;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--json") && a + 1 < argc) json_path = argv[++a];
    if (!std::strcmp(argv[a], "--frames") && a + 1 < argc) frames = std::atoi(argv[++a]);
    if (!std::strcmp(argv[a], "--no-examples")) examples = false;
    if (!std::strcmp(argv[a], "--tolerance") && a + 1 < argc) {
      defaults.displacement_tolerance = std::atof(argv[++a]);
      defaults.max_iterations = 5000;
    }
  }
  if (frames < 3 || frames % 2 == 0) {
    std::fprintf(stderr, "--frames must be odd and >= 3 (the middle frame is measured)\n");
    return 2;
  }
  nlohmann::json rows = nlohmann::json::array();
  std::vector<Case> cases = Cases();
  if (examples) {
    for (Case& c : ExampleCases()) cases.push_back(std::move(c));
  }
  std::printf("%-28s %-7s %9s %12s %9s %10s %12s %12s %12s %10s %9s\n", "case", "method",
              "vertices", "max_inverted", "inv_frames", "max_overlap", "distortion", "key_distort",
              "area_err_mid", "area_err_max", "it/frame");
  for (const Case& c : cases) {
    const Multimesh& mesh = c.mesh;
    const int keys = mesh.num_shapes();
    double key_distortion = 1.0;
    for (int i = 0; i + 1 < keys; ++i) {
      key_distortion =
          std::max(key_distortion, MaxDistortion(mesh, mesh.shapes[i], mesh.shapes[i + 1]));
    }
    std::vector<double> key_areas;
    for (const Points& s : mesh.shapes)
      key_areas.push_back(interp_test::TotalArea(s, mesh.triangles));
    const int case_frames = c.example ? 24 * (keys - 1) + 1 : frames;
    absl::StatusOr<Schedule> schedule = MakeSchedule(keys, case_frames);
    if (!schedule.ok()) return 1;
    for (InterpMethod method :
         {InterpMethod::kZhu17, InterpMethod::kAlexa, InterpMethod::kLinear}) {
      InbetweenOptions o = defaults;
      o.method = method;
      absl::StatusOr<Inbetweener> ib = Inbetweener::Create(mesh, o);
      if (!ib.ok()) {
        std::fprintf(stderr, "%s: %s\n", c.name.c_str(),
                     std::string(ib.status().message()).c_str());
        return 1;
      }
      int max_inverted = 0, inverted_frames = 0, max_overlaps = 0, iterations = 0;
      double distortion = 0.0, area_mid = 0.0, area_max = 0.0;
      Frame previous;
      for (int k = 0; k < case_frames; ++k) {
        const ExampleWeights& w = schedule->frames[k].weights;
        FrameReport report;
        absl::StatusOr<Frame> f = ib->Solve(w, previous, nullptr, &report);
        if (!f.ok()) {
          std::fprintf(stderr, "%s\n", std::string(f.status().message()).c_str());
          return 1;
        }
        max_inverted = std::max(max_inverted, report.inverted);
        iterations += report.iterations;
        inverted_frames += report.inverted > 0;
        max_overlaps = std::max(max_overlaps, report.overlaps);
        double target = 0.0;
        for (int i = 0; i < keys; ++i) target += w[i] * key_areas[i];
        const double area = interp_test::TotalArea(f->vertices, mesh.triangles);
        const double error = std::abs(area - target) / target;
        area_max = std::max(area_max, error);
        if (k == case_frames / 2) area_mid = error;
        if (c.example) {
          distortion =
              std::max(distortion, MaxDistortion(mesh, mesh.shapes[NearestKey(w)], f->vertices));
        } else if (k == case_frames / 2) {
          distortion = MaxDistortion(mesh, mesh.shapes[0], f->vertices);
        }
        previous = *std::move(f);
      }
      const char* name = method == InterpMethod::kZhu17   ? "zhu17"
                         : method == InterpMethod::kAlexa ? "alexa"
                                                          : "linear";
      std::printf("%-28s %-7s %9d %12d %9d %10d %12.3f %12.3f %12.4f %10.4f %9.2f\n",
                  c.name.c_str(), name, mesh.num_vertices(), max_inverted, inverted_frames,
                  max_overlaps, distortion, key_distortion, area_mid, area_max,
                  static_cast<double>(iterations) / case_frames);
      rows.push_back({{"case", c.name},
                      {"method", name},
                      {"vertices", mesh.num_vertices()},
                      {"frames", case_frames},
                      {"example", c.example},
                      {"max_inverted_triangles", max_inverted},
                      {"frames_with_inversions", inverted_frames},
                      {"max_overlaps", max_overlaps},
                      {c.example ? "max_distortion" : "middle_max_distortion",
                       std::isfinite(distortion) ? nlohmann::json(distortion) : nlohmann::json()},
                      {"key_max_distortion", key_distortion},
                      {"middle_area_error", area_mid},
                      {"max_area_error", area_max},
                      {"iterations_per_frame", static_cast<double>(iterations) / case_frames}});
    }
  }
  if (!json_path.empty()) std::ofstream(json_path) << rows.dump(2) << "\n";
  return 0;
}
