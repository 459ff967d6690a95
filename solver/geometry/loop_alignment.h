// Feature alignment of two closed loops: which point of one outline goes onto which of the other
// when no mark says so. An optimal monotone alignment of the two loops' samples by dynamic
// programming, in the spirit of Sederberg and Greenwood's minimum-work shape blending and of
// curvature-based curve alignment: corner against corner, turning against turning, with the
// matched pieces' stretching (and, far less, their distance) penalized. Arc length from an
// aligned start slides material around the corners wherever one side's length changes (a bar
// bent into a half ring: the bar's corner onto a third of the outer arc); the alignment keeps
// the corners paired and lets each side stretch as it must.
#pragma once

#include <vector>

#include "solver/core/types.h"

namespace inbetween::solver {

struct LoopAlignmentOptions {
  // Samples per loop: every corner (a vertex turning by more than corner_angle_degrees) and
  // points spread by arc length up to this many in all (more only when the corners alone are
  // more). The alignment's cost is O(starts * samples_a * band * 9) (starts: see max_starts).
  int max_samples = 192;
  double corner_angle_degrees = 30.0;
  // Cost of a step that pairs piece [i, i'] of loop a with [j, j'] of loop b, lengths la, lb as
  // fractions of their loops, end turns ta, tb (radians, the turning of each loop in the window
  // of its end sample):
  //   stretch_weight (la - lb)^2 / (la + lb)          stretching, resolution independent
  // + turn_weight ((ta - tb)^2 + sum of the squared turns of the samples the step skips)
  //                                                   corner onto corner, turn onto turn
  // + position_weight |pa - pb|^2 (la + lb) / 2       the two ends' distance (normalised
  //                                                   positions), which breaks the ties of
  //                                                   symmetric shapes (a square's four turns).
  double stretch_weight = 10.0;
  double turn_weight = 1.0;
  double position_weight = 1.0;
  // Steps pair 1..max_step samples of one loop with 1..max_step of the other (so a piece may
  // stretch up to max_step times between samples, and no two samples of one loop share a point
  // of the other).
  int max_step = 3;
  // Samples of b considered for sample i of a: within band * samples_b of the diagonal from the
  // start (a bar bent into a half ring moves its corners 0.16 of the perimeter off arc length).
  double band = 0.3;
  // Starts of b tried for a's start (a's most turning sample): b's samples that turn alike, the
  // best arc-length start (`hint`) and evenly spread ones, at most this many. Beyond 12, each is
  // first priced by the same alignment on 4 times fewer samples (every corner kept) and the 12
  // cheapest get the full one: a third less time, the same pairing on every case of
  // `scripts/bench correspondence` (6 of them change with 6 kept).
  int max_starts = 24;
};

struct LoopAlignment {
  // Matched points as fractions of each loop's arc length, in increasing order: a[k] in [0, 1)
  // from loop a's point 0, a[0] = 0; b[k] on loop b unwrapped (b[0] in [0, 1), b[k] < b[0] + 1).
  // Between them the correspondence is linear in arc length.
  std::vector<double> a, b;
  double cost = 0.0;
};

// Aligns closed loops `a` and `b` (same orientation, positions already in one normalised frame:
// used by the position term only). `hint`: a fraction of b's arc length thought to match a's
// point 0 (the arc-length alignment), tried as a start. Deterministic.
LoopAlignment AlignLoops(const Points& a, const Points& b, double hint,
                         const LoopAlignmentOptions& options = {});

}  // namespace inbetween::solver
