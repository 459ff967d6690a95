// A frame's art: morph corresponding layers, cross-fade the rest (see frame_art.h).
#include "solver/art/frame_art.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "solver/art/blend_paths.h"
#include "solver/geometry/polygon.h"
#include "solver/geometry/primitives.h"

namespace inbetween::solver {
namespace {

// One layer of one key, with that key's weight normalized over the active keys.
struct Member {
  int key = 0;
  int layer = 0;
  double weight = 0.0;
};
using Group = std::vector<Member>;  // one member per active key, in key order

bool SameKind(const ArtLayer& a, const ArtLayer& b) {
  return a.fill.has_value() == b.fill.has_value() && a.stroke.has_value() == b.stroke.has_value();
}

// Closed, non-empty paths only: layers of such paths morph even when their path counts differ
// (a face that gains a mouth hole, one cell that becomes two), see Morph::Layer.
bool AllClosedAndDrawn(const EmbeddedLayer& layer) {
  if (layer.paths.empty()) return false;
  for (const EmbeddedPath& path : layer.paths) {
    if (!path.closed || path.points.empty()) return false;
  }
  return true;
}

// Same path count, and each path closed (and empty) in all members or in none; or closed,
// non-empty paths in every member, in any count.
bool SameGeometry(const std::vector<EmbeddedArt>& keys, const Group& group) {
  const EmbeddedLayer& first = keys[group[0].key].layers[group[0].layer];
  const bool all_closed = std::all_of(group.begin(), group.end(), [&](const Member& m) {
    return AllClosedAndDrawn(keys[m.key].layers[m.layer]);
  });
  if (all_closed) return true;
  for (const Member& m : group) {
    const EmbeddedLayer& layer = keys[m.key].layers[m.layer];
    if (layer.paths.size() != first.paths.size()) return false;
    for (size_t j = 0; j < layer.paths.size(); ++j) {
      if (layer.paths[j].closed != first.paths[j].closed ||
          layer.paths[j].points.empty() != first.paths[j].points.empty()) {
        return false;
      }
    }
  }
  return true;
}

// Two layers that may morph into each other: the same kind of paint and the same path structure
// (path count, each closed in both or neither), or closed non-empty paths in both.
bool Compatible(const EmbeddedLayer& a, const EmbeddedLayer& b) {
  if (!SameKind(a.paint, b.paint)) return false;
  if (AllClosedAndDrawn(a) && AllClosedAndDrawn(b)) return true;
  if (a.paths.size() != b.paths.size()) return false;
  for (size_t j = 0; j < a.paths.size(); ++j) {
    if (a.paths[j].closed != b.paths[j].closed) return false;
  }
  return true;
}

// Where a layer lies in the frame: the mean of its points placed there.
Point Centroid(const EmbeddedLayer& layer, const Points& frame) {
  Point sum = Point::Zero();
  int count = 0;
  for (const EmbeddedPath& path : layer.paths) {
    for (const Point& p : PlacePath(path, frame)) sum += p, ++count;
  }
  return count > 0 ? Point(sum / count) : sum;
}

// The paint order alignment of `b`'s unnamed layers to `a`'s (an index into b per layer of a, or
// -1): the order-preserving matching of compatible layers with the largest score (dynamic
// programming over both paint orders, as for a longest common subsequence). A pair scores 2 when
// its colours agree and 1 otherwise, plus up to 1 for lying close together in the frame
// (1 / (1 + d / size), d between the layers' centroids placed in the frame, size the frame's
// diagonal), so that of two open strokes of one colour the mouth pairs with the mouth, not with
// an eye. Equal structures align index to index; a key that adds or drops layers (other eyes, an
// extra highlight) keeps the rest of its layers morphing. Above `max_cells` pairs, layers align
// index to index when the counts are equal and not at all otherwise.
template <typename Named>
std::vector<int> AlignLayers(const std::vector<EmbeddedLayer>& a,
                             const std::vector<EmbeddedLayer>& b, const Points& frame, Named named,
                             double max_cells) {
  const size_t n = a.size(), m = b.size();
  std::vector<int> match(n, -1);
  auto compatible = [&](size_t i, size_t j) {
    return !named(a[i]) && !named(b[j]) && Compatible(a[i], b[j]);
  };
  if (static_cast<double>(n) * static_cast<double>(m) > max_cells) {
    if (n == m) {
      for (size_t i = 0; i < n; ++i) match[i] = compatible(i, i) ? static_cast<int>(i) : -1;
    }
    return match;
  }
  Eigen::AlignedBox2d box;
  for (const Point& p : frame) box.extend(p);
  const double size = std::max(box.isEmpty() ? 0.0 : box.diagonal().norm(), 1e-300);
  std::vector<Point> ca(n), cb(m);
  for (size_t i = 0; i < n; ++i) ca[i] = Centroid(a[i], frame);
  for (size_t j = 0; j < m; ++j) cb[j] = Centroid(b[j], frame);
  auto score = [&](size_t i, size_t j) {
    if (!compatible(i, j)) return 0.0;
    const ArtLayer &p = a[i].paint, &q = b[j].paint;
    const bool same =
        (!p.fill || p.fill->rgb == q.fill->rgb) && (!p.stroke || p.stroke->rgb == q.stroke->rgb);
    return (same ? 2.0 : 1.0) + 1.0 / (1.0 + (ca[i] - cb[j]).norm() / size);
  };
  // best[i][j]: the best score aligning a[i..] with b[j..]; step[i][j]: how it starts (0: a[i]
  // and b[j] pair, 1: a[i] unpaired, 2: b[j] unpaired; the first of equals wins).
  std::vector<std::vector<double>> best(n + 1, std::vector<double>(m + 1, 0.0));
  std::vector<std::vector<char>> step(n + 1, std::vector<char>(m + 1, 1));
  for (size_t i = n; i-- > 0;) {
    for (size_t j = m; j-- > 0;) {
      const double s = score(i, j);
      const double pair = s > 0 ? s + best[i + 1][j + 1] : -1.0;
      best[i][j] = pair, step[i][j] = 0;
      if (best[i + 1][j] > best[i][j]) best[i][j] = best[i + 1][j], step[i][j] = 1;
      if (best[i][j + 1] > best[i][j]) best[i][j] = best[i][j + 1], step[i][j] = 2;
    }
  }
  for (size_t i = 0, j = 0; i < n && j < m;) {
    if (step[i][j] == 0) {
      match[i++] = static_cast<int>(j++);
    } else if (step[i][j] == 1) {
      ++i;
    } else {
      ++j;
    }
  }
  return match;
}

// The morphing groups among `active` (key indices ascending, weights normalized), ordered by
// their layer in the first active key (the backbone).
std::vector<Group> MatchLayers(const std::vector<EmbeddedArt>& keys,
                               const std::vector<Member>& active, const Points& frame,
                               const FrameArtOptions& options) {
  std::vector<Group> groups;
  auto named = [&](const EmbeddedLayer& l) {
    return options.match_by_name && !l.paint.name.empty();
  };
  if (options.match_by_name) {
    std::map<std::pair<std::string, int>, Group> by_name;  // (name, occurrence) -> members
    for (const Member& a : active) {
      std::map<std::string, int> seen;
      const std::vector<EmbeddedLayer>& layers = keys[a.key].layers;
      for (size_t l = 0; l < layers.size(); ++l) {
        if (!named(layers[l])) continue;
        const std::string& name = layers[l].paint.name;
        by_name[{name, seen[name]++}].push_back({a.key, static_cast<int>(l), a.weight});
      }
    }
    for (auto& [name, group] : by_name) {
      if (group.size() == active.size()) groups.push_back(std::move(group));
    }
  }
  if (options.match_by_order) {
    // Each other active key's unnamed layers aligned to the backbone's in paint order; a
    // backbone layer aligned in every key is a group.
    const std::vector<EmbeddedLayer>& backbone = keys[active[0].key].layers;
    std::vector<Group> by_layer(backbone.size());
    for (size_t l = 0; l < backbone.size(); ++l) {
      if (!named(backbone[l]))
        by_layer[l].push_back({active[0].key, static_cast<int>(l), active[0].weight});
    }
    for (size_t k = 1; k < active.size(); ++k) {
      const std::vector<int> match = AlignLayers(backbone, keys[active[k].key].layers, frame, named,
                                                 options.max_alignment_cells);
      for (size_t l = 0; l < backbone.size(); ++l) {
        if (match[l] >= 0) by_layer[l].push_back({active[k].key, match[l], active[k].weight});
      }
    }
    for (Group& group : by_layer) {
      if (group.size() == active.size()) groups.push_back(std::move(group));
    }
  }
  std::erase_if(groups, [&](const Group& g) { return !SameGeometry(keys, g); });
  std::sort(groups.begin(), groups.end(),
            [](const Group& a, const Group& b) { return a[0].layer < b[0].layer; });
  return groups;
}

// Per 8-bit channel, weighted mean over (rgb, weight) pairs, rounded.
uint32_t BlendRgb(const std::vector<std::pair<uint32_t, double>>& colours) {
  double total = 0.0;
  for (const auto& [rgb, w] : colours) total += w;
  uint32_t out = 0;
  for (int shift : {16, 8, 0}) {
    double v = 0.0;
    for (const auto& [rgb, w] : colours) v += w * ((rgb >> shift) & 0xFF);
    out |= static_cast<uint32_t>(std::clamp(std::lround(v / total), 0L, 255L)) << shift;
  }
  return out;
}

// The heaviest member for which `has` holds (ties: the lower key); members are in key order.
template <typename Has>
const Member* Heaviest(const Group& group, Has has) {
  const Member* best = nullptr;
  for (const Member& m : group) {
    if (has(m) && (best == nullptr || m.weight > best->weight)) best = &m;
  }
  return best;
}

// A key's layer cross-faded: its paint at `weight` times its opacity, placed in the frame.
ArtLayer FadedLayer(const EmbeddedLayer& layer, double weight, const Points& frame) {
  ArtLayer faded = layer.paint;
  faded.opacity *= weight;
  for (const EmbeddedPath& path : layer.paths) {
    faded.paths.push_back({PlacePath(path, frame), path.closed});
  }
  return faded;
}

class Morph {
 public:
  Morph(const std::vector<EmbeddedArt>& keys, const Points& frame, const FrameArtOptions& options)
      : keys_(keys), frame_(frame), options_(options) {}

