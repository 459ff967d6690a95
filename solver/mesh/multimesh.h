// The multimesh: one triangle list shared by every shape, one geometry per shape.
#pragma once

#include <vector>

#include "solver/core/embedded_art.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct Multimesh {
  std::vector<Triangle> triangles;  // shared topology, CCW in every shape
  std::vector<Points> shapes;       // shapes[i][v] = position of vertex v in drawing i
  std::vector<int> boundary;        // boundary vertex indices, in boundary order
  // Cohesive edge pairs {a, b, c, d}: a-b on one side, c-d its collocated twin (later issues).
  std::vector<std::array<int, 4>> cohesive_edges;
  // Each closed boundary loop (S-Alg.1) as vertex indices in order, interior on the left (outer
  // loops positive, holes negative in every shape). `boundary` is their concatenation.
  std::vector<std::vector<int>> boundary_loops;
  // cohesive_closed[s]: indices into cohesive_edges whose two sides are collocated in shape s
  // (the cut or opening is closed there). Empty when there are no cohesive edges.
  std::vector<std::vector<int>> cohesive_closed;
  // Vertices whose correspondence is pinned (a correspondence mark's boundary vertex), ascending:
  // comesh optimization moves them in no shape and no topology pass removes them. Empty when
  // the drawings had no marks.
  std::vector<int> pinned;
  // Each drawing's art embedded in its own shape (art_embedding.h), one per drawing in drawing
  // order, or empty when no drawing has art. BuildMultimesh fills it; OptimizeComesh returns a
  // mesh without it (its triangles are new): re-embed with EmbedDrawingsArt.
  std::vector<EmbeddedArt> art;

  int num_vertices() const { return shapes.empty() ? 0 : static_cast<int>(shapes[0].size()); }
  int num_shapes() const { return static_cast<int>(shapes.size()); }
};

}  // namespace inbetween::solver
