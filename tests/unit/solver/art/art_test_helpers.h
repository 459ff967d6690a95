// Small meshes and art for the art tests (grids from the inbetweening tests, jittered so that no
// edge is axis-aligned by accident).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "solver/core/art.h"
#include "solver/geometry/primitives.h"
#include "solver/mesh/multimesh.h"
#include "tests/unit/solver/interp/test_meshes.h"

namespace inbetween::solver::art_test {

// An nx x ny grid of unit cells with interior vertices moved by up to `jitter` (deterministic),
// as one shape.
inline Multimesh JitteredGrid(int nx, int ny, double jitter, unsigned seed = 7) {
  Multimesh mesh = interp_test::GridMesh(nx, ny);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  for (Point& p : mesh.shapes[0]) {
    const bool interior = p.x() > 0 && p.x() < nx && p.y() > 0 && p.y() < ny;
    if (interior) p += Point(u(rng), u(rng));
  }
  return mesh;
}

inline ArtLayer FillLayer(Points points, uint32_t rgb, double opacity = 1.0) {
  ArtLayer layer;
  layer.paths.push_back({std::move(points), true});
  layer.fill = FillPaint{rgb, opacity, false};
  return layer;
}

inline ArtLayer StrokeLayer(Points points, uint32_t rgb, double width, bool closed = false) {
  ArtLayer layer;
  layer.paths.push_back({std::move(points), closed});
  StrokePaint stroke;
  stroke.rgb = rgb;
  stroke.width = width;
  layer.stroke = stroke;
  return layer;
}

inline double DistanceToPolyline(const Points& path, bool closed, const Point& p) {
  double best = (path[0] - p).norm();
  const size_t segments = closed ? path.size() : path.size() - 1;
  for (size_t i = 0; i < segments; ++i) {
    best = std::min(best, DistanceToSegment(p, path[i], path[(i + 1) % path.size()]));
  }
  return best;
}

// Field-by-field equality of two layer lists (points bit-equal).
inline void ExpectSameLayers(const std::vector<ArtLayer>& a, const std::vector<ArtLayer>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t l = 0; l < a.size(); ++l) {
    SCOPED_TRACE(::testing::Message() << "layer " << l);
    EXPECT_EQ(a[l].id, b[l].id);
    EXPECT_EQ(a[l].name, b[l].name);
    EXPECT_EQ(a[l].opacity, b[l].opacity);
    ASSERT_EQ(a[l].fill.has_value(), b[l].fill.has_value());
    if (a[l].fill) {
      EXPECT_EQ(a[l].fill->rgb, b[l].fill->rgb);
      EXPECT_EQ(a[l].fill->opacity, b[l].fill->opacity);
      EXPECT_EQ(a[l].fill->even_odd, b[l].fill->even_odd);
    }
    ASSERT_EQ(a[l].stroke.has_value(), b[l].stroke.has_value());
    if (a[l].stroke) {
      const StrokePaint &s = *a[l].stroke, &t = *b[l].stroke;
      EXPECT_EQ(s.rgb, t.rgb);
      EXPECT_EQ(s.opacity, t.opacity);
      EXPECT_EQ(s.width, t.width);
      EXPECT_EQ(s.cap, t.cap);
      EXPECT_EQ(s.join, t.join);
      EXPECT_EQ(s.miter_limit, t.miter_limit);
      EXPECT_EQ(s.dashes, t.dashes);
      EXPECT_EQ(s.dash_offset, t.dash_offset);
    }
    ASSERT_EQ(a[l].paths.size(), b[l].paths.size());
    for (size_t k = 0; k < a[l].paths.size(); ++k) {
      EXPECT_EQ(a[l].paths[k].closed, b[l].paths[k].closed);
      EXPECT_EQ(a[l].paths[k].points, b[l].paths[k].points);
    }
  }
}

}  // namespace inbetween::solver::art_test
