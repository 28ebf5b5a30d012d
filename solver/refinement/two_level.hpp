// Two-level multi-block coupling, refinement ratio m = 2 (thesis 2.1.2; Yu, Mei & Shyy 2002;
// Yu & Girimaji 2006), written once for D2Q9 and D3Q19.
//
// Layout. The coarse grid covers the whole domain. The fine block's ghost ring is the line
// (surface) MN of thesis fig. 2.2 and lies on coarse nodes; coarse nodes strictly inside MN
// are "covered": the fine solution stands for them, so the innermost uncovered ring (AB) of
// the thesis is fed by the fine solution. Only the outermost covered layer streams into
// uncovered nodes, so only it is restricted from the coincident fine nodes every step; the
// covered nodes inside it evolve as a coarse solution that nothing reads (outputs read the
// fine nodes through them, fine_node_under).
//
// Transfers (pre-collision populations, so τ = 1 is not singular, unlike eq. 2.11/2.12):
//   fine from coarse:  f_f = f_eq + τ_f/(m τ_c) · (f_c − f_eq)
//   coarse from fine:  f_c = f_eq + m τ_c/τ_f · (f_f − f_eq)
// which keep ρ, u and the viscous stress continuous (f_neq ∝ τ Δt ∇u, τ_f = ½ + m(τ_c − ½)).
// The even and odd parts of f_neq are rescaled with their own relaxation times (τ+ and τ−
// of TRT; equal for BGK): the odd part ∝ τ− Δt, and rescaling it with τ+ breaks the
// exactness of linear shear across the interface (measured 1e-4 instead of 1e-7).
// Fine ghost values off coarse nodes use the symmetric 4-point (cubic) midpoint stencil
// (−1, 9, 9, −1)/16 along each axis where the node lies half way, in time the 3-point
// Lagrange formula (eq. 2.14) through t_{n−1}, t_n, t_{n+1}. The ghost node is then collided
// with the fine operator and pushes into the fine interior, like any ghost of a block.
//
// One coarse step: coarse collide-push (in place, parity flip) + boundaries, capture_coarse();
// two fine substeps, each: collide-push, fill_fine_ghosts(s) with s = 0 then ½; then
// restrict_to_coarse(). Populations are addressed at each block's current parity
// (field/populations.hpp). Exactness: uniform and linear shear flows cross the interface
// unchanged to round-off (tests/verification).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "collision/equilibrium.hpp"
#include "core/error.hpp"
#include "field/populations.hpp"

namespace caplab::refinement {

template <class L, class T>
class TwoLevel {
 public:
  static constexpr int D = L::d;
  static constexpr int Q = L::q;
  static constexpr int m = 2;

  TwoLevel() = default;
  /// Relaxation times of the even (τ+) and odd (τ−) non-equilibrium parts of one block.
  struct Taus {
    double plus, minus;
  };
  /// `tau_c`, `tau_f`: relaxation times of the two blocks (τ_f+ = ½ + m(τ_c+ − ½)).
  TwoLevel(const field::Grid<D>& coarse, const field::Grid<D>& fine, Taus tau_c, Taus tau_f)
      : coarse_(coarse),
        fine_(fine),
        c_from_f_{m * tau_c.plus / tau_f.plus, m * tau_c.minus / tau_f.minus},
        f_from_c_{tau_f.plus / (m * tau_c.plus), tau_f.minus / (m * tau_c.minus)} {
    CAPLAB_CHECK(std::abs(coarse.dx() - m * fine.dx()) < 1e-12 * coarse.dx(),
                 "two-level coupling needs coarse spacing = 2 × fine spacing");
    build_ghost_stencils();
    build_restriction();
    history_.assign(3 * sources_.size() * Q, T(0));
    at_s_.assign(sources_.size() * Q, T(0));
    // Whole batches: the last one is filled with ghosts that have no weight (f = 0, the rest
    // state) and no link.
    while (ghosts_.size() % batch != 0)
      ghosts_.push_back({static_cast<int>(weights_.size()), 0, static_cast<int>(links_.size()), 0});
  }

