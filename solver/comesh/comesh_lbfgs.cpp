// The comesh inner loop's blended L-BFGS (see comesh_lbfgs.h).
#include "solver/comesh/comesh_lbfgs.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace inbetween::solver {

using Eigen::VectorXd;

VectorXd ComeshLbfgs::Direction(const VectorXd& g, const ComeshPreconditioner& b0,
                                const CancelToken* cancel) const {
  VectorXd q = g;
  std::vector<double> alpha(pairs_.size());
  for (int i = static_cast<int>(pairs_.size()) - 1; i >= 0; --i) {
    if (Cancelled(cancel)) return VectorXd();
    alpha[i] = pairs_[i].rho * pairs_[i].s.dot(q);
    q -= alpha[i] * pairs_[i].y;
  }
  VectorXd r = b0.ApplyInverse(q, cancel);
  if (r.size() == 0) return r;  // cancelled
  r /= beta_;
  for (size_t i = 0; i < pairs_.size(); ++i) {
    if (Cancelled(cancel)) return VectorXd();
    const double b = pairs_[i].rho * pairs_[i].y.dot(r);
    r += (alpha[i] - b) * pairs_[i].s;
  }
  if (Cancelled(cancel)) return VectorXd();
  return VectorXd(-r);
}

bool ComeshLbfgs::Update(const VectorXd& z, const VectorXd& z_new, const VectorXd& g,
                         const VectorXd& g_new, double g0, const ComeshPreconditioner& b0,
                         const CancelToken* cancel) {
  Pair p = std::move(spare_);
  p.s = z_new - z;
  p.y = g_new - g;
  p.rho = 0.0;
  if (Cancelled(cancel)) return false;
  const double sy = p.s.dot(p.y);
  if (Cancelled(cancel)) return false;
  if (!(sy > 1e-12 * p.s.norm() * p.y.norm() && options_.history > 0)) {
    spare_ = std::move(p);
    return true;
  }
  const VectorXd b0s = b0.Apply(p.s, cancel);  // empty if cancelled
  if (b0s.size() != p.s.size() || Cancelled(cancel)) return false;
  if (options_.scaling_by_inverse) {
    const VectorXd hy = b0.ApplyInverse(p.y, cancel);
    if (hy.size() == 0) return false;
    beta_ = p.y.dot(hy) / sy;
  } else {
    beta_ = sy / p.s.dot(b0s);
  }
  if (options_.blend > 0.0) {
    const double theta = std::min(1.0, options_.blend * g_new.norm() / g0);
    p.y = (1.0 - theta) * p.y + theta * beta_ * b0s;
  }
  p.rho = 1.0 / sy;
  pairs_.push_back(std::move(p));
  if (static_cast<int>(pairs_.size()) > options_.history) {
    spare_ = std::move(pairs_.front());
    pairs_.pop_front();
  }
  return true;
}

}  // namespace inbetween::solver
