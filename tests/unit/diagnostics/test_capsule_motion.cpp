// Mode classification of capsule motion (diagnostics/capsule_motion.hpp) on synthetic
// signals whose answer is known: a steady tank-treader, an oscillating one, and Jeffery's
// orbit of a rigid ellipse (thesis eq. 3.11).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "diagnostics/capsule_motion.hpp"

namespace caplab::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

struct Signals {
  std::vector<double> t, theta;
};

template <class Theta>
Signals sample(double end, double dt, Theta&& theta) {
  Signals s;
  for (double t = 0; t <= end + 1e-12; t += dt) {
    s.t.push_back(t);
    s.theta.push_back(theta(t));
  }
  return s;
}

// Jeffery 1922 for a rigid ellipse of aspect ratio r in u = (k y, 0), k = 1: the major axis
// turns clockwise, theta(t) = -atan(r tan(r t/(1 + r^2))) continued through the branches.
double jeffery(double t, double r) {
  const double arg = r * t / (1 + r * r);
  const double branch = std::round(arg / pi);
  return -(std::atan(r * std::tan(arg - branch * pi)) + branch * pi);
}

TEST(AngleUnwrapper, FollowsAnAxisThroughManyTurns) {
  AngleUnwrapper unwrap(pi);
  double last = 0;
  for (int i = 0; i <= 1000; ++i) {
    const double truth = -0.05 * i;                                 // 50 rad clockwise
    const double axis = truth - pi * std::floor(truth / pi + 0.5);  // folded into [-pi/2, pi/2)
    last = unwrap(axis);
    ASSERT_NEAR(last, truth, 1e-12) << "sample " << i;
  }
  unwrap.reset();
  EXPECT_DOUBLE_EQ(unwrap(0.3), 0.3);
}

// The capsule tracks update their shape only every so often (sim/capsule_track.hpp,
// capsule_track_interval): the unwrapped value must not depend on the samples in between.
TEST(AngleUnwrapper, ValueDoesNotDependOnTheSamplesBetween) {
  AngleUnwrapper every(pi), sparse(pi);
  for (int i = 0; i <= 2000; ++i) {
    const double truth = -0.037 * i + 0.2 * std::sin(0.01 * i);    // about 74 rad clockwise, swinging
    const double axis = truth - pi * std::floor(truth / pi + 0.5);  // folded into [-pi/2, pi/2)
    const double dense = every(axis);
    if (i % 7 != 0) continue;
    ASSERT_EQ(sparse(axis), dense) << "sample " << i;  // the same double, not just close
  }
}

TEST(CapsuleMotion, SteadyTankTreading) {
  const auto s = sample(10, 0.01, [](double t) { return pi / 4 - 0.2 * (1 - std::exp(-t)); });
  const auto m = classify_capsule_motion(s.t, s.theta, 6);
  EXPECT_EQ(m.mode, "steady_tank_treading");
  EXPECT_FALSE(m.tumbling_period.has_value());
}

TEST(CapsuleMotion, FastMonotoneApproachIsSteady) {
  // 10 degrees of drift inside the window, but no reversal: still the transient of a steady
  // tank-treader (e.g. a short grid-study run), not an oscillation.
  const auto s = sample(4, 0.01, [](double t) { return 0.4 + 0.35 * std::exp(-t); });
  const auto m = classify_capsule_motion(s.t, s.theta, 1.0);
  EXPECT_GT(m.inclination_amplitude, 3 * pi / 180);
  EXPECT_EQ(m.inclination_reversals, 0);
  EXPECT_EQ(m.mode, "steady_tank_treading");
}

