// S-eq.13-16 cohesive edge energy with the tau cap (S-eq.6) and its majorize-minimize pieces
// (see cohesive_energy.h).
#include "solver/interp/cohesive_energy.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {
namespace {

// Two points count as collocated when closer than this fraction of the edge length.
constexpr double kCollocated = 1e-9;

}  // namespace

absl::StatusOr<CohesiveEnergy> CohesiveEnergy::Create(const std::vector<std::array<int, 4>>& edges,
                                                      const std::vector<Points>& shapes,
                                                      CohesiveOptions options) {
  if (!(options.lambda >= 0.0) || !std::isfinite(options.lambda)) {
    return absl::InvalidArgumentError(absl::StrCat("lambda must be >= 0, got ", options.lambda));
  }
  if (!(options.tau >= 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("tau must be >= 0, got ", options.tau));
  }
  if (!(options.alpha >= 0.0 && options.alpha <= 1.0)) {
    return absl::InvalidArgumentError(absl::StrCat("alpha must be in [0, 1], got ", options.alpha));
  }
  if (!(options.hysteresis >= 0.0 && options.hysteresis < 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("hysteresis must be in [0, 1), got ", options.hysteresis));
  }
  CohesiveEnergy c;
  c.options_ = options;
  c.mu_ = std::max(options.alpha, 1.0 - options.alpha);
  c.edges_ = edges;
  const int n = shapes.empty() ? 0 : static_cast<int>(shapes[0].size());
  for (size_t e = 0; e < edges.size(); ++e) {
    for (int v : edges[e]) {
      if (v < 0 || v >= n) {
        return absl::InvalidArgumentError(
            absl::StrCat("cohesive edge ", e, " has vertex index ", v, " outside [0, ", n, ")"));
      }
    }
    const auto [a, b, cc, d] = edges[e];
    double length = 0.0;
    std::vector<char> closed(shapes.size(), 0);
    for (size_t i = 0; i < shapes.size(); ++i) {
      const Points& x = shapes[i];
      const double l = 0.5 * ((x[b] - x[a]).norm() + (x[d] - x[cc]).norm());
      length += l / static_cast<double>(shapes.size());
      closed[i] =
          (x[a] - x[cc]).norm() <= kCollocated * l && (x[b] - x[d]).norm() <= kCollocated * l;
    }
    if (!(length > 0.0)) {
      return absl::InvalidArgumentError(absl::StrCat("cohesive edge ", e, " has zero length"));
    }
    const Eigen::Vector2d u = shapes[0][a] + shapes[0][cc] - shapes[0][b] - shapes[0][d];
    c.lengths_.push_back(length);
    c.rest_directions_.push_back(u.norm() > 0.0 ? Eigen::Vector2d(u.normalized())
                                                : Eigen::Vector2d(1.0, 0.0));
    c.closed_.push_back(std::move(closed));
  }
  return c;
}

double CohesiveEnergy::Activity(const std::vector<double>& w, int e) const {
  double c = 0.0;
  for (size_t i = 0; i < w.size(); ++i) {
    if (closed_[e][i]) c += w[i];
  }
  return c;
}

Eigen::Vector2d CohesiveEnergy::Direction(const Coords& x, int e) const {
  const auto [a, b, c, d] = edges_[e];
  const Eigen::Vector2d u = (x.row(a) + x.row(c) - x.row(b) - x.row(d)).transpose();
  const double norm = u.norm();
  return norm > 1e-12 * lengths_[e] ? Eigen::Vector2d(u / norm) : rest_directions_[e];
}

double CohesiveEnergy::EdgeEnergy(const Coords& x, int e) const {
  const auto [a, b, c, d] = edges_[e];
  const Eigen::Vector2d g0 = (x.row(a) - x.row(c)).transpose();
  const Eigen::Vector2d g1 = (x.row(b) - x.row(d)).transpose();
  const Eigen::Vector2d xhat = Direction(x, e);
  const double alpha = options_.alpha;
  auto form = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    // p^T P q = alpha p.q + (1 - 2 alpha) (xhat.p)(xhat.q)
    return alpha * p.dot(q) + (1.0 - 2.0 * alpha) * xhat.dot(p) * xhat.dot(q);
  };
  return options_.lambda * lengths_[e] / 3.0 * (form(g0, g0) + form(g1, g1) + form(g0, g1));
}

std::vector<double> CohesiveEnergy::Thresholds(const Coords* previous) const {
  std::vector<double> t(edges_.size());
  for (int e = 0; e < num_edges(); ++e) {
    double tau = options_.tau;
    if (previous != nullptr) {
      const bool was_separated = EdgeEnergy(*previous, e) >= options_.tau * lengths_[e];
      tau *= was_separated ? 1.0 - options_.hysteresis : 1.0 + options_.hysteresis;
    }
    t[e] = tau * lengths_[e];
  }
  return t;
}

double CohesiveEnergy::Value(const Coords& x, const std::vector<double>& w,
                             const std::vector<double>& thresholds) const {
  double sum = 0.0;
  for (int e = 0; e < num_edges(); ++e) {
    sum += Activity(w, e) * std::min(EdgeEnergy(x, e), thresholds[e]);
  }
  return sum;
}

