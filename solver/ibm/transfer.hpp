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
//   * Threads: update() and interpolation run in parallel over markers
//     (OpenMP, for large marker counts); the callables passed to interpolate must be safe to call
//     concurrently and must not throw. Spreading runs in parallel over ranges of planes (the
//     node index along the last axis): update() sorts the markers (stably) by the plane in
//     which their stencil starts; each thread owns a contiguous range of planes, chosen so
//     that the ranges hold about equally many stencil rows, and adds, marker by marker in the
//     sorted order, the rows of each stencil that lie in its planes. A node in plane p thus sums
//     its contributions by starting plane (p − support + 1 … p), markers in index order within
//     one, whatever the thread count: bit-reproducible without locks, and balanced however the
//     markers are distributed (solver/bench/NOTES.md: even and odd slabs of `support` planes in
//     two passes balanced worse). Marking
//     the stencil nodes (mark_stencil_nodes) splits the planes the same way, so that two threads
//     never write one word of the union's mask. Along a periodic last axis a stencil may wrap
//     onto the first planes, and both are serial.
#pragma once

#include <omp.h>

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
    corner_.resize(m_count);
    std::ptrdiff_t first_bad = m_count;
    int lo = grid_.n()[D - 1], hi = -1;  // the planes the stencils reach
    // Blocks of `lanes` markers: their nodes one by one, then their weights as vector code,
    // a lane per marker (the cosine kernel's polynomials were most of update()'s time).
    constexpr int lanes = 8;
    const std::ptrdiff_t blocks = (m_count + lanes - 1) / lanes;
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold) \
    reduction(min : first_bad, lo) reduction(max : hi)
    for (std::ptrdiff_t b = 0; b < blocks; ++b) {
      const std::ptrdiff_t m0 = b * lanes;
      const int count = static_cast<int>(std::min<std::ptrdiff_t>(lanes, m_count - m0));
      // The weights' arguments; lanes past the count, and failed markers, are computed and dropped.
      double d[D][lanes];
      for (auto& da : d)
        for (double& v : da) v = 1.5;
      for (int l = 0; l < count; ++l) {
        const std::ptrdiff_t m = m0 + l;
        x_lu_[m] = grid_.to_lattice(positions[m]);
        double dm[D];
        if (place_stencil(m, dm)) {
          for (int a = 0; a < D; ++a) d[a][l] = dm[a];
        } else if (m < first_bad) {
          first_bad = m;
        }
        const Stencil& s = stencil_[m];
        for (int k = 0; k < support; ++k) lo = std::min(lo, s.i[D - 1][k]), hi = std::max(hi, s.i[D - 1][k]);
      }
      for (int a = 0; a < D; ++a) {
        double w[support][lanes];
#pragma omp simd
        for (int l = 0; l < lanes; ++l) {
          double wl[support];
          Kernel::weights(d[a][l], wl);
          for (int k = 0; k < support; ++k) w[k][l] = wl[k];
        }
        for (int l = 0; l < count; ++l)
          for (int k = 0; k < support; ++k) stencil_[m0 + l].w[a][k] = w[k][l];
      }
    }
    if (first_bad < m_count)
      core::check_failed("stencil inside block", __FILE__, __LINE__,
                         stencil_error(first_bad, positions[first_bad]));
    plane_lo_ = lo;
    plane_hi_ = hi;
    sort_by_plane();
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

  /// Marks every stencil node of every marker in `nodes` (in parallel over ranges of planes, as
  /// spread(): two threads never mark one plane, so they never write one row of the mask): a
  /// row along axis 0 at once where it is `support` consecutive nodes, else node by node.
  void mark_stencil_nodes(StencilUnion& nodes) const {
    if (marker_count() == 0) return;
    // mark_row(row) for the mask rows of a stencil in `plane`: the plane itself in 2D, its
    // support rows i1(0) ... i1(support - 1) in 3D.
    auto rows_in_plane = [&](int plane, const auto& i1, const auto& mark_row) {
      if constexpr (D == 2)
        mark_row(plane);
      else
        for (int j = 0; j < support; ++j) mark_row(nodes.row_of(i1(j), plane));
    };
    for_each_marker_by_planes([&](std::size_t m, int lo, int hi) {
      const Corner& c = corner_[m];
      if (c.cube) {  // from the 16 bytes of its corner, not the 248 of its stencil
        for (int plane = std::max(lo, c.i[D - 1]); plane < std::min(hi, c.i[D - 1] + support); ++plane)
          rows_in_plane(
              plane, [&](int j) { return c.i[1] + j; },
              [&](std::ptrdiff_t row) { nodes.mark_run(row, c.i[0], support); });
        return;
      }
      const Stencil& s = stencil_[m];
      auto mark_row = [&](std::ptrdiff_t row) {
        if (s.rows)
          nodes.mark_run(row, s.i[0][0], support);
        else
          for (int i = 0; i < support; ++i) nodes.mark_node(row, s.i[0][i]);
      };
      for (int k = 0; k < support; ++k) {
        const int plane = s.i[D - 1][k];
        if (plane >= lo && plane < hi) rows_in_plane(plane, [&](int j) { return s.i[1][j]; }, mark_row);
      }
    });
    nodes.widen(plane_lo_ * nodes.rows_per_plane(), (plane_hi_ + 1) * nodes.rows_per_plane() - 1);
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
  /// ranges of planes, in an order that does not depend on the thread count (see the file
  /// header).
  void spread(std::span<const Vec<D>> force_density, std::span<const double> weight_lu,
              field::VectorField<D>& f) const {
    CAPLAB_CHECK(force_density.size() == marker_count() && weight_lu.size() == marker_count(),
                 "IB spread: need one force density and one weight per marker (as in the last update)");
    CAPLAB_CHECK(static_cast<std::ptrdiff_t>(f.comp[0].size()) == grid_.size(),
                 "IB spread: the force field is not sized for the grid of the last update");
    for_each_marker_by_planes([&](std::size_t m, int lo, int hi) {
      const Vec<D> fm = force_density[m] * weight_lu[m];
      const Stencil& s = stencil_[m];
      for_each_row_in_planes(m, lo, hi, [&](std::ptrdiff_t rest, const double(&w)[support]) {
        for (int a = 0; a < D; ++a) {
          if (s.rows) {  // rows of consecutive nodes: vector code, the same sums
            double* __restrict__ row = f.comp[a].data() + s.off[0][0] + rest;
#pragma omp simd
            for (int i = 0; i < support; ++i) row[i] += w[i] * fm[a];
          } else {
            for (int i = 0; i < support; ++i) f.comp[a][s.off[0][i] + rest] += w[i] * fm[a];
          }
        }
      });
    });
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
    const std::ptrdiff_t first = stencil_[m].off[0][0];
    for_each_row_in_planes(m, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(),
                           [&](std::ptrdiff_t rest, const double(&w)[support]) { f(first + rest, w); });
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

  // Fills the nodes of marker m's stencil and its corner, and sets d[a] to the weights' argument
  // along each axis (the marker's distance from the stencil's first node; update() computes the
  // weights); false if the stencil leaves the interior along a non-periodic axis or the position
  // has diverged.
  bool place_stencil(std::ptrdiff_t m, double (&d)[D]) {
    Stencil& st = stencil_[m];
    for (int a = 0; a < D; ++a) {
      const int n = grid_.n()[a];
      double x = x_lu_[m][a];
      if (!(std::abs(x) < max_lattice_coordinate)) return false;  // also NaN
      if (periodic_[a]) x -= n * std::floor(x / n);  // into [0, n] (n for a tiny negative x): same weights
      const double lo = first_node(x);
      if (!periodic_[a] && (lo < 0.0 || lo + support - 1 > n - 1)) return false;
      const int i0 = static_cast<int>(lo);
      d[a] = x - i0;
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
    auto unwrapped = [&](int a) { return st.i[a][support - 1] == st.i[a][0] + support - 1; };
    st.rows = unwrapped(0);
    Corner& c = corner_[m];
    c.cube = true;
    for (int a = 0; a < D; ++a) {
      c.i[a] = st.i[a][0];
      c.cube = c.cube && unwrapped(a);
    }
    return true;
  }

  // Calls f(rest, w) for the rows along axis 0 of marker m's stencil whose plane (index along
  // the last axis) lies in [lo, hi): the nodes s.off[0][i] + rest with the weights w[i],
  // i < support (the products of for_each_stencil_node, in its order).
  template <class F>
  void for_each_row_in_planes(std::size_t m, int lo, int hi, F&& f) const {
    const Stencil& s = stencil_[m];
    double w[support];
    for (int k = 0; k < support; ++k) {
      const int plane = s.i[D - 1][k];
      if (plane < lo || plane >= hi) continue;
      if constexpr (D == 2) {
        for (int i = 0; i < support; ++i) w[i] = s.w[0][i] * s.w[1][k];
        f(s.off[1][k], w);
      } else {
        for (int j = 0; j < support; ++j) {
          for (int i = 0; i < support; ++i) w[i] = s.w[0][i] * s.w[1][j] * s.w[2][k];
          f(s.off[1][j] + s.off[2][k], w);
        }
      }
    }
  }

  // Calls body(m, lo, hi) for the markers whose stencils reach planes [lo, hi), in the order of
  // sort_by_plane, each thread for its own range of planes: contiguous ranges holding about
  // equally many stencil planes. A node in plane p is thus reached by markers in the same
  // order whatever the thread count (see the file header). One range, serial, along a
  // periodic last axis (stencils wrap) or for few markers.
  template <class Body>
  void for_each_marker_by_planes(Body&& body) const {
    const int n = grid_.n()[D - 1];
    auto run = [&](int first, int lo, int hi) {  // the markers starting in [first, hi)
      for (std::size_t k = plane_start_[first]; k < plane_start_[hi]; ++k) body(order_[k], lo, hi);
    };
    if (periodic_[D - 1] || static_cast<std::ptrdiff_t>(marker_count()) <= detail::parallel_threshold) {
      run(0, 0, n);
      return;
    }
#pragma omp parallel
    {
      const int threads = omp_get_num_threads(), t = omp_get_thread_num();
      auto split = [&](int k) {  // the first plane of thread k's range
        if (k == 0 || k == threads) return k == 0 ? 0 : n;
        const std::size_t share = (plane_load_[n] * k + threads - 1) / threads;
        return static_cast<int>(std::lower_bound(plane_load_.begin(), plane_load_.end(), share) -
                                plane_load_.begin());
      };
      const int lo = split(t), hi = split(t + 1);
      if (lo < hi) run(std::max(0, lo - support + 1), lo, hi);
    }
  }

  // order_ = the markers sorted stably by the plane of their first stencil node along the last
  // axis (a counting sort); plane p holds order_[plane_start_[p] .. plane_start_[p + 1]).
  // Serial: it reads the planes from corner_ (16 bytes a marker) rather than the stencils
  // (a cache line and more each): the other thread waits meanwhile (solver/bench/NOTES.md).
  void sort_by_plane() {
    const int n = grid_.n()[D - 1];
    const std::size_t m_count = marker_count();
    auto plane_of = [&](std::size_t m) { return corner_[m].i[D - 1]; };
    plane_start_.assign(n + 1, 0);
    order_.resize(m_count);
    for (std::size_t m = 0; m < m_count; ++m) ++plane_start_[plane_of(m) + 1];
    for (int p = 0; p < n; ++p) plane_start_[p + 1] += plane_start_[p];
    for (std::size_t m = 0; m < m_count; ++m) order_[plane_start_[plane_of(m)]++] = m;
    for (int p = n; p > 0; --p) plane_start_[p] = plane_start_[p - 1];  // undo the fill's advance
    plane_start_[0] = 0;
    // plane_load_[p]: stencil planes (of `support` rows each) in the planes before p.
    plane_load_.assign(n + 1, 0);
    for (int p = 0; p < n; ++p)
      plane_load_[p + 1] =
          plane_load_[p] + (plane_start_[p + 1] - plane_start_[std::max(0, p - support + 1)]);
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
  // The markers by the plane their stencil starts in, and what the threads split (sort_by_plane).
  std::vector<std::size_t> plane_start_, order_, plane_load_;
  // Per marker: its stencil's first node, and whether the stencil is the cube of support^D
  // nodes from it (wraps around no periodic axis). Marking the union reads these alone.
  struct Corner {
    int i[D];
    bool cube;
  };
  std::vector<Corner> corner_;
  int plane_lo_ = 0, plane_hi_ = -1;  // the planes the stencils reach
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
