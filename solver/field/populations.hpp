// Population storage of one block: structure of arrays, two buffers (A–B pattern).
//
// Stored values are *shifted* populations f_i − w_i (deviation from the rest state ρ = 1,
// u = 0). Every operation of the method is linear in f or uses only moments, so the shift
// changes nothing but the round-off: it keeps single-precision storage accurate
// (the O(1) part of f is not stored). Moments: ρ = 1 + Σ f_i, ρu = Σ c_i f_i.
//
// Buffer `current()` holds the pre-collision (post-streaming) populations at time t: the
// fused kernel reads it, collides, and pushes into `next()`; `swap()` advances time.
// Population i of node n is at [i · grid.size() + n].
#pragma once

#include <span>
#include <string>

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
    for (auto& b : buf_) b.assign(static_cast<std::size_t>(Q) * grid.size(), T(0));
  }

  const Grid<D>& grid() const { return grid_; }
  T* current() { return buf_[cur_].data(); }
  const T* current() const { return buf_[cur_].data(); }
  T* next() { return buf_[1 - cur_].data(); }
  const T* next() const { return buf_[1 - cur_].data(); }
  void swap() { cur_ = 1 - cur_; }

  /// Shifted population i of linear node n in the current buffer.
  T& operator()(int i, std::ptrdiff_t n) { return buf_[cur_][i * grid_.size() + n]; }
  T operator()(int i, std::ptrdiff_t n) const { return buf_[cur_][i * grid_.size() + n]; }

  /// Both buffers and which one is current (io/checkpoint.hpp archive).
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    ar(prefix + "pop_a", std::span<T>(buf_[0]));
    ar(prefix + "pop_b", std::span<T>(buf_[1]));
    ar(prefix + "current", cur_);
  }

  /// Bytes one node update moves in the fused kernel (read Q, write Q values).
  static constexpr std::size_t bytes_per_update() { return 2 * Q * sizeof(T); }

 private:
  Grid<D> grid_;
  std::array<AlignedVector<T>, 2> buf_;
  int cur_ = 0;
};

}  // namespace caplab::field
