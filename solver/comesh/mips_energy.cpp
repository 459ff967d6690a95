// S-eq.2: MIPS map energy, closed form sigma* = ||Q adj P||^2 / (det P det Q) and its gradient
// (see mips_energy.h for the derivation).
#include "solver/comesh/mips_energy.h"

#include <Eigen/LU>
#include <cmath>
#include <limits>

namespace inbetween::solver {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Matrix2d Adjugate(const Eigen::Matrix2d& m) {
  Eigen::Matrix2d a;
  a << m(1, 1), -m(0, 1), -m(1, 0), m(0, 0);
  return a;
}

void ToCorners(const Eigen::Matrix2d& d, std::array<Point, 3>* g) {
  (*g)[1] = d.col(0);
  (*g)[2] = d.col(1);
  (*g)[0] = -(d.col(0) + d.col(1));
}

}  // namespace

Eigen::Matrix2d EdgeMatrix(const std::array<Point, 3>& x) {
  Eigen::Matrix2d m;
  m.col(0) = x[1] - x[0];
  m.col(1) = x[2] - x[0];
  return m;
}

Eigen::Matrix2d EdgeMatrix(const Points& x, const Triangle& t) {
  return EdgeMatrix({x[t[0]], x[t[1]], x[t[2]]});
}

double MipsSigma(const Eigen::Matrix2d& p, const Eigen::Matrix2d& q) {
  const double det_p = p.determinant();
  const double det_q = q.determinant();
  if (!(det_p > 0.0) || !(det_q > 0.0)) return kInf;
  return (q * Adjugate(p)).squaredNorm() / (det_p * det_q);
}

double MipsTriangleEnergy(const std::array<Point, 3>& xi, const std::array<Point, 3>& xj,
                          std::array<Point, 3>* gradient_i, std::array<Point, 3>* gradient_j) {
  const Eigen::Matrix2d p = EdgeMatrix(xi);
  const Eigen::Matrix2d q = EdgeMatrix(xj);
  const double det_p = p.determinant();
  const double det_q = q.determinant();
  if (!(det_p > 0.0) || !(det_q > 0.0)) return kInf;
  const Eigen::Matrix2d adj_p = Adjugate(p);
  const Eigen::Matrix2d m = q * adj_p;
  const double n = m.squaredNorm();
  if (gradient_i != nullptr) {
    const Eigen::Matrix2d qtm = q.transpose() * m;
    const Eigen::Matrix2d dp = (qtm.trace() * Eigen::Matrix2d::Identity() - qtm) / det_q;
    ToCorners(dp, gradient_i);
  }
  if (gradient_j != nullptr) {
    const Eigen::Matrix2d dq =
        m * adj_p.transpose() / det_q - (n / (2.0 * det_q * det_q)) * Adjugate(q).transpose();
    ToCorners(dq, gradient_j);
  }
  return n / (2.0 * det_q);
}

double MipsEnergy(const std::vector<Triangle>& triangles, const Points& xi, const Points& xj,
                  Points* gradient_i, Points* gradient_j) {
  double total = 0.0;
  std::array<Point, 3> gi, gj;
  for (const Triangle& t : triangles) {
    const std::array<Point, 3> ci = {xi[t[0]], xi[t[1]], xi[t[2]]};
    const std::array<Point, 3> cj = {xj[t[0]], xj[t[1]], xj[t[2]]};
    const double e =
        MipsTriangleEnergy(ci, cj, gradient_i ? &gi : nullptr, gradient_j ? &gj : nullptr);
    if (!std::isfinite(e)) return kInf;
    total += e;
    for (int k = 0; k < 3; ++k) {
      if (gradient_i != nullptr) (*gradient_i)[t[k]] += gi[k];
      if (gradient_j != nullptr) (*gradient_j)[t[k]] += gj[k];
    }
  }
  return total;
}

std::vector<double> MipsSigmas(const std::vector<Triangle>& triangles, const Points& xi,
                               const Points& xj) {
  std::vector<double> sigmas;
  sigmas.reserve(triangles.size());
  for (const Triangle& t : triangles) {
    sigmas.push_back(MipsSigma(EdgeMatrix(xi, t), EdgeMatrix(xj, t)));
  }
  return sigmas;
}

}  // namespace inbetween::solver
