// IB kernels: symmetry, support, unit integral, and the discrete moment identities with
// their true tolerances (the cosine kernel's first moment is not zero, and the test shows it).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ibm/kernels.hpp"

namespace caplab::ibm {
namespace {

template <class K>
class KernelTest : public ::testing::Test {};
using Kernels = ::testing::Types<Cosine4, Roma3, Linear2>;
TYPED_TEST_SUITE(KernelTest, Kernels);

// Discrete moment sum_i (x - i)^p phi(x - i)^q over all nodes i that can be in reach.
template <class K>
double moment(double x, int p, int q = 1) {
  double s = 0.0;
  for (int i = -4; i <= 5; ++i) s += std::pow(x - i, p) * std::pow(K::phi(x - i), q);
  return s;
}

TYPED_TEST(KernelTest, EvenNonNegativeAndCompact) {
  using K = TypeParam;
  const double half = 0.5 * K::support;
  for (int k = 0; k <= 4000; ++k) {
    const double r = -3.0 + 6.0 * k / 4000;
    EXPECT_DOUBLE_EQ(K::phi(r), K::phi(-r));
    EXPECT_GE(K::phi(r), 0.0);
    if (std::abs(r) >= half) {
      EXPECT_EQ(K::phi(r), 0.0) << "r = " << r;
    }
  }
  EXPECT_GT(K::phi(half - 1e-3), 0.0);
}

TYPED_TEST(KernelTest, UnitIntegral) {
  using K = TypeParam;
  const int n = 200000;
  const double a = -0.5 * K::support, h = K::support / static_cast<double>(n);
  double s = 0.0;
  for (int k = 0; k < n; ++k) s += K::phi(a + (k + 0.5) * h) * h;
  EXPECT_NEAR(s, 1.0, 1e-8);
}

TYPED_TEST(KernelTest, DiscretePartitionOfUnityIsExact) {
  for (int k = 0; k < 1000; ++k) {
    const double x = k / 1000.0;
    EXPECT_NEAR(moment<TypeParam>(x, 0), 1.0, 2e-15) << "x = " << x;
  }
}

TYPED_TEST(KernelTest, StencilWeightsArePhiAtTheSupportNodes) {
  // weights(d, w) is what the transfer uses; w[s] = phi(d - s) for the first node d behind.
  using K = TypeParam;
  for (int k = 0; k <= 1000; ++k) {
    const double x = -1.0 + 3.0 * k / 1000;
    const double i0 = std::floor(x - 0.5 * K::support) + 1.0;
    double w[K::support];
    K::weights(x - i0, w);
    for (int s = 0; s < K::support; ++s) EXPECT_NEAR(w[s], K::phi(x - i0 - s), 2e-16) << "x = " << x << ", s = " << s;
  }
}

TEST(Roma3, FirstMomentAndSquaresExact) {
  for (int k = 0; k < 1000; ++k) {
    const double x = k / 1000.0;
    EXPECT_NEAR(moment<Roma3>(x, 1), 0.0, 2e-15);
    EXPECT_NEAR(moment<Roma3>(x, 0, 2), 0.5, 2e-15);
  }
  // Continuity at the two breakpoints.
  EXPECT_NEAR(Roma3::phi(0.5 - 1e-12), Roma3::phi(0.5 + 1e-12), 1e-9);
  EXPECT_NEAR(Roma3::phi(1.5 - 1e-12), 0.0, 1e-5);
}

TEST(Linear2, FirstMomentExact) {
  for (int k = 0; k < 1000; ++k) EXPECT_NEAR(moment<Linear2>(k / 1000.0, 1), 0.0, 2e-15);
}

TEST(Cosine4, ThesisFormulaAndSquaresExact) {
  EXPECT_DOUBLE_EQ(Cosine4::phi(0.0), 0.5);
  EXPECT_DOUBLE_EQ(Cosine4::phi(1.0), 0.25);
  EXPECT_NEAR(Cosine4::phi(2.0), 0.0, 1e-300);
  EXPECT_NEAR(Cosine4::phi(0.7), 0.25 * (1.0 + std::cos(0.35 * std::numbers::pi)), 1e-16);
  for (int k = 0; k < 1000; ++k) EXPECT_NEAR(moment<Cosine4>(k / 1000.0, 0, 2), 0.375, 2e-15);
}

TEST(Cosine4, FirstMomentIsNotZeroButBounded) {
  // sum_i (x-i) phi(x-i) = x - 1/2 + (cos(pi x/2) - sin(pi x/2)) / 2 on [0, 1): zero only at
  // x = 0, 1/2; its extremes are +-0.021106 at x = 0.2129, 0.7871.
  const double pi = std::numbers::pi;
  double worst = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double x = k / 10000.0;
    const double m1 = moment<Cosine4>(x, 1);
    EXPECT_NEAR(m1, x - 0.5 + 0.5 * (std::cos(0.5 * pi * x) - std::sin(0.5 * pi * x)), 2e-15);
    worst = std::max(worst, std::abs(m1));
  }
  EXPECT_LT(worst, 0.02115);
  EXPECT_GT(worst, 0.0210);
}

}  // namespace
}  // namespace caplab::ibm
