// The art to draw in one frame, from every key's embedded art (art_embedding.h), the frame's
// vertex positions and its example weights (interp/timing.h: one per key, sum 1, >= 0).
//
// Which keys count: the active ones, weight > 0. With piecewise-linear or Catmull-Rom timing the
// active set changes only at a key's frame, where one key has weight 1 and every rule below gives
// that key's art, so the choice of morph or cross-fade never pops between frames.
//
// Correspondence (among the active keys; FrameArtOptions):
//  - by name: layers with the same non-empty name (data-layer) correspond, the m-th layer with
//    that name in one key to the m-th in every other. Their paint may differ in kind: a fill or
//    stroke one key lacks fades in with the others' weights (as if there at opacity 0).
//  - by order: unnamed layers are aligned in paint order, each key to the lowest active key:
//    the order-preserving matching of layers with the same kind of paint (fill present, stroke
//    present) and path structure that scores most (a pair: 2 for equal colours, else 1, plus up
//    to 1 for lying close together in the frame). Keys drawn with the same layers align index to
//    index; a key that adds or drops layers (other eyes) keeps its other layers (the face, its
//    outline, the mouth) morphing instead of fading.
//  A group of corresponding layers morphs if its members have the same number of paths and each
//  path is closed in all or none of them, or if every path of every member is closed and the
//  paths pair up closely in the frame (a face that gains a mouth hole: see Morph); otherwise its
//  layers cross-fade.
//
// Morph: each path is placed in the frame from every member's own embedding, the placements are
// resampled to one point count by arc length (at the union of every placement's own vertex
// parameters, so that each placement is kept exactly, corners included, and the morph tends to a
// key's drawn path as its weight tends to 1), then positions are blended by the weights. A
// closed path drawn from another point or in the other direction than the first member's is
// first restarted and turned to run along it in the frame (AlignClosedPath), so a square drawn
// from one corner and a hexagon drawn from another morph in place instead of turning and
// shrinking through the middle frames.
// Colours (per 8-bit channel), opacities, stroke widths, miter limits and dashes (when every
// member has as many) blend by the weights; discrete properties (cap, join, fill rule, id) are
// the heaviest member's (ties: the lower key).
//
// Closed paths in different counts: each path of the member with the most paths morphs with
// the nearest path of every other member (root mean squared distance of their aligned
// placements under 2% of the path's length, nearest pairs first); a member without a partner
// for it lends that path's own placement, so a hole one key lacks is carried by the mesh (it
// opens as the mesh's opening does). When some path finds no partner that close (one cell that
// becomes two), or a path a member lacks is not inside one of its paired paths (a second eye,
// which would appear at once), the group's layers cross-fade.
//
// Cross-fade: a layer without a morphing group is drawn with its opacity times its key's weight.
//
// Draw order: the lowest active key is the backbone. Morphed groups appear in its paint order;
// every cross-faded layer is drawn right after the morphed group that precedes it in its own
// key's paint order (first, before every group, when none does), and among layers sharing that
// place the lower key's are drawn first. Keys are ordered by index rather than by weight so the
// order never flips mid-way between two keys; in playback order the outgoing key (lower index)
// is under the incoming one.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "solver/art/art_embedding.h"
#include "solver/core/art.h"
#include "solver/core/types.h"

namespace inbetween::solver {

struct FrameArtOptions {
  bool match_by_name = true;   // layers with equal non-empty names correspond
  bool match_by_order = true;  // unnamed layers aligned in paint order correspond (see above)
  // Largest alignment table (layers of one key times layers of another); above it, layers
  // correspond index to index when the counts are equal.
  double max_alignment_cells = 4e6;
  // Arc-length parameters (fractions of a path's length) closer than this are one sample of the
  // morph's resampling: closer samples add points no renderer can tell apart.
  double merge_fraction = 1e-9;
};

// One layer of one key drawing: keys[key].layers[layer] of ArtForFrame's `keys` (`key` indexes
// that vector, like `weights`; it is not EmbeddedArt::key).
struct ArtLayerRef {
  int key = 0;
  int layer = 0;
  friend bool operator==(const ArtLayerRef&, const ArtLayerRef&) = default;
};

// Where one layer of a frame's art comes from: the key layers it is made of, in key order. One
// member for a cross-faded layer, one per active key for a morphed group, so a key frame's layers
// (one active key) each have one member. A renderer that animates layers over frames (Lottie)
// follows a layer through the frames by its members.
struct ArtLayerSource {
  std::vector<ArtLayerRef> members;
  friend bool operator==(const ArtLayerSource&, const ArtLayerSource&) = default;
};

// The frame's layers in paint order. `keys[k]` is key k's embedded art (any order of
// EmbeddedArt::key; weights[k] goes with keys[k]). Errors (INVALID_ARGUMENT): weights and keys
// of different sizes, a non-finite weight, no weight > 0, art embedded in a mesh whose vertex
// count is not frame_vertices.size(). `sources`, when given, receives one ArtLayerSource per
// returned layer (same order); it does not change the layers.
absl::StatusOr<std::vector<ArtLayer>> ArtForFrame(const std::vector<EmbeddedArt>& keys,
                                                  const Points& frame_vertices,
                                                  const std::vector<double>& weights,
                                                  const FrameArtOptions& options = {},
                                                  std::vector<ArtLayerSource>* sources = nullptr);

}  // namespace inbetween::solver
