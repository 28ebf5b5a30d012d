// Lattice descriptors: D2Q9 (thesis eq. 2.2, 2.5) and D3Q19 (eq. 5.13).
//
// Constant-only types: velocities c, weights w, opposite directions, cs² = 1/3.
// Every kernel is templated on one of them, so 2D and 3D share one code path.
// Invariants (tested in tests/unit/lattice): Σw = 1, Σw c = 0, Σw c c = cs² I,
// fourth-order isotropy, c[opposite[i]] = −c[i], direction 0 is the rest particle.
#pragma once

#include <array>

namespace caplab::lattice {

namespace detail {
template <int D, int Q>
constexpr std::array<int, Q> opposites(const std::array<std::array<int, D>, Q>& c) {
  std::array<int, Q> opp{};
  for (int i = 0; i < Q; ++i)
    for (int j = 0; j < Q; ++j) {
      bool is_opposite = true;
      for (int a = 0; a < D; ++a) is_opposite = is_opposite && c[j][a] == -c[i][a];
      if (is_opposite) opp[i] = j;
    }
  return opp;
}
}  // namespace detail

struct D2Q9 {
  static constexpr int d = 2;
  static constexpr int q = 9;
  static constexpr double cs2 = 1.0 / 3.0;
  static constexpr const char* name = "D2Q9";
  // Thesis eq. 2.2 ordering: rest, the four axis directions, the four diagonals.
  static constexpr std::array<std::array<int, 2>, 9> c{
      {{0, 0}, {1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}}};
  // Thesis eq. 2.5.
  static constexpr std::array<double, 9> w{4.0 / 9,  1.0 / 9,  1.0 / 9,  1.0 / 9, 1.0 / 9,
                                           1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36};
  static constexpr std::array<int, 9> opposite = detail::opposites<2, 9>(c);
};

struct D3Q19 {
  static constexpr int d = 3;
  static constexpr int q = 19;
  static constexpr double cs2 = 1.0 / 3.0;
  static constexpr const char* name = "D3Q19";
  // Thesis eq. 5.13: rest, six faces, twelve edges.
  static constexpr std::array<std::array<int, 3>, 19> c{{{0, 0, 0},
                                                         {1, 0, 0},
                                                         {-1, 0, 0},
                                                         {0, 1, 0},
                                                         {0, -1, 0},
                                                         {0, 0, 1},
                                                         {0, 0, -1},
                                                         {1, 1, 0},
                                                         {-1, -1, 0},
                                                         {1, -1, 0},
                                                         {-1, 1, 0},
                                                         {1, 0, 1},
                                                         {-1, 0, -1},
                                                         {1, 0, -1},
                                                         {-1, 0, 1},
                                                         {0, 1, 1},
                                                         {0, -1, -1},
                                                         {0, 1, -1},
                                                         {0, -1, 1}}};
  // Weights 1/3, 1/18 (faces), 1/36 (edges).
  static constexpr std::array<double, 19> w{1.0 / 3,  1.0 / 18, 1.0 / 18, 1.0 / 18, 1.0 / 18,
                                            1.0 / 18, 1.0 / 18, 1.0 / 36, 1.0 / 36, 1.0 / 36,
                                            1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36,
                                            1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36};
  static constexpr std::array<int, 19> opposite = detail::opposites<3, 19>(c);
};

/// Whether population i of lattice L enters a block's interior from a ghost of face `face`:
/// face 2a + s lies beyond the interior along axis a, on the low (s = 0) or high (s = 1) side,
/// so its ghosts reach the interior only along c_a = +1 or −1. The one face convention of the
/// boundaries (boundary/boundary_set.hpp) and the two-level coupling (refinement/two_level.hpp).
template <class L>
constexpr bool enters_through_face(int face, int i) {
  return L::c[i][face / 2] == (face % 2 == 0 ? 1 : -1);
}

/// The lattice of a dimension: D2Q9 in 2D, D3Q19 in 3D.
template <int D>
struct LatticeOf;
template <>
struct LatticeOf<2> {
  using type = D2Q9;
};
template <>
struct LatticeOf<3> {
  using type = D3Q19;
};

}  // namespace caplab::lattice