  /// Records the coarse populations needed by the fine ghosts at the new coarse time level.
  /// Call after the coarse step (and swap); the first call also fills the older levels.
  void capture_coarse(const field::Populations<L, T>& coarse) {
    newest_ = (newest_ + 1) % 3;
    store_level(coarse, newest_);
    if (!primed_) {
      store_level(coarse, (newest_ + 1) % 3);
      store_level(coarse, (newest_ + 2) % 3);
      primed_ = true;
    }
  }

  /// Fills the fine interior slots entering from the ghost ring (after the fine sweep and its
  /// parity flip), with the coarse state at fractional time s ∈ [0, 1) after the previous
  /// coarse level t_n.
  template <class Op>
  void fill_fine_ghosts(field::Populations<L, T>& fine, const Op& op_fine, double s) {
    // 3-point Lagrange through t_{n-1} = −1, t_n = 0, t_{n+1} = 1 (eq. 2.14).
    const double lag[3] = {0.5 * s * (s - 1.0), (1.0 - s) * (1.0 + s), 0.5 * s * (s + 1.0)};
    const int lev[3] = {(newest_ + 1) % 3, (newest_ + 2) % 3, newest_};  // t_{n-1}, t_n, t_{n+1}
    const std::array<T*, Q> P = fine.bases();
    const std::size_t S = sources_.size();
    // In time first, once per source (a source serves up to 16 ghosts), then in space. At
    // s = 0 the formula gives the level t_n itself.
    const T* at_s = &history_[lev[1] * S * Q];
    if (s != 0.0) {
      T* out = at_s_.data();
#pragma omp parallel for schedule(static)
      for (std::size_t src = 0; src < S; ++src) {
        const T* h0 = &history_[(lev[0] * S + src) * Q];
        const T* h1 = &history_[(lev[1] * S + src) * Q];
        const T* h2 = &history_[(lev[2] * S + src) * Q];
        for (int i = 0; i < Q; ++i) out[src * Q + i] = T(lag[0]) * h0[i] + T(lag[1]) * h1[i] + T(lag[2]) * h2[i];
      }
      at_s = out;
    }
    // Then, per batch of ghosts, in space (into a small structure of arrays) and the collision
    // vectorised over the batch (as the far field, boundary/boundary_set.hpp).
    const std::ptrdiff_t batches = static_cast<std::ptrdiff_t>(ghosts_.size()) / batch;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t bt = 0; bt < batches; ++bt) {
      T coarse_f[Q][batch];
      for (int b = 0; b < batch; ++b) {
        const auto& gh = ghosts_[bt * batch + b];
        T f[Q] = {};
        for (int w = gh.first_weight; w < gh.first_weight + gh.weight_count; ++w) {
          const auto& sw = weights_[w];
          const T* h = &at_s[sw.source * Q];
          const T c = T(sw.weight);
          for (int i = 0; i < Q; ++i) f[i] += c * h[i];
        }
        for (int i = 0; i < Q; ++i) coarse_f[i][b] = f[i];
      }
      collide_ghosts(coarse_f, P, op_fine, bt * batch);
    }
  }

  /// Sets the covered coarse nodes that stream into uncovered ones (the outermost covered
  /// layer) from the coincident fine nodes, at the current time. Deeper covered nodes reach
  /// nothing outside the fine block before they are overwritten, so they are left to evolve on
  /// their own; `restrict_everywhere` sets them too, and `fine_node_under` reads through them.
  void restrict_to_coarse(field::Populations<L, T>& coarse, const field::Populations<L, T>& fine) const {
    restrict_nodes(coarse, fine, band_);
  }

  /// Sets every covered coarse node from the fine block (the initial state).
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

