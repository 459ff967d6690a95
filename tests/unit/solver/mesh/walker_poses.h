// Generated key drawings of a walking character for tests and benchmarks: the side-view
// silhouette of examples/walk (head, torso, arm, two legs apart) at 16 phases of a stride, all of
// one topology, each with a correspondence mark (id 1) at the crotch and, with feature_marks,
// marks 2-8 at the toe tips, the fingertip, the top of the head, the armpit and the hips.
#pragma once

#include <cmath>
#include <numbers>

#include "solver/core/types.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver::testing {

// Direction of a limb at `degrees` from straight down (y-down coordinates), as in
// examples/make_examples.py.
inline Point LimbDirection(double degrees) {
  const double a = degrees * std::numbers::pi / 180.0;
  return {std::sin(a), std::cos(a)};
}
// Normal of a leg at `degrees` (points to the front of the leg).
inline Point LimbNormal(double degrees) {
  const double a = degrees * std::numbers::pi / 180.0;
  return {std::cos(a), -std::sin(a)};
}
// p + s d where the line p + s d meets q + t e.
inline Point LineIntersection(const Point& p, const Point& d, const Point& q, const Point& e) {
  const double s = Cross(q - p, e) / Cross(d, e);
  return p + s * d;
}

// The walker with its front leg at `front` degrees, back leg at `back` (negative: behind) and
// arm at `arm`, with its correspondence marks.
inline Drawing Walker(double front, double back, double arm, bool feature_marks = false) {
  const Point hip(0, -6);
  const double w = 9, leg = 54;
  Points pts;
  // Head: the long arc of a circle of radius 11 from (-3, -66) over the top to (5, -66).
  const Point centre(1, -66 - std::sqrt(121.0 - 16.0));
  const double a0 = std::atan2(-66 - centre.y(), -3 - centre.x());
  const double a1 = std::atan2(-66 - centre.y(), 5 - centre.x()) + 2 * std::numbers::pi;
  constexpr int kArc = 24;
  for (int k = 0; k <= kArc; ++k) {
    const double a = a0 + (a1 - a0) * k / kArc;
    pts.push_back(centre + 11.0 * Point(std::cos(a), std::sin(a)));
  }
  pts.emplace_back(5, -62);
  pts.emplace_back(9, -60);
  // Arm on the torso front from the shoulder.
  const Point shoulder(9, -60);
  const Point d = LimbDirection(arm);
  const Point n(-std::cos(arm * std::numbers::pi / 180.0), std::sin(arm * std::numbers::pi / 180.0));
  const Point hand = shoulder + 34.0 * d;
  pts.push_back(hand);
  pts.push_back(hand + 7.0 * n + 2.0 * d);
  const Point armpit = LineIntersection(shoulder + 7.0 * n, d, shoulder, Point(0, 1));
  pts.push_back(armpit);
  pts.emplace_back(9, -10);
  // Legs apart.
  const Point df = LimbDirection(front), nf = LimbNormal(front);
  const Point db = LimbDirection(back), nb = LimbNormal(back);
  const Point ff = hip + (w / 2) * nf, fb = hip - (w / 2) * nf;
  const Point bf = hip + (w / 2) * nb, bb = hip - (w / 2) * nb;
  auto toe = [](const Point& e, const Point& dir, const Point& nor) {
    return e + 8.0 * nor + 2.0 * dir;
  };
  const Point crotch = LineIntersection(fb, df, bf, db);
  Point ef = ff + leg * df, eb = fb + leg * df;
  pts.insert(pts.end(), {ff, ef, toe(ef, df, nf), eb + 2.0 * df, eb, crotch});
  ef = bf + leg * db;
  eb = bb + leg * db;
  pts.insert(pts.end(), {ef, toe(ef, db, nb), eb + 2.0 * db, eb, bb});
  pts.emplace_back(-9, -10);
  pts.emplace_back(-10, -56);
  pts.emplace_back(-3, -62);
  Drawing drawing;
  drawing.outlines.push_back({pts});
  drawing.marks.push_back({1, crotch});
  if (feature_marks) {  // what an animator would pin as well: tips and the armpit
    drawing.marks.push_back({2, toe(ff + leg * df, df, nf)});
    drawing.marks.push_back({3, toe(bf + leg * db, db, nb)});
    drawing.marks.push_back({4, hand + 7.0 * n + 2.0 * d});
    drawing.marks.push_back({5, centre + Point(0, -11)});
    drawing.marks.push_back({6, armpit});
    drawing.marks.push_back({7, ff});  // where the legs meet the torso
    drawing.marks.push_back({8, bb});
  }
  return drawing;
}

// Pose k of 16 along a stride: legs swing between 14 and 30 degrees apart, the arm counters.
inline Drawing WalkerPose(int k, bool feature_marks = false) {
  const double phase = 2.0 * std::numbers::pi * k / 16.0;
  const double front = 22.0 + 8.0 * std::sin(phase);
  const double back = -22.0 + 8.0 * std::cos(phase);
  const double arm = 40.0 - 10.0 * std::sin(phase);
  return Walker(front, back, arm, feature_marks);
}

}  // namespace inbetween::solver::testing
