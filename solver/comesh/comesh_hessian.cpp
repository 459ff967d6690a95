// Edge-space Hessians of the ODT and MIPS triangle energies (see comesh_hessian.h).
#include "solver/comesh/comesh_hessian.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace inbetween::solver {
namespace {

// d^2(det E)/du^2 for u = vec(E) = (e1x, e1y, e2x, e2y): det E = u0 u3 - u1 u2.
Matrix4 DetHessian() {
  Matrix4 j = Matrix4::Zero();
  j(0, 3) = j(3, 0) = 1.0;
  j(1, 2) = j(2, 1) = -1.0;
  return j;
}

Eigen::Vector4d Vec(const Eigen::Matrix2d& e) { return {e(0, 0), e(1, 0), e(0, 1), e(1, 1)}; }

// d(det E)/du.
Eigen::Vector4d DetGradient(const Eigen::Vector4d& u) { return {u[3], -u[2], -u[1], u[0]}; }

// G (x) I_2 for a symmetric 2 x 2 G, in the vec(E) ordering.
Matrix4 KroneckerI2(const Eigen::Matrix2d& g) {
  Matrix4 k = Matrix4::Zero();
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) k.block<2, 2>(2 * i, 2 * j) = g(i, j) * Eigen::Matrix2d::Identity();
  }
  return k;
}

}  // namespace

Matrix4 OdtEdgeHessian(const Eigen::Matrix2d& e) {
  const Eigen::Vector4d u = Vec(e);
  const double area = 0.5 * (u[0] * u[3] - u[1] * u[2]);
  const Eigen::Vector4d grad_area = 0.5 * DetGradient(u);
  const Eigen::Vector4d grad_s(4 * u[0] - 2 * u[2], 4 * u[1] - 2 * u[3], 4 * u[2] - 2 * u[0],
                               4 * u[3] - 2 * u[1]);
  const double s =
      2 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]) - 2 * (u[0] * u[2] + u[1] * u[3]);
  Eigen::Matrix2d pattern;
  pattern << 4.0, -2.0, -2.0, 4.0;
  const Matrix4 hess_s = KroneckerI2(pattern);
  return (grad_area * grad_s.transpose() + grad_s * grad_area.transpose() + area * hess_s +
          0.5 * s * DetHessian()) /
         12.0;
}

void MipsEdgeHessians(const Eigen::Matrix2d& p, const Eigen::Matrix2d& q, Matrix4* hp,
                      Matrix4* hq) {
  Eigen::Matrix2d adj_p;
  adj_p << p(1, 1), -p(0, 1), -p(1, 0), p(0, 0);
  const double d = q.determinant();
  if (hp != nullptr) {
    Matrix4 t = Matrix4::Zero();  // vec(adj P) = T vec(P)
    t(0, 3) = 1.0;
    t(1, 1) = -1.0;
    t(2, 2) = -1.0;
    t(3, 0) = 1.0;
    const Eigen::Matrix2d k = q.transpose() * q;
    Matrix4 kk = Matrix4::Zero();
    kk.block<2, 2>(0, 0) = k;
    kk.block<2, 2>(2, 2) = k;
    *hp = t.transpose() * kk * t / d;
  }
  if (hq != nullptr) {
    const Eigen::Vector4d u = Vec(q);
    const Matrix4 hess_n = 2.0 * KroneckerI2(adj_p * adj_p.transpose());
    const Eigen::Vector4d grad_n = hess_n * u;
    const double n = 0.5 * u.dot(grad_n);
    const Eigen::Vector4d grad_d = DetGradient(u);
    *hq = hess_n / (2 * d) -
          (grad_n * grad_d.transpose() + grad_d * grad_n.transpose()) / (2 * d * d) +
          (n / (d * d * d)) * grad_d * grad_d.transpose() - (n / (2 * d * d)) * DetHessian();
  }
}

Matrix4 ProjectPositiveDefinite(const Matrix4& h, double floor) {
  // Most sums are definite already: a 4 x 4 Cholesky (far cheaper than the eigensolver) tells,
  // and then only the floor is added, on the diagonal (the eigenvalues all shift by it).
  const Eigen::LLT<Matrix4> llt(h);
  if (llt.info() == Eigen::Success &&
      llt.matrixLLT().diagonal().minCoeff() > 1e-6 * std::sqrt(h.diagonal().maxCoeff())) {
    // Gershgorin bounds the largest eigenvalue by the largest absolute row sum.
    const double top = h.cwiseAbs().rowwise().sum().maxCoeff();
    return h + (floor * top) * Matrix4::Identity();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix4> eig(h);
  Eigen::Vector4d lambda = eig.eigenvalues();
  const double top = std::max(lambda.maxCoeff(), 0.0);
  for (int i = 0; i < 4; ++i) lambda[i] = std::max(lambda[i], 0.0) + floor * top;
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

Matrix6 CornerHessian(const Matrix4& h) {
  Eigen::Matrix<double, 4, 6> d = Eigen::Matrix<double, 4, 6>::Zero();
  for (int k = 0; k < 2; ++k) {
    d(k, k) = -1.0;  // e1 = x1 - x0
    d(k, 2 + k) = 1.0;
    d(2 + k, k) = -1.0;  // e2 = x2 - x0
    d(2 + k, 4 + k) = 1.0;
  }
  return d.transpose() * h * d;
}

}  // namespace inbetween::solver
