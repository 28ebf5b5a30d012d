// Immersed-boundary transfer between Lagrangian markers and the Eulerian grid of a block.
//
// Interpolation (thesis eq. 2.19 / 5.11) and spreading (eq. 2.16 / 5.8), discretised with a
// tensor-product kernel (eq. 2.18 / 5.9, policies in ibm/kernels.hpp), in the lattice units
// of the block (grid spacing 1, time step 1):
//   U(X_m) = sum_x u(x) phi(x - X_m)                    (interpolate)
//   f(x)  += sum_m F_m phi(x - X_m) w_m                 (spread)
// with X_m = grid.to_lattice(X_m^phys), node (i, j[, k]) at lattice coordinate (i, j[, k]),
// F_m the marker force per unit marker measure and w_m = measure / dx^(D-1) the marker
// measure in lattice units (measure_to_lattice). Both use the same stencils, so they are
// adjoint: sum_m U(X_m).F_m w_m == sum_x u(x).f(x) to round-off.
//
// Invariants and choices:
//   * Stencils touch interior nodes only (0..n-1 per axis), never the ghost layer. Along a
//     periodic axis indices wrap modulo n; along a non-periodic axis a stencil node outside
//     the interior is an error (CAPLAB_CHECK) naming the marker, its position and the block.
//     The check is on the whole support^D stencil, including nodes of zero weight.
//   * Stencils are computed once per step by update() into member buffers that only grow,
//     so the time loop does not allocate once the marker count is stable. A stencil is
//     stored compactly, per axis: the `support` node indices, their weights and their parts
//     of the linear index (248 bytes per 3D marker); its support^D entries (node, linear
//     index, weight w0 w1 [w2]) are formed where they are used (for_each_stencil_node).
//     Storing the expanded entries (64 x 28 bytes per 3D marker) made update() a wall of
//     stores and cost as much as spreading (solver/bench/NOTES.md).
//   * Threads: update(), interpolation and mark_stencil_nodes() run in parallel over markers
//     (OpenMP, for large marker counts); the callables passed to interpolate must be safe to call
//     concurrently and must not throw. Spreading runs in parallel over slabs: spread()
//     first sorts the markers (stably) by the slab of `support` nodes along the last axis in
//     which their stencil starts. A node is reached from at most two consecutive slabs, so
//     the even slabs can spread at once, then the odd ones; each node then sums its
//     contributions in the same order (even slab, then odd, markers in index order within
//     a slab) whatever the thread count: bit-reproducible without locks. Along a periodic
//     last axis a stencil may wrap onto the first slab, and the spread is serial, slab by
//     slab (markers in index order within a slab).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/vec.hpp"
#include "field/grid.hpp"
#include "ibm/kernels.hpp"
#include "ibm/stencil_union.hpp"

namespace caplab::ibm {

/// Marker measure (arc length in 2D, area in 3D) in lattice units: measure / dx^(D-1).
template <int D>
double measure_to_lattice(double measure, double dx) {
  return measure / std::pow(dx, D - 1);
}

namespace detail {
constexpr int ipow(int base, int exp) { return exp == 0 ? 1 : base * ipow(base, exp - 1); }
constexpr std::ptrdiff_t parallel_threshold = 256;  // markers below which loops stay serial
}  // namespace detail

/// Stencils of a set of markers on one block and the interpolation / spreading with them.
/// Lifecycle per step: update(grid, periodic, positions), then any number of
/// interpolate(...) and spread(...) calls with the same markers.
template <int D, class Kernel = Cosine4>
class Transfer {
 public:
  static constexpr int support = Kernel::support;
  /// Nodes per marker stencil: support^D.
  static constexpr int stencil_size = detail::ipow(Kernel::support, D);