  /// Whether a coarse node lies strictly inside the fine block (it is read through the fine grid).
  bool covered(const Index<D>& c) const {
    for (int a = 0; a < D; ++a)
      if (c[a] <= cov_lo_[a] || c[a] >= cov_hi_[a]) return false;
    return true;
  }

 private:
  /// Nodes per vector loop (collide_ghosts, restrict_nodes): one 64-byte cache line of T.
  static constexpr int batch = static_cast<int>(64 / sizeof(T));

  /// Ghosts k0 … k0 + batch − 1 from their interpolated coarse populations: rescaled to the
  /// fine block, collided with the fine operator, then pushed along their links.
  template <class Op>
  void collide_ghosts(const T (&coarse_f)[Q][batch], const std::array<T*, Q>& P, const Op& op,
                      std::ptrdiff_t k0) const {
    T post[Q][batch];
#pragma omp simd
    for (int b = 0; b < batch; ++b) {
      T f[Q], feq[Q], out[Q];
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i) f[i] = coarse_f[i][b];
      rescale_non_equilibrium(f, feq, f_from_c_);
      op.template collide<L, T>(f, feq, out);
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i) post[i][b] = out[i];
    }
    for (int b = 0; b < batch; ++b) {
      const auto& gh = ghosts_[k0 + b];
      for (int l = gh.first_link; l < gh.first_link + gh.link_count; ++l)
        P[links_[l].i][links_[l].dst] = post[links_[l].i][b];
    }
  }

  struct Weight {
    std::size_t source;  // index into sources_
    double weight;
  };
  struct Ghost {
    int first_weight, weight_count, first_link, link_count;
  };
  struct Link {
    int i;
    std::ptrdiff_t dst;
  };
  /// Coincident coarse and fine nodes, in whole batches (the last pair repeated: rewriting a
  /// node with the same value is harmless).
  struct NodePairs {
    std::vector<int> coarse, fine;
    void push_back(std::ptrdiff_t c, std::ptrdiff_t f) {
      CAPLAB_CHECK(std::max(c, f) <= std::numeric_limits<int>::max(), "block too large for 32-bit node indices");
      coarse.push_back(static_cast<int>(c));
      fine.push_back(static_cast<int>(f));
    }
    void pad() {
      while (!coarse.empty() && coarse.size() % batch != 0) push_back(coarse.back(), fine.back());
    }
  };

  /// f ← f_eq + s+ · (even part of f_neq) + s− · (odd part of f_neq), with feq the equilibrium
  /// of f's moments (which the rescaling keeps).
  static void rescale_non_equilibrium(T (&f)[Q], T (&feq)[Q], const Taus& s) {
    T rho, u[D];
    collision::moments<L, T>(f, rho, u);
    collision::equilibrium<L, T>(rho, u, feq);
    // Unrolled: inside the `omp simd` loops of collide_ghosts and restrict_nodes an inner loop
    // stops GCC from vectorising over the nodes.
    T neq[Q];
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) neq[i] = f[i] - feq[i];
#pragma GCC unroll 19
    for (int i = 0; i < Q; ++i) {
      const int o = L::opposite[i];
      f[i] = feq[i] + T(0.5 * s.plus) * (neq[i] + neq[o]) + T(0.5 * s.minus) * (neq[i] - neq[o]);
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

  void build_ghost_stencils() {
    std::map<std::ptrdiff_t, std::size_t> source_of;  // coarse node -> index in sources_
    field::for_each_ghost<D>(fine_, [&](const Index<D>& h) {
      const int first_link = static_cast<int>(links_.size());
      for (int i = 0; i < Q; ++i) {
        Index<D> t;
        for (int a = 0; a < D; ++a) t[a] = h[a] + L::c[i][a];
        if (fine_.is_interior(t)) links_.push_back({i, fine_.index(t)});
      }
      const int link_count = static_cast<int>(links_.size()) - first_link;
      if (link_count == 0) return;
      const Index<D> k2 = doubled_coarse_coordinate(h);
      // 1D stencils per axis, then their tensor product.
      std::array<std::vector<std::pair<int, double>>, D> axis;
      for (int a = 0; a < D; ++a) {
        if (k2[a] % 2 == 0) {
          axis[a] = {{k2[a] / 2, 1.0}};
        } else {
          const int lo = (k2[a] - 1) / 2;
          axis[a] = {{lo - 1, -1.0 / 16}, {lo, 9.0 / 16}, {lo + 1, 9.0 / 16}, {lo + 2, -1.0 / 16}};
        }
      }
      const int first_weight = static_cast<int>(weights_.size());
      Index<D> pick{};
      auto recurse = [&](auto&& self, int a, Index<D> c, double w) -> void {
        if (a == D) {
          CAPLAB_CHECK(coarse_.is_interior(c), "fine block too close to the domain boundary for the coupling");
          const auto idx = coarse_.index(c);
          auto [it, inserted] = source_of.try_emplace(idx, sources_.size());
          if (inserted) sources_.push_back(idx);
          weights_.push_back({it->second, w});
          return;
        }
        for (const auto& [ci, wi] : axis[a]) {
          c[a] = ci;
          self(self, a + 1, c, w * wi);
        }
      };
      recurse(recurse, 0, pick, 1.0);
      ghosts_.push_back({first_weight, static_cast<int>(weights_.size()) - first_weight, first_link, link_count});
    });
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
      if (outermost || !band_only) pairs.push_back(coarse_.index(c), fine_node_under(c));
    });
    pairs.pad();
    return pairs;
  }

  /// Coarse nodes from their coincident fine nodes, vectorised over batches of nodes.
  void restrict_nodes(field::Populations<L, T>& coarse, const field::Populations<L, T>& fine,
                      const NodePairs& nodes) const {
    const std::array<const T*, Q> src = fine.bases();
    const std::array<T*, Q> dst = coarse.bases();
    const std::ptrdiff_t batches = static_cast<std::ptrdiff_t>(nodes.coarse.size()) / batch;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t bt = 0; bt < batches; ++bt) {
      const std::ptrdiff_t k0 = bt * batch;
      T out[Q][batch];
#pragma omp simd
      for (int b = 0; b < batch; ++b) {
        T f[Q], feq[Q];
        // 32-bit node indices into each population's array: a vector gather (as the far field).
#pragma GCC unroll 19
        for (int i = 0; i < Q; ++i) f[i] = src[i][nodes.fine[k0 + b]];
        rescale_non_equilibrium(f, feq, c_from_f_);
#pragma GCC unroll 19
        for (int i = 0; i < Q; ++i) out[i][b] = f[i];
      }
      for (int b = 0; b < batch; ++b)
        for (int i = 0; i < Q; ++i) dst[i][nodes.coarse[k0 + b]] = out[i][b];
    }
  }

  void store_level(const field::Populations<L, T>& coarse, int level) {
    const std::size_t S = sources_.size();
    for (std::size_t s = 0; s < S; ++s)
      for (int i = 0; i < Q; ++i) history_[(level * S + s) * Q + i] = coarse(i, sources_[s]);
  }

  field::Grid<D> coarse_, fine_;
  Taus c_from_f_{1.0, 1.0}, f_from_c_{1.0, 1.0};  // rescaling factors of the even and odd parts
  std::vector<std::ptrdiff_t> sources_;  // coarse nodes read by the fine ghost stencils
  std::vector<Weight> weights_;
  std::vector<Ghost> ghosts_;
  std::vector<Link> links_;
  NodePairs band_;  // restricted every step
  std::vector<T> history_;  // [level][source][i]
  std::vector<T> at_s_;     // [source][i]: the history interpolated to the substep (s > 0) being filled
  Index<D> cov_lo_{}, cov_hi_{};
  int newest_ = 0;
  bool primed_ = false;
};

}  // namespace caplab::refinement
