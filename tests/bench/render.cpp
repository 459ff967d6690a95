// The art's cost, against the baselines it adds to, in one run on the same drawings:
//  - drawing a frame: the frame's art (ArtForFrame over both keys, then cairo, as the CLI's PNG,
//    GIF, WebP and contact sheet draw it) against its one-colour silhouette (the boundary loops
//    filled), at 512 px, for the middle frame of each pair (the keys' shapes blended halfway,
//    both keys' art active: the morph and the cross-fades both run);
//  - embedding: MultimeshReport::art_seconds against the rest of BuildMultimesh.
// Pairs of layered drawings: --pairs FILE (a line per pair: two SVG paths, relative to the
// file's folder unless absolute) and every example under examples/ whose drawings have more
// than one art layer (its first two drawings). Prints one row per pair, the medians and the
// totals (sum over pairs, so large drawings weigh by their cost); --json FILE writes them.
// Targets: art <= 1.5x the silhouette per frame; embedding <= 10 % of the build.
// Usage: render [--pairs FILE] [--no-examples] [--runs N] [--json FILE]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "client/render/frame_set.h"
#include "client/render/raster.h"
#include "nlohmann/json.hpp"
#include "solver/io/svg_import.h"
#include "solver/mesh/build_multimesh.h"

namespace {

namespace fs = std::filesystem;
using namespace inbetween;  // NOLINT(build/namespaces): a benchmark program
using Clock = std::chrono::steady_clock;

struct Pair {
  std::string name;
  fs::path a, b;
};

struct Row {
  std::string name;
  int layers = 0, art_points = 0, vertices = 0;
  double build_ms = 0, embed_ms = 0;   // the median build, and its embedding
  double art_ms = 0, silhouette_ms = 0;  // per frame, medians
  double blend_ms = 0;                   // of art_ms: ArtForFrame
  std::string error;
};

double Ms(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Three frames: key a, halfway, key b (the middle one is measured).
render::FrameSet Frames(const solver::Multimesh& mesh) {
  render::FrameSet set;
  for (const solver::Triangle& t : mesh.triangles) set.triangles.push_back(t);
  set.keys = {0, 2};
  for (int f = 0; f < 3; ++f) {
    render::FrameData data;
    data.index = f;
    data.time = f / 2.0;
    data.weights = {1.0 - f / 2.0, f / 2.0};
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const solver::Point p = data.weights[0] * mesh.shapes[0][v] + data.weights[1] * mesh.shapes[1][v];
      data.vertices.push_back({p.x(), p.y()});
    }
    set.frames.push_back(std::move(data));
  }
  set.art = mesh.art;
  return set;
}

// The median milliseconds of rendering frame 1, `runs` times (after one warm-up).
double RenderMs(const render::FrameSet& set, bool art, int runs, std::string* error) {
  absl::StatusOr<render::FrameRasterizer> raster =
      render::FrameRasterizer::Create(set, {.width = 512, .art = art});
  if (!raster.ok()) {
    *error = std::string(raster.status().message());
    return 0;
  }
  raster->Render(1);
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    const auto start = Clock::now();
    const render::RgbaImage image = raster->Render(1);
    ms.push_back(Ms(start));
    if (image.width != 512) *error = "unexpected image width";
  }
  return Median(ms);
}

Row Measure(const Pair& pair, int runs) {
  Row row{pair.name};
  std::vector<solver::Drawing> drawings;
  for (const fs::path& path : {pair.a, pair.b}) {
    absl::StatusOr<solver::Drawing> d = solver::ImportSvg(ReadText(path));
    if (!d.ok()) {
      row.error = path.string() + ": " + std::string(d.status().message());
      return row;
    }
    drawings.push_back(*std::move(d));
  }
  for (const solver::Drawing& d : drawings) {
    row.layers += static_cast<int>(d.art.size());
    for (const solver::ArtLayer& layer : d.art) {
      for (const solver::ArtPath& path : layer.paths) {
        row.art_points += static_cast<int>(path.points.size());
      }
    }
  }
  // Builds: the one of median time gives both numbers (its embedding is part of it).
  std::vector<std::pair<double, double>> builds;  // (build ms, embedding ms)
  absl::StatusOr<solver::Multimesh> mesh;
  for (int r = 0; r < runs; ++r) {
    solver::MultimeshReport report;
    const auto start = Clock::now();
    mesh = solver::BuildMultimesh(drawings, {}, nullptr, nullptr, &report);
    const double ms = Ms(start);
    if (!mesh.ok()) {
      row.error = "build: " + std::string(mesh.status().message());
      return row;
    }
    builds.emplace_back(ms, 1000.0 * report.art_seconds);
  }
  std::sort(builds.begin(), builds.end());
  row.build_ms = builds[builds.size() / 2].first;
  row.embed_ms = builds[builds.size() / 2].second;
  row.vertices = mesh->num_vertices();
  const render::FrameSet set = Frames(*mesh);
  row.art_ms = RenderMs(set, /*art=*/true, 3 * runs, &row.error);
  std::vector<double> blend;  // of art_ms: the frame's layers (ArtForFrame), before cairo
  for (int r = 0; r < 3 * runs; ++r) {
    const auto start = Clock::now();
    absl::StatusOr<std::vector<solver::ArtLayer>> layers = render::FrameArt(set, 1);
    blend.push_back(Ms(start));
    if (!layers.ok()) row.error = std::string(layers.status().message());
  }
  row.blend_ms = Median(blend);
  row.silhouette_ms = RenderMs(set, /*art=*/false, 3 * runs, &row.error);
  return row;
}