  /// Computes the stencils (nodes and tensor-product weights) of the markers at the
  /// physical positions `positions` on `grid`. Throws core::Error if a marker position is
  /// not finite or its stencil leaves the interior along a non-periodic axis.
  void update(const field::Grid<D>& grid, const std::array<bool, D>& periodic,
              std::span<const Vec<D>> positions) {
    grid_ = grid;
    periodic_ = periodic;
    const std::ptrdiff_t m_count = static_cast<std::ptrdiff_t>(positions.size());
    x_lu_.resize(m_count);
    stencil_.resize(m_count);
    std::ptrdiff_t first_bad = m_count;
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold) reduction(min : first_bad)
    for (std::ptrdiff_t m = 0; m < m_count; ++m) {
      x_lu_[m] = grid_.to_lattice(positions[m]);
      if (!fill_stencil(m) && m < first_bad) first_bad = m;
    }
    if (first_bad < m_count)
      core::check_failed("stencil inside block", __FILE__, __LINE__,
                         stencil_error(first_bad, positions[first_bad]));
  }

  std::size_t marker_count() const { return x_lu_.size(); }
  /// The grid of the last update().
  const field::Grid<D>& grid() const { return grid_; }
  const std::array<bool, D>& periodic() const { return periodic_; }
  /// Marker position in lattice units (fractional node index), not wrapped.
  const Vec<D>& lattice_position(std::size_t m) const { return x_lu_[m]; }
  /// Calls f(const Index<D>& node, std::ptrdiff_t linear_index, double weight) for the
  /// support^D nodes of the stencil of marker m (nodes wrapped into the interior, linear
  /// index as grid.index, weights phi(x - X_m) summing to 1), axis 0 fastest.
  template <class F>
  void for_each_stencil_node(std::size_t m, F&& f) const {
    const Stencil& s = stencil_[m];
    if constexpr (D == 2) {
      for (int j = 0; j < support; ++j)
        for (int i = 0; i < support; ++i)
          f(Index<2>{s.i[0][i], s.i[1][j]}, s.off[0][i] + s.off[1][j], s.w[0][i] * s.w[1][j]);
    } else {
      for (int k = 0; k < support; ++k)
        for (int j = 0; j < support; ++j)
          for (int i = 0; i < support; ++i)
            f(Index<3>{s.i[0][i], s.i[1][j], s.i[2][k]}, s.off[0][i] + s.off[1][j] + s.off[2][k],
              s.w[0][i] * s.w[1][j] * s.w[2][k]);
    }
  }

