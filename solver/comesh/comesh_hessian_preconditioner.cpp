// The comesh inner loop's shape-block Hessian model (see comesh_hessian_preconditioner.h).
#include "solver/comesh/comesh_hessian_preconditioner.h"

#include <algorithm>
#include <atomic>
#include <span>
#include <utility>

#include "absl/strings/str_cat.h"
#include "solver/comesh/mips_energy.h"
#include "solver/core/cancellable_call.h"

namespace inbetween::solver {
namespace {

using Eigen::VectorXd;

constexpr double kDiagonalShift = 1e-10;  // relative to the largest diagonal entry
// Below this many unknowns a thread start costs more than it saves ("Decisions and what they
// rest on" in docs/benchmarks.md: shapes on separate threads from 4,000 unknowns).
constexpr int kParallelUnknowns = 4000;
constexpr int kSetUpPoll = 4096;  // items between two polls of the set-up's loops

// Calls f(begin, end) over [0, n) in spans of kSetUpPoll * 256 items, polling `cancel` before
// each span and after the last; false (work partly done) if it was set.
template <typename F>
bool InPolledSpans(size_t n, const CancelToken* cancel, F&& f) {
  constexpr size_t kSpan = size_t{kSetUpPoll} * 256;
  for (size_t begin = 0; begin < n; begin += kSpan) {
    if (Cancelled(cancel)) return false;
    f(begin, std::min(n, begin + kSpan));
  }
  return !Cancelled(cancel);
}

// Adds `value` at (row, col) of a block (binary search in the column).
void Add(Eigen::SparseMatrix<double>* m, int row, int col, double value) {
  const int* begin = m->innerIndexPtr() + m->outerIndexPtr()[col];
  const int* end = m->innerIndexPtr() + m->outerIndexPtr()[col + 1];
  m->valuePtr()[std::lower_bound(begin, end, row) - m->innerIndexPtr()] += value;
}

// Adds a at (row, col) and b at (row + 1, col): the rows of a free vertex's two unknowns are
// next to each other in every column.
void AddPair(Eigen::SparseMatrix<double>* m, int row, int col, double a, double b) {
  const int* begin = m->innerIndexPtr() + m->outerIndexPtr()[col];
  const int* end = m->innerIndexPtr() + m->outerIndexPtr()[col + 1];
  double* v = m->valuePtr() + (std::lower_bound(begin, end, row) - m->innerIndexPtr());
  v[0] += a;
  v[1] += b;
}

// Adds the 2 x 2 corner block `block` of unknowns va (rows) and vb (columns), each reduced to its
// slider direction where it slides, at rows ra and column cb of its shape's block.
void AddCornerBlock(Eigen::SparseMatrix<double>* m, const ComeshLayout::Var& va, int ra,
                    const ComeshLayout::Var& vb, int cb, const Eigen::Matrix2d& block) {
  if (va.slider && vb.slider) {
    Add(m, ra, cb, va.direction.dot(block * vb.direction));
  } else if (va.slider) {
    const Eigen::RowVector2d r = va.direction.transpose() * block;
    Add(m, ra, cb, r[0]);
    Add(m, ra, cb + 1, r[1]);
  } else if (vb.slider) {
    const Eigen::Vector2d c = block * vb.direction;
    AddPair(m, ra, cb, c[0], c[1]);
  } else {
    AddPair(m, ra, cb, block(0, 0), block(1, 0));
    AddPair(m, ra, cb + 1, block(0, 1), block(1, 1));
  }
}

}  // namespace

// Each vertex's neighbours and itself, ascending: (*this)(v) (compressed rows, one allocation).
struct HessianPreconditioner::VertexNeighbours {
  // False if `cancel` was set (polled every kSetUpPoll triangles and vertices).
  bool Build(const std::vector<Triangle>& triangles, int n, const CancelToken* cancel) {
    start.assign(n + 1, 0);
    list.resize(9 * triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
      if (t % kSetUpPoll == 0 && Cancelled(cancel)) return false;
      for (int a = 0; a < 3; ++a) start[triangles[t][a] + 1] += 3;
    }
    for (int v = 0; v < n; ++v) start[v + 1] += start[v];
    {
      std::vector<int> fill(start.begin(), start.end() - 1);
      for (size_t t = 0; t < triangles.size(); ++t) {
        if (t % kSetUpPoll == 0 && Cancelled(cancel)) return false;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) list[fill[triangles[t][a]]++] = triangles[t][b];
        }
      }
    }
    count.resize(n);
    for (int v = 0; v < n; ++v) {
      if (v % kSetUpPoll == 0 && Cancelled(cancel)) return false;
      auto begin = list.begin() + start[v], end = list.begin() + start[v + 1];
      std::sort(begin, end);
      count[v] = static_cast<int>(std::unique(begin, end) - begin);
    }
    return true;
  }
  std::span<const int> operator()(int v) const {
    return std::span<const int>(list.data() + start[v], static_cast<size_t>(count[v]));
  }

  std::vector<int> start, list, count;
};

