// Shared helpers of the IB unit tests: small grids, fields stored per linear index, random markers.
#pragma once

#include <array>
#include <random>
#include <vector>

#include "core/vec.hpp"
#include "field/grid.hpp"

namespace caplab::ibm::testing {

/// A block of n^D interior nodes with a non-trivial origin and spacing.
template <int D>
field::Grid<D> make_grid(int n, double dx = 0.25) {
  Index<D> nn;
  nn.fill(n);
  Vec<D> origin;
  for (int a = 0; a < D; ++a) origin[a] = -1.0 + 0.5 * a;
  return field::Grid<D>(nn, origin, dx);
}

/// Uniform random vector with components in [lo, hi).
template <int D>
Vec<D> random_vec(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Vec<D> v;
  for (int a = 0; a < D; ++a) v[a] = u(rng);
  return v;
}

/// Physical positions of markers whose lattice coordinates lie in [lo, hi) per axis.
template <int D>
std::vector<Vec<D>> random_positions(const field::Grid<D>& g, int count, double lo, double hi,
                                     std::mt19937& rng) {
  std::vector<Vec<D>> x(count);
  for (auto& p : x) p = g.origin() + g.dx() * random_vec<D>(rng, lo, hi);
  return x;
}

/// Sum over interior nodes of f(ijk, linear index).
template <int D, class T, class F>
T sum_interior(const field::Grid<D>& g, T zero, F&& f) {
  T s = zero;
  field::for_each_interior(g, [&](const Index<D>& ijk) { s += f(ijk, g.index(ijk)); });
  return s;
}

}  // namespace caplab::ibm::testing
