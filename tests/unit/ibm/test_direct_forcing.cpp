// Direct forcing: zero force when the fluid already moves with the body, the slip at the
// markers shrinking with the multi-direct iterations, momentum conservation between markers
// and grid (2D, 3D, periodic wrap), torque of a rigid rotation, errors, and the
// internal-mass correction.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "geometry/marker_set.hpp"
#include "ibm/direct_forcing.hpp"
#include "ibm_test_util.hpp"

namespace caplab::ibm {
namespace {

using testing::make_grid;
using testing::sum_interior;
constexpr double pi = std::numbers::pi;

// A body of diameter d_lu lattice units at lattice centre c_lu, markers ~0.8 lattice apart.
template <int D>
geometry::MarkerSet<D> body(const field::Grid<D>& g, const Vec<D>& c_lu, double d_lu) {
  const Vec<D> c = g.origin() + g.dx() * c_lu;
  if constexpr (D == 2)
    return geometry::circle_markers(c, d_lu * g.dx(), 0.8 * g.dx());
  else
    return geometry::sphere_markers(c, d_lu * g.dx(), 0.8 * g.dx());
}

template <int D>
std::vector<double> weights_lu(const geometry::MarkerSet<D>& m, double dx) {
  std::vector<double> w(m.size());
  for (std::size_t k = 0; k < m.size(); ++k) w[k] = measure_to_lattice<D>(m.weight[k], dx);
  return w;
}

template <int D>
Vec<D> field_sum(const field::Grid<D>& g, const field::VectorField<D>& f) {
  return sum_interior<D>(g, Vec<D>(Vec<D>::Zero()), [&](const Index<D>&, std::ptrdiff_t id) {
    Vec<D> v;
    for (int a = 0; a < D; ++a) v[a] = f.comp[a][id];
    return v;
  });
}

// Smooth analytic flow and density (lattice units) on a block of n nodes per axis.
template <int D>
Vec<D> analytic_u(const Index<D>& ijk, int n) {
  Vec<D> u;
  for (int a = 0; a < D; ++a)
    u[a] = 0.05 * std::sin(2 * pi * (ijk[(a + 1) % D] + 0.5 * a) / n) + 0.01 * std::cos(2 * pi * ijk[a] / n);
  return u;
}
template <int D>
double analytic_rho(const Index<D>& ijk, int n) {
  double s = 0.0;
  for (int a = 0; a < D; ++a) s += ijk[a];
  return 1.0 + 0.02 * std::sin(2 * pi * s / n);
}

template <class T>
class DirectForcingTest : public ::testing::Test {};
template <int Dim>
struct Dimension {
  static constexpr int D = Dim;
};
using Dimensions = ::testing::Types<Dimension<2>, Dimension<3>>;
TYPED_TEST_SUITE(DirectForcingTest, Dimensions);

template <int D>
std::array<bool, D> all(bool v) {
  std::array<bool, D> p;
  p.fill(v);
  return p;
}

TYPED_TEST(DirectForcingTest, FluidMovingWithBodyGivesZeroForce) {
  constexpr int D = TypeParam::D;
  const int n = D == 2 ? 32 : 16;
  const auto g = make_grid<D>(n);
  Vec<D> c = Vec<D>::Constant(0.5 * n + 0.37);
  const auto m = body<D>(g, c, D == 2 ? 12.0 : 8.0);
  const auto w = weights_lu(m, g.dx());
  Vec<D> u0;
  for (int a = 0; a < D; ++a) u0[a] = 0.03 - 0.02 * a;
  const std::vector<Vec<D>> ud(m.size(), u0);
  for (int iterations : {1, 3}) {
    DirectForcing<D> df(iterations);
    field::VectorField<D> f(g.size());
    df.apply(
        g, all<D>(false), m.X, ud, w, [&](const Index<D>&, std::ptrdiff_t) { return u0; },
        [](const Index<D>& ijk, std::ptrdiff_t) { return 1.0 + 0.01 * ijk[0]; }, f);
    for (const auto& F : df.marker_force()) EXPECT_LT(F.norm(), 1e-14);
    EXPECT_LT(df.max_slip(), 1e-15);
    EXPECT_LT(field_sum(g, f).norm(), 1e-13);
  }
}

// Slip after the forcing, measured independently: interpolate u* + f / (2 rho) over the
// whole grid with a separate Transfer.
template <int D>
struct Slip {
  double rms, max;
};
template <int D, class Kernel>
Slip<D> measured_slip(const field::Grid<D>& g, const geometry::MarkerSet<D>& m, const std::vector<Vec<D>>& ud,
                      const field::VectorField<D>& f) {
  const int n = g.n()[0];
  Transfer<D, Kernel> t;
  t.update(g, all<D>(false), m.X);
  std::vector<Vec<D>> u(m.size());
  t.interpolate(
      [&](const Index<D>& ijk, std::ptrdiff_t id) {
        Vec<D> fx;
        for (int a = 0; a < D; ++a) fx[a] = f.comp[a][id];
        return Vec<D>(analytic_u<D>(ijk, n) + fx / (2.0 * analytic_rho<D>(ijk, n)));
      },
      u);
  Slip<D> s{0.0, 0.0};
  for (std::size_t k = 0; k < m.size(); ++k) {
    const double e = (u[k] - ud[k]).norm();
    s.rms += e * e;
    s.max = std::max(s.max, e);
  }
  s.rms = std::sqrt(s.rms / m.size());
  return s;
}

TYPED_TEST(DirectForcingTest, MultiDirectForcingReducesSlipMonotonically) {
  constexpr int D = TypeParam::D;
  const int n = D == 2 ? 40 : 20;
  const auto g = make_grid<D>(n);
  const Vec<D> c = Vec<D>::Constant(0.5 * n - 0.21);
  const auto m = body<D>(g, c, D == 2 ? 16.0 : 9.0);
  const auto w = weights_lu(m, g.dx());
  // Desired: a slow rigid rotation about the centre (about z in 3D).
  std::vector<Vec<D>> ud(m.size());
  for (std::size_t k = 0; k < m.size(); ++k) {
    const Vec<D> r = g.to_lattice(m.X[k]) - c;
    ud[k].setZero();
    ud[k][0] = -0.004 * r[1];
    ud[k][1] = 0.004 * r[0];
  }
  auto u_star = [&](const Index<D>& ijk, std::ptrdiff_t) { return analytic_u<D>(ijk, n); };
  auto rho = [&](const Index<D>& ijk, std::ptrdiff_t) { return analytic_rho<D>(ijk, n); };

  const field::VectorField<D> no_force(g.size());
  const Slip<D> initial = measured_slip<D, Cosine4>(g, m, ud, no_force);
  Slip<D> previous = initial;
  for (int iterations : {1, 2, 5}) {
    DirectForcing<D> df(iterations);
    field::VectorField<D> f(g.size());
    df.apply(g, all<D>(false), m.X, ud, w, u_star, rho, f);
    const Slip<D> s = measured_slip<D, Cosine4>(g, m, ud, f);
    EXPECT_NEAR(df.max_slip(), s.max, 1e-14);
    EXPECT_LT(s.rms, previous.rms) << iterations << " iterations";
    EXPECT_LT(s.max, previous.max) << iterations << " iterations";
    previous = s;
  }
  // A smooth slip contracts by ~1 - sum phi^2 = 5/8 per iteration with the cosine kernel
  // (the spread force of a marker sheet is a 1D kernel across it): 0.625^5 = 0.095.
  EXPECT_LT(previous.rms, 0.15 * initial.rms);
}

TYPED_TEST(DirectForcingTest, TotalForceEqualsSpreadFieldIncludingPeriodicWrap) {
  constexpr int D = TypeParam::D;
  const int n = D == 2 ? 32 : 16;
  const auto g = make_grid<D>(n);
  // The body straddles the corner of the periodic block.
  const Vec<D> c = Vec<D>::Constant(0.4);
  const auto m = body<D>(g, c, D == 2 ? 10.0 : 6.0);
  const auto w = weights_lu(m, g.dx());
  std::vector<Vec<D>> ud(m.size(), Vec<D>::Zero());
  ud[0][0] = 0.01;
  DirectForcing<D, Roma3> df(3);
  field::VectorField<D> f(g.size());
  df.apply(
      g, all<D>(true), m.X, ud, w, [&](const Index<D>& ijk, std::ptrdiff_t) { return analytic_u<D>(ijk, n); },
      [&](const Index<D>& ijk, std::ptrdiff_t) { return analytic_rho<D>(ijk, n); }, f);
  const Vec<D> total = df.total_force_on_fluid();
  EXPECT_GT(total.norm(), 1e-3);
  EXPECT_NEAR((field_sum(g, f) - total).norm(), 0.0, 1e-13 * m.size());
  // The same body without wrap is an error naming the block edge.
  EXPECT_THROW(
      df.apply(
          g, all<D>(false), m.X, ud, w, [](const Index<D>&, std::ptrdiff_t) { return Vec<D>::Zero(); },
          [](const Index<D>&, std::ptrdiff_t) { return 1.0; }, f),
      core::Error);
}

TEST(DirectForcingTorque, RigidRotation2D) {
  // Fluid at rest, rho = 1, one iteration: F_m = 2 U_d, so the torque on the fluid about the
  // centre is 2 omega r^2 times the perimeter (lattice units).
  const auto g = make_grid<2>(40, 0.5);
  const Vec<2> c_lu(19.6, 20.3);
  const double r = 7.0, omega = 0.003;
  const auto m = body<2>(g, c_lu, 2 * r);
  const auto w = weights_lu(m, g.dx());
  std::vector<Vec<2>> ud(m.size());
  for (std::size_t k = 0; k < m.size(); ++k) {
    const Vec<2> d = g.to_lattice(m.X[k]) - c_lu;
    ud[k] = omega * Vec<2>(-d[1], d[0]);
  }
  auto zero = [](const Index<2>&, std::ptrdiff_t) { return Vec<2>::Zero(); };
  auto one = [](const Index<2>&, std::ptrdiff_t) { return 1.0; };
  const Vec<2> centre = g.origin() + g.dx() * c_lu;
  DirectForcing<2, Roma3> roma(1);
  field::VectorField<2> f(g.size());
  roma.apply(g, {false, false}, m.X, ud, w, zero, one, f);
  EXPECT_NEAR(roma.torque_on_fluid(centre), 2.0 * omega * r * r * 2.0 * pi * r, 1e-12);
  EXPECT_LT(roma.total_force_on_fluid().norm(), 1e-14);
  // Angular momentum put into the grid equals the marker torque exactly for a kernel with a
  // vanishing first moment.
  const double grid_torque = sum_interior<2>(g, 0.0, [&](const Index<2>& ij, std::ptrdiff_t id) {
    return (ij[0] - c_lu[0]) * f.comp[1][id] - (ij[1] - c_lu[1]) * f.comp[0][id];
  });
  EXPECT_NEAR(grid_torque, roma.torque_on_fluid(centre), 1e-12);

  // The cosine kernel: same marker torque, grid angular momentum off by at most the first-moment
  // error 0.02115 times sum |F| w per axis.
  DirectForcing<2, Cosine4> cosine(1);
  field::VectorField<2> fc(g.size());
  cosine.apply(g, {false, false}, m.X, ud, w, zero, one, fc);
  EXPECT_NEAR(cosine.torque_on_fluid(centre), roma.torque_on_fluid(centre), 1e-12);
  double bound = 0.0;
  for (std::size_t k = 0; k < m.size(); ++k) bound += 0.02115 * cosine.marker_force()[k].lpNorm<1>() * w[k];
  const double grid_torque_c = sum_interior<2>(g, 0.0, [&](const Index<2>& ij, std::ptrdiff_t id) {
    return (ij[0] - c_lu[0]) * fc.comp[1][id] - (ij[1] - c_lu[1]) * fc.comp[0][id];
  });
  EXPECT_LT(std::abs(grid_torque_c - cosine.torque_on_fluid(centre)), bound);
}

TEST(DirectForcingTorque, RigidRotation3D) {
  // F_m = 2 Omega x r: torque 2 sum w (r^2 Omega - (r.Omega) r) = (4/3) r^2 A Omega for an
  // isotropic marker distribution (the golden spiral is isotropic to ~1e-3).
  const auto g = make_grid<3>(20, 0.5);
  const Vec<3> c_lu(9.7, 10.1, 10.2);
  const double r = 5.0;
  const Vec<3> omega(0.001, -0.002, 0.003);
  const auto m = body<3>(g, c_lu, 2 * r);
  const auto w = weights_lu(m, g.dx());
  std::vector<Vec<3>> ud(m.size());
  for (std::size_t k = 0; k < m.size(); ++k) ud[k] = omega.cross(Vec<3>(g.to_lattice(m.X[k]) - c_lu));
  DirectForcing<3> df(1);
  field::VectorField<3> f(g.size());
  df.apply(
      g, {false, false, false}, m.X, ud, w, [](const Index<3>&, std::ptrdiff_t) { return Vec<3>::Zero(); },
      [](const Index<3>&, std::ptrdiff_t) { return 1.0; }, f);
  const Vec<3> expected = 4.0 / 3.0 * r * r * (4.0 * pi * r * r) * omega;
  const Vec<3> torque = df.torque_on_fluid(g.origin() + g.dx() * c_lu);
  EXPECT_LT((torque - expected).norm(), 5e-3 * expected.norm());
  EXPECT_LT(df.total_force_on_fluid().norm(), 1e-2 * 2.0 * omega.norm() * r * 4.0 * pi * r * r);
}

TEST(DirectForcingBuffers, RepeatedApplyReusesStorage) {
  const auto g = make_grid<2>(32);
  const auto m = body<2>(g, Vec<2>(16.2, 15.9), 10.0);
  const auto w = weights_lu(m, g.dx());
  const std::vector<Vec<2>> ud(m.size(), Vec<2>(0.01, 0.0));
  auto zero = [](const Index<2>&, std::ptrdiff_t) { return Vec<2>::Zero(); };
  auto one = [](const Index<2>&, std::ptrdiff_t) { return 1.0; };
  DirectForcing<2> df(2);
  field::VectorField<2> f(g.size());
  const auto* first = df.apply(g, {false, false}, m.X, ud, w, zero, one, f).data();
  const auto* second = df.apply(g, {false, false}, m.X, ud, w, zero, one, f).data();
  EXPECT_EQ(first, second);
  EXPECT_THROW(DirectForcing<2>(0), core::Error);
}

TEST(DirectForcingErrors, NonPositiveDensityIsReported) {
  const auto g = make_grid<2>(32);
  const auto m = body<2>(g, Vec<2>(16.2, 15.9), 10.0);
  const auto w = weights_lu(m, g.dx());
  const std::vector<Vec<2>> ud(m.size(), Vec<2>::Zero());
  DirectForcing<2> df(1);
  field::VectorField<2> f(g.size());
  try {
    df.apply(
        g, {false, false}, m.X, ud, w, [](const Index<2>&, std::ptrdiff_t) { return Vec<2>::Zero(); },
        [](const Index<2>& ij, std::ptrdiff_t) { return ij[0] == 20 ? -1.0 : 1.0; }, f);
    FAIL() << "expected core::Error";
  } catch (const core::Error& e) {
    EXPECT_NE(std::string(e.what()).find("density -1"), std::string::npos) << e.what();
  }
}

TEST(InternalMass, RigidAndIntegratedFormsAgree) {
  // 2D disk of radius 5 accelerating at a, spinning up at alpha, with inner fluid rho.
  const double rho = 1.02, r = 5.0;
  const Vec<2> f_fluid(0.3, -0.1), a(1e-4, 2e-4);
  const double v = ball_volume<2>(r);
  EXPECT_DOUBLE_EQ(v, pi * 25.0);
  const Vec<2> rigid = rigid_body_force<2>(f_fluid, rho, v, a);
  EXPECT_NEAR((rigid - (-f_fluid + rho * v * a)).norm(), 0.0, 1e-16);
  const Vec<2> u_before(0.01, 0.02);
  const Vec<2> integrated = body_load_from_internal_momentum<Vec<2>>(
      f_fluid, Vec<2>(rho * v * (u_before + a)), Vec<2>(rho * v * u_before));
  EXPECT_NEAR((rigid - integrated).norm(), 0.0, 1e-14);

  const double i2 = ball_second_moment<2>(r), alpha = 3e-5;
  EXPECT_DOUBLE_EQ(i2, 0.5 * pi * 625.0);
  EXPECT_DOUBLE_EQ(rigid_body_torque(0.2, rho, i2, alpha), -0.2 + rho * i2 * alpha);

  // 3D: isotropic inertia has no gyroscopic term; an anisotropic one does.
  const Vec<3> t_fluid(0.1, 0.2, 0.3), alpha3(1e-5, 0, 2e-5), omega(0.01, 0.02, 0.0);
  const Eigen::Matrix3d iso = ball_second_moment<3>(r) * Eigen::Matrix3d::Identity();
  EXPECT_NEAR((rigid_body_torque(t_fluid, rho, iso, alpha3, omega) - (-t_fluid + rho * iso * alpha3)).norm(),
              0.0, 1e-14);
  const Eigen::Matrix3d aniso = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  const Vec<3> gyro = omega.cross(Vec<3>(aniso * omega));
  EXPECT_GT(gyro.norm(), 0.0);
  EXPECT_NEAR(
      (rigid_body_torque(t_fluid, rho, aniso, alpha3, omega) - (-t_fluid + rho * (aniso * alpha3 + gyro)))
          .norm(),
      0.0, 1e-15);
  // Torque helper: r x F.
  EXPECT_DOUBLE_EQ(cross<2>(Vec<2>(2.0, 0.0), Vec<2>(0.0, 3.0)), 6.0);
}

}  // namespace
}  // namespace caplab::ibm
