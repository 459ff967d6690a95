// ComeshIterationStream: reads the numbers out of the optimizer's progress lines (the solver's
// ProgressFn carries text only; solver/comesh/comesh_inner_loop.cpp and comesh_optimizer.cpp
// write them).
#include "server/comesh_progress.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <utility>

namespace inbetween::server {
namespace {

namespace v1 = ::inbetween::v1;

// The number right after "`key` " in `text` (at a word start), if any.
std::optional<double> NumberAfter(const std::string& text, const std::string& key) {
  const std::string needle = key + " ";
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) {
    if (at > 0 && std::isalnum(static_cast<unsigned char>(text[at - 1]))) continue;
    const char* begin = text.c_str() + at + needle.size();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end != begin) return value;
  }
  return std::nullopt;
}

v1::OptimizeComeshResponse Wrap(v1::ComeshIteration iteration) {
  v1::OptimizeComeshResponse message;
  *message.mutable_iteration() = std::move(iteration);
  return message;
}

}  // namespace

std::optional<v1::OptimizeComeshResponse> ComeshIterationStream::Begin(
    int iteration, const std::vector<solver::Points>& shapes) {
  std::optional<v1::OptimizeComeshResponse> previous = Flush();
  v1::ComeshIteration& it = open_.emplace();
  it.set_outer(outer_);
  it.set_inner(static_cast<uint32_t>(std::max(iteration, 0)));
  it.set_vertices(shapes.empty() ? 0 : static_cast<uint32_t>(shapes[0].size()));
  return previous;
}

v1::OptimizeComeshResponse ComeshIterationStream::OnProgress(const std::string& stage,
                                                             double fraction,
                                                             const std::string& detail) {
  if (open_) {
    v1::ComeshIteration it = *std::move(open_);
    open_.reset();
    if (auto v = NumberAfter(detail, "objective")) it.set_objective(*v);
    if (auto v = NumberAfter(detail, "map")) it.set_map_energy(*v);
    if (auto v = NumberAfter(detail, "mesh")) it.set_mesh_energy(*v);
    return Wrap(std::move(it));
  }
  if (detail.rfind("outer ", 0) == 0) {
    if (auto v = NumberAfter(detail, "outer"); v && *v >= 0) outer_ = static_cast<uint32_t>(*v);
  }
  v1::OptimizeComeshResponse message;
  v1::Progress* p = message.mutable_progress();
  p->set_stage(stage);
  p->set_fraction(std::clamp(fraction, 0.0, 1.0));
  p->set_detail(detail);
  return message;
}

std::optional<v1::OptimizeComeshResponse> ComeshIterationStream::Flush() {
  if (!open_) return std::nullopt;
  v1::OptimizeComeshResponse message = Wrap(*std::move(open_));
  open_.reset();
  return message;
}

}  // namespace inbetween::server