absl::StatusOr<std::unique_ptr<HessianPreconditioner>> HessianPreconditioner::Create(
    const std::vector<Triangle>& triangles, const ComeshLayout& layout,
    const ComeshObjective& objective, const std::vector<Points>& shapes,
    HessianPreconditionerOptions options, const CancelToken* cancel, SharedFactors* factors) {
  std::unique_ptr<HessianPreconditioner> h(
      new HessianPreconditioner(triangles, layout, objective, options));
  const int num_shapes = layout.num_shapes();
  VertexNeighbours nbrs;
  if (!nbrs.Build(triangles, layout.num_vertices(), cancel)) return SetUpCancelled();
  if (Cancelled(cancel)) return SetUpCancelled();
  // Shape s's unknowns are z[begin_[s], begin_[s + 1]) (ComeshLayout numbers them shape by shape).
  h->begin_.assign(num_shapes + 1, layout.size());
  for (int i = static_cast<int>(layout.vars().size()) - 1; i >= 0; --i) {
    h->begin_[layout.vars()[i].shape] = layout.vars()[i].offset;
  }
  for (int s = num_shapes - 1; s >= 0; --s) {
    h->begin_[s] = std::min(h->begin_[s], h->begin_[s + 1]);
  }
  h->blocks_.resize(num_shapes);
  Patterns patterns;
  if (!h->BuildPatterns(nbrs, cancel, &patterns) || !h->BuildNodeGraphs(nbrs, cancel) ||
      Cancelled(cancel) || !h->AllocateBlocks(&patterns, cancel, factors)) {
    return SetUpCancelled();
  }
  h->threads_ = layout.size() >= kParallelUnknowns ? objective.threads() : 1;
  if (absl::Status st = h->Refactor(shapes, /*analyze=*/true, cancel); !st.ok()) return st;
  return h;
}

// Column-major pattern of each symmetric block: column j = unknown j, rows = the unknowns of the
// same shape at the vertex and its neighbours, ascending (offsets grow with the vertex).
bool HessianPreconditioner::BuildPatterns(const VertexNeighbours& nbrs, const CancelToken* cancel,
                                          Patterns* patterns) {
  const ComeshLayout& layout = *layout_;
  const int num_shapes = layout.num_shapes();
  std::vector<std::vector<int>>& outer = patterns->outer;
  std::vector<std::vector<int>>& inner = patterns->inner;
  outer.resize(num_shapes);
  inner.resize(num_shapes);
  for (int s = 0; s < num_shapes; ++s) outer[s].assign(begin_[s + 1] - begin_[s] + 1, 0);
  // Room for every entry first (at most 2 rows per neighbour and column): growing by doubling
  // copied ~16 MB at once at 311k vertices, ~0.1 s without a poll.
  {
    std::vector<size_t> bound(num_shapes, 0);
    for (size_t i = 0; i < layout.vars().size(); ++i) {
      if (i % kSetUpPoll == 0 && Cancelled(cancel)) return false;
      const ComeshLayout::Var& var = layout.vars()[i];
      bound[var.shape] += (var.slider ? 2 : 4) * static_cast<size_t>(nbrs.count[var.vertex]);
    }
    for (int s = 0; s < num_shapes; ++s) {
      inner[s].reserve(bound[s]);
      // As many graph entries as vertex neighbours at most (rows <= column, BuildNodeGraphs).
      blocks_[s].node_inner.reserve(bound[s] / 2);
    }
  }
  for (size_t i = 0; i < layout.vars().size(); ++i) {
    if (i % kSetUpPoll == 0 && Cancelled(cancel)) return false;
    const ComeshLayout::Var& var = layout.vars()[i];
    const int s = var.shape;
    for (int c = 0; c < (var.slider ? 1 : 2); ++c) {
      outer[s][var.offset + c - begin_[s]] = static_cast<int>(inner[s].size());
      for (int w : nbrs(var.vertex)) {
        const int j = layout.index(s, w);
        if (j < 0) continue;
        const ComeshLayout::Var& other = layout.vars()[j];
        inner[s].push_back(other.offset - begin_[s]);
        if (!other.slider) inner[s].push_back(other.offset + 1 - begin_[s]);
      }
    }
  }
  return true;
}

