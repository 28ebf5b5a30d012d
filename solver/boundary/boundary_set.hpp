// Boundary conditions of a block, applied through its ghost layer after the fused kernel.
//
// After collide-and-push, the interior slots whose source is a ghost node are empty (slots
// addressed at the new parity, field/populations.hpp: the slot of population i entering
// interior node t, and the one where interior node s left population i that went out). Each
// ghost node has one owner (the first of interface > wall > far field > periodic among
// the axes along which it lies outside the interior), and the owner fills those slots:
//  - periodic: the population that left through the opposite face (a copy);
//  - wall (half-way bounce-back, Ladd 1994): the population that left towards the wall,
//    reversed, plus the moving-wall term 2 w_i ρ0 (c_i·u_w)/cs²; the wall lies half way
//    between the ghost and the interior node;
//  - far field, one of two schemes (FarField), u_b being the imposed unperturbed flow:
//    non-equilibrium extrapolation (Guo, Zheng & Shi 2002): the ghost node gets
//    f = f_eq(ρ_f, u_b) + (f_f − f_eq(ρ_f, u_f)) from its nearest interior node f, is
//    collided, and pushes into the interior; or equilibrium (thesis 2.2.1, "the density
//    distribution function is set at its equilibrium state"): the ghost node holds
//    f_eq(ρ0 = 1, u_b), so what enters is the unperturbed far-field state, whatever leaves;
//  - interface: left to the multi-block coupling (refinement module).
// All links are precomputed once, the copies as buffer indices for either parity; applying
// them touches only the block surface. Far-field ghosts are stored as structure of arrays,
// face by face (beside the faces normal to y or z row by row: their interior nodes are
// consecutive, read as vectors), edges and corners last. Their post-collision values are
// computed before the sweep (prepare(): the extrapolation reads the interior at time t, which
// the in-place sweep overwrites; the equilibrium values are constant and computed once), in
// batches of one face, one vector loop computing the values that enter the interior from that
// face; apply() writes them along the links. Every entering slot has exactly one source, so
// the result does not depend on the order or the batching. Periodic
// and wall copies read slots of leaving populations only and write entering slots only: they
// run in parallel in any order.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "collision/equilibrium.hpp"
#include "core/error.hpp"
#include "field/populations.hpp"
#include "lattice/lattice.hpp"

namespace caplab::boundary {

enum class Kind { periodic, far_field, wall, interface };

/// How a far-field ghost node is set (see the file comment).
enum class FarField { extrapolation, equilibrium };

template <class L, class T>
class BoundarySet {
 public:
  static constexpr int D = L::d;
  static constexpr int Q = L::q;
  /// Imposed velocity (lattice units) at a physical position.
  using VelocityField = std::function<Vec<D>(const Vec<D>&)>;

  BoundarySet() = default;
  BoundarySet(const field::Grid<D>& g, const std::array<Kind, D>& kinds, const VelocityField& imposed,
              FarField far_field = FarField::extrapolation)
      : far_field_(far_field) {
    CAPLAB_CHECK(g.size() <= std::numeric_limits<int>::max(),
                 "block too large for the far field's 32-bit node indices");
    field::for_each_ghost<D>(g, [&](const Index<D>& h) { add_ghost(g, kinds, imposed, h); });
    order_far_field(g.n()[0]);
  }

  /// Before the sweep: the far-field ghosts' post-collision values from the state at time t
  /// (Guo's extrapolation; nothing to do for the constant equilibrium).
  template <class Op>
  void prepare(const field::Populations<L, T>& pop, const Op& op) {
    if (far_field_ != FarField::extrapolation) return;
    const auto bases = pop.bases();
    const std::ptrdiff_t batches = static_cast<std::ptrdiff_t>(far_interior_.size()) / batch;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t b = 0; b < batches; ++b) batch_of_face<false>(bases, op, b);
  }

