// Grid of one block: interior nodes, one ghost layer, physical placement, and the
// fields sized by rule on it (scalar, D-vector, Q-vector as structure of arrays).
//
// Node (i, j[, k]) with 0 <= i < n[0] ... is interior and sits at origin + dx·(i, j, k).
// Index −1 and n[a] along axis a are the ghost layer, where boundary conditions and the
// multi-block coupling put the populations that stream into the interior. Storage is
// x-fastest with the ghost layer included, so a node's neighbour along direction c is at
// a constant offset in the linear index.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#include "core/error.hpp"
#include "core/vec.hpp"

namespace caplab::field {

/// Allocator with 64-byte alignment, so SoA rows start on cache lines and vector loads align.
template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = ((n * sizeof(T) + 63) / 64) * 64;
    void* p = std::aligned_alloc(64, bytes);
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const {
    return true;
  }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T>>;

/// The nodes lo ≤ ijk < hi of a grid (none when hi ≤ lo along an axis).
template <int D>
struct Box {
  Index<D> lo{}, hi{};
  bool empty() const {
    for (int a = 0; a < D; ++a)
      if (hi[a] <= lo[a]) return true;
    return false;
  }
  std::ptrdiff_t size() const {
    std::ptrdiff_t s = 1;
    for (int a = 0; a < D; ++a) s *= std::max(0, hi[a] - lo[a]);
    return s;
  }
  /// Whether the row (x line) through ijk crosses the box.
  bool crosses_row(const Index<D>& ijk) const {
    if (empty()) return false;
    for (int a = 1; a < D; ++a)
      if (ijk[a] < lo[a] || ijk[a] >= hi[a]) return false;
    return true;
  }
};

/// Geometry of a block: number of interior nodes, placement and spacing, ghost-aware strides.
template <int D>
class Grid {
 public:
  Grid() = default;
  Grid(Index<D> n, Vec<D> origin, double dx) : n_(n), origin_(origin), dx_(dx) {
    std::ptrdiff_t s = 1;
    for (int a = 0; a < D; ++a) {
      CAPLAB_CHECK(n[a] >= 1, "grid needs at least one interior node per axis");
      stride_[a] = s;
      s *= n[a] + 2;
    }
    size_ = s;
  }

  const Index<D>& n() const { return n_; }
  const Vec<D>& origin() const { return origin_; }
  double dx() const { return dx_; }
  /// Nodes including the ghost layer (the length of every field on this grid).
  std::ptrdiff_t size() const { return size_; }
  std::ptrdiff_t interior_size() const {
    std::ptrdiff_t s = 1;
    for (int a = 0; a < D; ++a) s *= n_[a];
    return s;
  }
  std::ptrdiff_t stride(int axis) const { return stride_[axis]; }

  /// Linear index of node (i, j[, k]); each index may be −1 … n (ghost layer included).
  std::ptrdiff_t index(const Index<D>& ijk) const {
    std::ptrdiff_t id = 0;
    for (int a = 0; a < D; ++a) id += (ijk[a] + 1) * stride_[a];
    return id;
  }
  /// Offset in the linear index of the neighbour along the lattice direction c.
  template <class C>
  std::ptrdiff_t offset(const C& c) const {
    std::ptrdiff_t o = 0;
    for (int a = 0; a < D; ++a) o += c[a] * stride_[a];
    return o;
  }
  bool is_interior(const Index<D>& ijk) const {
    for (int a = 0; a < D; ++a)
      if (ijk[a] < 0 || ijk[a] >= n_[a]) return false;
    return true;
  }
  /// Physical position of a node.
  Vec<D> position(const Index<D>& ijk) const {
    Vec<D> x = origin_;
    for (int a = 0; a < D; ++a) x[a] += dx_ * ijk[a];
    return x;
  }
  /// Position in lattice units relative to node 0 (fractional node index).
  Vec<D> to_lattice(const Vec<D>& x) const { return (x - origin_) / dx_; }

 private:
  Index<D> n_{};
  Vec<D> origin_ = Vec<D>::Zero();
  double dx_ = 1.0;
  std::array<std::ptrdiff_t, D> stride_{};
  std::ptrdiff_t size_ = 0;
};

/// Calls f(Index<D>) for every interior node (x fastest).
template <int D, class F>
void for_each_interior(const Grid<D>& g, F&& f) {
  if constexpr (D == 2) {
    for (int j = 0; j < g.n()[1]; ++j)
      for (int i = 0; i < g.n()[0]; ++i) f(Index<2>{i, j});
  } else {
    for (int k = 0; k < g.n()[2]; ++k)
      for (int j = 0; j < g.n()[1]; ++j)
        for (int i = 0; i < g.n()[0]; ++i) f(Index<3>{i, j, k});
  }
}

/// Calls f(Index<D>) for every ghost node (the layer around the interior).
template <int D, class F>
void for_each_ghost(const Grid<D>& g, F&& f) {
  Index<D> lo, hi;
  for (int a = 0; a < D; ++a) lo[a] = -1, hi[a] = g.n()[a];
  auto visit = [&](const Index<D>& ijk) {
    if (!g.is_interior(ijk)) f(ijk);
  };
  if constexpr (D == 2) {
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) visit(Index<2>{i, j});
  } else {
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) visit(Index<3>{i, j, k});
  }
}

/// D components of a vector quantity on a grid, structure of arrays (e.g. the IB force density).
template <int D, class T = double>
struct VectorField {
  std::array<AlignedVector<T>, D> comp;
  explicit VectorField(std::ptrdiff_t size = 0) {
    for (auto& c : comp) c.assign(size, T(0));
  }
  void fill(T v) {
    for (auto& c : comp) std::fill(c.begin(), c.end(), v);
  }
};

}  // namespace caplab::field
