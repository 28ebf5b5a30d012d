// Two-level multi-block coupling, refinement ratio m = 2 (thesis 2.1.2; Yu, Mei & Shyy 2002;
// Yu & Girimaji 2006), written once for D2Q9 and D3Q19.
//
// Layout. The coarse grid covers the whole domain. The fine block's ghost ring is the line
// (surface) MN of thesis fig. 2.2 and lies on coarse nodes; coarse nodes strictly inside MN
// are "covered": the fine solution stands for them, so the innermost uncovered ring (AB) of
// the thesis is fed by the fine solution. Only the outermost covered layer (the band) streams
// into uncovered nodes, so only its step is taken, by the coupling (collide_band): each band
// node's populations restricted from its coincident fine node, collided with the coarse
// operator, pushed along the links that leave the covered region. The coarse sweep leaves the
// whole covered region alone (idle_coarse; outputs read the fine nodes through it,
// fine_node_under).
//
// Transfers (pre-collision populations, so τ = 1 is not singular, unlike eq. 2.11/2.12):
//   fine from coarse:  f_f = f_eq + τ_f/(m τ_c) · (f_c − f_eq)
//   coarse from fine:  f_c = f_eq + m τ_c/τ_f · (f_f − f_eq)
// which keep ρ, u and the viscous stress continuous (f_neq ∝ τ Δt ∇u, τ_f = ½ + m(τ_c − ½)).
// The even and odd parts of f_neq are rescaled with their own relaxation times (τ+ and τ−
// of TRT; equal for BGK): the odd part ∝ τ− Δt, and rescaling it with τ+ breaks the
// exactness of linear shear across the interface (measured 1e-4 instead of 1e-7). With an
// operator whose bulk mode relaxes on its own (collision::TrtBulk) the bulk part of the even
// part, β_i Π (collision::bulk_shape), is rescaled with τ_b: f_neq's trace Π ∝ τ_b Δt ∇·u.
// Fine ghost values off coarse nodes use the symmetric 4-point (cubic) midpoint stencil
// (−1, 9, 9, −1)/16 along each axis where the node lies half way, in time the 3-point
// Lagrange formula (eq. 2.14) through t_{n−1}, t_n, t_{n+1}. The ghost node is then collided
// with the fine operator and pushes into the fine interior, like any ghost of a block.
//
// Evaluation. The ghost ring is cut into disjoint faces (a face: the ghosts at fine index −1 or
// n along its normal axis; the in-face axes before the normal over the interior range, those
// after it over the ring too, so edges and corners belong to exactly one face). The stencils
// are tensor products, so a face is interpolated axis by axis on whole rows of one population
// (structure of arrays, vector loops): the coarse plane under the face in time, then along the
// first in-face axis u onto the fine spacing, then along the second, v (3D), row by row just
// before the row's ghosts are collided. The history keeps the coarse planes, not whole nodes,
// and of each plane node only what its face's ghosts use (channels): the density and momentum
// (D + 1 values) and the populations that enter through the face and their opposites (2E);
// 14 of 19 values in D3Q19 (9 of 9 in D2Q9), 4 + 5 of them with BGK, whose rescaling and
// collision need no opposite; with a bulk mode of its own also the trace of the second moment
// (the ghost's Π, which the kept populations alone do not give). The moments and the
// interpolation are linear, so interpolated moments are the moments of the interpolated
// populations (to round-off): the ghosts' ρ and u come from them.
//
// One coarse step: collide_band(), the coarse collide-push (in place, parity flip) +
// boundaries, capture_coarse(); two fine substeps, each: collide-push, fill_fine_ghosts(s) with
// s = 0 then ½. Populations are addressed at each block's current parity
// (field/populations.hpp). Exactness: uniform and linear shear flows cross the interface
// unchanged to round-off (tests/verification).
#pragma once

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "collision/equilibrium.hpp"
#include "collision/stream_collide.hpp"
#include "core/error.hpp"
#include "field/populations.hpp"
#include "lattice/lattice.hpp"

namespace caplab::refinement {

template <class L, class T>
class TwoLevel {
 public:
  static constexpr int D = L::d;
  static constexpr int Q = L::q;
  static constexpr int m = 2;
  /// Populations entering through one face (the links of its ghosts), and the channels a face
  /// keeps of each coarse plane node: δρ, j, the entering populations, their opposites.
  static constexpr int E = [] {
    int n = 0;
    for (int i = 0; i < Q; ++i) n += lattice::enters_through_face<L>(0, i) ? 1 : 0;
    return n;
  }();
  /// Channels: δρ, j, the E entering populations, their opposites, the trace of the second
  /// moment (the last, kept only with a bulk mode of its own).
  static constexpr int C = D + 2 + 2 * E;
  static constexpr int trace_channel = C - 1;
  /// The channels the fill of operator Op reads (captured and interpolated): BGK rescales and
  /// collides each population alone, so not the opposites; only an operator with a bulk mode
  /// of its own reads the trace.
  template <class Op>
  static constexpr int kept_channels = std::is_same_v<Op, collision::Bgk> ? D + 1 + E
                                       : collision::has_bulk_mode<Op>     ? C
                                                                          : C - 1;

