// The inclination of an initially round capsule: its axis is noise until the capsule has
// deformed, and that noise must not pick the branch of the angle that follows.
#include <gtest/gtest.h>

#include <numbers>

#include "sim/capsule_track.hpp"

namespace caplab::sim {
namespace {

constexpr double pi = std::numbers::pi;

TEST(FollowAxis, ARoundFirstReadingDoesNotChooseTheBranch) {
  diagnostics::AngleUnwrapper unwrap(pi);
  // A round shape whose axis reads -80 degrees, then the shear's 45 degrees once it deforms.
  EXPECT_DOUBLE_EQ(follow_axis(unwrap, 0.0, -80 * pi / 180), -80 * pi / 180);
  EXPECT_DOUBLE_EQ(follow_axis(unwrap, 1e-2, pi / 4), pi / 4);  // not pi/4 - pi
  // From there on the angle is continuous: a turn past -pi/2 keeps decreasing (tumbling).
  EXPECT_DOUBLE_EQ(follow_axis(unwrap, 1e-2, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(follow_axis(unwrap, 1e-2, -1.5), -1.5);
  EXPECT_NEAR(follow_axis(unwrap, 1e-2, 1.5), 1.5 - pi, 1e-15);
}

TEST(FollowAxis, ACapsuleThatTurnsRoundForgetsItsHistory) {
  diagnostics::AngleUnwrapper unwrap(pi);
  follow_axis(unwrap, 0.1, 0.3);
  follow_axis(unwrap, 0.1, -0.4);
  follow_axis(unwrap, 0.1, -1.2);
  EXPECT_NEAR(follow_axis(unwrap, 0.1, 1.4), 1.4 - pi, 1e-15);
  follow_axis(unwrap, 0.0, 1.2);                         // round again: the axis means nothing
  EXPECT_DOUBLE_EQ(follow_axis(unwrap, 0.1, 0.5), 0.5);  // starts afresh in (-pi/2, pi/2]
}

}  // namespace
}  // namespace caplab::sim
