// Turns the comesh optimizer's callbacks (on_iterate, then a progress line per accepted iterate,
// and a progress line per topology pass) into the OptimizeComesh stream's messages: one
// ComeshIteration per iterate with its energies, Progress for everything else.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "inbetween/v1/inbetween.pb.h"
#include "solver/core/types.h"

namespace inbetween::server {

class ComeshIterationStream {
 public:
  // `outer`: topology passes already made (a run resumed from a checkpoint).
  explicit ComeshIterationStream(uint32_t outer = 0) : outer_(outer) {}

  // Opens iterate `iteration` (numbered from 1 over the whole run) with the shapes' vertex
  // count. Returns the previously opened iterate if no progress line completed it.
  std::optional<inbetween::v1::OptimizeComeshResponse> Begin(
      int iteration, const std::vector<solver::Points>& shapes);

  // A progress line. With an open iterate: that iterate, its energies read from `detail`
  // ("objective X", "map X", "mesh X"; missing ones stay 0). Otherwise a Progress message; an
  // "outer N: ..." line sets the outer count of the following iterates.
  inbetween::v1::OptimizeComeshResponse OnProgress(const std::string& stage, double fraction,
                                                   const std::string& detail);

  // The open iterate, if any (call once the optimizer returned).
  std::optional<inbetween::v1::OptimizeComeshResponse> Flush();

 private:
  std::optional<inbetween::v1::ComeshIteration> open_;
  uint32_t outer_ = 0;
};

}  // namespace inbetween::server