  /// After the sweep (and its parity flip): fills the interior slots entering from the ghost
  /// layer.
  void apply(field::Populations<L, T>& pop) const {
    T* data = pop.data();
    // A copy reads a leaving slot and writes an entering slot, so the copies are independent.
    // Serial, they took 8 % of a quick biconcave step on one thread (perf; periodic in x and y,
    // walls in z), with any other thread waiting.
    const Copy* copies = copies_[pop.parity()].data();
    const std::ptrdiff_t n_copies = static_cast<std::ptrdiff_t>(copies_[pop.parity()].size());
#pragma omp parallel for schedule(static) if (n_copies > 4096)
    for (std::ptrdiff_t k = 0; k < n_copies; ++k)
      data[copies[k].dst] = data[copies[k].src] + T(copies[k].add);
    const auto P = pop.bases();
    const std::ptrdiff_t K = static_cast<std::ptrdiff_t>(far_interior_.size());
    const T* post = far_post_.data();
#pragma omp parallel for schedule(static) if (K > 4096)
    for (std::ptrdiff_t k = 0; k < K; ++k)
      for (int l = far_first_link_[k]; l < far_first_link_[k + 1]; ++l)
        P[far_links_[l].i][far_links_[l].dst] = post[far_links_[l].i * K + k];
  }

  bool empty() const { return copies_[0].empty() && far_interior_.empty(); }

 private:
  /// Far-field ghosts per vector loop: one 64-byte cache line of T.
  static constexpr int batch = static_cast<int>(64 / sizeof(T));

  struct Copy {
    std::ptrdiff_t dst, src;  // buffer indices (Populations::slot) at one parity
    double add;
  };
  struct Link {
    int i;
    std::ptrdiff_t dst;  // interior node receiving population i
  };

  /// Far-field ghosts per face: face 2a + s lies beyond the interior along axis a only, on the
  /// low (s = 0) or high (s = 1) side; the ghosts outside along several axes (edges, corners)
  /// are the group `mixed`.
  static constexpr int mixed = 2 * D;
  /// Whether population i enters the interior from a ghost of face `face` (all do for mixed).
  static constexpr bool enters_from(int face, int i) {
    return face == mixed || lattice::enters_through_face<L>(face, i);
  }

  /// Whether face `face`'s ghosts are laid out in rows of consecutive interior nodes: beside
  /// the faces normal to y or z, when the rows are at least a batch long (order_far_field).
  bool in_rows(int face) const { return face != mixed && face / 2 != 0 && rows_of_batches_; }

  /// far_field_batch for batch b with the face of its ghosts as a compile-time constant.
  template <bool Equilibrium, int Face = 0, class Op>
  void batch_of_face(const std::array<const T*, Q>& current, const Op& op, std::ptrdiff_t b) {
    if constexpr (Face == mixed) {
      far_field_batch<Equilibrium, Face, false>(current, op, b * batch);
    } else if (batch_face_[b] == Face) {
      if (in_rows(Face))
        far_field_batch<Equilibrium, Face, true>(current, op, b * batch);
      else
        far_field_batch<Equilibrium, Face, false>(current, op, b * batch);
    } else {
      batch_of_face<Equilibrium, Face + 1>(current, op, b);
    }
  }