// The vertex graph of each shape (one node per free or sliding vertex, in unknown order), for the
// fill-reducing ordering: AMD on it, each node expanded to its 1 or 2 unknowns, costs a quarter of
// AMD on the unknowns' graph and orders a vertex's two unknowns together anyway.
bool HessianPreconditioner::BuildNodeGraphs(const VertexNeighbours& nbrs,
                                            const CancelToken* cancel) {
  const ComeshLayout& layout = *layout_;
  std::vector<int> node(layout.vars().size(), -1);
  for (size_t i = 0; i < layout.vars().size(); ++i) {
    if (i % kSetUpPoll == 0 && Cancelled(cancel)) return false;
    const ComeshLayout::Var& var = layout.vars()[i];
    Block& block = blocks_[var.shape];
    node[i] = static_cast<int>(block.node_unknowns.size());
    block.node_unknowns.push_back(var.offset - begin_[var.shape]);
    block.node_outer.push_back(static_cast<int>(block.node_inner.size()));
    for (int w : nbrs(var.vertex)) {
      const int j = layout.index(var.shape, w);
      if (j >= 0 && node[j] >= 0) block.node_inner.push_back(node[j]);  // rows <= column
    }
  }
  for (Block& block : blocks_) {
    block.node_outer.push_back(static_cast<int>(block.node_inner.size()));
  }
  return true;
}

// The blocks' matrices with the patterns (fresh memory, its pages faulted in as they are
// written: copied in polled spans, as AssembleShape zeroes the values) and their solvers.
bool HessianPreconditioner::AllocateBlocks(Patterns* patterns, const CancelToken* cancel,
                                           SharedFactors* factors) {
  auto copy_polled = [cancel](const std::vector<int>& from, int* to) {
    return InPolledSpans(from.size(), cancel, [&](size_t begin, size_t end) {
      std::copy(from.begin() + begin, from.begin() + end, to + begin);
    });
  };
  for (size_t s = 0; s < blocks_.size(); ++s) {
    Block& block = blocks_[s];
    std::vector<int>& outer = patterns->outer[s];
    const std::vector<int>& inner = patterns->inner[s];
    const int size = begin_[s + 1] - begin_[s];
    outer[size] = static_cast<int>(inner.size());
    block.matrix = std::make_shared<Eigen::SparseMatrix<double>>(size, size);
    block.matrix->resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
    if (!copy_polled(outer, block.matrix->outerIndexPtr()) ||
        !copy_polled(inner, block.matrix->innerIndexPtr())) {
      return false;
    }
    if (factors->size() <= s) factors->resize(s + 1);
    std::shared_ptr<SparseCholesky>& solver = (*factors)[s];
    if (solver == nullptr) {
      solver = std::make_shared<SparseCholesky>(SparseCholesky::Method::kAuto);
    }
    solver->set_float_substitutions(options_.float_substitutions);
    block.solver = solver;
  }
  return true;
}

