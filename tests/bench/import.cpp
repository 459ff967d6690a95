// Import of layered drawings: ImportSvg on generated documents of 250-4,000 painted layers (a
// body with spots painted over it, each spot a filled and stroked circle or a curved, stroked
// open path, all overlapping: the union, stroke offsetting and cleaning do real work). The same
// documents with every stroke removed and every spot moved apart (the one-colour convention:
// no union needed beyond the check) are the baseline row. Prints per size the median and
// minimum milliseconds, the layers kept and the outlines; --json FILE writes the rows.
// Target: a 2,000-layer drawing under 1 s on the 2-core machine.
// Usage: import [--runs N] [--json FILE]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "nlohmann/json.hpp"
#include "solver/io/svg_import.h"

namespace {

using namespace inbetween::solver;  // NOLINT(build/namespaces): a benchmark program

// A drawing of `layers` painted layers: the body, then spots on a grid over it. `layered`:
// spots overlap the body and each other and carry strokes; otherwise disjoint plain fills.
std::string Document(int layers, bool layered) {
  const int spots = layers - 1;
  int side = 1;
  while (side * side < spots) ++side;
  const double cell = 1000.0 / side;
  std::string svg = absl::StrCat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"-100 -100 1200 1200\">",
      layered
          ? "<rect x=\"-20\" y=\"-20\" width=\"1040\" height=\"1040\" rx=\"80\" fill=\"#fcea2b\" "
            "stroke=\"#000\" stroke-width=\"6\" stroke-linejoin=\"round\"/>"
          : "<rect x=\"-90\" y=\"-90\" width=\"40\" height=\"40\" fill=\"#fcea2b\"/>");
  for (int i = 0; i < spots; ++i) {
    const double x = (i % side + 0.5) * cell, y = (i / side + 0.5) * cell;
    const double r = layered ? 0.7 * cell : 0.4 * cell;
    if (!layered) {
      absl::StrAppend(&svg, "<circle cx=\"", x, "\" cy=\"", y, "\" r=\"", r,
                      "\" fill=\"#a57939\"/>");
    } else if (i % 2 == 0) {
      absl::StrAppend(&svg, "<circle cx=\"", x, "\" cy=\"", y, "\" r=\"", r,
                      "\" fill=\"#ea5a47\" stroke=\"#000\" stroke-width=\"", 0.1 * cell, "\"/>");
    } else {
      absl::StrAppend(&svg, "<path d=\"M", x - r, " ", y, " C", x - r / 2, " ", y - r, " ",
                      x + r / 2, " ", y + r, " ", x + r, " ", y,
                      "\" fill=\"none\" stroke=\"#000\" stroke-linecap=\"round\" "
                      "stroke-linejoin=\"round\" stroke-width=\"",
                      0.15 * cell, "\"/>");
    }
  }
  return svg + "</svg>";
}

struct Row {
  std::string kind;
  int layers = 0;
  size_t bytes = 0;
  double ms_median = 0, ms_min = 0;
  size_t art = 0, outlines = 0;
};

Row Measure(const std::string& kind, int layers, bool layered, int runs) {
  const std::string svg = Document(layers, layered);
  Row row{kind, layers, svg.size()};
  std::vector<double> ms;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<Drawing> d = ImportSvg(svg);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
    if (!d.ok()) {
      std::fprintf(stderr, "import failed (%s, %d layers): %s\n", kind.c_str(), layers,
                   std::string(d.status().message()).c_str());
      std::exit(1);
    }
    row.art = d->art.size();
    row.outlines = d->outlines.size();
  }
  std::sort(ms.begin(), ms.end());
  row.ms_median = ms[ms.size() / 2];
  row.ms_min = ms.front();
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--json") && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: import [--runs N] [--json FILE]\n");
      return 2;
    }
  }
  std::vector<Row> rows;
  for (int layers : {250, 500, 1000, 2000, 4000}) {
    rows.push_back(Measure("layered", layers, true, runs));
    rows.push_back(Measure("one-colour", layers, false, runs));
  }
  std::printf("%-11s %7s %9s %10s %10s %7s %9s\n", "drawing", "layers", "bytes", "ms median",
              "ms min", "art", "outlines");
  nlohmann::json out = nlohmann::json::array();
  for (const Row& r : rows) {
    std::printf("%-11s %7d %9zu %10.1f %10.1f %7zu %9zu\n", r.kind.c_str(), r.layers, r.bytes,
                r.ms_median, r.ms_min, r.art, r.outlines);
    out.push_back({{"drawing", r.kind},
                   {"layers", r.layers},
                   {"bytes", r.bytes},
                   {"ms_median", r.ms_median},
                   {"ms_min", r.ms_min},
                   {"art_layers", r.art},
                   {"outlines", r.outlines}});
  }
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}
