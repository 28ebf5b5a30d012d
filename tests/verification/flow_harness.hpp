// Small helpers shared by the verification tests: build a Fluid on a box and read fields.
#pragma once

#include "collision/operators.hpp"
#include "lattice/lattice.hpp"
#include "sim/fluid.hpp"

namespace caplab::testing {

template <class L>
using Kinds = std::array<boundary::Kind, L::d>;

/// Velocity (lattice units, with half the body force) of interior node ijk of block b.
template <class L, class T, class Op>
Vec<L::d> velocity(const sim::Fluid<L, T, Op>& fluid, std::size_t b, const Index<L::d>& ijk) {
  const auto& blk = fluid.block(b);
  const auto n = blk.pop.grid().index(ijk);
  double F[L::d];
  for (int a = 0; a < L::d; ++a) F[a] = fluid.body_force(b)[a];
  double f[L::q];
  for (int i = 0; i < L::q; ++i) f[i] = blk.pop(i, n);
  const auto m = collision::moments<L, double>(f, F);
  Vec<L::d> u;
  for (int a = 0; a < L::d; ++a) u[a] = m.u[a];
  return u;
}

/// Total mass Σρ over the interior of block b.
template <class L, class T, class Op>
double mass(const sim::Fluid<L, T, Op>& fluid, std::size_t b) {
  const auto& blk = fluid.block(b);
  double m = 0;
  field::for_each_interior<L::d>(blk.pop.grid(), [&](const Index<L::d>& ijk) {
    const auto n = blk.pop.grid().index(ijk);
    for (int i = 0; i < L::q; ++i) m += L::w[i] + blk.pop(i, n);
  });
  return m;
}

}  // namespace caplab::testing
