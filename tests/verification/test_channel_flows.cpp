// Verification against analytic solutions: body-force Poiseuille (2D, 3D) with observed
// second-order convergence, Couette flow between moving walls (exact), the decay rate
// of Taylor–Green vortices (2D, and in two planes of D3Q19), and the attenuation of a standing
// sound wave, which the bulk viscosity sets (collision::TrtBulk).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "flow_harness.hpp"

namespace caplab {
namespace {

using boundary::Kind;

/// L2 relative error of body-force Poiseuille flow in a channel of H nodes (walls half way).
template <class L, class Op>
double poiseuille_error(int H, Op op) {
  constexpr int D = L::d;
  Index<D> n;
  n.fill(4);
  n[1] = H;
  Vec<D> origin = Vec<D>::Zero();
  origin[1] = 0.5;  // walls at y = 0 and y = H
  typename sim::Fluid<L, double, Op>::Setup s;
  s.coarse = field::Grid<D>(n, origin, 1.0);
  s.boundaries.fill(Kind::periodic);
  s.boundaries[1] = Kind::wall;
  s.imposed_velocity_lu = [](const Vec<D>&) { return Vec<D>::Zero(); };
  s.coarse_op = op;
  const double nu = (op.tau - 0.5) / 3.0;
  const double umax = 0.02;
  const double g = 8.0 * nu * umax / (H * H);
  s.body_force_lu = Vec<D>::Zero();
  s.body_force_lu[0] = g;
  sim::Fluid<L, double, Op> fluid(s);
  fluid.initialise([](const Vec<D>&) { return std::pair{1.0, Vec<D>::Zero().eval()}; });
  const int steps = static_cast<int>(8.0 * H * H / nu / 10.0) + 2000;  // several viscous times
  for (int t = 0; t < steps; ++t) fluid.step();
  double num = 0, den = 0;
  for (int j = 0; j < H; ++j) {
    Index<D> ijk{};
    ijk[1] = j;
    const double y = j + 0.5;
    const double exact = g / (2 * nu) * y * (H - y);
    const double u = testing::velocity(fluid, 0, ijk)[0];
    num += (u - exact) * (u - exact);
    den += exact * exact;
  }
  return std::sqrt(num / den);
}

TEST(Poiseuille, D2Q9BgkSecondOrder) {
  const collision::Bgk op{0.8};
  const double e8 = poiseuille_error<lattice::D2Q9>(8, op);
  const double e16 = poiseuille_error<lattice::D2Q9>(16, op);
  const double order = std::log2(e8 / e16);
  EXPECT_GT(order, 1.8) << "errors " << e8 << " " << e16;
  EXPECT_LT(e16, 5e-3);
}

TEST(Poiseuille, D3Q19BgkSecondOrder) {
  const collision::Bgk op{0.8};
  const double e8 = poiseuille_error<lattice::D3Q19>(8, op);
  const double e16 = poiseuille_error<lattice::D3Q19>(16, op);
  EXPECT_GT(std::log2(e8 / e16), 1.8) << "errors " << e8 << " " << e16;
}

TEST(Poiseuille, TrtMagicThreeSixteenthsIsExact) {
  // With Λ = 3/16 half-way bounce-back puts the wall exactly half way: parabola to round-off.
  const collision::Trt op{1.4, 3.0 / 16.0};
  EXPECT_LT(poiseuille_error<lattice::D2Q9>(8, op), 1e-6);
}

TEST(Couette, LinearProfileBetweenMovingWallsIsExact) {
  using L = lattice::D2Q9;
  const int H = 10;
  const double k = 0.01 / H * 2;  // wall speeds ±0.01
  sim::Fluid<L, double, collision::Bgk>::Setup s;
  s.coarse = field::Grid<2>({4, H}, Vec<2>(0.0, 0.5), 1.0);
  s.boundaries = {Kind::periodic, Kind::wall};
  s.imposed_velocity_lu = [&](const Vec<2>& x) { return Vec<2>(k * (x[1] - 0.5 * H), 0.0); };
  s.coarse_op = collision::Bgk{0.9};
  sim::Fluid<L, double, collision::Bgk> fluid(s);
  fluid.initialise([](const Vec<2>&) { return std::pair{1.0, Vec<2>::Zero().eval()}; });
  for (int t = 0; t < 6000; ++t) fluid.step();
  for (int j = 0; j < H; ++j) {
    const double exact = k * (j + 0.5 - 0.5 * H);
    EXPECT_NEAR(testing::velocity(fluid, 0, {1, j})[0], exact, 1e-9) << j;
  }
}

/// Measured decay rate of a Taylor–Green vortex in the plane (a, b) against 2νk².
template <class L, class Op>
void taylor_green(int a, int b, Op op) {
  constexpr int D = L::d;
  const int n = 32;
  Index<D> nn;
  nn.fill(D == 3 ? 4 : n);
  nn[a] = n;
  nn[b] = n;
  sim::Fluid<L, double, Op> fluid(testing::periodic_box<L, double>(nn, op));
  const double kw = 2 * std::numbers::pi / n, u0 = 0.01;
  fluid.initialise([&](const Vec<D>& x) {
    Vec<D> u = Vec<D>::Zero();
    u[a] = -u0 * std::cos(kw * x[a]) * std::sin(kw * x[b]);
    u[b] = u0 * std::sin(kw * x[a]) * std::cos(kw * x[b]);
    const double p = -0.25 * u0 * u0 * (std::cos(2 * kw * x[a]) + std::cos(2 * kw * x[b]));
    return std::pair{1.0 + 3.0 * p, u};
  });
  auto amplitude = [&] {
    Index<D> ijk{};
    ijk[a] = n / 4;
    ijk[b] = 0;
    return testing::velocity(fluid, 0, ijk)[b];
  };
  const int steps = 400;
  for (int t = 0; t < 100; ++t) fluid.step();  // let the initial pressure/noneq transient pass
  const double A0 = amplitude();
  for (int t = 0; t < steps; ++t) fluid.step();
  const double rate = std::log(A0 / amplitude()) / steps;
  const double nu = (op.tau - 0.5) / 3.0;
  EXPECT_NEAR(rate / (2 * nu * kw * kw), 1.0, 0.01);
}

TEST(TaylorGreen, D2Q9Bgk) { taylor_green<lattice::D2Q9>(0, 1, collision::Bgk{0.8}); }
TEST(TaylorGreen, D2Q9Trt) { taylor_green<lattice::D2Q9>(0, 1, collision::Trt{0.8, 0.25}); }
TEST(TaylorGreen, D3Q19PlaneXY) { taylor_green<lattice::D3Q19>(0, 1, collision::Bgk{0.8}); }
TEST(TaylorGreen, D3Q19PlaneXZ) { taylor_green<lattice::D3Q19>(0, 2, collision::Trt{0.8, 0.25}); }
// A bulk viscosity of its own leaves a divergence-free flow alone.
TEST(TaylorGreen, D2Q9TrtBulk) { taylor_green<lattice::D2Q9>(0, 1, collision::TrtBulk{0.8, 0.25, 20.0}); }
TEST(TaylorGreen, D3Q19TrtBulk) { taylor_green<lattice::D3Q19>(0, 2, collision::TrtBulk{0.8, 0.25, 20.0}); }

/// Measured amplitude decay rate of a standing sound wave ρ' ∝ cos(k x) on a periodic box
/// against the linearised isothermal Navier–Stokes rate Γ = k²/2 [(2 − 2/D) ν + ζ/ρ], with
/// ζ/μ = `bulk_ratio` (the lattice's own 2/D for BGK and TRT). The mode's amplitude
/// A(t) = Σ ρ' cos(k x) is a damped oscillation e^{−Γt} cos(ω t + φ): Γ is the slope of
/// log |A| through its extrema (each located by a parabola through three steps). Measured
/// 1.000 (BGK, TRT), 0.994 (2D, ζ/μ = 20), 0.985 (3D, ζ/μ = 20: τ_b = 3.5, and the bulk
/// mode's own relaxation lags at ω τ_b = 0.2), 1.003 (BGK odd part, ζ/μ = 5).
template <class L, class Op>
void sound_attenuation(Op op, double bulk_ratio) {
  constexpr int D = L::d;
  const int n = 64;
  Index<D> nn;
  nn.fill(4);
  nn[0] = n;
  sim::Fluid<L, double, Op> fluid(testing::periodic_box<L, double>(nn, op));
  const double kw = 2 * std::numbers::pi / n, eps = 1e-4;
  fluid.initialise([&](const Vec<D>& x) {
    return std::pair{1.0 + eps * std::cos(kw * x[0]), Vec<D>::Zero().eval()};
  });
  auto amplitude = [&] {
    const auto& blk = fluid.block(0);
    double a = 0;
    for (int i = 0; i < n; ++i) {
      Index<D> ijk{};
      ijk[0] = i;
      const auto node = blk.pop.grid().index(ijk);
      double rho = 0;
      for (int q = 0; q < L::q; ++q) rho += blk.pop(q, node);
      a += rho * std::cos(kw * i);
    }
    return a;
  };
  std::vector<double> A;
  const double nu = (op.tau - 0.5) / 3.0;
  const double rate = 0.5 * kw * kw * ((2.0 - 2.0 / D) * nu + bulk_ratio * nu);
  const int steps = static_cast<int>(std::min(4.0 / rate, 2000.0));  // about e^-4 or 18 periods
  for (int t = 0; t < steps; ++t) {
    fluid.step();
    A.push_back(amplitude());
  }
  int extrema = 0;
  const double measured = testing::damped_oscillation_rate(A, 50, extrema);  // after the initial layer
  ASSERT_GE(extrema, 6) << "too few extrema to fit";
  EXPECT_NEAR(measured / rate, 1.0, 0.02) << "measured " << measured << " per step, expected " << rate;
}

TEST(SoundAttenuation, D2Q9BgkBulkViscosityIsTheShear) {
  sound_attenuation<lattice::D2Q9>(collision::Bgk{0.8}, 1.0);
}
TEST(SoundAttenuation, D3Q19TrtBulkViscosityIsTwoThirdsTheShear) {
  sound_attenuation<lattice::D3Q19>(collision::Trt{0.8, 0.25}, 2.0 / 3.0);
}
TEST(SoundAttenuation, D2Q9TrtBulkRatio20) {
  sound_attenuation<lattice::D2Q9>(collision::TrtBulk{0.6, 0.25, 20.0}, 20.0);
}
TEST(SoundAttenuation, D2Q9BgkBulkRatio5) {
  sound_attenuation<lattice::D2Q9>(collision::TrtBulk{0.8, 0.25, 5.0, true}, 5.0);
}
TEST(SoundAttenuation, D3Q19TrtBulkRatio20) {
  sound_attenuation<lattice::D3Q19>(collision::TrtBulk{0.6, 0.25, 20.0}, 20.0);
}

}  // namespace
}  // namespace caplab