VectorXd HessianPreconditioner::ApplyInverse(const VectorXd& g, const CancelToken* cancel) const {
  VectorXd x = g;
  std::atomic<bool> cancelled{false};
  ForEachShape([&](int s) {
    const int size = begin_[s + 1] - begin_[s];
    if (size == 0) return;
    Eigen::MatrixXd part = x.segment(begin_[s], size);
    // Fails only when cancelled, after a successful factorization.
    if (!blocks_[s].solver->SolveInPlace(&part, 1, cancel).ok()) {
      cancelled = true;
      return;
    }
    x.segment(begin_[s], size) = part.col(0);
  });
  return cancelled ? VectorXd() : x;
}

VectorXd HessianPreconditioner::Apply(const VectorXd& x, const CancelToken* cancel) const {
  constexpr int kApplyColumns = 1 << 14;
  VectorXd out = VectorXd::Zero(x.size());
  std::atomic<bool> cancelled{false};
  ForEachShape([&](int s) {
    const int begin = begin_[s], size = begin_[s + 1] - begin_[s];
    for (int j = 0; j < size; j += kApplyColumns) {
      if (Cancelled(cancel)) {
        cancelled = true;
        return;
      }
      const int columns = std::min(kApplyColumns, size - j);
      out.segment(begin, size).noalias() +=
          blocks_[s].matrix->middleCols(j, columns) * x.segment(begin + j, columns);
    }
  });
  return cancelled ? VectorXd() : out;
}

absl::Status HessianPreconditioner::Refactor(const std::vector<Points>& shapes, bool analyze,
                                             const CancelToken* cancel) {
  ForEachShape([&](int s) {
    Block& block = blocks_[s];
    block.status = absl::OkStatus();
    if (!AssembleShape(s, shapes, cancel)) {
      block.status = SetUpCancelled();
      return;
    }
    if (block.matrix->rows() == 0) return;
    if (analyze) block.status = Analyze(&block, options_.background_analysis_unknowns, cancel);
    if (block.status.ok() && Cancelled(cancel)) block.status = SetUpCancelled();
    if (block.status.ok()) block.status = block.solver->Factorize(*block.matrix, cancel);
  });
  for (size_t s = 0; s < blocks_.size(); ++s) {
    if (absl::IsCancelled(blocks_[s].status)) return blocks_[s].status;
  }
  for (size_t s = 0; s < blocks_.size(); ++s) {
    if (!blocks_[s].status.ok()) {
      return absl::Status(
          blocks_[s].status.code(),
          absl::StrCat("comesh Hessian of shape ", s, ": ", blocks_[s].status.message()));
    }
  }
  return absl::OkStatus();
}

// Symbolic analysis with the vertex graph's AMD ordering expanded to the unknowns. AMD and
// CHOLMOD's analysis are single library calls that grow with the mesh (at 311k vertices up to
// ~1 s per shape, far past the 100 ms a cancel may take): on blocks of `background` unknowns or
// more they run on a helper thread (RunCancellable) that owns its inputs (a copy of the node
// graph, the matrix and solver shared), so a cancel returns at once and the helper finishes the
// abandoned analysis on its own.
absl::Status HessianPreconditioner::Analyze(Block* block, int background,
                                            const CancelToken* cancel) {
  if (Cancelled(cancel)) return SetUpCancelled();
  struct Job {
    std::vector<int> node_outer, node_inner, node_unknowns;
    std::shared_ptr<Eigen::SparseMatrix<double>> matrix;
    std::shared_ptr<SparseCholesky> solver;
    absl::Status status;
  };
  // Copies of the node graph: ~1 ms against AMD's ~0.3 s at 311k vertices.
  auto job = std::make_shared<Job>(Job{block->node_outer, block->node_inner, block->node_unknowns,
                                       block->matrix, block->solver, absl::OkStatus()});
  auto work = [job] {
    absl::StatusOr<std::vector<int>> nodes =
        SparseCholesky::AmdOrdering(job->node_outer, job->node_inner);
    if (!nodes.ok()) {
      job->status = nodes.status();
      return;
    }
    const int size = static_cast<int>(job->matrix->rows());
    std::vector<int> ordering;
    ordering.reserve(size);
    for (int k : *nodes) {
      const int first = job->node_unknowns[k];
      const int end =
          k + 1 < static_cast<int>(job->node_unknowns.size()) ? job->node_unknowns[k + 1] : size;
      for (int u = first; u < end; ++u) ordering.push_back(u);
    }
    job->status = job->solver->Analyze(*job->matrix, &ordering);
  };
  const bool helper = background > 0 && block->matrix->rows() >= background;
  if (!RunCancellable(work, helper ? cancel : nullptr)) return SetUpCancelled();
  return job->status;
}

