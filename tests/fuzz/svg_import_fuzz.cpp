// libFuzzer: SVG import (solver/io/svg_import.cpp) on arbitrary bytes. Any crash, sanitizer
// report, hang or error code other than INVALID_ARGUMENT / RESOURCE_EXHAUSTED is a finding; an
// accepted document must give finite outlines of at least 3 points.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "solver/io/svg_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace inbetween::solver;
  SvgImportOptions options;
  options.max_points = 100'000;  // keep each run fast; the limit path is exercised too
  absl::StatusOr<Drawing> d =
      ImportSvg(std::string_view(reinterpret_cast<const char*>(data), size), options);
  if (!d.ok()) {
    const absl::StatusCode code = d.status().code();
    if (code != absl::StatusCode::kInvalidArgument &&
        code != absl::StatusCode::kResourceExhausted) {
      std::fprintf(stderr, "unexpected status: %s\n", d.status().ToString().c_str());
      std::abort();
    }
    return 0;
  }
  for (const Outline& o : d->outlines) {
    if (o.points.size() < 3) std::abort();
    for (const Point& p : o.points) {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y())) std::abort();
    }
  }
  return 0;
}