  /// The post-collision state of ghosts k0 … k0 + batch − 1, all of face Face, into far_post_
  /// (Guo's extrapolation from the state `current` and the collision, or the far-field
  /// equilibrium, a fixed point of the collision): only the populations that enter the interior
  /// from that face (5 of 19 in D3Q19), the only rows of far_post_ that apply() reads for them.
  /// Storing all Q rows moved 3.4 more MB per step on a 60^3 block, to DRAM and back, and the
  /// compiler drops the arithmetic of the outputs not stored. Beside the faces normal to y or z
  /// the batch's interior nodes are consecutive (order_far_field) and read as vectors; beside x
  /// and in the mixed group they are gathered.
  template <bool Equilibrium, int Face, bool contiguous, class Op>
  void far_field_batch(const std::array<const T*, Q>& current, const Op& op, std::ptrdiff_t k0) {
    const std::ptrdiff_t K = static_cast<std::ptrdiff_t>(far_interior_.size());
    // What the loop reads through, in locals: through `this` or the array reference the
    // pointers are reloaded after every store.
    T* __restrict__ post = far_post_.data() + k0;
    const T* cur[Q];
    for (int i = 0; i < Q; ++i) cur[i] = current[i];
    const T* ubp[D];
    for (int a = 0; a < D; ++a) ubp[a] = far_u_b_[a].data() + k0;
    const int* src = far_interior_.data() + k0;
    const std::ptrdiff_t first = src[0];
#pragma omp simd
    for (int b = 0; b < batch; ++b) {
      T out[Q], ub[D];
      for (int a = 0; a < D; ++a) ub[a] = ubp[a][b];
      if constexpr (Equilibrium) {
        collision::equilibrium<L, T>(T(1), ub, out);
      } else {
        T f[Q], feq_f[Q], feq_b[Q], fb[Q], rho, u[D];
        // Gathered: a 32-bit node index into population i's array, which GCC 12 turns into a
        // vector gather (a 64-bit index into the whole buffer leaves the loop scalar).
        if constexpr (contiguous) {
#pragma GCC unroll 19
          for (int i = 0; i < Q; ++i) f[i] = cur[i][first + b];
        } else {
#pragma GCC unroll 19
          for (int i = 0; i < Q; ++i) f[i] = cur[i][src[b]];
        }
        collision::moments<L, T>(f, rho, u);
        collision::equilibrium<L, T>(rho, u, feq_f);
        collision::equilibrium<L, T>(rho, ub, feq_b);
#pragma GCC unroll 19
        for (int i = 0; i < Q; ++i) fb[i] = feq_b[i] + (f[i] - feq_f[i]);
        op.template collide<L, T>(fb, feq_b, out);
      }
#pragma GCC unroll 19
      for (int i = 0; i < Q; ++i)
        if (enters_from(Face, i)) post[i * K + b] = out[i];
    }
  }

  void add_ghost(const field::Grid<D>& g, const std::array<Kind, D>& kinds, const VelocityField& imposed,
                 const Index<D>& h) {
    Kind owner = Kind::periodic;
    auto rank = [](Kind k) { return k == Kind::interface ? 3 : k == Kind::wall ? 2 : k == Kind::far_field ? 1 : 0; };
    for (int a = 0; a < D; ++a)
      if ((h[a] < 0 || h[a] >= g.n()[a]) && rank(kinds[a]) > rank(owner)) owner = kinds[a];
    if (owner == Kind::interface) return;
    const int first = static_cast<int>(far_links_.size());
    for (int i = 0; i < Q; ++i) {
      Index<D> t;
      for (int a = 0; a < D; ++a) t[a] = h[a] + L::c[i][a];
      if (!g.is_interior(t)) continue;
      if (owner == Kind::periodic) {
        Index<D> src = t;  // the ghost on the opposite side that received population i
        for (int a = 0; a < D; ++a) {
          if (h[a] < 0) src[a] += g.n()[a];
          if (h[a] >= g.n()[a]) src[a] -= g.n()[a];
        }
        add_copy(g, i, g.index(t), i, g.index(src), 0.0);
      } else if (owner == Kind::wall) {
        const Vec<D> x_wall = 0.5 * (g.position(h) + g.position(t));
        const Vec<D> u_w = imposed(x_wall);
        double cu = 0;
        for (int a = 0; a < D; ++a) cu += L::c[i][a] * u_w[a];
        add_copy(g, i, g.index(t), L::opposite[i], g.index(h), 2.0 * L::w[i] * cu / L::cs2);
      } else {
        far_links_.push_back({i, g.index(t)});
      }
    }
    if (owner == Kind::far_field && static_cast<int>(far_links_.size()) > first) {
      Index<D> inner;
      int outside = 0;
      for (int a = 0; a < D; ++a) {
        inner[a] = std::clamp(h[a], 0, g.n()[a] - 1);
        outside += inner[a] != h[a];
      }
      int face = mixed;
      for (int a = 0; a < D && outside == 1; ++a)
        if (inner[a] != h[a]) face = 2 * a + (h[a] < 0 ? 0 : 1);
      staged_.push_back({static_cast<int>(g.index(inner)), imposed(g.position(h)), first,
                         static_cast<int>(far_links_.size()), face});
    }
  }

  /// Entering population i of interior node t ← population j at node `src` + add, for both
  /// parities after the sweep. Population j at src is where a population left: for periodic
  /// ghosts src is the ghost it left into (j = i), for walls src = t − c_i and j = ī (what t
  /// sent towards the wall).
  void add_copy(const field::Grid<D>& g, int i, std::ptrdiff_t t, int j, std::ptrdiff_t src, double add) {
    using Pop = field::Populations<L, T>;
    for (int p = 0; p < 2; ++p) copies_[p].push_back({Pop::slot(g, p, i, t), Pop::slot(g, p, j, src), add});
  }

