// Lattice identities: weights, isotropy up to fourth order, opposite directions.
#include "lattice/lattice.hpp"

#include <gtest/gtest.h>

namespace caplab::lattice {
namespace {

template <class L>
class LatticeTest : public ::testing::Test {};
using Lattices = ::testing::Types<D2Q9, D3Q19>;
TYPED_TEST_SUITE(LatticeTest, Lattices);

TYPED_TEST(LatticeTest, WeightsSumToOne) {
  using L = TypeParam;
  double s = 0;
  for (int i = 0; i < L::q; ++i) s += L::w[i];
  EXPECT_NEAR(s, 1.0, 1e-15);
}

TYPED_TEST(LatticeTest, RestParticleFirstAndOppositesConsistent) {
  using L = TypeParam;
  for (int a = 0; a < L::d; ++a) EXPECT_EQ(L::c[0][a], 0);
  for (int i = 0; i < L::q; ++i) {
    const int o = L::opposite[i];
    EXPECT_EQ(L::opposite[o], i);
    EXPECT_DOUBLE_EQ(L::w[o], L::w[i]);
    for (int a = 0; a < L::d; ++a) EXPECT_EQ(L::c[o][a], -L::c[i][a]);
  }
}

TYPED_TEST(LatticeTest, IsotropyUpToFourthOrder) {
  using L = TypeParam;
  const double cs2 = L::cs2;
  for (int a = 0; a < L::d; ++a) {
    double m1 = 0;
    for (int i = 0; i < L::q; ++i) m1 += L::w[i] * L::c[i][a];
    EXPECT_NEAR(m1, 0.0, 1e-15);
    for (int b = 0; b < L::d; ++b) {
      double m2 = 0;
      for (int i = 0; i < L::q; ++i) m2 += L::w[i] * L::c[i][a] * L::c[i][b];
      EXPECT_NEAR(m2, a == b ? cs2 : 0.0, 1e-15);
      for (int g = 0; g < L::d; ++g) {
        double m3 = 0;
        for (int i = 0; i < L::q; ++i) m3 += L::w[i] * L::c[i][a] * L::c[i][b] * L::c[i][g];
        EXPECT_NEAR(m3, 0.0, 1e-15);
        for (int h = 0; h < L::d; ++h) {
          double m4 = 0;
          for (int i = 0; i < L::q; ++i) m4 += L::w[i] * L::c[i][a] * L::c[i][b] * L::c[i][g] * L::c[i][h];
          const double expected =
              cs2 * cs2 * ((a == b) * (g == h) + (a == g) * (b == h) + (a == h) * (b == g));
          EXPECT_NEAR(m4, expected, 1e-15) << a << b << g << h;
        }
      }
    }
  }
}

TYPED_TEST(LatticeTest, EnteringThroughAFaceIsPointingInwardsAlongItsAxis) {
  // Face 2a + s: a ghost at -1 (s = 0) or n (s = 1) along axis a and inside along the others
  // reaches the interior exactly along the directions with c_a = +1 or -1: 3 of 9 in D2Q9,
  // 5 of 19 in D3Q19 (what the far field and the two-level ghosts keep of their collision).
  using L = TypeParam;
  constexpr int n = 3;  // a box of 3 nodes per axis; the ghost in the middle of a face
  for (int face = 0; face < 2 * L::d; ++face) {
    int count = 0;
    for (int i = 0; i < L::q; ++i) {
      bool inside = true;
      for (int b = 0; b < L::d; ++b) {
        const int ghost = b != face / 2 ? 1 : face % 2 == 0 ? -1 : n;
        inside = inside && ghost + L::c[i][b] >= 0 && ghost + L::c[i][b] < n;
      }
      EXPECT_EQ(enters_through_face<L>(face, i), inside) << "face " << face << ", i " << i;
      count += enters_through_face<L>(face, i);
    }
    EXPECT_EQ(count, L::d == 2 ? 3 : 5) << "face " << face;
  }
}

}  // namespace
}  // namespace caplab::lattice
