// Comesh optimization objective (DESIGN "Comesh optimization"; S-eq.1, S-eq.2, S §6):
//   E(X_1..X_n) = (1 - w) sum_i D_hat(X_i) + w sum_i C_hat(X_i, X_{i+1 mod n}),
//   D_hat(X_i) = D(X_i) / N_i,             N_i = OdtNormalization(rest X_i)   (odt_energy.h)
//   C_hat(X_i, X_j) = C(X_i, X_j) / A_i,   A_i = total area of rest X_i       (mips_energy.h)
// Both terms are dimensionless and resolution independent, so w means the same at any scale and
// mesh size (w = 0.5 by default, S-Table 1). The normalizers are frozen at the rest (input)
// geometry so that E is a plain sum of per-triangle terms; with a fixed boundary they equal the
// current values anyway. The cyclic sum suffices by the transitivity of MIPS (S §6).
//
// The ODT normalizer N_i = A_i^2 / (sqrt(3) T) depends on the triangle count T of the topology
// the objective is created for; the outer topology loop recreates the objective after it changes
// the topology, so E stays comparable across vertex counts (it is a mean quality, not a sum).
//
// Area-invariant mode (Create's `area_invariant`; the optimizer's outline sliding, where the
// boundary may cut soft corners and the areas change): the normalizers follow the current areas,
//   D_hat(X_i) = D(X_i) / (N_i r_i^2),  C_hat(X_i, X_j) = C(X_i, X_j) / (A_i r_i),
//   r_i = A_i(X) / A_i (current over rest area),
// so E does not change when a shape is scaled and shrinking a shape gains nothing; with the areas
// kept (r_i = 1) it equals the plain E. Its gradient has one more term, on boundary vertices only:
// dE/dX_i += -(2 E_i^mesh + E_i^map) / A_i(X) dA_i/dX_i (E_i^mesh, E_i^map: shape i's ODT part and
// the MIPS part of the pair (i, i+1)), dA_i/dX from the mesh's boundary edges. The per-triangle
// accessors (TriangleTerm(s), AccumulateTriangle) use the normalizers of the last Evaluate.
//
// Evaluation is a fused pass over triangles (ODT of every shape and the cyclic MIPS terms of one
// triangle at once) in fixed-size chunks that may run on several threads; corner gradients go to
// a per-corner buffer and are summed per vertex in triangle order, and chunk sums are reduced in
// chunk order, so results are bit-identical for any thread count.
//
// Reported numbers (the paper's columns):
//   mesh energy = (1/n) sum_i D_hat(X_i)   (1 = tiling by equal equilateral triangles)
//   map energy  = (1/n) sum_i C_hat(X_i, X_{i+1})  = mean over the cycle of the area-weighted
//                 mean sigma* (2 = every map conformal).
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/core/cancel.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct ComeshEnergies {
  double objective = 0.0;  // E
  double mesh = 0.0;       // mean normalized ODT energy
  double map = 0.0;        // mean area-weighted sigma* over the cycle
};

class ComeshObjective {
 public:
  // Fails (InvalidArgument) without shapes, on shapes of different sizes, on triangle indices out
  // of range or repeated, on w outside [0, 1], or on a shape of zero area.
  static absl::StatusOr<ComeshObjective> Create(const std::vector<Triangle>& triangles,
                                                const std::vector<Points>& rest,
                                                double map_weight = 0.5, int threads = 1,
                                                bool area_invariant = false);

  // E(shapes); +inf if any triangle is inverted or degenerate in any shape. If `gradient` is
  // given it is overwritten with dE/dX (same layout as `shapes`; not meaningful when E = +inf).
  // With `cancel` set during the call (polled before every chunk of 2048 triangles: one call
  // takes ~0.1 s at 311k vertices), stops early and returns NaN; the caller polls after it.
  // Uses internal scratch buffers: do not call concurrently on one object.
  double Evaluate(const std::vector<Points>& shapes, std::vector<Points>* gradient = nullptr,
                  ComeshEnergies* energies = nullptr, const CancelToken* cancel = nullptr) const;

  // The contribution of one triangle (any vertex triple, e.g. a candidate after a flip) to E
  // with this objective's normalizers: (1 - w) sum_i D_t(X_i) / N_i + w sum_i C_t(X_i, X_i+1) /
  // A_i. +inf if the triangle is not positive in some shape.
  double TriangleTerm(const Triangle& t, const std::vector<Points>& shapes) const;
  // The same split into its ODT part sum_i D_t(X_i) / N_i and MIPS part sum_i C_t / A_i.
  void TriangleTerms(const Triangle& t, const std::vector<Points>& shapes, double* odt,
                     double* mips) const;

  // Adds triangle t's sum_i D_t(X_i) / N_i to *mesh_sum and sum_i C_t(X_i, X_i+1) / A_i to
  // *map_sum (shape by shape, as Evaluate sums them) and, if `corner_gradient` is given (3 n
  // entries), overwrites it with the gradient of t's part of E: entry k n + i is d/dX_i(t[k]).
  // False (sums partly added) if t is not positive in some shape.
  // `shape_sums` (may be null; 2 n entries): shape i's ODT part is also added to entry i and the
  // MIPS part of the pair (i, i+1) to entry n + i.
  bool AccumulateTriangle(const Triangle& t, const std::vector<Points>& shapes, double* mesh_sum,
                          double* map_sum, Point* corner_gradient = nullptr,
                          double* shape_sums = nullptr) const;

  int num_shapes() const { return static_cast<int>(areas_.size()); }
  int num_vertices() const { return num_vertices_; }
  double map_weight() const { return map_weight_; }
  double rest_area(int shape) const { return areas_[shape]; }
  bool area_invariant() const { return area_invariant_; }
  // The normalizers the per-triangle terms use now (see "Area-invariant mode" above): N_i and
  // A_i, or N_i r_i^2 and A_i r_i at the last Evaluate.
  double mesh_scale(int shape) const { return mesh_scale_[shape]; }
  double map_scale(int shape) const { return map_scale_[shape]; }
  double odt_normalizer(int shape) const { return odt_normalizer_[shape]; }
  int threads() const { return threads_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }

 private:
  ComeshObjective() = default;

  std::vector<Triangle> triangles_;
  int num_vertices_ = 0;
  double map_weight_ = 0.5;
  std::vector<double> areas_;           // A_i
  std::vector<double> odt_normalizer_;  // N_i
  int threads_ = 1;
  bool area_invariant_ = false;
  // The normalizers the per-triangle terms use: N_i and A_i, or (area-invariant mode) N_i r_i^2
  // and A_i r_i at the last Evaluate.
  mutable std::vector<double> mesh_scale_;
  mutable std::vector<double> map_scale_;
  // Area-invariant mode: the boundary edges (a, b), oriented as in their triangle.
  std::vector<std::array<int, 2>> boundary_edges_;
  // Vertex -> corners (3 t + k) in increasing order, CSR.
  std::vector<int> corner_begin_;
  std::vector<int> corners_;
  mutable std::vector<Point> corner_gradient_;  // [(3 t + k) * num_shapes + shape]
};

}  // namespace inbetween::solver