  /// Lays the staged far-field ghosts out in batches of one face each (face by face, the mixed
  /// group last), each face's ghosts in the order of the ghost layer. Beside the faces normal
  /// to y or z, when the rows (along x) are at least a batch long, each row ends in a batch
  /// shifted back to the row's last node, its first lanes padding ghosts over nodes of the
  /// batch before: every batch reads consecutive interior nodes of one row (never past the
  /// row, whose slots at the end of the block may lie past the buffer). Padding ghosts own no
  /// links; elsewhere they repeat the face's last ghost to fill its last batch. Then sizes the
  /// post-collision values (the constant far-field equilibrium: computed now).
  void order_far_field(int row_length) {
    rows_of_batches_ = row_length >= batch;
    std::vector<Link> links;
    Vec<D> last_u_b = Vec<D>::Zero();
    auto put = [&](int interior, const Vec<D>& u_b, int first, int last) {
      last_u_b = u_b;
      far_interior_.push_back(interior);
      for (int a = 0; a < D; ++a) far_u_b_[a].push_back(T(u_b[a]));
      far_first_link_.push_back(static_cast<int>(links.size()));
      links.insert(links.end(), far_links_.begin() + first, far_links_.begin() + last);
    };
    std::vector<const Staged*> row;  // the ghosts of one row, in order
    auto put_row = [&] {
      const int n = static_cast<int>(row.size()), whole = n - n % batch;
      for (int k = 0; k < whole; ++k) put(row[k]->interior, row[k]->u_b, row[k]->first, row[k]->last);
      if (whole < n) {
        for (int k = n - batch; k < whole; ++k) put(row[k]->interior, row[k]->u_b, 0, 0);  // padding
        for (int k = whole; k < n; ++k) put(row[k]->interior, row[k]->u_b, row[k]->first, row[k]->last);
      }
      row.clear();
    };
    for (int face = 0; face <= mixed; ++face) {
      for (const Staged& gh : staged_) {
        if (gh.face != face) continue;
        if (!in_rows(face)) {
          put(gh.interior, gh.u_b, gh.first, gh.last);
          continue;
        }
        if (!row.empty() && gh.interior != row.back()->interior + 1) put_row();
        row.push_back(&gh);
      }
      if (!row.empty()) put_row();
      while (far_interior_.size() % batch != 0) put(far_interior_.back(), last_u_b, 0, 0);
      batch_face_.resize(far_interior_.size() / batch, static_cast<std::int8_t>(face));
    }
    far_first_link_.push_back(static_cast<int>(links.size()));
    far_links_ = std::move(links);
    staged_.clear();
    staged_.shrink_to_fit();
    far_post_.assign(Q * far_interior_.size(), T(0));
    if (far_field_ == FarField::equilibrium) {
      struct NoCollision {} none;
      for (std::size_t b = 0; b < batch_face_.size(); ++b) batch_of_face<true>({}, none, b);
    }
  }

  FarField far_field_ = FarField::extrapolation;
  std::array<std::vector<Copy>, 2> copies_;  // by the parity after the sweep
  // Far-field ghosts in whole batches of one face (order_far_field): nearest interior node
  // (extrapolation source), imposed velocity u_b, and the links of ghost k,
  // far_links_[far_first_link_[k] … far_first_link_[k + 1]).
  std::vector<int> far_interior_;
  std::array<std::vector<T>, D> far_u_b_;
  std::vector<int> far_first_link_;
  std::vector<Link> far_links_;
  std::vector<std::int8_t> batch_face_;  // the face of each batch's ghosts
  bool rows_of_batches_ = false;          // rows at least a batch long (in_rows)
  // A far-field ghost as the constructor finds it (order_far_field lays them out).
  struct Staged {
    int interior;
    Vec<D> u_b;
    int first, last;  // its links, far_links_[first … last)
    int face;         // as batch_face_
  };
  std::vector<Staged> staged_;
  field::AlignedVector<T> far_post_;  // [i][k]: ghost k's post-collision population i
};

}  // namespace caplab::boundary