Coords CohesiveEnergy::Gradient(const Coords& x, const std::vector<double>& w,
                                const std::vector<double>& thresholds) const {
  Coords grad = Coords::Zero(x.rows(), 2);
  const double alpha = options_.alpha;
  for (int e = 0; e < num_edges(); ++e) {
    const double activity = Activity(w, e);
    if (activity == 0.0 || EdgeEnergy(x, e) >= thresholds[e]) continue;  // capped: constant
    const auto [a, b, c, d] = edges_[e];
    const Eigen::Vector2d g0 = (x.row(a) - x.row(c)).transpose();
    const Eigen::Vector2d g1 = (x.row(b) - x.row(d)).transpose();
    const Eigen::Vector2d u = (x.row(a) + x.row(c) - x.row(b) - x.row(d)).transpose();
    const Eigen::Vector2d xhat = Direction(x, e);
    const double k = activity * options_.lambda * lengths_[e] / 3.0;
    auto p_times = [&](const Eigen::Vector2d& v) -> Eigen::Vector2d {
      return alpha * v + (1.0 - 2.0 * alpha) * xhat.dot(v) * xhat;
    };
    // f = k (g0^T P g0 + g1^T P g1 + g0^T P g1): df/dg0 = k P (2 g0 + g1), df/dg1 = k P (2 g1 + g0)
    const Eigen::Vector2d d0 = k * p_times(2.0 * g0 + g1);
    const Eigen::Vector2d d1 = k * p_times(2.0 * g1 + g0);
    grad.row(a) += d0.transpose();
    grad.row(c) -= d0.transpose();
    grad.row(b) += d1.transpose();
    grad.row(d) -= d1.transpose();
    // Through xhat = u / |u|: df/dxhat = k (1 - 2 alpha) (2 (xhat.g0) g0 + 2 (xhat.g1) g1
    //   + (xhat.g1) g0 + (xhat.g0) g1), df/du = (I - xhat xhat^T) df/dxhat / |u|.
    const double norm = u.norm();
    if (norm > 1e-12 * lengths_[e] && alpha != 0.5) {
      const double s0 = xhat.dot(g0), s1 = xhat.dot(g1);
      const Eigen::Vector2d dxhat =
          k * (1.0 - 2.0 * alpha) * (2.0 * s0 * g0 + 2.0 * s1 * g1 + s1 * g0 + s0 * g1);
      const Eigen::Vector2d du = (dxhat - xhat.dot(dxhat) * xhat) / norm;
      grad.row(a) += du.transpose();
      grad.row(c) += du.transpose();
      grad.row(b) -= du.transpose();
      grad.row(d) -= du.transpose();
    }
  }
  return grad;
}

void CohesiveEnergy::AddMatrix(std::vector<Eigen::Triplet<double>>* triplets) const {
  // g = C x with C = [[1, 0, -1, 0], [0, 1, 0, -1]] on (a, b, c, d); Hbar = k [[1, .5], [.5, 1]].
  for (int e = 0; e < num_edges(); ++e) {
    const double k = mu_ * options_.lambda * lengths_[e] / 3.0;
    if (k == 0.0) continue;
    const std::array<int, 4>& v = edges_[e];
    const double l[2][2] = {{1.0, 0.5}, {0.5, 1.0}};
    const double sign[4] = {1.0, 1.0, -1.0, -1.0};
    const int jump[4] = {0, 1, 0, 1};
    for (int p = 0; p < 4; ++p) {
      for (int q = 0; q < 4; ++q) {
        triplets->emplace_back(v[p], v[q], k * sign[p] * sign[q] * l[jump[p]][jump[q]]);
      }
    }
  }
}

double CohesiveEnergy::LocalStep(const Coords& x, const std::vector<double>& w,
                                 const std::vector<double>& thresholds, Coords* b,
                                 std::vector<char>* separated) const {
  separated->assign(edges_.size(), 0);
  const double alpha = options_.alpha;
  double energy = 0.0;
  for (int e = 0; e < num_edges(); ++e) {
    const auto [a, bb, c, d] = edges_[e];
    const Eigen::Vector2d g0 = (x.row(a) - x.row(c)).transpose();
    const Eigen::Vector2d g1 = (x.row(bb) - x.row(d)).transpose();
    const double activity = Activity(w, e);
    const double f = EdgeEnergy(x, e);
    const bool capped = activity == 0.0 || f >= thresholds[e];
    (*separated)[e] = capped;
    energy += activity * std::min(f, thresholds[e]);
    const double k = options_.lambda * lengths_[e] / 3.0;
    // Hbar g_k on (g0, g1): mu k (g0 + g1 / 2, g1 + g0 / 2).
    Eigen::Vector2d q0 = mu_ * k * (g0 + 0.5 * g1);
    Eigen::Vector2d q1 = mu_ * k * (g1 + 0.5 * g0);
    if (!capped) {
      const Eigen::Vector2d xhat = Direction(x, e);
      auto p_times = [&](const Eigen::Vector2d& v) -> Eigen::Vector2d {
        return alpha * v + (1.0 - 2.0 * alpha) * xhat.dot(v) * xhat;
      };
      q0 -= activity * k * p_times(g0 + 0.5 * g1);
      q1 -= activity * k * p_times(g1 + 0.5 * g0);
    }
    b->row(a) += q0.transpose();
    b->row(c) -= q0.transpose();
    b->row(bb) += q1.transpose();
    b->row(d) -= q1.transpose();
  }
  return energy;
}

}  // namespace inbetween::solver
