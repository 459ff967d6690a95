// BCQN's Laplacian initial Hessian for the comesh inner loop (see
// comesh_laplacian_preconditioner.h).
#include "solver/comesh/comesh_laplacian_preconditioner.h"

#include <algorithm>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inbetween::solver {

using Eigen::VectorXd;

absl::StatusOr<std::unique_ptr<LaplacianPreconditioner>> LaplacianPreconditioner::Create(
    const std::vector<Triangle>& triangles, const ComeshLayout& layout, std::vector<double> areas,
    const CancelToken* cancel) {
  std::unique_ptr<LaplacianPreconditioner> h(new LaplacianPreconditioner());
  h->areas_ = std::move(areas);
  h->layout_ = &layout;
  const int n = layout.num_vertices();
  const int num_shapes = layout.num_shapes();
  h->compact_.assign(n, -1);
  for (int v = 0; v < n; ++v) {
    bool everywhere = true;
    for (int s = 0; s < num_shapes && everywhere; ++s) everywhere = layout.index(s, v) >= 0;
    if (everywhere) h->compact_[v] = h->size_++;
  }
  h->degree_.assign(n, 0.0);
  std::vector<Eigen::Triplet<double>> trip;
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      constexpr double w = 0.5;  // each interior edge is seen from two triangles
      const int a = t[k], b = t[(k + 1) % 3];
      h->degree_[a] += w;
      h->degree_[b] += w;
      const int ca = h->compact_[a], cb = h->compact_[b];
      if (ca >= 0) trip.emplace_back(ca, ca, w);
      if (cb >= 0) trip.emplace_back(cb, cb, w);
      if (ca >= 0 && cb >= 0) {
        trip.emplace_back(ca, cb, -w);
        trip.emplace_back(cb, ca, -w);
      }
    }
  }
  if (h->size_ == 0) return h;
  h->FindFloating(triangles);
  h->matrix_.resize(h->size_, h->size_);
  h->matrix_.setFromTriplets(trip.begin(), trip.end());
  // A floating component makes L singular: regularized slightly for the factorization, and
  // ApplyInverse keeps the constant out of its right-hand sides and solutions.
  for (int k = 0; k < h->size_; ++k) h->matrix_.coeffRef(k, k) *= 1.0 + 1e-8;
  h->matrix_.makeCompressed();
  h->solver_ = std::make_unique<SparseCholesky>();
  absl::Status st = h->solver_->Analyze(h->matrix_);
  if (st.ok()) st = h->solver_->Factorize(h->matrix_, cancel);
  if (absl::IsCancelled(st)) return st;
  if (!st.ok()) {
    return absl::InternalError(
        absl::StrCat("factorizing the comesh Laplacian preconditioner: ", st.message()));
  }
  return h;
}

VectorXd LaplacianPreconditioner::ApplyInverse(const VectorXd& g, const CancelToken* cancel) const {
  const ComeshLayout& layout = *layout_;
  const int num_shapes = layout.num_shapes();
  VectorXd out(g.size());
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(size_, 2 * num_shapes);
  for (const ComeshLayout::Var& var : layout.vars()) {
    const int c = compact_[var.vertex];
    const double a = areas_[var.shape];
    if (c < 0) {
      const double jacobi = a / std::max(degree_[var.vertex], 1e-300);
      if (var.slider) {
        out[var.offset] = jacobi * g[var.offset];
      } else {
        out.segment<2>(var.offset) = jacobi * g.segment<2>(var.offset);
      }
      continue;
    }
    const Point lifted =
        var.slider ? Point(g[var.offset] * var.direction) : Point(g.segment<2>(var.offset));
    rhs(c, 2 * var.shape) = lifted.x();
    rhs(c, 2 * var.shape + 1) = lifted.y();
  }
  RemoveFloatingMeans(&rhs);
  // Fails only when cancelled, after a successful factorization.
  if (size_ > 0 && !solver_->SolveInPlace(&rhs, 1, cancel).ok()) return VectorXd();
  RemoveFloatingMeans(&rhs);
  for (const ComeshLayout::Var& var : layout.vars()) {
    const int c = compact_[var.vertex];
    if (c < 0) continue;
    const Point p(rhs(c, 2 * var.shape), rhs(c, 2 * var.shape + 1));
    const double a = areas_[var.shape];
    if (var.slider) {
      out[var.offset] = a * p.dot(var.direction);
    } else {
      out.segment<2>(var.offset) = a * p;
    }
  }
  return out;
}

