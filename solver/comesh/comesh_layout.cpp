// The comesh inner loop's unknowns (see comesh_layout.h).
#include "solver/comesh/comesh_layout.h"

#include <algorithm>
#include <optional>
#include <limits>
#include <tuple>

#include "solver/comesh/comesh_topology.h"

namespace inbetween::solver {
namespace {

using Eigen::VectorXd;

// The vertices that may move at all (used by a triangle, not pinned) and every vertex's
// neighbours along the topological boundary (empty inside the mesh). False if `cancel` was set.
bool FindMovable(const Multimesh& mesh, const CancelToken* cancel, std::vector<char>* movable,
                 std::vector<std::vector<int>>* boundary_nbrs) {
  const int n = mesh.num_vertices();
  std::vector<char> used(n, 0), pinned(n, 0);
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) used[t[k]] = 1;
  }
  std::vector<std::pair<std::pair<int, int>, int>> uses;
  if (!EdgeUses(mesh.triangles, std::vector<char>(mesh.triangles.size(), 1), cancel, &uses)) {
    return false;
  }
  boundary_nbrs->assign(n, {});
  for (const auto& [edge, count] : uses) {
    if (count % 2 == 0) continue;  // a boundary edge: used an odd number of times
    (*boundary_nbrs)[edge.first].push_back(edge.second);
    (*boundary_nbrs)[edge.second].push_back(edge.first);
  }
  for (int v : mesh.boundary) {
    // Listed as boundary but inside the mesh: keep it.
    if ((*boundary_nbrs)[v].empty()) pinned[v] = 1;
  }
  for (const auto& c : mesh.cohesive_edges) {
    for (int v : c) pinned[v] = 1;
  }
  for (int v : mesh.pinned) pinned[v] = 1;  // correspondence marks
  movable->assign(n, 0);
  for (int v = 0; v < n; ++v) (*movable)[v] = used[v] && !pinned[v];
  return true;
}

// Makes *var (boundary vertex v at x[v], neighbours `nbrs`) a slider; false if it stays fixed.
// `outline`: the shape's reference outline when it slides along it, else null.
bool MakeBoundarySlider(const Points& x, int v, const std::vector<int>& nbrs, bool slide_boundary,
                        const ShapeOutline* outline, double tolerance,
                        const std::optional<BoundaryPairing::Window>& window,
                        const ShapeOutline* pairing_outline, ComeshLayout::Var* var) {
  if (!slide_boundary || nbrs.size() != 2) return false;
  // On the reference outline: it slides along it, or stays at a hard point. (A straight slider
  // there could follow its line off the outline once a neighbour has moved along a curve.)
  const std::optional<ShapeOutline::Location> at =
      outline != nullptr ? outline->Locate(x[v], tolerance) : std::nullopt;
  if (at) {
    if (outline->AtHardPoint(at->loop, at->u, tolerance)) return false;
    var->direction = outline->Tangent(at->loop, at->u);
    if (!(var->direction.squaredNorm() > 0.5)) return false;  // a degenerate stretch: fixed
    var->slider = true;
    var->outline = at->loop;
    var->u0 = at->u;
    var->prev = nbrs[0];
    var->next = nbrs[1];
    std::tie(var->lo, var->hi) = outline->Stretch(at->loop, at->u);
    if (window && window->loop == at->loop) {
      // The pairing's frame and the sliding outline are both the input's outline.
      var->lo = std::max(var->lo, at->u + (window->lo - window->u));
      var->hi = std::min(var->hi, at->u + (window->hi - window->u));
    }
    return true;
  }
  // Otherwise (no outlines, or a vertex off them): along the straight segment of its neighbours
  // if it lies strictly inside it, else fixed.
  const Point a = x[nbrs[0]], b = x[nbrs[1]];
  if (!StrictlyInsideSegment(a, b, x[v])) return false;
  var->slider = true;
  var->direction = (b - a).normalized();
  var->lo = -std::numeric_limits<double>::infinity();
  var->hi = std::numeric_limits<double>::infinity();
  if (window && pairing_outline != nullptr) {
    // z runs along `direction`, which may run against the outline's orientation.
    const bool along = var->direction.dot(pairing_outline->Tangent(window->loop, window->u)) >= 0.0;
    var->lo = along ? window->lo - window->u : window->u - window->hi;
    var->hi = along ? window->hi - window->u : window->u - window->lo;
  }
  return true;
}

}  // namespace

ComeshLayout::ComeshLayout(const Multimesh& mesh, bool slide_boundary,
                           const std::vector<ShapeOutline>* outlines,
                           const BoundaryPairing* pairing, const CancelToken* cancel) {
  const int n = mesh.num_vertices();
  num_vertices_ = n;
  num_shapes_ = mesh.num_shapes();
  std::vector<char> movable;
  std::vector<std::vector<int>> boundary_nbrs;
  if (!FindMovable(mesh, cancel, &movable, &boundary_nbrs)) {
    cancelled_ = true;
    return;
  }
  index_.assign(num_shapes_, std::vector<int>(n, -1));
  for (int s = 0; s < num_shapes_; ++s) {
    // A shape without soft corners keeps the straight sliders (ShapeOutline::curved).
    const ShapeOutline* outline =
        outlines != nullptr && (*outlines)[s].curved() ? &(*outlines)[s] : nullptr;
    AddShape(s, mesh.shapes, movable, boundary_nbrs, slide_boundary, outline, pairing);
  }
  outlines_ = num_outline_ > 0 ? outlines : nullptr;
}

