// Population storage of one block: structure of arrays, one buffer updated in place (the
// AA pattern of Bailey et al. 2009, as in the RRZE lbmbench kernels).
//
// Stored values are *shifted* populations f_i − w_i (deviation from the rest state ρ = 1,
// u = 0). Every operation of the method is linear in f or uses only moments, so the shift
// changes nothing but the round-off: it keeps single-precision storage accurate
// (the O(1) part of f is not stored). Moments: ρ = 1 + Σ f_i, ρu = Σ c_i f_i.
//
// Where the pre-collision (post-streaming) population f_i of node n at the current time lies
// depends on the parity of the step count:
//   parity 0 ("natural"): slot (i, n), population i's array at node n;
//   parity 1 ("swapped"): slot (ī, n − c_i), ī the opposite of i: the value node n − c_i
//                         pushed towards n, still where that node wrote it.
// Both are base(i) + n with a per-direction base (bases()), so every stage addresses
// population i of node n as bases[i][n]. A step at parity p reads node n's f_i from
// bases_p[i][n] and writes its post-collision value i to bases_{1−p}[i][n + c_i]: at parity 0
// that is (ī, n), at parity 1 (i, n + c_i). Node n reads and writes the same Q slots
// ({(j, n + c_j)} at parity 1, {(i, n)} at parity 0), no two nodes share a slot, so the update
// is in place and the order of the nodes does not matter; each step moves 2 Q values per node
// with no write-allocate (the A–B pattern moved 3 Q). After the step the parity flips, and
// bases[i][t] of the new parity is also where population i *entering* interior node t from a
// ghost belongs, and bases[i][g] for a ghost g = s + c_i where interior node s put the
// population i that *left* it: the boundary and coupling stages fill the first from the second.
// Only slots reached that way are addressed (base(i) + n stays inside the buffer), and the
// loads of the fused kernel's idle lanes, at most one chunk past them (the buffer's `slack`).
//
// Each population's array holds stride(N) ≥ N values for the N nodes of the grid: a whole,
// odd number of 64-byte lines, so that the Q arrays start in Q different sets of a 4 KiB
// page. With exactly N values, a grid of 8k + 2 nodes per axis (3D, double: (8k)^3 values of
// 8 B are a multiple of 4 KiB) put every array's node n at the same page offset: the sweep's
// 2Q streams then competed for one L1 set and its loads waited on unrelated stores (4K
// aliasing). Measured, D3Q19 BGK double, 2 threads, sweep only: 62^3 / 94^3 / 126^3 interior
// 46 / 48 / 48 MLUPS against 104 / 102 / 100 at 63^3 / 95^3 / 127^3.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "core/error.hpp"
#include "field/grid.hpp"

namespace caplab::field {

template <class L, class T>
class Populations {
 public:
  using Lattice = L;
  using value_type = T;
  static constexpr int D = L::d;
  static constexpr int Q = L::q;

  Populations() = default;
  explicit Populations(const Grid<D>& grid) : grid_(grid) {
    buf_.assign(static_cast<std::size_t>(Q) * stride(grid.size()) + slack, T(0));
    for (int i = 0; i < Q; ++i) off_[i] = grid.offset(L::c[i]);
  }

  const Grid<D>& grid() const { return grid_; }
  /// 0 (natural) or 1 (swapped): see the file comment.
  int parity() const { return parity_; }
  /// Called by the fused kernel after its in-place sweep (time advances by one step).
  void flip_parity() { parity_ = 1 - parity_; }

  T* data() { return buf_.data(); }
  const T* data() const { return buf_.data(); }

  /// Index into the buffer of grid g's populations of population i of node n at parity p.
  static std::ptrdiff_t slot(const Grid<D>& g, int p, int i, std::ptrdiff_t n) {
    return base(stride(g.size()), p, i, g.offset(L::c[i])) + n;
  }
  std::ptrdiff_t slot(int i, std::ptrdiff_t n) const { return base(stride(grid_.size()), parity_, i, off_[i]) + n; }

  /// Base pointers of parity p: population i of node n is at bases[i][n].
  std::array<T*, Q> bases(int p) {
    std::array<T*, Q> b;
    for (int i = 0; i < Q; ++i) b[i] = buf_.data() + base(stride(grid_.size()), p, i, off_[i]);
    return b;
  }
  std::array<const T*, Q> bases(int p) const {
    std::array<const T*, Q> b;
    for (int i = 0; i < Q; ++i) b[i] = buf_.data() + base(stride(grid_.size()), p, i, off_[i]);
    return b;
  }
  std::array<T*, Q> bases() { return bases(parity_); }
  std::array<const T*, Q> bases() const { return bases(parity_); }

  /// Shifted population i of linear node n at the current time.
  T& operator()(int i, std::ptrdiff_t n) { return buf_[slot(i, n)]; }
  T operator()(int i, std::ptrdiff_t n) const { return buf_[slot(i, n)]; }

  /// The buffer and its parity (io/checkpoint.hpp archive). The entry names differ from the
  /// two-buffer layout of caplab before 2026-12-06, so such a checkpoint is refused by name;
  /// one written before the arrays were padded (2026-12-07) has no "population_stride".
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    std::int64_t s = stride(grid_.size());
    ar(prefix + "population_stride", s);
    if (s != stride(grid_.size()))
      throw core::Error("checkpoint: " + prefix + " holds " + std::to_string(s) +
                        " values per population, this build " + std::to_string(stride(grid_.size())) +
                        ": resume it with the build that wrote it or run afresh");
    ar(prefix + "populations_in_place", std::span<T>(buf_.data(), buf_.size() - slack));
    ar(prefix + "parity", parity_);
  }

  /// Values per population's array for a grid of `nodes` nodes (see the file comment).
  static constexpr std::ptrdiff_t stride(std::ptrdiff_t nodes) {
    constexpr std::ptrdiff_t line = 64 / sizeof(T);
    std::ptrdiff_t s = (nodes + line - 1) / line * line;
    if (s / line % 2 == 0) s += line;
    return s;
  }

  /// Bytes one node update moves in the fused kernel: read Q and write Q values, in place
  /// (no write-allocate: the written lines were just read).
  static constexpr std::size_t bytes_per_update() { return 2 * Q * sizeof(T); }

 private:
  /// Where population i's values of parity p start, S values per population (stride), off_i
  /// the linear offset of c_i: node n's value is at base + n.
  static std::ptrdiff_t base(std::ptrdiff_t S, int p, int i, std::ptrdiff_t off_i) {
    return p == 0 ? i * S : L::opposite[i] * S - off_i;
  }

  /// Values after the last population's array: the idle lanes of the fused kernel's last
  /// chunk of a row (collision::update_tail) load up to one chunk past the last slot addressed.
  static constexpr std::size_t slack = 64 / sizeof(T);

  Grid<D> grid_;
  AlignedVector<T> buf_;
  std::array<std::ptrdiff_t, Q> off_{};  // linear offsets of the lattice directions
  int parity_ = 0;
};

}  // namespace caplab::field