  // The group's morphed layer, or nullopt when its closed paths come in different counts and do
  // not pair up closely (see MorphUnequalCounts): then its layers cross-fade.
  std::optional<ArtLayer> Layer(const Group& group) const {
    const Member& top = *Heaviest(group, [](const Member&) { return true; });
    ArtLayer out = Paint(top).paint;
    out.opacity = 0.0;
    for (const Member& m : group) out.opacity += m.weight * Paint(m).paint.opacity;
    out.fill = Fill(group);
    out.stroke = Stroke(group);
    std::vector<double> weights;
    for (const Member& m : group) weights.push_back(m.weight);
    const size_t most = std::max_element(group.begin(), group.end(),
                                         [&](const Member& a, const Member& b) {
                                           return Paint(a).paths.size() < Paint(b).paths.size();
                                         }) -
                        group.begin();
    if (std::any_of(group.begin(), group.end(), [&](const Member& m) {
          return Paint(m).paths.size() != Paint(group[most]).paths.size();
        })) {
      std::optional<std::vector<ArtPath>> paths = MorphUnequalCounts(group, weights, most);
      if (!paths) return std::nullopt;
      out.paths = *std::move(paths);
      return out;
    }
    for (size_t j = 0; j < Paint(top).paths.size(); ++j) {
      std::vector<Points> placed;
      for (const Member& m : group) placed.push_back(PlacePath(Paint(m).paths[j], frame_));
      const bool closed = Paint(top).paths[j].closed;
      // Closed paths drawn from other points or in the other direction in different keys: each
      // runs from the point nearest the first member's start, in its direction, in this frame.
      if (closed && !placed[0].empty()) {
        for (size_t m = 1; m < placed.size(); ++m) {
          placed[m] = AlignClosedPath(placed[0], placed[m]);
        }
      }
      out.paths.push_back({placed[0].empty()
                               ? Points{}
                               : BlendPaths(placed, closed, weights, options_.merge_fraction),
                           closed});
    }
    return out;
  }