VectorXd LaplacianPreconditioner::Apply(const VectorXd& x, const CancelToken* cancel) const {
  const ComeshLayout& layout = *layout_;
  const int num_shapes = layout.num_shapes();
  Eigen::MatrixXd lifted = Eigen::MatrixXd::Zero(size_, 2 * num_shapes);
  VectorXd out(x.size());
  for (const ComeshLayout::Var& var : layout.vars()) {
    const int c = compact_[var.vertex];
    if (c < 0) {
      const double d = degree_[var.vertex] / areas_[var.shape];
      if (var.slider) {
        out[var.offset] = d * x[var.offset];
      } else {
        out.segment<2>(var.offset) = d * x.segment<2>(var.offset);
      }
      continue;
    }
    const Point p =
        var.slider ? Point(x[var.offset] * var.direction) : Point(x.segment<2>(var.offset));
    lifted(c, 2 * var.shape) = p.x();
    lifted(c, 2 * var.shape + 1) = p.y();
  }
  const Eigen::MatrixXd product = matrix_ * lifted;
  for (const ComeshLayout::Var& var : layout.vars()) {
    const int c = compact_[var.vertex];
    if (c < 0) continue;
    const Point p =
        Point(product(c, 2 * var.shape), product(c, 2 * var.shape + 1)) / areas_[var.shape];
    if (var.slider) {
      out[var.offset] = p.dot(var.direction);
    } else {
      out.segment<2>(var.offset) = p;
    }
  }
  return out;
}

void LaplacianPreconditioner::FindFloating(const std::vector<Triangle>& triangles) {
  std::vector<int> parent(size_);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::vector<char> anchored(size_, 0);
  for (const Triangle& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int ca = compact_[t[k]], cb = compact_[t[(k + 1) % 3]];
      if (ca >= 0 && cb >= 0) {
        parent[find(ca)] = find(cb);
      } else if (ca >= 0 || cb >= 0) {
        anchored[ca >= 0 ? ca : cb] = 1;
      }
    }
  }
  std::vector<char> root_anchored(size_, 0);
  for (int k = 0; k < size_; ++k) {
    if (anchored[k]) root_anchored[find(k)] = 1;
  }
  for (int k = 0; k < size_; ++k) {
    if (!root_anchored[find(k)]) floating_rows_.push_back(k);
  }
  if (floating_rows_.empty()) return;  // the usual case
  // Grouped by component (ascending rows within each), one run per component.
  std::stable_sort(floating_rows_.begin(), floating_rows_.end(),
                   [&](int a, int b) { return find(a) < find(b); });
  floating_begin_ = {0};
  for (size_t i = 1; i <= floating_rows_.size(); ++i) {
    if (i == floating_rows_.size() || find(floating_rows_[i]) != find(floating_rows_[i - 1])) {
      floating_begin_.push_back(static_cast<int>(i));
    }
  }
}

void LaplacianPreconditioner::RemoveFloatingMeans(Eigen::MatrixXd* m) const {
  for (size_t c = 0; c + 1 < floating_begin_.size(); ++c) {
    const int begin = floating_begin_[c], end = floating_begin_[c + 1];
    for (int col = 0; col < m->cols(); ++col) {
      double mean = 0.0;
      for (int i = begin; i < end; ++i) mean += (*m)(floating_rows_[i], col);
      mean /= end - begin;
      for (int i = begin; i < end; ++i) (*m)(floating_rows_[i], col) -= mean;
    }
  }
}

}  // namespace inbetween::solver
