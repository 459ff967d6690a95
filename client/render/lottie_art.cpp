// The art's Lottie animation (lottie_json.h): every frame's art followed layer by layer, one
// Lottie layer per track with path, colour and opacity keyframes (the rules are in
// lottie_export.h).
#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/render/lottie_json.h"
#include "solver/art/frame_art.h"

namespace inbetween::render::lottie {
namespace {

// The dash array art_painter draws: none when the dashes add up to nothing.
size_t DashCount(const solver::StrokePaint& s) {
  double total = 0;
  for (double d : s.dashes) total += d;
  return total > 0 ? s.dashes.size() : 0;
}

// What one Lottie layer cannot animate: its paths' structure and the paints' discrete
// properties, each fixed by the first frame that has that paint (so a paint that is set is one
// the layer has in some frame).
struct DiscretePaint {
  std::vector<std::pair<bool, bool>> paths;  // per path: closed, empty
  std::optional<bool> even_odd;              // the fill's rule
  std::optional<std::tuple<solver::LineCap, solver::LineJoin, size_t>> stroke;  // + dash count

  bool has_fill() const { return even_odd.has_value(); }
  bool has_stroke() const { return stroke.has_value(); }

  static std::vector<std::pair<bool, bool>> Paths(const solver::ArtLayer& layer) {
    std::vector<std::pair<bool, bool>> out;
    for (const solver::ArtPath& p : layer.paths) out.emplace_back(p.closed, p.points.empty());
    return out;
  }
  static auto Stroke(const solver::StrokePaint& s) {
    return std::make_tuple(s.cap, s.join, DashCount(s));
  }
  bool Fits(const solver::ArtLayer& layer) const {
    return Paths(layer) == paths &&
           !(layer.fill && even_odd && layer.fill->even_odd != *even_odd) &&
           !(layer.stroke && stroke && Stroke(*layer.stroke) != *stroke);
  }
  void Note(const solver::ArtLayer& layer) {
    if (layer.fill && !even_odd) even_odd = layer.fill->even_odd;
    if (layer.stroke && !stroke) stroke = Stroke(*layer.stroke);
  }
};

// One art layer followed through consecutive frames: one Lottie layer.
struct Track {
  int first = 0;                                // the frame of layers[0]
  std::vector<const solver::ArtLayer*> layers;  // one per frame from `first`
  std::vector<solver::ArtLayerRef> members;     // the latest frame's source
  DiscretePaint paint;
};

int SharedMembers(const std::vector<solver::ArtLayerRef>& a,
                  const std::vector<solver::ArtLayerRef>& b) {
  int n = 0;
  for (const solver::ArtLayerRef& r : a) n += std::find(b.begin(), b.end(), r) != b.end();
  return n;
}

// The indices of a longest strictly increasing subsequence of `values` (-1 entries skipped), the
// earliest of equals.
std::vector<bool> LongestIncreasing(const std::vector<int>& values) {
  const size_t n = values.size();
  std::vector<int> length(n, 0), previous(n, -1);
  int best = -1;
  for (size_t i = 0; i < n; ++i) {
    if (values[i] < 0) continue;
    length[i] = 1;
    for (size_t j = 0; j < i; ++j) {
      if (values[j] >= 0 && values[j] < values[i] && length[j] + 1 > length[i]) {
        length[i] = length[j] + 1, previous[i] = static_cast<int>(j);
      }
    }
    if (best < 0 || length[i] > length[best]) best = static_cast<int>(i);
  }
  std::vector<bool> keep(n, false);
  for (int i = best; i >= 0; i = previous[i]) keep[i] = true;
  return keep;
}

// Every frame's art followed layer by layer (the rules are in the header): the tracks, and their
// paint order bottom first.
class LayerFollower {
 public:
  void AddFrame(int f, const std::vector<solver::ArtLayer>& layers,
                const std::vector<solver::ArtLayerSource>& sources) {
    // Continue the previous frame's tracks: each layer, in paint order, takes the untaken one
    // sharing most members whose discrete paint fits (ties: the lower).
    std::vector<int> seq(layers.size(), -1);
    std::vector<bool> taken(previous_.size(), false);
    for (size_t i = 0; i < layers.size(); ++i) {
      int best = -1, most = 0;
      for (size_t p = 0; p < previous_.size(); ++p) {
        const Track& t = tracks_[previous_[p]];
        const int shared = SharedMembers(sources[i].members, t.members);
        if (!taken[p] && shared > most && t.paint.Fits(layers[i])) {
          best = static_cast<int>(p), most = shared;
        }
      }
      if (best >= 0) taken[best] = true, seq[i] = previous_[best];
    }
    // Keep the continued tracks in the global order where they agree with this frame (a longest
    // increasing run of their places); the others end and start anew.
    std::vector<int> place(seq.size(), -1);
    for (size_t i = 0; i < seq.size(); ++i) {
      if (seq[i] >= 0) {
        place[i] =
            static_cast<int>(std::find(order_.begin(), order_.end(), seq[i]) - order_.begin());
      }
    }
    const std::vector<bool> keep = LongestIncreasing(place);
    for (size_t i = 0; i < seq.size(); ++i) {
      if (seq[i] >= 0 && !keep[i]) seq[i] = -1;
    }
    // New tracks go right above the layer under them in this frame (at the bottom when none).
    for (size_t i = 0; i < seq.size(); ++i) {
      if (seq[i] < 0) {
        seq[i] = static_cast<int>(tracks_.size());
        tracks_.push_back({.first = f, .layers = {}, .members = {}, .paint = {}});
        tracks_.back().paint.paths = DiscretePaint::Paths(layers[i]);
        const auto at =
            i == 0 ? order_.begin() : std::find(order_.begin(), order_.end(), seq[i - 1]) + 1;
        order_.insert(at, seq[i]);
      }
      Track& t = tracks_[seq[i]];
      t.layers.push_back(&layers[i]);
      t.members = sources[i].members;
      t.paint.Note(layers[i]);
    }
    previous_ = std::move(seq);
  }