  // Closed paths in different counts (a face that gains a mouth hole, one cell that becomes two):
  // each path of the member with the most (group[most]) is morphed with the path of every other
  // member that pairs with it, nearest first (mean squared distance of their placements in this
  // frame, aligned), and a member without a partner for it lends that path's own placement: the
  // mesh carries it (a hole opens as the mesh's opening does), instead of the layer fading.
  // Pairs must lie close in the frame (root mean squared distance under kPairDistance of the
  // path's length): a hole that opens pairs its face's outline with the face's outline, but one
  // cell that becomes two would pair its outline with one of the cells, which then drags the
  // other's half along; nullopt then (the layers cross-fade), as when a path some member lacks
  // is not a hole in one it has.
  std::optional<std::vector<ArtPath>> MorphUnequalCounts(const Group& group,
                                                         const std::vector<double>& weights,
                                                         size_t most) const {
    constexpr double kPairDistance = 0.02;
    const auto place = [&](const Member& m) {
      std::vector<Points> placed;
      for (const EmbeddedPath& path : Paint(m).paths) placed.push_back(PlacePath(path, frame_));
      return placed;
    };
    const std::vector<Points> full = place(group[most]);
    // partner[m][j]: member m's path (aligned) that morphs with full[j], if any.
    std::vector<std::vector<std::optional<Points>>> partner(group.size());
    for (size_t m = 0; m < group.size(); ++m) {
      partner[m].resize(full.size());
      if (m == most) {
        for (size_t j = 0; j < full.size(); ++j) partner[m][j] = full[j];
        continue;
      }
      const std::vector<Points> own = place(group[m]);
      struct Pair {
        double cost;
        size_t i, j;
        Points aligned;
      };
      std::vector<Pair> pairs;
      for (size_t i = 0; i < own.size(); ++i) {
        for (size_t j = 0; j < full.size(); ++j) {
          Points aligned = AlignClosedPath(full[j], own[i]);
          pairs.push_back({MeanSquaredDistance(full[j], aligned), i, j, std::move(aligned)});
        }
      }
      std::stable_sort(pairs.begin(), pairs.end(),
                       [](const Pair& a, const Pair& b) { return a.cost < b.cost; });
      std::vector<bool> used(own.size(), false);
      for (Pair& pair : pairs) {
        if (used[pair.i] || partner[m][pair.j]) continue;
        const double length = CumulativeLength(full[pair.j]).back();  // the perimeter
        if (!(pair.cost <= kPairDistance * kPairDistance * length * length)) return std::nullopt;
        used[pair.i] = true;
        partner[m][pair.j] = std::move(pair.aligned);
      }
      // A path this member lacks is carried only if it lies inside one it has (a hole, which
      // the mesh keeps shut where this member's drawing is closed); a separate region it lacks
      // (a second eye) would appear at once, so the layers cross-fade instead.
      for (size_t j = 0; j < full.size(); ++j) {
        if (partner[m][j]) continue;
        bool inside = false;
        for (size_t k = 0; k < full.size() && !inside; ++k) {
          inside = k != j && partner[m][k] && PolygonContains(full[k], full[j][0]);
        }
        if (!inside) return std::nullopt;
      }
    }
    std::vector<ArtPath> paths;
    for (size_t j = 0; j < full.size(); ++j) {
      std::vector<Points> placed;
      for (size_t m = 0; m < group.size(); ++m) {
        placed.push_back(partner[m][j] ? *partner[m][j] : full[j]);
      }
      paths.push_back({BlendPaths(placed, true, weights, options_.merge_fraction), true});
    }
    return paths;
  }

