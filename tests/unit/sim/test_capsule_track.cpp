// The inclination of an initially round capsule: its axis is noise until the capsule has
// deformed, and that noise must not pick the branch of the angle that follows. The 3D track's
// middle cross section follows the capsule through the volume centroid.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <memory>
#include <numbers>

#include "geometry/triangle_mesh.hpp"
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

// An ellipsoid (1.6, 1, 0.7) turned by `theta` from x toward z about y, centred at c.
geometry::TriangleMesh tilted_ellipsoid(double theta, const Vec<3>& c) {
  geometry::TriangleMesh m = geometry::octahedron_sphere(3, 1.0);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(-theta, Vec<3>::UnitY()).toRotationMatrix();
  for (Vec<3>& x : m.nodes) x = c + Q * Vec<3>(1.6, 1.0, 0.7).cwiseProduct(x);
  return m;
}

TEST(CapsuleTrack3d, SectionInclinationThroughTheCentroid) {
  const Vec<3> c(3.0, 2.5, 2.0);
  const auto mesh = tilted_ellipsoid(0.4, c);
  const Capsule<3> capsule("cell", mesh.nodes, std::make_unique<membrane::FemMembrane>(mesh, membrane::NeoHookean{1.0}),
                           ibm::Transfer<3, ibm::Cosine4>());
  const CapsuleTrack<3> track(capsule, static_cast<const membrane::FemMembrane&>(capsule.membrane()), true);
  // An ellipsoid's central section in x-z is the ellipse of its x-z semi-axes: same angle.
  EXPECT_NEAR(track.value("section_inclination", capsule, 1.0), 0.4, 1e-12);
  EXPECT_NEAR(track.value("inclination", capsule, 1.0), 0.4, 1e-12);
}

}  // namespace
}  // namespace caplab::sim