TEST(CapsuleMotion, OscillatingTankTreading) {
  const double amp = 3 * pi / 180;  // 3 degrees, above the 1 degree threshold
  const auto s = sample(20, 0.01, [&](double t) { return 0.3 + amp * std::sin(2 * t); });
  const auto m = classify_capsule_motion(s.t, s.theta, 5);
  EXPECT_EQ(m.mode, "oscillating_tank_treading");
  EXPECT_NEAR(m.inclination_amplitude, amp, 1e-4);
  EXPECT_GE(m.inclination_reversals, 8);  // sin(2t) over t in [5, 20]: 9 extremes, 8 turns between them
  // The same signal with a 0.5 degree wobble is steady.
  const auto small = sample(20, 0.01, [&](double t) { return 0.3 + amp / 6 * std::sin(2 * t); });
  EXPECT_EQ(classify_capsule_motion(small.t, small.theta, 5).mode, "steady_tank_treading");
  // ... and swinging once the threshold (a case's outputs.oscillation_threshold) is 0.25 degree,
  // i.e. a 0.5 degree reversal counts.
  EXPECT_EQ(classify_capsule_motion(small.t, small.theta, 5, 0.25 * pi / 180).mode, "oscillating_tank_treading");
}

TEST(CapsuleMotion, JefferyOrbitTumblesWithItsPeriod) {
  const double r = 2;
  const double half_period = pi * (1 + r * r) / r;  // 7.854 for r = 2
  // Window over exactly two half-turns, so the mean rate is exact.
  const auto s = sample(3 * half_period, 1e-3, [&](double t) { return jeffery(t, r); });
  const auto m = classify_capsule_motion(s.t, s.theta, half_period);
  EXPECT_EQ(m.mode, "tumbling");
  ASSERT_TRUE(m.tumbling_period.has_value());
  EXPECT_NEAR(*m.tumbling_period, half_period, 1e-3 * half_period);
  EXPECT_GT(m.inclination_turn, 2 * pi);
  // A window of 1.15 half-turns starting at an arbitrary phase: the mean rate over it is off
  // by several percent, the half-turn crossing is not.
  const auto w = sample(2.3 * half_period, 1e-3, [&](double t) { return jeffery(t, r); });
  const auto p = classify_capsule_motion(w.t, w.theta, 1.15 * half_period);
  ASSERT_TRUE(p.tumbling_period.has_value());
  EXPECT_NEAR(*p.tumbling_period, half_period, 1e-3 * half_period);
}

TEST(TankTreadingFrequency, IsTwoPiOverTheRevolutionTimeAsInThesisSection6_3_1) {
  // A node revolving once every T = 28.6/k (t in 1/k) has f/k = 2 pi/(k T) = 0.22, the
  // Tran-Son-Tay value the thesis compares with; not 1/(k T) = 0.035 (the summary reported
  // that until 2026-12-03, 2 pi too small).
  const double T = 28.6;
  const auto s = sample(100, 1e-3, [&](double t) { return -2 * std::numbers::pi * t / T; });
  const auto f = tank_treading_frequency_per_k(s.t, s.theta, 10.0);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(*f, 2 * std::numbers::pi / T, 1e-3);
  EXPECT_NEAR(*f, 0.22, 0.0005);
}

TEST(RevolutionRate, CountsWholeTurnsOfAnUnevenPhase) {
  // A node turning clockwise at the mean rate 0.3 with a 40 % modulation per revolution (as on
  // a deformed contour): whole revolutions give the mean rate exactly, whatever the window.
  const double w = 0.3;
  auto phase = [&](double t) { return -(w * t + 0.4 * std::sin(w * t)); };
  const auto s = sample(100, 1e-3, phase);
  for (const double from : {0.0, 7.3, 31.0}) {
    const auto r = revolution_rate(s.t, s.theta, from);
    ASSERT_TRUE(r.has_value()) << from;
    EXPECT_NEAR(*r, w, 2e-3 * w) << from;
  }
  // Less than one revolution in the window: no rate.
  EXPECT_FALSE(revolution_rate(s.t, s.theta, 85.0).has_value());
  EXPECT_THROW(revolution_rate(s.t, s.theta, 100.0), core::Error);
}

TEST(CapsuleMotion, RejectsShortOrMismatchedInput) {
  const std::vector<double> t{0, 1, 2, 3}, a{0, 0, 0, 0}, shorter{0, 0, 0};
  EXPECT_THROW(classify_capsule_motion(t, shorter, 0), core::Error);
  EXPECT_THROW(classify_capsule_motion(t, a, 2.5), core::Error);
}

}  // namespace
}  // namespace caplab::diagnostics