 private:
  const EmbeddedLayer& Paint(const Member& m) const { return keys_[m.key].layers[m.layer]; }

  // Present in some member: colour blended among those that have it, opacity among all (a
  // member without it counts as opacity 0, so it fades in).
  std::optional<FillPaint> Fill(const Group& group) const {
    const Member* top =
        Heaviest(group, [&](const Member& m) { return Paint(m).paint.fill.has_value(); });
    if (top == nullptr) return std::nullopt;
    FillPaint fill = *Paint(*top).paint.fill;
    std::vector<std::pair<uint32_t, double>> colours;
    fill.opacity = 0.0;
    for (const Member& m : group) {
      const std::optional<FillPaint>& f = Paint(m).paint.fill;
      if (!f) continue;
      colours.emplace_back(f->rgb, m.weight);
      fill.opacity += m.weight * f->opacity;
    }
    fill.rgb = BlendRgb(colours);
    return fill;
  }

  std::optional<StrokePaint> Stroke(const Group& group) const {
    auto has = [&](const Member& m) { return Paint(m).paint.stroke.has_value(); };
    const Member* top = Heaviest(group, has);
    if (top == nullptr) return std::nullopt;
    StrokePaint stroke = *Paint(*top).paint.stroke;
    const size_t dashes = stroke.dashes.size();
    bool same_dashes = true;
    double present = 0.0;
    for (const Member& m : group) {
      if (!has(m)) continue;
      present += m.weight;
      same_dashes = same_dashes && Paint(m).paint.stroke->dashes.size() == dashes;
    }
    std::vector<std::pair<uint32_t, double>> colours;
    stroke.opacity = stroke.width = stroke.miter_limit = 0.0;
    if (same_dashes) {
      std::fill(stroke.dashes.begin(), stroke.dashes.end(), 0.0);
      stroke.dash_offset = 0.0;
    }
    for (const Member& m : group) {
      if (!has(m)) continue;
      const StrokePaint& s = *Paint(m).paint.stroke;
      const double w = m.weight / present;  // among the members that stroke
      colours.emplace_back(s.rgb, m.weight);
      stroke.opacity += m.weight * s.opacity;
      stroke.width += w * s.width;
      stroke.miter_limit += w * s.miter_limit;
      if (!same_dashes) continue;
      for (size_t d = 0; d < dashes; ++d) stroke.dashes[d] += w * s.dashes[d];
      stroke.dash_offset += w * s.dash_offset;
    }
    stroke.rgb = BlendRgb(colours);
    return stroke;
  }