void ComeshLayout::AddShape(int s, const std::vector<Points>& shapes,
                            const std::vector<char>& movable,
                            const std::vector<std::vector<int>>& boundary_nbrs, bool slide_boundary,
                            const ShapeOutline* outline, const BoundaryPairing* pairing) {
  const Points& x = shapes[s];
  const double tolerance = outline != nullptr ? outline->tolerance() : 0.0;
  for (int v = 0; v < num_vertices_; ++v) {
    if (!movable[v]) continue;
    Var var{s, v, size_, false, Point::Zero(), x[v]};
    const std::vector<int>& nbrs = boundary_nbrs[v];
    if (!nbrs.empty()) {
      const std::optional<BoundaryPairing::Window> window =
          pairing != nullptr && slide_boundary && nbrs.size() == 2
              ? pairing->WindowOf(shapes, s, v, nbrs[0], nbrs[1])
              : std::nullopt;
      if (!MakeBoundarySlider(x, v, nbrs, slide_boundary, outline, tolerance, window,
                              pairing != nullptr ? &pairing->outline(s) : nullptr, &var)) {
        continue;
      }
    }
    index_[s][v] = static_cast<int>(vars_.size());
    size_ += var.slider ? 1 : 2;
    vars_.push_back(var);
    tangent_.push_back(var.direction);
    sides_.emplace_back(var.direction, var.direction);
    if (var.outline >= 0) {
      ++num_outline_;
      UpdateTangents(*outline, vars_.size() - 1, var.u0);
    }
  }
}

VectorXd ComeshLayout::Gather(const std::vector<Points>& shapes) const {
  VectorXd z(size_);
  for (const Var& var : vars_) {
    const Point& p = shapes[var.shape][var.vertex];
    if (var.outline >= 0) {
      z[var.offset] = var.u0;
    } else if (var.slider) {
      z[var.offset] = (p - var.base).dot(var.direction);
    } else {
      z.segment<2>(var.offset) = p;
    }
  }
  return z;
}

VectorXd ComeshLayout::GatherGradient(const std::vector<Points>& gradient) {
  VectorXd g(size_);
  for (size_t i = 0; i < vars_.size(); ++i) {
    const Var& var = vars_[i];
    const Point& p = gradient[var.shape][var.vertex];
    if (var.outline >= 0 && sides_[i].first != sides_[i].second) {
      const double forward = p.dot(sides_[i].second), back = p.dot(sides_[i].first);
      if (forward < 0.0) {
        g[var.offset] = forward;
        tangent_[i] = sides_[i].second;
      } else if (back > 0.0) {
        g[var.offset] = back;
        tangent_[i] = sides_[i].first;
      } else {
        g[var.offset] = 0.0;
        tangent_[i] = sides_[i].second;
      }
    } else if (var.slider) {
      g[var.offset] = p.dot(tangent_[i]);
    } else {
      g.segment<2>(var.offset) = p;
    }
  }
  return g;
}

void ComeshLayout::Scatter(const VectorXd& z, std::vector<Points>* shapes) const {
  for (const Var& var : vars_) {
    Point& p = (*shapes)[var.shape][var.vertex];
    if (var.outline >= 0) {
      p = OutlinePoint(var, z[var.offset]);
    } else {
      p = var.slider ? Point(var.base + std::clamp(z[var.offset], var.lo, var.hi) * var.direction)
                     : Point(z.segment<2>(var.offset));
    }
  }
}

void ComeshLayout::Displacements(const VectorXd& d, std::vector<Points>* out) const {
  out->resize(num_shapes_);
  for (Points& shape : *out) shape.assign(num_vertices_, Point::Zero());
  for (size_t i = 0; i < vars_.size(); ++i) {
    const Var& var = vars_[i];
    (*out)[var.shape][var.vertex] =
        var.slider ? Point(d[var.offset] * tangent_[i]) : Point(d.segment<2>(var.offset));
  }
}

Point ComeshLayout::OutlinePoint(const Var& var, double u) const {
  return (*outlines_)[var.shape].At(var.outline, std::clamp(u, var.lo, var.hi));
}

void ComeshLayout::Track(const VectorXd& z) {
  if (num_outline_ == 0) return;
  for (size_t i = 0; i < vars_.size(); ++i) {
    const Var& var = vars_[i];
    if (var.outline < 0) continue;
    UpdateTangents((*outlines_)[var.shape], i, std::clamp(z[var.offset], var.lo, var.hi));
  }
}

void ComeshLayout::UpdateTangents(const ShapeOutline& outline, size_t i, double u) {
  const int loop = vars_[i].outline;
  const Point t = outline.Tangent(loop, u);
  if (t.squaredNorm() > 0.5) tangent_[i] = t;  // (zero only on a zero-length segment)
  sides_[i] = outline.Tangents(loop, u);
  if (!(sides_[i].first.squaredNorm() > 0.5 && sides_[i].second.squaredNorm() > 0.5)) {
    sides_[i] = {tangent_[i], tangent_[i]};
  }
}

}  // namespace inbetween::solver
