// The union of the immersed-boundary stencils of a step: each node once, in memory order.
//
// The forced collision (with the velocity the capsules move with) runs on the nodes that some
// stencil touches.
// Stencils overlap heavily (a 3D capsule of 4098 markers has 262k stencil entries, many times
// its distinct nodes), so the union is marked in byte masks over the block and read back over
// the range the stencils span (a sort of the entries cost as much as spreading).
// A stencil row along axis 0 is `run` consecutive linear indices unless it wraps around a
// periodic axis 0. Rows that do not wrap are marked once, at their first node, in
// `run_start_`, and the read-back extends each start over `run` nodes; the nodes of rows that
// wrap go one by one into `single_`. One store per row instead of per node (measured: the
// per-node stores were 6 % of a chapter 6 biconcave step; solver/bench/NOTES.md).
//
// Threads: mark_run and mark_node store 1 with relaxed atomic stores, so concurrent marking
// (every thread writes the same value) is race-free; widen and collect are serial.
// Invariant: both masks are all zero between collect() calls.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace caplab::ibm {

class StencilUnion {
 public:
  /// Prepares the masks for a block of `grid_size` linear indices.
  void begin(std::ptrdiff_t grid_size) {
    if (static_cast<std::ptrdiff_t>(run_start_.size()) != grid_size) {
      run_start_.assign(grid_size, 0);
      single_.assign(grid_size, 0);
    }
    run_ = 0;
    lo_ = grid_size;
    hi_ = -1;
  }
  /// Whether rows of `length` nodes can be marked with mark_run: the first length asked for
  /// after begin() is the run length (all transfers of a scene share one kernel; another
  /// length marks node by node). Serial.
  bool runs_of(int length) {
    if (run_ == 0) run_ = length;
    return run_ == length;
  }

  /// Marks the nodes first .. first + run - 1 (after runs_of(run) was true).
  void mark_run(std::ptrdiff_t first) { store_one(run_start_[first]); }
  /// Marks node n.
  void mark_node(std::ptrdiff_t n) { store_one(single_[n]); }
  /// The marked nodes lie in [lo, hi]: every marking pass widens the range once, with the
  /// bounds of what it marked (not thread-safe: call it outside parallel regions).
  void widen(std::ptrdiff_t lo, std::ptrdiff_t hi) {
    lo_ = std::min(lo_, lo);
    hi_ = std::max(hi_, hi);
  }

  /// Appends every marked node to `nodes` in increasing order and clears the marks. Where no
  /// run covers it, the range is read 8 bytes of both masks at a time: most of it (whole planes
  /// across the block around a capsule) holds no mark.
  void collect(std::vector<std::ptrdiff_t>& nodes) {
    int left = 0;  // nodes still covered by the last run start
    for (std::ptrdiff_t n = lo_; n <= hi_;) {
      if (left == 0 && n + 8 <= hi_ + 1 && !any_mark_in_8(n)) {
        n += 8;
        continue;
      }
      if (run_start_[n]) {
        left = run_;
        run_start_[n] = 0;
      }
      if (single_[n]) {
        single_[n] = 0;
        nodes.push_back(n);
      } else if (left > 0) {
        nodes.push_back(n);
      }
      if (left > 0) --left;
      ++n;
    }
  }

 private:
  bool any_mark_in_8(std::ptrdiff_t n) const {
    std::uint64_t a, b;
    std::memcpy(&a, &run_start_[n], 8);
    std::memcpy(&b, &single_[n], 8);
    return (a | b) != 0;
  }
  static void store_one(std::uint8_t& b) {
    std::atomic_ref<std::uint8_t>(b).store(1, std::memory_order_relaxed);
  }

  std::vector<std::uint8_t> run_start_, single_;
  int run_ = 0;  // 0: not chosen yet
  std::ptrdiff_t lo_ = 0, hi_ = -1;
};

}  // namespace caplab::ibm