// Every example whose first drawing has more than one art layer: its first two drawings.
std::vector<Pair> ExamplePairs(const fs::path& dir) {
  std::vector<Pair> pairs;
  std::vector<fs::path> projects;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (fs::exists(entry.path() / "project.json")) projects.push_back(entry.path());
  }
  std::sort(projects.begin(), projects.end());
  for (const fs::path& p : projects) {
    const nlohmann::json project =
        nlohmann::json::parse(ReadText(p / "project.json"), nullptr, false);
    if (project.is_discarded() || !project.contains("drawings") ||
        project["drawings"].size() < 2) {
      continue;
    }
    // A drawing is a file name or {"file": NAME, ...} (docs/project-file.md).
    auto file = [&](const nlohmann::json& d) {
      return p / (d.is_string() ? d.get<std::string>() : d.value("file", std::string()));
    };
    const fs::path a = file(project["drawings"][0]), b = file(project["drawings"][1]);
    absl::StatusOr<solver::Drawing> d = solver::ImportSvg(ReadText(a));
    if (d.ok() && d->art.size() > 1) pairs.push_back({p.filename().string(), a, b});
  }
  return pairs;
}

std::vector<Pair> FilePairs(const fs::path& file) {
  std::vector<Pair> pairs;
  std::ifstream in(file);
  std::string a, b;
  while (in >> a >> b) {
    auto resolve = [&](const std::string& s) {
      const fs::path path(s);
      return path.is_absolute() ? path : file.parent_path() / path;
    };
    pairs.push_back({fs::path(a).stem().string() + "-" + fs::path(b).stem().string(), resolve(a),
                     resolve(b)});
  }
  return pairs;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 3;
  std::string json_path, pairs_file;
  bool examples = true;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--json") && i + 1 < argc) {
      json_path = argv[++i];
    } else if (!std::strcmp(argv[i], "--pairs") && i + 1 < argc) {
      pairs_file = argv[++i];
    } else if (!std::strcmp(argv[i], "--no-examples")) {
      examples = false;
    } else {
      std::fprintf(stderr,
                   "usage: render [--pairs FILE] [--no-examples] [--runs N] [--json FILE]\n");
      return 2;
    }
  }
  std::vector<Pair> pairs;
  if (examples) pairs = ExamplePairs(fs::path(INBETWEEN_SOURCE_DIR) / "examples");
  if (!pairs_file.empty()) {
    for (Pair& p : FilePairs(pairs_file)) pairs.push_back(std::move(p));
  }
  std::printf("%-34s %6s %7s %7s %9s %8s %6s %8s %8s %8s %6s\n", "pair", "layers", "points",
              "verts", "build ms", "embed ms", "embed", "art ms", "blend ms", "sil ms", "ratio");
  nlohmann::json out = {{"rows", nlohmann::json::array()}};
  std::vector<double> embed_ratios, render_ratios;
  double sum_build = 0, sum_embed = 0, sum_art = 0, sum_silhouette = 0;
  int failed = 0;
  for (const Pair& pair : pairs) {
    const Row r = Measure(pair, runs);
    if (!r.error.empty()) {
      std::printf("%-34.34s  skipped: %s\n", r.name.c_str(), r.error.c_str());
      ++failed;
      continue;
    }
    const double embed = r.embed_ms / std::max(r.build_ms - r.embed_ms, 1e-9);
    const double ratio = r.art_ms / std::max(r.silhouette_ms, 1e-9);
    embed_ratios.push_back(embed);
    render_ratios.push_back(ratio);
    sum_build += r.build_ms - r.embed_ms;
    sum_embed += r.embed_ms;
    sum_art += r.art_ms;
    sum_silhouette += r.silhouette_ms;
    std::printf("%-34.34s %6d %7d %7d %9.1f %8.2f %5.1f%% %8.3f %8.3f %8.3f %6.2f\n",
                r.name.c_str(), r.layers, r.art_points, r.vertices, r.build_ms, r.embed_ms,
                100 * embed, r.art_ms, r.blend_ms, r.silhouette_ms, ratio);
    out["rows"].push_back({{"pair", r.name},
                           {"layers", r.layers},
                           {"art_points", r.art_points},
                           {"vertices", r.vertices},
                           {"build_ms", r.build_ms},
                           {"embed_ms", r.embed_ms},
                           {"embed_fraction", embed},
                           {"art_ms", r.art_ms},
                           {"blend_ms", r.blend_ms},
                           {"silhouette_ms", r.silhouette_ms},
                           {"art_over_silhouette", ratio}});
  }
  if (embed_ratios.empty()) {
    std::fprintf(stderr, "no pair measured\n");
    return 1;
  }
  const double total_embed = sum_embed / std::max(sum_build, 1e-9);
  const double total_render = sum_art / std::max(sum_silhouette, 1e-9);
  std::printf("\n%zu pairs (%d skipped)\n", embed_ratios.size(), failed);
  std::printf("embedding / rest of build:  median %.1f %%, max %.1f %%, total %.1f %%\n",
              100 * Median(embed_ratios),
              100 * *std::max_element(embed_ratios.begin(), embed_ratios.end()),
              100 * total_embed);
  std::printf("art / silhouette per frame: median %.2fx, max %.2fx, total %.2fx\n",
              Median(render_ratios),
              *std::max_element(render_ratios.begin(), render_ratios.end()), total_render);
  out["summary"] = {{"pairs", embed_ratios.size()},
                    {"skipped", failed},
                    {"embed_fraction_median", Median(embed_ratios)},
                    {"embed_fraction_max",
                     *std::max_element(embed_ratios.begin(), embed_ratios.end())},
                    {"embed_fraction_total", total_embed},
                    {"art_over_silhouette_median", Median(render_ratios)},
                    {"art_over_silhouette_max",
                     *std::max_element(render_ratios.begin(), render_ratios.end())},
                    {"art_over_silhouette_total", total_render}};
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}