  /// Marks every stencil node of every marker in `nodes` (in parallel for many markers): a
  /// row along axis 0 at once where it is `support` consecutive nodes, else node by node.
  void mark_stencil_nodes(StencilUnion& nodes) const {
    const std::ptrdiff_t m_count = static_cast<std::ptrdiff_t>(marker_count());
    const bool rows = nodes.runs_of(support);
    std::ptrdiff_t lo = std::numeric_limits<std::ptrdiff_t>::max(), hi = -1;
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold) \
    reduction(min : lo) reduction(max : hi)
    for (std::ptrdiff_t m = 0; m < m_count; ++m) {
      const Stencil& s = stencil_[m];
      if (rows && s.rows) {
        for_each_stencil_row(m,
                             [&](std::ptrdiff_t first, const double(&)[support]) { nodes.mark_run(first); });
      } else {
        for_each_stencil_node(m, [&](const Index<D>&, std::ptrdiff_t n, double) { nodes.mark_node(n); });
      }
      std::ptrdiff_t first = 0, last = 0;
      for (int a = 0; a < D; ++a) {
        first += *std::min_element(std::begin(s.off[a]), std::end(s.off[a]));
        last += *std::max_element(std::begin(s.off[a]), std::end(s.off[a]));
      }
      lo = std::min(lo, first);
      hi = std::max(hi, last);
    }
    if (m_count > 0) nodes.widen(lo, hi);
  }

  /// out[m] = sum_x u(x) phi(x - X_m) (eq. 2.19 / 5.11), with
  /// u = velocity_at(const Index<D>& node, std::ptrdiff_t linear_index) -> Vec<D>.
  template <class VelocityAt>
  void interpolate(VelocityAt&& velocity_at, std::span<Vec<D>> out) const {
    gather<Vec<D>>(velocity_at, out);
  }
  /// out[m] = sum_x u(x) phi(x - X_m) (eq. 2.19 / 5.11) from a vector field on the grid of the
  /// last update() (only the stencil nodes are read). Rows of consecutive nodes as vector code: the sums
  /// differ from the callable form's at round-off.
  void interpolate_field(const field::VectorField<D>& u, std::span<Vec<D>> out) const {
    CAPLAB_CHECK(out.size() == marker_count(),
                 "IB interpolation: the output needs one entry per marker (as in the last update)");
    CAPLAB_CHECK(static_cast<std::ptrdiff_t>(u.comp[0].size()) == grid_.size(),
                 "IB interpolation: the field is not sized for the grid of the last update");
    const std::ptrdiff_t m_count = static_cast<std::ptrdiff_t>(marker_count());
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold)
    for (std::ptrdiff_t m = 0; m < m_count; ++m) {
      Vec<D> acc = Vec<D>::Zero();
      if (stencil_[m].rows) {
        double lane[D][support] = {};  // per component and row position, summed at the end
        for_each_stencil_row(m, [&](std::ptrdiff_t first, const double(&w)[support]) {
          for (int a = 0; a < D; ++a) {
            const double* __restrict__ row = u.comp[a].data() + first;
#pragma omp simd
            for (int i = 0; i < support; ++i) lane[a][i] += w[i] * row[i];
          }
        });
        for (int a = 0; a < D; ++a)
          for (int i = 0; i < support; ++i) acc[a] += lane[a][i];
      } else {
        for_each_stencil_node(m, [&](const Index<D>&, std::ptrdiff_t id, double w) {
          for (int a = 0; a < D; ++a) acc[a] += w * u.comp[a][id];
        });
      }
      out[m] = acc;
    }
  }
  /// Interpolation of a scalar field: out[m] = sum_x s(x) phi(x - X_m), with
  /// s = value_at(const Index<D>& node, std::ptrdiff_t linear_index) -> double.
  template <class ValueAt>
  void interpolate_scalar(ValueAt&& value_at, std::span<double> out) const {
    gather<double>(value_at, out);
  }

  /// f(x) += sum_m force_density[m] weight_lu[m] phi(x - X_m) (eq. 2.16 / 5.8), with the
  /// force per unit marker measure and the marker measure in lattice units. In parallel over
  /// slabs, in an order that does not depend on the thread count (see the file header).
  /// (Not const: it sorts the markers into slabs first, which only spreading needs; direct
  /// forcing of rigid bodies updates stencils every step but spreads through its own copy.)
  void spread(std::span<const Vec<D>> force_density, std::span<const double> weight_lu,
              field::VectorField<D>& f) {
    CAPLAB_CHECK(force_density.size() == marker_count() && weight_lu.size() == marker_count(),
                 "IB spread: need one force density and one weight per marker (as in the last update)");
    CAPLAB_CHECK(static_cast<std::ptrdiff_t>(f.comp[0].size()) == grid_.size(),
                 "IB spread: the force field is not sized for the grid of the last update");
    sort_into_slabs();
    auto spread_slab = [&](int slab) {
      for (std::size_t k = slab_start_[slab]; k < slab_start_[slab + 1]; ++k) {
        const std::size_t m = order_[k];
        const Vec<D> fm = force_density[m] * weight_lu[m];
        if (stencil_[m].rows) {  // rows of consecutive nodes: vector code, same sums as below
          for_each_stencil_row(m, [&](std::ptrdiff_t first, const double(&w)[support]) {
            for (int a = 0; a < D; ++a) {
              double* __restrict__ row = f.comp[a].data() + first;
#pragma omp simd
              for (int i = 0; i < support; ++i) row[i] += w[i] * fm[a];
            }
          });
        } else {
          for_each_stencil_node(m, [&](const Index<D>&, std::ptrdiff_t id, double w) {
            for (int a = 0; a < D; ++a) f.comp[a][id] += w * fm[a];
          });
        }
      }
    };
    const int slabs = slab_count();
    if (periodic_[D - 1]) {
      for (int slab = 0; slab < slabs; ++slab) spread_slab(slab);
      return;
    }
    const bool parallel = static_cast<std::ptrdiff_t>(marker_count()) > detail::parallel_threshold;
    for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
      for (int slab = parity; slab < slabs; slab += 2) spread_slab(slab);
    }
  }

 private:
  // The stencil of one marker, per axis: node indices (wrapped into the interior), kernel
  // weights, and the nodes' parts (i + 1) * stride of the linear index.
  struct Stencil {
    int i[D][support];
    double w[D][support];
    std::ptrdiff_t off[D][support];
    bool rows;  // not wrapped along axis 0: its rows are support consecutive linear indices
  };

  // For a stencil that does not wrap along axis 0 (Stencil::rows): calls
  // f(std::ptrdiff_t first, const double(&w)[support]) for each of its rows along axis 0, the
  // nodes first .. first + support - 1 with the weights of for_each_stencil_node (the same
  // products in the same order), rows in the order of for_each_stencil_node.
  template <class F>
  void for_each_stencil_row(std::size_t m, F&& f) const {
    const Stencil& s = stencil_[m];
    double w[support];
    if constexpr (D == 2) {
      for (int j = 0; j < support; ++j) {
        for (int i = 0; i < support; ++i) w[i] = s.w[0][i] * s.w[1][j];
        f(s.off[0][0] + s.off[1][j], w);
      }
    } else {
      for (int k = 0; k < support; ++k)
        for (int j = 0; j < support; ++j) {
          for (int i = 0; i < support; ++i) w[i] = s.w[0][i] * s.w[1][j] * s.w[2][k];
          f(s.off[0][0] + s.off[1][j] + s.off[2][k], w);
        }
    }
  }

  template <class T, class ValueAt>
  void gather(ValueAt& value_at, std::span<T> out) const {
    CAPLAB_CHECK(out.size() == marker_count(),
                 "IB interpolation: the output needs one entry per marker (as in the last update)");
    const std::ptrdiff_t m_count = static_cast<std::ptrdiff_t>(marker_count());
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold)
    for (std::ptrdiff_t m = 0; m < m_count; ++m) {
      T acc;
      if constexpr (std::is_arithmetic_v<T>)
        acc = T(0);
      else
        acc = T::Zero();
      for_each_stencil_node(
          m, [&](const Index<D>& ijk, std::ptrdiff_t id, double w) { acc += w * value_at(ijk, id); });
      out[m] = acc;
    }
  }

  // First stencil node along axis a for the lattice coordinate x: the support nodes
  // i0 .. i0 + support - 1 are those with |x - i| < support / 2 (plus one node at exactly
  // support / 2, of weight zero, when x - support / 2 is an integer).
  static double first_node(double x) { return std::floor(x - 0.5 * support) + 1.0; }

  // A lattice coordinate beyond this is a diverged marker (finite, but no block is this large,
  // and wrapping it into a periodic axis would lose all its digits).
  static constexpr double max_lattice_coordinate = 1 << 30;

  // Fills the stencil of marker m; false if it leaves the interior along a non-periodic axis or
  // its position has diverged.
  bool fill_stencil(std::ptrdiff_t m) {
    Stencil& st = stencil_[m];
    for (int a = 0; a < D; ++a) {
      const int n = grid_.n()[a];
      double x = x_lu_[m][a];
      if (!(std::abs(x) < max_lattice_coordinate)) return false;  // also NaN
      if (periodic_[a]) x -= n * std::floor(x / n);  // into [0, n] (n for a tiny negative x): same weights
      const double lo = first_node(x);
      if (!periodic_[a] && (lo < 0.0 || lo + support - 1 > n - 1)) return false;
      const int i0 = static_cast<int>(lo);
      Kernel::weights(x - i0, st.w[a]);
      for (int s = 0; s < support; ++s) {
        const int i = i0 + s;
        // x in [0, n] gives i in [-support / 2, n + support / 2]: one wrap suffices when
        // n >= support.
        if (!periodic_[a])
          st.i[a][s] = i;
        else if (n >= support)
          st.i[a][s] = i < 0 ? i + n : i >= n ? i - n : i;
        else
          st.i[a][s] = ((i % n) + n) % n;
        st.off[a][s] = (st.i[a][s] + 1) * grid_.stride(a);
      }
    }
    st.rows = st.i[0][support - 1] == st.i[0][0] + support - 1;
    return true;
  }

  // Slabs of `support` nodes along the last axis; a stencil starting in slab k reaches slab k + 1
  // at most (support - 1 nodes further), never k + 2.
  int slab_count() const { return grid_.n()[D - 1] / support + 1; }

  // order_ = the markers sorted stably by the slab of their first stencil node along the last
  // axis (a counting sort); slab k holds order_[slab_start_[k] .. slab_start_[k + 1]).
  void sort_into_slabs() {
    const int slabs = slab_count();
    const std::size_t m_count = marker_count();
    auto slab_of = [&](std::size_t m) { return stencil_[m].i[D - 1][0] / support; };
    slab_start_.assign(slabs + 1, 0);
    order_.resize(m_count);
    for (std::size_t m = 0; m < m_count; ++m) ++slab_start_[slab_of(m) + 1];
    for (int k = 0; k < slabs; ++k) slab_start_[k + 1] += slab_start_[k];
    for (std::size_t m = 0; m < m_count; ++m) order_[slab_start_[slab_of(m)]++] = m;
    for (int k = slabs; k > 0; --k) slab_start_[k] = slab_start_[k - 1];  // undo the fill's advance
    slab_start_[0] = 0;
  }

  std::string stencil_error(std::ptrdiff_t m, const Vec<D>& x_phys) const {
    std::ostringstream msg;
    msg.precision(10);
    auto vec = [&](const Vec<D>& v) {
      std::ostringstream s;
      s.precision(10);
      s << "(";
      for (int a = 0; a < D; ++a) s << (a ? ", " : "") << v[a];
      s << ")";
      return s.str();
    };
    msg << "IB marker " << m << " at physical position " << vec(x_phys) << " (lattice " << vec(x_lu_[m])
        << ") of the block with " << grid_.n()[0];
    for (int a = 1; a < D; ++a) msg << " x " << grid_.n()[a];
    msg << " interior nodes, origin " << vec(grid_.origin()) << ", dx " << grid_.dx() << ": ";
    for (int a = 0; a < D; ++a) {
      const double x = x_lu_[m][a];
      if (!(std::abs(x) < max_lattice_coordinate)) {
        msg << "the position is not finite or beyond " << max_lattice_coordinate
            << " lattice units along axis " << a
            << " (the markers have diverged: reduce the time step or check the membrane forces)";
        return msg.str();
      }
      const double lo = first_node(x), hi = lo + support - 1;
      if (!periodic_[a] && (lo < 0.0 || hi > grid_.n()[a] - 1)) {
        msg << "its " << Kernel::name << " stencil needs nodes " << lo << " .. " << hi << " along axis " << a
            << ", outside the interior 0 .. " << grid_.n()[a] - 1
            << " of this non-periodic axis. Keep markers at least " << 0.5 * support
            << " nodes inside a non-periodic block edge (enlarge the block or move the body).";
        return msg.str();
      }
    }
    msg << "unknown stencil failure";
    return msg.str();
  }

  field::Grid<D> grid_;
  std::array<bool, D> periodic_{};
  std::vector<Vec<D>> x_lu_;
  std::vector<Stencil> stencil_;
  std::vector<std::size_t> slab_start_, order_;  // markers by slab (sort_into_slabs)
};