Matrix6 HessianPreconditioner::TriangleHessian(int s, const Triangle& t,
                                               const std::vector<Points>& shapes) const {
  const ComeshObjective& obj = *objective_;
  const int num_shapes = layout_->num_shapes();
  const double w = obj.map_weight();
  const int next = (s + 1) % num_shapes, prev = (s + num_shapes - 1) % num_shapes;
  const Eigen::Matrix2d e = EdgeMatrix(shapes[s], t);
  Matrix4 h4 = ((1.0 - w) / obj.odt_normalizer(s)) * OdtEdgeHessian(e);
  if (num_shapes > 1 && w > 0.0) {
    Matrix4 hp, hq;
    MipsEdgeHessians(e, EdgeMatrix(shapes[next], t), &hp, nullptr);
    MipsEdgeHessians(EdgeMatrix(shapes[prev], t), e, nullptr, &hq);
    const double damping = options_.mips_damping;
    if (damping > 0.0) {  // ComeshOptions::mips_damping; Gershgorin bounds
      hp.diagonal().array() += damping * hp.cwiseAbs().rowwise().sum().maxCoeff();
      hq.diagonal().array() += damping * hq.cwiseAbs().rowwise().sum().maxCoeff();
    }
    h4 += (w / obj.rest_area(s)) * hp + (w / obj.rest_area(prev)) * hq;
  }
  return CornerHessian(ProjectPositiveDefinite(h4, 1e-8));
}

bool HessianPreconditioner::AssembleShape(int s, const std::vector<Points>& shapes,
                                          const CancelToken* cancel) {
  const ComeshLayout& layout = *layout_;
  Eigen::SparseMatrix<double>* m = blocks_[s].matrix.get();
  // Zeroing a fresh block faults its pages in (~130 ms at 311k vertices): in polled spans.
  const bool zeroed =
      InPolledSpans(static_cast<size_t>(m->nonZeros()), cancel, [m](size_t begin, size_t end) {
        std::fill(m->valuePtr() + begin, m->valuePtr() + end, 0.0);
      });
  if (!zeroed) return false;
  const int base = begin_[s];
  int count = 0;
  for (const Triangle& t : *triangles_) {
    if ((count++ & 4095) == 0 && Cancelled(cancel)) return false;
    int vars[3];
    bool any = false;
    for (int k = 0; k < 3; ++k) {
      vars[k] = layout.index(s, t[k]);
      any |= vars[k] >= 0;
    }
    if (!any) continue;
    const Matrix6 h6 = TriangleHessian(s, t, shapes);
    for (int a = 0; a < 3; ++a) {
      if (vars[a] < 0) continue;
      const ComeshLayout::Var& va = layout.vars()[vars[a]];
      for (int b = 0; b < 3; ++b) {
        if (vars[b] < 0) continue;
        const ComeshLayout::Var& vb = layout.vars()[vars[b]];
        AddCornerBlock(m, va, va.offset - base, vb, vb.offset - base, h6.block<2, 2>(2 * a, 2 * b));
      }
    }
  }
  // A tiny diagonal shift keeps the factor definite where the projection left a null direction
  // (e.g. a vertex whose every triangle has all other corners fixed along one line).
  double top = 0.0;
  for (int c = 0; c < m->cols(); ++c) top = std::max(top, m->coeff(c, c));
  for (int c = 0; c < m->cols(); ++c) Add(m, c, c, kDiagonalShift * top);
  return true;
}

}  // namespace inbetween::solver