  const std::vector<Track>& tracks() const { return tracks_; }
  const std::vector<int>& order() const { return order_; }  // bottom first

 private:
  std::vector<Track> tracks_;
  std::vector<int> order_;
  std::vector<int> previous_;  // the previous frame's tracks in its paint order
};

// Arc-length fractions of a polyline's vertices (a closed one's closing edge counted), from 0;
// evenly spread when it has no length.
std::vector<double> Fractions(const solver::Points& p, bool closed) {
  std::vector<double> at(p.size(), 0.0);
  for (size_t i = 1; i < p.size(); ++i) at[i] = at[i - 1] + (p[i] - p[i - 1]).norm();
  const double total = p.empty() ? 0.0 : at.back() + (closed ? (p.front() - p.back()).norm() : 0);
  for (size_t i = 0; i < p.size(); ++i) {
    const double even =
        static_cast<double>(i) / std::max<size_t>(closed ? p.size() : p.size() - 1, 1);
    at[i] = total > 0 ? at[i] / total : even;
  }
  return at;
}

// `points` (not empty, at most reference.size()) with points added on its own edges up to
// reference.size(), so that it draws the same polyline with the reference's vertex count: each
// own vertex takes the reference vertex nearest in arc-length fraction, in order (the first the
// first, an open path's last the last), and the reference vertices between two taken ones become
// points on the own edge between them, spaced as in the reference.
solver::Points PadPath(const solver::Points& points, bool closed, const solver::Points& reference) {
  const size_t n = points.size(), count = reference.size();
  if (n >= count) return points;
  const std::vector<double> a = Fractions(points, closed), b = Fractions(reference, closed);
  std::vector<size_t> slot(n, 0);
  for (size_t i = 1; i < n; ++i) {
    if (!closed && i + 1 == n) {
      slot[i] = count - 1;
      break;
    }
    size_t j = slot[i - 1] + 1;
    const size_t last = count - n + i;  // room for the vertices after i
    while (j < last && std::abs(b[j + 1] - a[i]) < std::abs(b[j] - a[i])) ++j;
    slot[i] = j;
  }
  solver::Points out;
  for (size_t i = 0; i < n; ++i) {
    out.push_back(points[i]);
    const bool wraps = i + 1 == n;
    const size_t end = wraps ? count : slot[i + 1];
    const solver::Point& from = points[i];
    const solver::Point& to = wraps ? (closed ? points[0] : points[i]) : points[i + 1];
    const double b0 = b[slot[i]], b1 = wraps ? 1.0 : b[end];
    for (size_t j = slot[i] + 1; j < end; ++j) {
      const double t =
          b1 > b0 ? (b[j] - b0) / (b1 - b0) : static_cast<double>(j - slot[i]) / (end - slot[i]);
      out.push_back(from + std::clamp(t, 0.0, 1.0) * (to - from));
    }
  }
  return out;
}

json ArtPath(const solver::Points& points, bool closed, const Viewport& viewport) {
  json v = json::array(), tangents = json::array();
  for (const solver::Point& p : points) {
    const auto [x, y] = viewport.ToPixels({p.x(), p.y()});
    v.push_back({Round3(x), Round3(y)});
    tangents.push_back({0, 0});
  }
  return {{"c", closed}, {"v", std::move(v)}, {"i", tangents}, {"o", tangents}};
}

// Path `j` of the track, a keyframe per frame, padded to one vertex count (see the header).
json TrackPath(const Track& track, size_t j, const Viewport& viewport) {
  const size_t frames = track.layers.size();
  const bool closed = track.layers[0]->paths[j].closed;
  size_t most = 0;
  for (const solver::ArtLayer* l : track.layers) most = std::max(most, l->paths[j].points.size());
  std::vector<json> values;
  for (size_t k = 0; k < frames; ++k) {
    const solver::Points& own = track.layers[k]->paths[j].points;
    if (own.size() == most) {
      values.push_back(ArtPath(own, closed, viewport));
      continue;
    }
    // The nearest frame with the largest count (ties: the earlier).
    size_t ref = 0, distance = frames;
    for (size_t r = 0; r < frames; ++r) {
      const size_t d = r > k ? r - k : k - r;
      if (track.layers[r]->paths[j].points.size() == most && d < distance) ref = r, distance = d;
    }
    values.push_back(
        ArtPath(PadPath(own, closed, track.layers[ref]->paths[j].points), closed, viewport));
  }
  return Animated(values, track.first);
}

// A paint's values per frame of the track; a frame without the paint repeats the nearest frame's
// (ties: the earlier) and has opacity 0.
template <typename Paint, typename Get>
std::vector<json> PaintValues(const Track& track, Paint paint, Get get, bool opacity) {
  const size_t frames = track.layers.size();
  std::vector<json> out(frames);
  for (size_t k = 0; k < frames; ++k) {
    size_t from = frames, distance = frames + 1;
    for (size_t r = 0; r < frames; ++r) {
      const size_t d = r > k ? r - k : k - r;
      if (paint(*track.layers[r]) && d < distance) from = r, distance = d;
    }
    out[k] = opacity && from != k ? json(0.0) : get(*paint(*track.layers[from]));
  }
  return out;
}

json TrackFill(const Track& track) {
  const auto fill = [](const solver::ArtLayer& l) -> const std::optional<solver::FillPaint>& {
    return l.fill;
  };
  return {
      {"ty", "fl"},
      {"nm", "Fill"},
      {"c",
       Animated(PaintValues(
                    track, fill, [](const solver::FillPaint& p) { return Rgba(p.rgb); }, false),
                track.first)},
      {"o",
       Animated(PaintValues(
                    track, fill,
                    [](const solver::FillPaint& p) { return json(Round3(100 * p.opacity)); }, true),
                track.first)},
      {"r", *track.paint.even_odd ? 2 : 1}};
}

json TrackStroke(const Track& track, double scale) {
  const auto stroke = [](const solver::ArtLayer& l) -> const std::optional<solver::StrokePaint>& {
    return l.stroke;
  };
  const auto values = [&](auto get, bool opacity = false) {
    return Animated(PaintValues(track, stroke, get, opacity), track.first);
  };
  const auto [cap, join, dashes] = *track.paint.stroke;
  const solver::StrokePaint* first = nullptr;
  for (const solver::ArtLayer* l : track.layers) {
    if (l->stroke && first == nullptr) first = &*l->stroke;
  }
  json out = {
      {"ty", "st"},
      {"nm", "Stroke"},
      {"c", values([](const solver::StrokePaint& p) { return Rgba(p.rgb); })},
      {"o",
       values([](const solver::StrokePaint& p) { return json(Round3(100 * p.opacity)); }, true)},
      {"w", values([&](const solver::StrokePaint& p) { return json(Round3(p.width * scale)); })},
      {"lc", cap == solver::LineCap::kButt    ? 1
             : cap == solver::LineCap::kRound ? 2
                                              : 3},
      {"lj", join == solver::LineJoin::kMiter   ? 1
             : join == solver::LineJoin::kRound ? 2
                                                : 3},
      {"ml", first->miter_limit}};
  if (dashes > 0) {
    json d = json::array();
    for (size_t i = 0; i < dashes; ++i) {
      d.push_back({{"n", i % 2 == 0 ? "d" : "g"},
                   {"nm", i % 2 == 0 ? "dash" : "gap"},
                   {"v", values([&](const solver::StrokePaint& p) {
                      return json(Round3(p.dashes[i] * scale));
                    })}});
    }
    d.push_back({{"n", "o"}, {"nm", "offset"}, {"v", values([&](const solver::StrokePaint& p) {
                                                  return json(Round3(p.dash_offset * scale));
                                                })}});
    out["d"] = std::move(d);
  }
  return out;
}

// The track's Lottie layer, or null when it paints nothing (no paint or no points).
json TrackLayer(const Track& track, int ind, const Viewport& viewport) {
  json items = json::array();
  const solver::ArtLayer& first = *track.layers[0];
  for (size_t j = 0; j < first.paths.size(); ++j) {
    if (first.paths[j].points.empty()) continue;  // empty in every frame (DiscretePaint)
    items.push_back({{"ty", "sh"},
                     {"nm", absl::StrCat("Path ", j + 1)},
                     {"ks", TrackPath(track, j, viewport)}});
  }
  if (items.empty() || (!track.paint.has_stroke() && !track.paint.has_fill())) return nullptr;
  if (track.paint.has_stroke()) items.push_back(TrackStroke(track, viewport.scale));  // on top
  if (track.paint.has_fill()) items.push_back(TrackFill(track));
  items.push_back(GroupTransform());
  std::vector<json> opacity;
  for (const solver::ArtLayer* l : track.layers) opacity.push_back(Round3(100 * l->opacity));
  json transform = LayerTransform();
  transform["o"] = Animated(opacity, track.first);
  const std::string name = !first.name.empty() ? first.name
                           : !first.id.empty() ? first.id
                                               : absl::StrCat("Layer ", ind);
  const int last = track.first + static_cast<int>(track.layers.size());
  return ShapeLayer(ind, name, std::move(transform), std::move(items), track.first, last);
}

}  // namespace

absl::StatusOr<json> ArtAnimation(const FrameSet& frames, const LottieOptions& options,
                                  const Viewport& viewport) {
  const int count = static_cast<int>(frames.frames.size());
  std::vector<std::vector<solver::ArtLayer>> art(count);  // the tracks point into it
  LayerFollower follower;
  for (int f = 0; f < count; ++f) {
    // FrameArt's call, with the sources it does not return.
    const FrameData& frame = frames.frames[f];
    solver::Points vertices;
    for (const Vertex& v : frame.vertices) vertices.emplace_back(v[0], v[1]);
    std::vector<solver::ArtLayerSource> sources;
    absl::StatusOr<std::vector<solver::ArtLayer>> layers =
        solver::ArtForFrame(frames.art, vertices, frame.weights, {}, &sources);
    if (!layers.ok()) return layers.status();
    art[f] = *std::move(layers);
    follower.AddFrame(f, art[f], sources);
  }
  json layers = json::array();
  const std::vector<int>& order = follower.order();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {  // top first
    json layer = TrackLayer(follower.tracks()[*it], static_cast<int>(layers.size()) + 1, viewport);
    if (!layer.is_null()) layers.push_back(std::move(layer));
  }
  return Document(options, viewport, count, std::move(layers));
}

}  // namespace inbetween::render::lottie
