// Boundary conditions of a block, applied through its ghost layer after the fused kernel.
//
// After collide-and-push, the interior slots whose source is a ghost node are empty. Each
// ghost node has one owner (the first of interface > wall > far field > periodic among
// the axes along which it lies outside the interior), and the owner fills those slots:
//  - periodic: the population that left through the opposite face (a copy);
//  - wall (half-way bounce-back, Ladd 1994): the population that left towards the wall,
//    reversed, plus the moving-wall term 2 w_i ρ0 (c_i·u_w)/cs²; the wall lies half way
//    between the ghost and the interior node;
//  - far field (non-equilibrium extrapolation, Guo, Zheng & Shi 2002): the ghost node gets
//    f = f_eq(ρ_f, u_b) + (f_f − f_eq(ρ_f, u_f)) from its nearest interior node f, is
//    collided, and pushes into the interior; u_b is the imposed unperturbed flow;
//  - interface: left to the multi-block coupling (refinement module).
// All links are precomputed once; applying them touches only the block surface.
#pragma once

#include <functional>
#include <vector>

#include "collision/equilibrium.hpp"
#include "field/populations.hpp"

namespace caplab::boundary {

enum class Kind { periodic, far_field, wall, interface };

template <class L, class T>
class BoundarySet {
 public:
  static constexpr int D = L::d;
  static constexpr int Q = L::q;
  /// Imposed velocity (lattice units) at a physical position.
  using VelocityField = std::function<Vec<D>(const Vec<D>&)>;

  BoundarySet() = default;
  BoundarySet(const field::Grid<D>& g, const std::array<Kind, D>& kinds, const VelocityField& imposed) {
    field::for_each_ghost<D>(g, [&](const Index<D>& h) { add_ghost(g, kinds, imposed, h); });
  }

  /// Fills the interior slots entering from the ghost layer, in pop.next().
  /// Reads pop.current() (time t) for the far-field extrapolation.
  template <class Op>
  void apply(field::Populations<L, T>& pop, const Op& op) const {
    T* next = pop.next();
    const std::ptrdiff_t N = pop.grid().size();
    for (const auto& c : copies_) next[c.dst] = next[c.src] + T(c.add);
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < far_.size(); ++k) {
      const auto& s = far_[k];
      T post[Q];
      ghost_post_collision(pop, op, s, post);
      for (int l = s.first_link; l < s.first_link + s.link_count; ++l)
        next[far_links_[l].i * N + far_links_[l].dst] = post[far_links_[l].i];
    }
  }

  bool empty() const { return copies_.empty() && far_.empty(); }

 private:
  struct Copy {
    std::ptrdiff_t dst, src;  // full slot indices i·N + node
    double add;
  };
  struct FarNode {
    std::ptrdiff_t interior;  // nearest interior node (extrapolation source)
    std::array<double, D> u_b;
    int first_link, link_count;
  };
  struct Link {
    int i;
    std::ptrdiff_t dst;  // interior node receiving population i
  };

  template <class Op>
  static void ghost_post_collision(const field::Populations<L, T>& pop, const Op& op, const FarNode& s,
                                   T (&post)[Q]) {
    T f[Q], feq_f[Q], feq_b[Q], fb[Q];
    for (int i = 0; i < Q; ++i) f[i] = pop(i, s.interior);
    const auto m = collision::moments<L, T>(f);
    collision::equilibrium<L, T>(m.rho, m.u, feq_f);
    std::array<T, D> ub;
    for (int a = 0; a < D; ++a) ub[a] = T(s.u_b[a]);
    collision::equilibrium<L, T>(m.rho, ub, feq_b);
    for (int i = 0; i < Q; ++i) fb[i] = feq_b[i] + (f[i] - feq_f[i]);
    op.template collide<L, T>(fb, feq_b, post);
  }

  void add_ghost(const field::Grid<D>& g, const std::array<Kind, D>& kinds, const VelocityField& imposed,
                 const Index<D>& h) {
    Kind owner = Kind::periodic;
    auto rank = [](Kind k) { return k == Kind::interface ? 3 : k == Kind::wall ? 2 : k == Kind::far_field ? 1 : 0; };
    for (int a = 0; a < D; ++a)
      if ((h[a] < 0 || h[a] >= g.n()[a]) && rank(kinds[a]) > rank(owner)) owner = kinds[a];
    if (owner == Kind::interface) return;
    const std::ptrdiff_t N = g.size();
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
        copies_.push_back({i * N + g.index(t), i * N + g.index(src), 0.0});
      } else if (owner == Kind::wall) {
        const Vec<D> x_wall = 0.5 * (g.position(h) + g.position(t));
        const Vec<D> u_w = imposed(x_wall);
        double cu = 0;
        for (int a = 0; a < D; ++a) cu += L::c[i][a] * u_w[a];
        const int o = L::opposite[i];
        copies_.push_back({i * N + g.index(t), o * N + g.index(h), 2.0 * L::w[i] * cu / L::cs2});
      } else {
        far_links_.push_back({i, g.index(t)});
      }
    }
    const int count = static_cast<int>(far_links_.size()) - first;
    if (owner == Kind::far_field && count > 0) {
      Index<D> inner;
      for (int a = 0; a < D; ++a) inner[a] = std::clamp(h[a], 0, g.n()[a] - 1);
      const Vec<D> u = imposed(g.position(h));
      FarNode s{g.index(inner), {}, first, count};
      for (int a = 0; a < D; ++a) s.u_b[a] = u[a];
      far_.push_back(s);
    }
  }

  std::vector<Copy> copies_;
  std::vector<FarNode> far_;
  std::vector<Link> far_links_;
};

}  // namespace caplab::boundary