  TwoLevel() = default;
  /// Relaxation times of the even (τ+), odd (τ−) and bulk (τ_b) non-equilibrium parts of one
  /// block.
  struct Taus {
    double plus, minus, bulk;
  };
  /// `tau_c`, `tau_f`: relaxation times of the two blocks (τ_f+ = ½ + m(τ_c+ − ½)); `trace`:
  /// whether the operator relaxes its bulk mode on its own (the history then keeps the trace).
  TwoLevel(const field::Grid<D>& coarse, const field::Grid<D>& fine, Taus tau_c, Taus tau_f, bool trace)
      : coarse_(coarse),
        fine_(fine),
        c_from_f_{m * tau_c.plus / tau_f.plus, m * tau_c.minus / tau_f.minus, m * tau_c.bulk / tau_f.bulk},
        f_from_c_{tau_f.plus / (m * tau_c.plus), tau_f.minus / (m * tau_c.minus), tau_f.bulk / (m * tau_c.bulk)},
        trace_(trace) {
    CAPLAB_CHECK(std::abs(coarse.dx() - m * fine.dx()) < 1e-12 * coarse.dx(),
                 "two-level coupling needs coarse spacing = 2 × fine spacing");
    build_restriction();
    build_faces();
    history_.assign(3 * stored_channels() * sources_.size(), T(0));
  }

  /// Records what the fine ghosts of the fill with operator Op need of the coarse block at the
  /// new coarse time level. Call after the coarse step (and swap); the first call also fills
  /// the older levels.
  template <class Op>
  void capture_coarse(const field::Populations<L, T>& coarse) {
    check_operator<Op>();
    newest_ = (newest_ + 1) % 3;
    store_level<kept_channels<Op>>(coarse, newest_);
    if (!primed_) {
      store_level<kept_channels<Op>>(coarse, (newest_ + 1) % 3);
      store_level<kept_channels<Op>>(coarse, (newest_ + 2) % 3);
      primed_ = true;
    }
  }

  /// Fills the fine interior slots entering from the ghost ring (after the fine sweep and its
  /// parity flip), with the coarse state at fractional time s ∈ [0, 1) after the previous
  /// coarse level t_n.
  template <class Op>
  void fill_fine_ghosts(field::Populations<L, T>& fine, const Op& op_fine, double s) {
    check_operator<Op>();
    // 3-point Lagrange through t_{n-1} = −1, t_n = 0, t_{n+1} = 1 (eq. 2.14).
    const T lag[3] = {T(0.5 * s * (s - 1.0)), T((1.0 - s) * (1.0 + s)), T(0.5 * s * (s + 1.0))};
    const std::size_t S = sources_.size();
    const std::size_t level = stored_channels() * S;
    const T* h[3] = {&history_[(newest_ + 1) % 3 * level], &history_[(newest_ + 2) % 3 * level],
                     &history_[newest_ * level]};  // t_{n-1}, t_n, t_{n+1}
    constexpr int channels = kept_channels<Op>;
    const std::array<T*, Q> P = fine.bases();
    // Scratch per thread, sized once (and again only if more threads run than before).
    const std::size_t threads = static_cast<std::size_t>(omp_get_max_threads());
    if (scratch_.size() < threads) scratch_.resize(threads, std::vector<T>(max_coarse_u_ + scratch_size_));
    const std::ptrdiff_t tasks = static_cast<std::ptrdiff_t>(chunks_.size());
#pragma omp parallel for schedule(dynamic)
    for (std::ptrdiff_t task = 0; task < tasks; ++task) {
      const Chunk& ch = chunks_[task];
      const Face& fc = faces_[ch.face];
      const int cu_n = fc.axis[0].coarse, row = fc.row;
      T* in_time = scratch_[omp_get_thread_num()].data();  // one coarse row (s > 0)
      T* along_u = in_time + max_coarse_u_;                // [channel][coarse v − cv0][row]
      // The chunk's coarse rows: in time (at s = 0 the formula gives the level t_n), along u.
      for (int k = 0; k < channels; ++k)
        for (int cv = ch.cv0; cv < ch.cv1; ++cv) {
          const std::size_t at = k * S + fc.first_source + static_cast<std::size_t>(cv) * cu_n;
          const T* coarse_row = h[1] + at;
          if (s != 0.0) {
#pragma omp simd
            for (int cu = 0; cu < cu_n; ++cu) in_time[cu] = lag[0] * h[0][at + cu] + lag[1] * h[1][at + cu] + lag[2] * h[2][at + cu];
            coarse_row = in_time;
          }
          fc.axis[0].interpolate(coarse_row, along_u + (k * (ch.cv1 - ch.cv0) + cv - ch.cv0) * row);
        }
      // Its ghost rows along v, a batch at a time, then their collision and push.
      for (int fv = ch.fv0; fv < ch.fv1; ++fv) {
        const auto [first, count] = fc.axis[1].stencil(fv);
        const T* u_rows = along_u + (first - ch.cv0) * row;
        const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(ch.cv1 - ch.cv0) * row;  // between channels
        for (int b0 = 0; b0 < row; b0 += batch) {
          T coarse_c[C][batch];
          for (int k = 0; k < channels; ++k) {
            const T* r0 = u_rows + k * stride + b0;
            if (count == 1) {
#pragma omp simd
              for (int b = 0; b < batch; ++b) coarse_c[k][b] = r0[b];
            } else {
#pragma omp simd
              for (int b = 0; b < batch; ++b)
                coarse_c[k][b] = midpoint(r0[b], r0[row + b], r0[2 * row + b], r0[3 * row + b]);
            }
          }
          collide_ghosts_of(ch.face, coarse_c, P, op_fine, fc.first_ghost + static_cast<std::ptrdiff_t>(fv) * row + b0,
                            std::make_integer_sequence<int, 2 * D>());
        }
      }
    }
  }