/// One-shot interpolation of velocity_at(const Index<D>&, std::ptrdiff_t) -> Vec<D> at the
/// markers (physical positions); allocates a Transfer, prefer the class in time loops.
template <class Kernel, int D, class VelocityAt>
void interpolate(const field::Grid<D>& grid, const std::type_identity_t<std::array<bool, D>>& periodic,
                 std::type_identity_t<std::span<const Vec<D>>> positions, VelocityAt&& velocity_at,
                 std::type_identity_t<std::span<Vec<D>>> out) {
  Transfer<D, Kernel> t;
  t.update(grid, periodic, positions);
  t.interpolate(velocity_at, out);
}

/// One-shot spreading f(x) += sum_m F_m w_m phi(x - X_m); allocates a Transfer, prefer the
/// class in time loops.
template <class Kernel, int D>
void spread(const field::Grid<D>& grid, const std::type_identity_t<std::array<bool, D>>& periodic,
            std::type_identity_t<std::span<const Vec<D>>> positions,
            std::type_identity_t<std::span<const Vec<D>>> marker_force_density,
            std::type_identity_t<std::span<const double>> marker_weight_lu, field::VectorField<D>& f) {
  Transfer<D, Kernel> t;
  t.update(grid, periodic, positions);
  t.spread(marker_force_density, marker_weight_lu, f);
}

}  // namespace caplab::ibm
