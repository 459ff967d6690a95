// Closed-form 2x2 polar decomposition (see polar.h).
#include "solver/interp/polar.h"

#include <cmath>
#include <numbers>

namespace inbetween::solver {

Eigen::Matrix2d RotationMatrix(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

double ClosestRotationAngle(const Eigen::Matrix2d& m) {
  const double c = m(0, 0) + m(1, 1);
  const double s = m(1, 0) - m(0, 1);
  if (c == 0.0 && s == 0.0) return 0.0;
  return std::atan2(s, c);  // in [-pi, pi]; -pi only for s == -0.0, mapped below
}

Eigen::Matrix2d ClosestRotation(const Eigen::Matrix2d& m) {
  const double c = m(0, 0) + m(1, 1);
  const double s = m(1, 0) - m(0, 1);
  const double r = std::hypot(c, s);
  if (r == 0.0) return Eigen::Matrix2d::Identity();
  Eigen::Matrix2d rot;
  rot << c / r, -s / r, s / r, c / r;
  return rot;
}

PolarDecomposition Polar(const Eigen::Matrix2d& m) {
  PolarDecomposition p;
  p.angle = ClosestRotationAngle(m);
  if (p.angle == -std::numbers::pi) p.angle = std::numbers::pi;
  p.rotation = RotationMatrix(p.angle);
  const Eigen::Matrix2d s = p.rotation.transpose() * m;
  // Exactly symmetric in exact arithmetic; symmetrize the rounding.
  p.stretch(0, 0) = s(0, 0);
  p.stretch(1, 1) = s(1, 1);
  p.stretch(0, 1) = p.stretch(1, 0) = 0.5 * (s(0, 1) + s(1, 0));
  return p;
}

double UnwrapAngle(double angle, double reference) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  return angle - kTwoPi * std::round((angle - reference) / kTwoPi);
}

}  // namespace inbetween::solver