  /// The band's part of the coarse step (call before the coarse sweep, at the time level of
  /// both blocks): each band node's populations restricted from its coincident fine node and
  /// collided with the coarse operator, as the coarse sweep would (Guo forcing with the uniform
  /// body force F when Forced), and written where the sweep writes them, along the links that
  /// leave the covered region only: the others reach covered nodes, which nothing reads.
  /// Restricting the band after the fine substeps and colliding it in the sweep wrote all Q
  /// populations of every band node twice, scattered (the faces normal to x a cache line each).
  template <bool Forced, class Op>
  void collide_band(field::Populations<L, T>& coarse, const field::Populations<L, T>& fine, const Op& op,
                    const T (&F)[D]) const {
    check_operator<Op>();
    const std::array<T*, Q> dst = coarse.bases();
    auto collide = [=](const T(&f)[Q], T(&out)[Q]) __attribute__((always_inline)) {  // F, op copied
      collision::collide_node<Forced, L, T>(f, F, op, out);  // as the sweep would
    };
    auto store = [&](std::ptrdiff_t k0, const T(&post)[Q][batch]) {
      for (int b = 0; b < batch; ++b) {
        const std::ptrdiff_t n = band_.coarse[k0 + b];
        const std::uint32_t leaving = band_.leaving[k0 + b];
        for (int i = 0; i < Q; ++i)
          if (leaving >> i & 1U) dst[L::opposite[i]][n] = post[i][b];
      }
    };
    for_each_restricted_batch<collision::has_bulk_mode<Op>>(fine, band_, collide, store);
  }

  /// Sets every covered coarse node from the fine block. Nothing needs it (the coarse sweep
  /// skips them and nothing reads them): the tests use it as the reference that shows so.
  void restrict_everywhere(field::Populations<L, T>& coarse, const field::Populations<L, T>& fine) const {
    restrict_nodes(coarse, fine, covered_pairs(false));
  }

  /// The fine node that coincides with the covered coarse node c.
  std::ptrdiff_t fine_node_under(const Index<D>& c) const {
    Index<D> f;
    for (int a = 0; a < D; ++a) f[a] = 2 * (c[a] - cov_lo_[a]) - 1;
    return fine_.index(f);
  }

  /// The coarse history the ghosts interpolate in time (io/checkpoint.hpp archive).
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    ar(prefix + "history", std::span<T>(history_));
    ar(prefix + "newest", newest_);
    ar(prefix + "primed", primed_);
  }

  /// The covered coarse nodes, which the coarse sweep leaves alone: the band's step is
  /// collide_band's, and nothing reads the nodes inside it.
  field::Box<D> idle_coarse() const {
    field::Box<D> idle;
    for (int a = 0; a < D; ++a) idle.lo[a] = cov_lo_[a] + 1, idle.hi[a] = cov_hi_[a];
    return idle;
  }

