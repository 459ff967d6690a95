// A key drawing's art in mesh coordinates (the data; solver/art/art_embedding.h computes and
// places it): every art point as a triangle of the multimesh and barycentric coordinates in that
// key's own shape, so that any geometry of the mesh (a frame, another key) places the art.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "solver/core/art.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct EmbeddedPoint {
  int triangle = -1;                        // index into Multimesh::triangles
  Triangle corners = {0, 0, 0};             // that triangle's vertex indices
  Eigen::Vector3d barycentric = {1, 0, 0};  // sums to 1; negative outside the triangle
  bool inserted = false;                    // a crossing point inserted on a drawn segment
};

struct EmbeddedPath {
  std::vector<EmbeddedPoint> points;  // in path order; crossings between their segment's ends
  bool closed = false;
};

struct EmbeddedLayer {
  // The layer's paint, id and name as drawn; its `paths` are left empty (the geometry is below).
  ArtLayer paint;
  std::vector<EmbeddedPath> paths;  // one per ArtLayer path, same order
};

struct EmbeddedArt {
  int key = 0;           // the key drawing (shape index) the art was embedded in
  int num_vertices = 0;  // the multimesh's vertex count: the frames it can be placed in
  std::vector<EmbeddedLayer> layers;  // in paint order
};

}  // namespace inbetween::solver
