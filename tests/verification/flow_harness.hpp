// Small helpers shared by the verification tests: build a Fluid on a box and read fields.
#pragma once

#include <cmath>
#include <vector>

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

/// A fully periodic box of n nodes (spacing 1, origin 0) at rest, one block, operator op.
template <class L, class T, class Op>
typename sim::Fluid<L, T, Op>::Setup periodic_box(const Index<L::d>& n, const Op& op) {
  typename sim::Fluid<L, T, Op>::Setup s;
  s.coarse = field::Grid<L::d>(n, Vec<L::d>::Zero(), 1.0);
  s.boundaries.fill(boundary::Kind::periodic);
  s.imposed_velocity_lu = [](const Vec<L::d>&) { return Vec<L::d>::Zero(); };
  s.coarse_op = op;
  return s;
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

/// Decay rate (per sample) of a damped oscillation A(t) = e^{−Γt} cos(ωt + φ) sampled every
/// step: the least-squares slope of log |A| through its extrema after `skip` samples, each
/// located by a parabola through three samples (the extrema of |A| are π/ω apart, so the ratio
/// of successive ones is e^{−Γπ/ω} for any Γ/ω). `extrema` returns how many were fitted.
inline double damped_oscillation_rate(const std::vector<double>& A, int skip, int& extrema) {
  double st = 0, sl = 0, stt = 0, stl = 0;
  int m = 0;
  for (std::size_t t = static_cast<std::size_t>(skip); t + 1 < A.size(); ++t) {
    const double a = std::abs(A[t - 1]), b = std::abs(A[t]), c = std::abs(A[t + 1]);
    if (!(b > a && b >= c)) continue;
    const double dt = 0.5 * (a - c) / (a - 2 * b + c);  // vertex of the parabola, in samples
    const double tp = static_cast<double>(t) + dt, lp = std::log(b - 0.25 * (a - c) * dt);
    st += tp, sl += lp, stt += tp * tp, stl += tp * lp, ++m;
  }
  extrema = m;
  return -(m * stl - st * sl) / (m * stt - st * st);
}

}  // namespace caplab::testing