  /// Whether a coarse node lies strictly inside the fine block (it is read through the fine grid).
  bool covered(const Index<D>& c) const {
    for (int a = 0; a < D; ++a)
      if (c[a] <= cov_lo_[a] || c[a] >= cov_hi_[a]) return false;
    return true;
  }

 private:
  /// Nodes per vector loop (collide_ghosts, restrict_nodes): one 64-byte cache line of T.
  static constexpr int batch = static_cast<int>(64 / sizeof(T));

  /// collide_ghosts with the face as a compile-time constant.
  template <class Op, int... Faces>
  void collide_ghosts_of(int face, const T (&coarse_c)[C][batch], const std::array<T*, Q>& P, const Op& op,
                         std::ptrdiff_t k0, std::integer_sequence<int, Faces...>) const {
    ((face == Faces ? collide_ghosts<Faces>(coarse_c, P, op, k0) : void()), ...);
  }

  /// The populations of face `face`'s channels D + 1 … C − 1: the E entering ones (increasing
  /// i), then their opposites in the same order.
  static constexpr std::array<int, 2 * E> channel_populations(int face) {
    std::array<int, 2 * E> pops{};
    int e = 0;
    for (int i = 0; i < Q; ++i)
      if (lattice::enters_through_face<L>(face, i)) pops[e] = i, pops[E + e] = L::opposite[i], ++e;
    return pops;
  }

