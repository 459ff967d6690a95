// 2x2 polar decomposition M = R S in closed form, R in SO(2) the closest rotation to M in the
// Frobenius norm (the local step of S-eq.3, and Alexa et al. 2000's rotation/stretch split).
// tr(R(a)^T M) = cos(a) (m00 + m11) + sin(a) (m10 - m01) is maximal at
// a = atan2(m10 - m01, m00 + m11); then S = R^T M is symmetric, positive definite iff det M > 0.
#pragma once

#include <Eigen/Core>

namespace inbetween::solver {

// Rotation by `angle` radians (counter-clockwise in a y-up frame).
Eigen::Matrix2d RotationMatrix(double angle);

// Angle in (-pi, pi] of the rotation closest to `m` (0 when m has no rotational part, e.g. 0).
double ClosestRotationAngle(const Eigen::Matrix2d& m);

// The rotation closest to `m` (identity when m has no rotational part). Always det = +1.
Eigen::Matrix2d ClosestRotation(const Eigen::Matrix2d& m);

struct PolarDecomposition {
  double angle = 0.0;        // in (-pi, pi]
  Eigen::Matrix2d rotation;  // RotationMatrix(angle)
  Eigen::Matrix2d stretch;   // symmetric; rotation * stretch == m
};

PolarDecomposition Polar(const Eigen::Matrix2d& m);

// `angle` + 2 pi k closest to `reference`.
double UnwrapAngle(double angle, double reference);

}  // namespace inbetween::solver
