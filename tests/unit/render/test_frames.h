// Small frame sets shared by the render tests: rings (square with a hole, annuli), separate and
// touching components, and a morphing animation with two keys.
#pragma once

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "client/render/frame_set.h"

namespace inbetween::render::testing {

// Positive signed area in y-down coordinates, as frames.json requires.
inline void OrientPositive(std::vector<std::array<int, 3>>& tris, const std::vector<Vertex>& v) {
  for (auto& t : tris) {
    const Vertex &a = v[t[0]], &b = v[t[1]], &c = v[t[2]];
    const double cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (cross < 0) std::swap(t[1], t[2]);
  }
}

// An n-gon annulus: vertices 0..n-1 on the outer circle, n..2n-1 on the inner one.
inline std::pair<std::vector<Vertex>, std::vector<std::array<int, 3>>> Ring(
    int n, double outer, double inner, double cx = 0, double cy = 0, double phase = 0) {
  std::vector<Vertex> v;
  for (double r : {outer, inner}) {
    for (int i = 0; i < n; ++i) {
      const double a = phase + 2 * std::numbers::pi * i / n;
      v.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
    }
  }
  std::vector<std::array<int, 3>> tris;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    tris.push_back({i, j, n + i});
    tris.push_back({n + i, j, n + j});
  }
  OrientPositive(tris, v);
  return {v, tris};
}

inline FrameSet OneFrame(std::vector<Vertex> v, std::vector<std::array<int, 3>> tris) {
  FrameSet set;
  set.triangles = std::move(tris);
  set.keys = {0};
  set.frames.push_back({0, 0.0, {1.0}, std::move(v)});
  return set;
}

// Square [0,10]^2 with the hole [3,7]^2 (a 4-gon ring rotated by 45 degrees, scaled).
inline FrameSet SquareWithHole() {
  auto [v, tris] = Ring(4, 2, 1, 0, 0, std::numbers::pi / 4);
  for (int i = 0; i < 8; ++i) {
    const double h = i < 4 ? 5.0 : 2.0;
    v[i] = {5 + (v[i][0] > 0 ? h : -h), 5 + (v[i][1] > 0 ? h : -h)};
  }
  OrientPositive(tris, v);
  return OneFrame(v, tris);
}

// Two unit squares far apart (two components, no hole).
inline FrameSet TwoSquares() {
  std::vector<Vertex> v = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {5, 0}, {6, 0}, {6, 1}, {5, 1}};
  std::vector<std::array<int, 3>> tris = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  OrientPositive(tris, v);
  return OneFrame(v, tris);
}

// A ring morphing from a square-ish 4-gon to a translated 24-gon over `count` frames; keys at the
// ends.
inline FrameSet MorphingRing(int count, int n = 24) {
  auto [from, tris] = Ring(n, 40, 20, 50, 50);
  auto [to, unused] = Ring(n, 30, 10, 90, 60, 0.3);
  for (int i = 0; i < n; ++i) {  // pull the first ring onto a square
    for (int ring = 0; ring < 2; ++ring) {
      Vertex& p = from[ring * n + i];
      const double dx = p[0] - 50, dy = p[1] - 50;
      const double s = std::hypot(dx, dy) / std::max(std::abs(dx), std::abs(dy));
      p = {50 + dx * s, 50 + dy * s};
    }
  }
  FrameSet set;
  set.triangles = tris;
  set.keys = {0, count - 1};
  for (int f = 0; f < count; ++f) {
    const double t = count > 1 ? static_cast<double>(f) / (count - 1) : 0.0;
    FrameData data{f, t, {1 - t, t}, {}};
    for (size_t i = 0; i < from.size(); ++i) {
      data.vertices.push_back(
          {(1 - t) * from[i][0] + t * to[i][0], (1 - t) * from[i][1] + t * to[i][1]});
    }
    set.frames.push_back(std::move(data));
  }
  return set;
}

}  // namespace inbetween::render::testing