  /// Ghosts k0 … k0 + batch − 1 of face Face from their interpolated coarse channels: ρ and u
  /// from the moments, the kept populations rescaled to the fine block and collided with the
  /// fine operator, then pushed along their links. Only the populations that enter the interior
  /// from the face are stored (5 of 19 in D3Q19; every link of a ghost of the face is one of
  /// them); the compiler drops the rest of the equilibrium.
  template <int Face, class Op>
  void collide_ghosts(const T (&coarse_c)[C][batch], const std::array<T*, Q>& P, const Op& op,
                      std::ptrdiff_t k0) const {
    constexpr std::array<int, 2 * E> pops = channel_populations(Face);
    constexpr bool bulk = collision::has_bulk_mode<Op>;
    // 2E, or E without the opposites (BGK); the trace is not a population.
    constexpr int kept = std::min(kept_channels<Op>, C - 1) - (D + 1);
    const T half_plus = T(0.5 * f_from_c_.plus), half_minus = T(0.5 * f_from_c_.minus);
    const T bulk_minus_plus = T(f_from_c_.bulk - f_from_c_.plus), s_bulk = T(f_from_c_.bulk);
    T post[Q][batch];
#pragma omp simd
    for (int b = 0; b < batch; ++b) {
      const T rho = T(1) + coarse_c[0][b];
      T u[D];
      for (int a = 0; a < D; ++a) u[a] = coarse_c[1 + a][b] / rho;
      T feq[Q], f[Q], out[Q];
      collision::equilibrium<L, T>(rho, u, feq);
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i) f[i] = feq[i];  // the populations no channel keeps: unused
      T neq[2 * E] = {};  // without the opposites' channels their part is 0: s+ = s− for BGK
#pragma GCC unroll 10
      for (int e = 0; e < kept; ++e) neq[e] = coarse_c[D + 1 + e][b] - feq[pops[e]];
#pragma GCC unroll 10
      for (int e = 0; e < kept; ++e)
        f[pops[e]] = rescaled(feq[pops[e]], neq[e], neq[e < E ? e + E : e - E], half_plus, half_minus);
      if constexpr (bulk) {
        // The bulk part β_i Π of the even part rescaled with s_b, and the fine Π = s_b Π_c.
        const T trace = coarse_c[trace_channel][b] - collision::second_moment_trace<L, T>(feq);
#pragma GCC unroll 10
        for (int e = 0; e < kept; ++e)
          f[pops[e]] += bulk_minus_plus * T(collision::bulk_shape<L>(pops[e])) * trace;
        op.template collide_with_trace<L, T>(f, feq, s_bulk * trace, out);
      } else {
        op.template collide<L, T>(f, feq, out);
      }
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i)
        if (lattice::enters_through_face<L>(Face, i)) post[i][b] = out[i];
    }
    for (int b = 0; b < batch; ++b) {
      const auto& gh = ghosts_[k0 + b];
      for (int l = gh.first_link; l < gh.first_link + gh.link_count; ++l)
        P[links_[l].i][links_[l].dst] = post[links_[l].i][b];
    }
  }

  struct Ghost {
    int first_link, link_count;
  };
  /// The cubic midpoint value (−1, 9, 9, −1)/16 of four consecutive coarse values.
  static T midpoint(T a, T b, T c, T d) { return T(9.0 / 16) * (b + c) - T(1.0 / 16) * (a + d); }

  /// One in-face axis of a face: its fine ghost coordinates (from `fine_lo`, `fine` of them) and
  /// the coarse nodes under them (from `coarse_lo`, `coarse` of them). The fine coordinate j
  /// lies at doubled coarse coordinate k = k0 + j relative to coarse_lo: on node k/2 (k even)
  /// or half way, between the four nodes from (k − 1)/2 − 1 (k odd).
  struct FaceAxis {
    int fine_lo = 0, fine = 1, coarse_lo = 0, coarse = 1, k0 = 0;
    /// First coarse node (relative) and count (1 or 4) of fine coordinate j's stencil.
    std::pair<int, int> stencil(int j) const {
      const int k = k0 + j;
      return k % 2 == 0 ? std::pair{k / 2, 1} : std::pair{(k - 1) / 2 - 1, 4};
    }
    /// Values at the fine coordinates from a row of coarse values (the even and odd
    /// coordinates as two strided vector loops).
    void interpolate(const T* coarse_row, T* fine_row) const {
      const int on = k0 % 2 == 0 ? 0 : 1;  // first fine coordinate on a node
      const int on_first = (k0 + on) / 2, mid_first = (k0 - on) / 2 - 1;
      for (int j = on, c = on_first; j < fine; j += 2, ++c) fine_row[j] = coarse_row[c];
      for (int j = 1 - on, c = mid_first; j < fine; j += 2, ++c)
        fine_row[j] = midpoint(coarse_row[c], coarse_row[c + 1], coarse_row[c + 2], coarse_row[c + 3]);
    }
  };
  /// Fine rows fv0 … fv1 − 1 of a face, filled by one thread from its coarse rows cv0 … cv1 − 1.
  struct Chunk {
    int face, fv0, fv1, cv0, cv1;
  };
  /// Fine rows per chunk: the chunk's rows along u stay in the thread's cache; neighbouring
  /// chunks share up to three coarse rows, interpolated by both.
  static constexpr int chunk_rows = 16;
  /// A face of the ghost ring (see the file comment): normal axis, side, in-face axes u and v
  /// (in 2D v has one coordinate, on node), and where its data lie in the flat arrays.
  struct Face {
    std::array<FaceAxis, 2> axis;
    int row = 0;                     // ghosts per row along u, rounded up to whole batches
    std::size_t first_source = 0;    // its coarse plane in sources_ (v-major rows along u)
    std::ptrdiff_t first_ghost = 0;  // its ghosts in ghosts_ (fine v × row)
  };
  struct Link {
    int i;
    std::ptrdiff_t dst;
  };
  /// Coincident coarse and fine nodes, with the links of the coarse node that leave the
  /// covered region (bit i for link i), in whole batches (the last entry repeated: rewriting a
  /// node with the same value is harmless).
  struct NodePairs {
    std::vector<int> coarse, fine;
    std::vector<std::uint32_t> leaving;
    void push_back(std::ptrdiff_t c, std::ptrdiff_t f, std::uint32_t out) {
      CAPLAB_CHECK(std::max(c, f) <= std::numeric_limits<int>::max(), "block too large for 32-bit node indices");
      coarse.push_back(static_cast<int>(c));
      fine.push_back(static_cast<int>(f));
      leaving.push_back(out);
    }
    void pad() {
      while (!coarse.empty() && coarse.size() % batch != 0) push_back(coarse.back(), fine.back(), leaving.back());
    }
  };

  /// One population rescaled between the blocks: f_eq + s+ · (even part of f_neq) + s− · (odd
  /// part), from its f_neq and its opposite's, with half_± = s±/2.
  [[gnu::always_inline]] static T rescaled(T feq, T neq, T neq_opposite, T half_plus, T half_minus) {
    return feq + half_plus * (neq + neq_opposite) + half_minus * (neq - neq_opposite);
  }

  /// f ← f_eq + s+ · (even part of f_neq) + s− · (odd part of f_neq), with feq the equilibrium
  /// of f's moments (which the rescaling keeps); with Bulk the even part's bulk part β_i Π
  /// with s_b.
  template <bool Bulk>
  static void rescale_non_equilibrium(T (&f)[Q], T (&feq)[Q], const Taus& s) {
    T rho, u[D];
    collision::moments<L, T>(f, rho, u);
    collision::equilibrium<L, T>(rho, u, feq);
    // Unrolled: inside the `omp simd` loop of restrict_nodes an inner loop stops GCC from
    // vectorising over the nodes.
    T neq[Q];
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) neq[i] = f[i] - feq[i];
    const T half_plus = T(0.5 * s.plus), half_minus = T(0.5 * s.minus);
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) f[i] = rescaled(feq[i], neq[i], neq[L::opposite[i]], half_plus, half_minus);
    if constexpr (Bulk) {
      const T bulk = T(s.bulk - s.plus) * collision::second_moment_trace<L, T>(neq);
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i) f[i] += T(collision::bulk_shape<L>(i)) * bulk;
    }
  }

  /// Coarse index of a fine position, as twice the coordinate (odd = half way between nodes).
  Index<D> doubled_coarse_coordinate(const Index<D>& fine_node) const {
    const Vec<D> x = fine_.position(fine_node);
    const Vec<D> k = coarse_.to_lattice(x) * 2.0;
    Index<D> k2;
    for (int a = 0; a < D; ++a) {
      k2[a] = static_cast<int>(std::lround(k[a]));
      CAPLAB_CHECK(std::abs(k[a] - k2[a]) < 1e-6, "fine block is not aligned with the coarse grid");
    }
    return k2;
  }

  /// The faces of the ghost ring with their coarse planes (sources_), the rows to fill and the
  /// ghosts' links into the fine interior.
  void build_faces() {
    const Index<D> nf = fine_.n();
    for (int a = 0; a < D; ++a)
      for (int side = 0; side < 2; ++side) {
        Face fc;
        std::array<int, 2> ax{-1, -1};
        for (int b = 0, k = 0; b < D; ++b)
          if (b != a) ax[k++] = b;
        for (int k = 0; k < 2 && ax[k] >= 0; ++k) {
          const int b = ax[k];
          FaceAxis& fa = fc.axis[k];
          // Axes before the normal: interior range (their ring is another face's); after: ring too.
          fa.fine_lo = b < a ? 0 : -1;
          fa.fine = b < a ? nf[b] : nf[b] + 2;
          // Coarse nodes under the stencils, from the absolute doubled coordinates.
          const int k2_lo = doubled_coarse_coordinate_along(b, fa.fine_lo);
          FaceAxis absolute = fa;
          absolute.coarse_lo = 0;
          absolute.k0 = k2_lo;
          int lo = std::numeric_limits<int>::max(), hi = std::numeric_limits<int>::min();
          for (int j = 0; j < fa.fine; ++j) {
            const auto [first, count] = absolute.stencil(j);
            lo = std::min(lo, first);
            hi = std::max(hi, first + count - 1);
          }
          fa.coarse_lo = lo;
          fa.coarse = hi - lo + 1;
          fa.k0 = k2_lo - 2 * lo;
        }
        fc.row = (fc.axis[0].fine + batch - 1) / batch * batch;
        fc.first_source = sources_.size();
        fc.first_ghost = static_cast<std::ptrdiff_t>(ghosts_.size());
        const int normal_k2 = doubled_coarse_coordinate_along(a, side == 0 ? -1 : nf[a]);
        for (int cv = 0; cv < fc.axis[1].coarse; ++cv)
          for (int cu = 0; cu < fc.axis[0].coarse; ++cu) {
            Index<D> c{};
            c[a] = normal_k2 / 2;
            c[ax[0]] = fc.axis[0].coarse_lo + cu;
            if (ax[1] >= 0) c[ax[1]] = fc.axis[1].coarse_lo + cv;
            CAPLAB_CHECK(coarse_.is_interior(c), "fine block too close to the domain boundary for the coupling");
            sources_.push_back(coarse_.index(c));
          }
        for (int fv0 = 0; fv0 < fc.axis[1].fine; fv0 += chunk_rows) {
          Chunk ch{static_cast<int>(faces_.size()), fv0, std::min(fv0 + chunk_rows, fc.axis[1].fine), 0, 0};
          ch.cv0 = std::numeric_limits<int>::max();
          for (int fv = ch.fv0; fv < ch.fv1; ++fv) {
            const auto [first, count] = fc.axis[1].stencil(fv);
            ch.cv0 = std::min(ch.cv0, first);
            ch.cv1 = std::max(ch.cv1, first + count);
          }
          chunks_.push_back(ch);
          max_coarse_u_ = std::max<std::size_t>(max_coarse_u_, fc.axis[0].coarse);
          scratch_size_ = std::max<std::size_t>(scratch_size_, static_cast<std::size_t>(C) * (ch.cv1 - ch.cv0) * fc.row);
        }
        for (int fv = 0; fv < fc.axis[1].fine; ++fv) {
          for (int fu = 0; fu < fc.row; ++fu) {
            const int first_link = static_cast<int>(links_.size());
            if (fu < fc.axis[0].fine) {
              Index<D> g{};
              g[a] = side == 0 ? -1 : nf[a];
              g[ax[0]] = fc.axis[0].fine_lo + fu;
              if (ax[1] >= 0) g[ax[1]] = fc.axis[1].fine_lo + fv;
              for (int i = 0; i < Q; ++i) {
                Index<D> t;
                for (int d = 0; d < D; ++d) t[d] = g[d] + L::c[i][d];
                if (!fine_.is_interior(t)) continue;
                // collide_ghosts keeps only these populations (a ghost outside the interior
                // along a reaches it only with c_a pointing inwards).
                CAPLAB_CHECK(lattice::enters_through_face<L>(2 * a + side, i),
                             "two-level coupling: a ghost link leaves its face");
                links_.push_back({i, fine_.index(t)});
              }
            }
            // Padding (fu beyond the face) has no link.
            ghosts_.push_back({first_link, static_cast<int>(links_.size()) - first_link});
          }
        }
        faces_.push_back(fc);
      }
  }

  /// Doubled coarse coordinate along axis a of fine index j along it.
  int doubled_coarse_coordinate_along(int a, int j) const {
    Index<D> f{};
    f[a] = j;
    return doubled_coarse_coordinate(f)[a];
  }

  void build_restriction() {
    // Covered coarse nodes: strictly between the coarse indices of the ghost ring (which lies
    // half a fine spacing outside the first fine node, fine index -1).
    Index<D> lo_f, hi_f;
    for (int a = 0; a < D; ++a) lo_f[a] = -1, hi_f[a] = fine_.n()[a];
    const Index<D> lo2 = doubled_coarse_coordinate(lo_f), hi2 = doubled_coarse_coordinate(hi_f);
    for (int a = 0; a < D; ++a) {
      CAPLAB_CHECK(lo2[a] % 2 == 0 && hi2[a] % 2 == 0,
                   "the fine block's ghost ring must lie on coarse nodes (an odd number of fine nodes per axis)");
      cov_lo_[a] = lo2[a] / 2;
      cov_hi_[a] = hi2[a] / 2;
    }
    band_ = covered_pairs(true);
  }

  /// Covered coarse nodes and their fine nodes: all, or only the band (one link, max norm,
  /// from an uncovered node).
  NodePairs covered_pairs(bool band_only) const {
    NodePairs pairs;
    field::for_each_interior<D>(coarse_, [&](const Index<D>& c) {
      if (!covered(c)) return;
      bool outermost = false;
      for (int a = 0; a < D; ++a) outermost = outermost || c[a] == cov_lo_[a] + 1 || c[a] == cov_hi_[a] - 1;
      if (!outermost && band_only) return;
      std::uint32_t leaving = 0;
      for (int i = 0; i < Q; ++i) {
        Index<D> t;
        for (int a = 0; a < D; ++a) t[a] = c[a] + L::c[i][a];
        if (!covered(t)) leaving |= 1U << i;
      }
      pairs.push_back(coarse_.index(c), fine_node_under(c), leaving);
    });
    pairs.pad();
    return pairs;
  }

  /// Coarse nodes from their coincident fine nodes.
  void restrict_nodes(field::Populations<L, T>& coarse, const field::Populations<L, T>& fine,
                      const NodePairs& nodes) const {
    const std::array<T*, Q> dst = coarse.bases();
    auto keep = [](const T(&f)[Q], T(&out)[Q]) __attribute__((always_inline)) {
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i) out[i] = f[i];
    };
    auto store = [&](std::ptrdiff_t k0, const T(&out)[Q][batch]) {
      for (int b = 0; b < batch; ++b)
        for (int i = 0; i < Q; ++i) dst[i][nodes.coarse[k0 + b]] = out[i][b];
    };
    if (trace_)
      for_each_restricted_batch<true>(fine, nodes, keep, store);
    else
      for_each_restricted_batch<false>(fine, nodes, keep, store);
  }

  /// For each batch of `nodes`, in parallel: the fine populations of its fine nodes rescaled to
  /// the coarse block (the restriction), through node(f, out) per node in one vector loop
  /// (`node` marked always_inline and its loops unrolled, or GCC 12 leaves the loop scalar), then
  /// store(k0, out) with out[i][b] for the batch's coarse nodes k0 + b (scattered stores,
  /// outside the vector loop). Bulk: the operator relaxes its bulk mode on its own.
  template <bool Bulk, class Node, class Store>
  void for_each_restricted_batch(const field::Populations<L, T>& fine, const NodePairs& nodes, const Node& node,
                                 const Store& store) const {
    const std::array<const T*, Q> bases = fine.bases();
    const int* fine_node = nodes.fine.data();
    const std::ptrdiff_t batches = static_cast<std::ptrdiff_t>(nodes.coarse.size()) / batch;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t bt = 0; bt < batches; ++bt) {
      const std::ptrdiff_t k0 = bt * batch;
      const T* src[Q];  // loop invariants in locals, as in collision::sweep
      for (int i = 0; i < Q; ++i) src[i] = bases[i];
      const Node node_l = node;
      T out[Q][batch];
#pragma omp simd
      for (int b = 0; b < batch; ++b) {
        T f[Q], feq[Q], post[Q];
        // 32-bit node indices into each population's array: a vector gather (as the far field).
#pragma GCC unroll 19
        for (int i = 0; i < Q; ++i) f[i] = src[i][fine_node[k0 + b]];
        rescale_non_equilibrium<Bulk>(f, feq, c_from_f_);
        node_l(f, post);
#pragma GCC unroll 19
        for (int i = 0; i < Q; ++i) out[i][b] = post[i];
      }
      store(k0, out);
    }
  }

  /// Plane nodes ahead whose Q values store_level prefetches. Within the step the coarse planes
  /// are cold and each node of an x-normal face reads Q cache lines; the loads' misses, not the
  /// bandwidth, set its time (solver/bench/NOTES.md, "The capture prefetches its plane nodes").
  static constexpr std::size_t capture_ahead = 8;
  /// The first `Channels` channels of every face's plane nodes at the coarse block's current
  /// time level.
  template <int Channels>
  void store_level(const field::Populations<L, T>& coarse, int level) {
    const std::size_t S = sources_.size();
    const std::array<const T*, Q> P = coarse.bases();
    T* out = &history_[level * stored_channels() * S];
#pragma omp parallel
    for (int face = 0; face < 2 * D; ++face) {
      const auto pops = channel_populations(face);
      const std::size_t first = faces_[face].first_source;
      const std::size_t last = face + 1 < 2 * D ? faces_[face + 1].first_source : S;
#pragma omp for schedule(static) nowait
      for (std::size_t k = first; k < last; ++k) {
        if (k + capture_ahead < last)
          for (int i = 0; i < Q; ++i) __builtin_prefetch(P[i] + sources_[k + capture_ahead], 0, 3);
        T f[Q], drho, j[D];
        for (int i = 0; i < Q; ++i) f[i] = P[i][sources_[k]];
        collision::shifted_density_momentum<L, T>(f, drho, j);
        out[k] = drho;
        for (int a = 0; a < D; ++a) out[(1 + a) * S + k] = j[a];
        for (int e = 0; e < std::min(Channels, C - 1) - (D + 1); ++e) out[(D + 1 + e) * S + k] = f[pops[e]];
        if constexpr (Channels == C) out[trace_channel * S + k] = collision::second_moment_trace<L, T>(f);
      }
    }
  }

  /// Channels per level in the history: the trace only when the operator reads it.
  std::size_t stored_channels() const { return trace_ ? C : C - 1; }
  /// The history's layout was fixed at construction (`trace`): an operator of the other kind
  /// would read or write the trace channel outside it.
  template <class Op>
  void check_operator() const {
    CAPLAB_CHECK(collision::has_bulk_mode<Op> == trace_,
                 "two-level coupling constructed for an operator with(out) a bulk mode of its own, used with the "
                 "other kind: pass collision::has_bulk_mode<Op> as `trace`");
  }

  field::Grid<D> coarse_, fine_;
  Taus c_from_f_{1.0, 1.0, 1.0}, f_from_c_{1.0, 1.0, 1.0};  // rescaling factors of the even, odd, bulk parts
  bool trace_ = false;  // the history keeps the trace channel
  std::vector<Face> faces_;
  std::vector<Chunk> chunks_;               // the tasks of fill_fine_ghosts
  std::vector<std::ptrdiff_t> sources_;     // coarse nodes of the face planes, face after face
  std::vector<Ghost> ghosts_;               // face after face, rows along u padded to batches
  std::vector<Link> links_;
  NodePairs band_;                         // the outermost covered layer (collide_band)
  std::vector<T> history_;  // [level][channel][source]
  std::vector<std::vector<T>> scratch_;  // per thread: a coarse row in time, a chunk's rows along u
  std::size_t max_coarse_u_ = 0, scratch_size_ = 0;
  Index<D> cov_lo_{}, cov_hi_{};
  int newest_ = 0;
  bool primed_ = false;
};

}  // namespace caplab::refinement
