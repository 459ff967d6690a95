// The Lottie JSON building blocks (lottie_json.h).
#include "client/render/lottie_json.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace inbetween::render::lottie {

json Static(json value) { return {{"a", 0}, {"k", std::move(value)}}; }

double Round3(double x) { return std::round(x * 1000.0) / 1000.0; }

json LayerTransform() {
  return {{"o", Static(100)},
          {"r", Static(0)},
          {"p", Static({0, 0, 0})},
          {"a", Static({0, 0, 0})},
          {"s", Static({100, 100, 100})}};
}

json GroupTransform() {
  return {{"ty", "tr"},          {"nm", "Transform"},       {"p", Static({0, 0})},
          {"a", Static({0, 0})}, {"s", Static({100, 100})}, {"r", Static(0)},
          {"o", Static(100)},    {"sk", Static(0)},         {"sa", Static(0)}};
}

json Animated(const std::vector<json>& values, int first) {
  if (std::all_of(values.begin(), values.end(), [&](const json& v) { return v == values[0]; })) {
    return Static(values[0]);
  }
  json keyframes = json::array();
  for (size_t k = 0; k < values.size(); ++k) {
    json key = {{"t", first + static_cast<int>(k)},
                {"s", values[k].is_array() ? values[k] : json::array({values[k]})}};
    if (k + 1 < values.size()) {  // linear easing to the next keyframe
      key["o"] = {{"x", 0}, {"y", 0}};
      key["i"] = {{"x", 1}, {"y", 1}};
    }
    keyframes.push_back(std::move(key));
  }
  return {{"a", 1}, {"k", std::move(keyframes)}};
}

json Rgba(const Rgba8& c) { return json::array({c.r / 255.0, c.g / 255.0, c.b / 255.0, 1}); }

json Rgba(uint32_t rgb) {
  return Rgba({static_cast<uint8_t>(rgb >> 16), static_cast<uint8_t>(rgb >> 8),
               static_cast<uint8_t>(rgb), 255});
}

json Document(const LottieOptions& options, const Viewport& viewport, int count, json layers) {
  return json{{"v", "5.7.4"},
              {"nm", options.name},
              {"fr", options.fps},
              {"ip", 0},
              {"op", count},
              {"w", viewport.width},
              {"h", viewport.height},
              {"assets", json::array()},
              {"layers", std::move(layers)}};
}

json ShapeLayer(int ind, const std::string& name, json transform, json items, int ip, int op) {
  return {{"ind", ind},
          {"ty", 4},
          {"nm", name},
          {"sr", 1},
          {"ks", std::move(transform)},
          {"ao", 0},
          {"shapes", json::array({{{"ty", "gr"}, {"nm", name}, {"it", std::move(items)}}})},
          {"ip", ip},
          {"op", op},
          {"st", 0}};
}

}  // namespace inbetween::render::lottie