  const std::vector<EmbeddedArt>& keys_;
  const Points& frame_;
  const FrameArtOptions& options_;
};

}  // namespace

absl::StatusOr<std::vector<ArtLayer>> ArtForFrame(const std::vector<EmbeddedArt>& keys,
                                                  const Points& frame_vertices,
                                                  const std::vector<double>& weights,
                                                  const FrameArtOptions& options,
                                                  std::vector<ArtLayerSource>* sources) {
  if (weights.size() != keys.size()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "frame art: %d weights for the art of %d keys", weights.size(), keys.size()));
  }
  double total = 0.0;
  for (size_t k = 0; k < keys.size(); ++k) {
    if (!std::isfinite(weights[k])) {
      return absl::InvalidArgumentError(
          absl::StrFormat("frame art: weight %d is not finite", k + 1));
    }
    if (keys[k].num_vertices != static_cast<int>(frame_vertices.size())) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "frame art: key %d's art is embedded in a mesh of %d vertices, the frame has %d", k + 1,
          keys[k].num_vertices, frame_vertices.size()));
    }
    if (weights[k] > 0.0) total += weights[k];
  }
  if (!(total > 0.0)) return absl::InvalidArgumentError("frame art: no key has a weight > 0");
  std::vector<Member> active;
  std::vector<std::vector<int>> group_of(keys.size());  // [key][layer] -> group, or -1
  for (size_t k = 0; k < keys.size(); ++k) {
    group_of[k].assign(keys[k].layers.size(), -1);
    // w / total is exactly 1 for a key frame's only active key: its art comes out unchanged.
    if (weights[k] > 0.0) active.push_back({static_cast<int>(k), -1, weights[k] / total});
  }
  const std::vector<Group> groups = MatchLayers(keys, active, frame_vertices, options);
  for (size_t g = 0; g < groups.size(); ++g) {
    for (const Member& m : groups[g]) group_of[m.key][m.layer] = static_cast<int>(g);
  }
  // slots[g + 1]: cross-faded layers drawn right after group g (slots[0]: before every group);
  // slot_sources: their (key, layer).
  std::vector<std::vector<ArtLayer>> slots(groups.size() + 1);
  std::vector<std::vector<ArtLayerRef>> slot_sources(groups.size() + 1);
  for (const Member& a : active) {
    int last = -1;
    const std::vector<EmbeddedLayer>& layers = keys[a.key].layers;
    for (size_t l = 0; l < layers.size(); ++l) {
      if (group_of[a.key][l] >= 0) {
        last = group_of[a.key][l];
        continue;
      }
      slot_sources[last + 1].push_back({a.key, static_cast<int>(l)});
      slots[last + 1].push_back(FadedLayer(layers[l], a.weight, frame_vertices));
    }
  }
  const Morph morph(keys, frame_vertices, options);
  std::vector<ArtLayer> out = std::move(slots[0]);
  std::vector<ArtLayerSource> out_sources;
  const auto faded = [&](size_t slot) {
    for (const ArtLayerRef& ref : slot_sources[slot]) out_sources.push_back({{ref}});
  };
  faded(0);
  for (size_t g = 0; g < groups.size(); ++g) {
    if (std::optional<ArtLayer> morphed = morph.Layer(groups[g])) {
      out.push_back(*std::move(morphed));
      ArtLayerSource& source = out_sources.emplace_back();
      for (const Member& m : groups[g]) source.members.push_back({m.key, m.layer});
    } else {
      // Not morphable in this frame: its members cross-fade where the group stands.
      for (const Member& m : groups[g]) {
        out.push_back(FadedLayer(keys[m.key].layers[m.layer], m.weight, frame_vertices));
        out_sources.push_back({{{m.key, m.layer}}});
      }
    }
    for (ArtLayer& layer : slots[g + 1]) out.push_back(std::move(layer));
    faded(g + 1);
  }
  if (sources != nullptr) *sources = std::move(out_sources);
  return out;
}

}  // namespace inbetween::solver
