// The turning points of a signal through a zigzag filter: the extremes it comes back from by
// more than a given swing. Shared by the capsule-motion classifier (its reversal count) and the
// claims' regime sequences (where a capsule's last turn ends, score/claims.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

namespace caplab::diagnostics {

/// Indices of the extremes v turns back from by more than `swing` since its last turn, in order:
/// none for a monotone signal, however it curves. The start is not a turn: the first departure
/// by more than `swing` only sets the direction.
inline std::vector<std::size_t> turning_points(std::span<const double> v, double swing) {
  std::vector<std::size_t> turns;
  if (v.empty()) return turns;
  int dir = 0;
  std::size_t hi = 0, lo = 0;  // the extremes since the last turn
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (v[k] > v[hi]) hi = k;
    if (v[k] < v[lo]) lo = k;
    if (dir >= 0 && v[hi] - v[k] > swing) {  // fell from a maximum
      if (dir > 0) turns.push_back(hi);
      dir = -1, hi = lo = k;
    } else if (dir <= 0 && v[k] - v[lo] > swing) {  // rose from a minimum
      if (dir < 0) turns.push_back(lo);
      dir = 1, hi = lo = k;
    }
  }
  return turns;
}

}  // namespace caplab::diagnostics
