// The union of the immersed-boundary stencils of a step: each node once, in memory order.
//
// The forced collision (with the velocity the capsules move with) runs on the nodes that some
// stencil touches.
// Stencils overlap heavily (a 3D capsule of 4098 markers has 262k stencil entries, many times
// its distinct nodes), so the union is marked in a bit mask and read back in order (a sort of
// the entries cost as much as spreading). The mask holds one bit per interior node, a row
// along axis 0 in whole 64-bit words: a stencil row of `support` consecutive nodes is one or
// two OR operations, and the mask of a chapter 5 fine block (47^3) is 18 KB, so marking stays
// in the first-level cache. (Byte masks over the whole block, one byte per row start, cost
// twice the marking and a serial read-back of the block's bytes: solver/bench/NOTES.md.)
//
// Threads: marking is not atomic. The transfers mark in parallel over ranges of planes
// (Transfer::mark_stencil_nodes): a thread writes only the rows of its own planes, so no two
// threads write one word. collect() reads back in parallel over ranges of rows.
// Invariant: the mask is all zero between collect() calls.
#pragma once

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "field/grid.hpp"

namespace caplab::ibm {

class StencilUnion {
 public:
  /// Prepares the mask for the interior nodes of `grid`. A row is an interior line along axis 0,
  /// numbered row_of(i1, i2) (3D) or i1 (2D).
  template <int D>
  void begin(const field::Grid<D>& grid) {
    const std::ptrdiff_t rows = grid.interior_size() / grid.n()[0];
    const int words = (grid.n()[0] + 63) / 64;
    if (rows != rows_ || words != words_) {
      rows_ = rows;
      words_ = words;
      bits_.assign(static_cast<std::size_t>(rows * words), 0);
    }
    rows_per_plane_ = D == 3 ? grid.n()[1] : 1;
    row_stride_ = D == 3 ? grid.stride(1) : 0;
    plane_stride_ = grid.stride(D - 1);
    lo_ = rows_;
    hi_ = -1;
  }

  /// The row of interior node (., i1, i2) in 3D.
  std::ptrdiff_t row_of(int i1, int i2) const { return i1 + static_cast<std::ptrdiff_t>(rows_per_plane_) * i2; }
  /// The rows of plane p (the index along the last axis): [p, p + 1) * rows_per_plane.
  std::ptrdiff_t rows_per_plane() const { return rows_per_plane_; }

  /// Marks the `length` (at most 64) nodes x0 .. x0 + length - 1 of `row`.
  void mark_run(std::ptrdiff_t row, int x0, int length) {
    std::uint64_t* w = &bits_[row * words_ + (x0 >> 6)];
    const int b = x0 & 63;
    const std::uint64_t run = length == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << length) - 1;
    w[0] |= run << b;
    if (b + length > 64) w[1] |= run >> (64 - b);
  }
  /// Marks node x of `row`.
  void mark_node(std::ptrdiff_t row, int x) { bits_[row * words_ + (x >> 6)] |= std::uint64_t(1) << (x & 63); }
  /// The marked nodes lie in the rows [lo, hi]: every marking pass widens the range once, with
  /// the bounds of what it marked (not thread-safe: call it outside parallel regions).
  void widen(std::ptrdiff_t lo, std::ptrdiff_t hi) {
    lo_ = std::min(lo_, std::max<std::ptrdiff_t>(lo, 0));
    hi_ = std::max(hi_, std::min(hi, rows_ - 1));
  }

  /// Sets `nodes` to every marked node's linear index (field::Grid::index) in increasing order and
  /// clears the mask. In parallel over ranges of rows: each thread counts its marks, then writes
  /// them at its offset.
  void collect(std::vector<std::ptrdiff_t>& nodes) {
    nodes.clear();
    if (hi_ < lo_) return;
    const std::ptrdiff_t rows = hi_ - lo_ + 1;
#pragma omp parallel if (rows * words_ > 4096)
    {
      const int threads = omp_get_num_threads(), t = omp_get_thread_num();
#pragma omp single
      counts_.assign(threads + 1, 0);
      const std::ptrdiff_t first = lo_ + rows * t / threads, last = lo_ + rows * (t + 1) / threads;
      std::size_t count = 0;
      for (std::ptrdiff_t w = first * words_; w < last * words_; ++w) count += std::popcount(bits_[w]);
      counts_[t + 1] = count;
#pragma omp barrier
#pragma omp single
      {
        for (int k = 0; k < threads; ++k) counts_[k + 1] += counts_[k];
        nodes.resize(counts_[threads]);
      }
      std::ptrdiff_t* out = nodes.data() + counts_[t];
      for (std::ptrdiff_t r = first; r < last; ++r) {
        std::uint64_t* w = &bits_[r * words_];
        const std::ptrdiff_t base = 1 + (r % rows_per_plane_ + 1) * row_stride_ + (r / rows_per_plane_ + 1) * plane_stride_;
        for (int k = 0; k < words_; ++k) {
          for (std::uint64_t b = w[k]; b != 0; b &= b - 1) *out++ = base + 64 * k + std::countr_zero(b);
          w[k] = 0;
        }
      }
    }
  }

 private:
  std::vector<std::uint64_t> bits_;  // rows_ x words_
  std::vector<std::size_t> counts_;  // collect(): the threads' offsets
  std::ptrdiff_t rows_ = 0;
  int words_ = 0;
  int rows_per_plane_ = 1;
  std::ptrdiff_t row_stride_ = 0, plane_stride_ = 0;  // linear index = 1 + x + (i1 + 1) row_stride + (p + 1) plane_stride
  std::ptrdiff_t lo_ = 0, hi_ = -1;                    // the rows marked
};

}  // namespace caplab::ibm
