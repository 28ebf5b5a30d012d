// Shape diagnostics of 3D capsules: exact second moments of a scaled octahedron, the
// equivalent ellipsoid of sphere and ellipsoid meshes (semi-axes with their convergence, D_xz,
// inclination at several angles, translation invariance, a long axis along the vorticity axis),
// rejection of inward surfaces, sections with a plane y = y0 and their equivalent ellipse, and
// the local area change.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "diagnostics/shape3d.hpp"
#include "geometry/triangle_mesh.hpp"

namespace caplab::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;
using geometry::TriangleMesh;

// Rotation by `angle` about y taking +x toward +z, and about z taking +x toward +y.
Eigen::Matrix3d about_y(double angle) {
  return Eigen::AngleAxisd(-angle, Vec<3>::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d about_z(double angle) { return Eigen::AngleAxisd(angle, Vec<3>::UnitZ()).toRotationMatrix(); }

// The mesh's nodes scaled by `semi` along x, y, z, then rotated by Q and moved by `shift`.
TriangleMesh transformed(TriangleMesh m, const Vec<3>& semi, const Eigen::Matrix3d& Q,
                         const Vec<3>& shift = Vec<3>::Zero()) {
  for (Vec<3>& x : m.nodes) x = shift + Q * semi.cwiseProduct(x);
  return m;
}

EquivalentEllipsoid ellipsoid_of(const TriangleMesh& m) { return equivalent_ellipsoid(m.nodes, m.triangles); }

TEST(Shape3d, ScaledOctahedronMomentsAreExact) {
  // |x| + |y| + |z| <= 1: V = 4/3 and ∫ x² dV = 2/15, so every semi-axis is sqrt(5 (2/15) / (4/3))
  // = sqrt(1/2); scaling by (a1, a2, a3) scales them alike.
  const Vec<3> semi(3.0, 2.0, 0.5), shift(-4.0, 1.0, 2.0);
  const auto e = ellipsoid_of(
      transformed(geometry::octahedron_sphere(0, 1.0), semi, Eigen::Matrix3d::Identity(), shift));
  EXPECT_NEAR(e.volume, 4.0 / 3.0 * semi.prod(), 1e-13);
  EXPECT_NEAR((e.center - shift).norm(), 0.0, 1e-14);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(e.semi_axes[k], std::sqrt(0.5) * semi[k], 1e-14);
    EXPECT_NEAR(e.axes[k].dot(Vec<3>::Unit(k)), 1.0, 1e-14) << "axes along x, y, z with positive signs";
  }
  EXPECT_NEAR(e.taylor_xz, (3.0 - 0.5) / (3.0 + 0.5), 1e-14);  // y (2.0) is the vorticity axis
  EXPECT_DOUBLE_EQ(e.inclination, 0.0);
}

TEST(Shape3d, SphereIsRound) {
  const TriangleMesh m = geometry::octahedron_sphere(5, 1.0);
  const auto e = ellipsoid_of(m);
  EXPECT_LT(e.taylor_xz, 1e-12);  // the octahedral mesh has cubic symmetry: M is isotropic
  EXPECT_DOUBLE_EQ(e.volume, geometry::enclosed_volume(m.nodes, m.triangles));
  EXPECT_NEAR(e.volume, 4.0 / 3.0 * pi, 5e-3 * 4.0 / 3.0 * pi);
  EXPECT_NEAR(e.center.norm(), 0.0, 1e-14);
  for (double a : e.semi_axes) EXPECT_NEAR(a, 1.0, 5e-3);
}

TEST(Shape3d, EllipsoidSemiAxesTaylorAndInclination) {
  const Vec<3> semi(1.6, 1.0, 0.7);
  const double D = (1.6 - 0.7) / (1.6 + 0.7);
  const TriangleMesh sphere = geometry::octahedron_sphere(4, 1.0);
  for (double theta : {0.0, 0.3, -0.7, 0.5 * pi - 1e-3, -0.5 * pi + 1e-3, 0.5 * pi}) {
    const auto e = ellipsoid_of(transformed(sphere, semi, about_y(theta)));
    EXPECT_NEAR(e.taylor_xz, D, 1e-13) << "theta " << theta;
    // An axis has no direction: compare modulo pi (exactly +-pi/2 may come out either way).
    EXPECT_NEAR(std::sin(e.inclination - theta), 0.0, 1e-12) << "theta " << theta;
    EXPECT_GT(e.inclination, -0.5 * pi);
    EXPECT_LE(e.inclination, 0.5 * pi);
    if (std::abs(theta) < 0.5 * pi - 1e-4) {
      EXPECT_NEAR(e.inclination, theta, 1e-12);
    }
    EXPECT_NEAR(std::abs(e.axes[0].dot(Vec<3>(std::cos(theta), 0, std::sin(theta)))), 1.0, 1e-13);
    EXPECT_NEAR(std::abs(e.axes[1][1]), 1.0, 1e-13);
    // The mesh is a linear image of the sphere mesh, whose moments are isotropic: the semi-axes
    // are semi times one common factor (the sphere mesh's equivalent radius).
    const double f = e.semi_axes[0] / semi[0];
    for (int k = 1; k < 3; ++k) EXPECT_NEAR(e.semi_axes[k] / semi[k], f, 1e-13);
  }
  // The semi-axes converge to (a1, a2, a3) at second order.
  std::vector<double> err;
  for (int n = 3; n <= 6; ++n) {
    const auto e = ellipsoid_of(transformed(geometry::octahedron_sphere(n, 1.0), semi, about_y(0.3)));
    double worst = 0;
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(e.semi_axes[k] / semi[k] - 1.0));
    err.push_back(worst);
  }
  for (std::size_t k = 1; k + 1 < err.size(); ++k) {
    const double p = std::log2(err[k] / err[k + 1]);
    std::cout << "ellipsoid semi-axes n = " << k + 3 << " -> " << k + 4 << ": relative error " << err[k]
              << " -> " << err[k + 1] << " (order " << p << ")\n";
    RecordProperty("semi_axes_order_n" + std::to_string(k + 3), std::to_string(p));
    EXPECT_NEAR(p, 2.0, 0.1);
  }
}

TEST(Shape3d, TranslationInvariance) {
  const TriangleMesh base =
      transformed(geometry::oblate_spheroid(4, 0.5, 1.0), Vec<3>(1.3, 1.0, 0.8), about_y(0.45));
  const Vec<3> shift(120.0, -35.0, 7.5);
  const TriangleMesh moved = transformed(base, Vec<3>::Ones(), Eigen::Matrix3d::Identity(), shift);
  const auto a = ellipsoid_of(base), b = ellipsoid_of(moved);
  EXPECT_NEAR((b.center - a.center - shift).norm(), 0.0, 1e-11);
  EXPECT_NEAR(b.volume / a.volume, 1.0, 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.semi_axes[k] / a.semi_axes[k], 1.0, 1e-11);
  EXPECT_NEAR(b.taylor_xz, a.taylor_xz, 1e-11);
  EXPECT_NEAR(b.inclination, a.inclination, 1e-11);
  EXPECT_GT(a.taylor_xz, 0.1);
}

TEST(Shape3d, LongAxisAlongTheVorticityAxis) {
  // Semi-axes (2, 1, 0.5) turned about z: the long axis leaves the shear plane, and D_xz comes
  // from the other two, (1 − 0.5)/(1 + 0.5), whether the long axis lies along y or only nearest to it.
  const Vec<3> semi(2.0, 1.0, 0.5);
  const TriangleMesh sphere = geometry::octahedron_sphere(4, 1.0);
  for (double phi : {0.5 * pi, 1.2}) {
    const auto e = ellipsoid_of(transformed(sphere, semi, about_z(phi)));
    EXPECT_NEAR(e.taylor_xz, 1.0 / 3.0, 1e-13) << "phi " << phi;
    EXPECT_NEAR(e.inclination, 0.0, 1e-12) << "phi " << phi;
  }
  // Long axis along y, then the shear-plane axes turned by 0.4 about y.
  const auto e = ellipsoid_of(transformed(sphere, semi, about_y(0.4) * about_z(0.5 * pi)));
  EXPECT_NEAR(e.taylor_xz, 1.0 / 3.0, 1e-13);
  EXPECT_NEAR(e.inclination, 0.4, 1e-12);
  EXPECT_NEAR(std::abs(e.axes[0][1]), 1.0, 1e-13);
}

TEST(Shape3d, RejectsInwardSurfaces) {
  TriangleMesh m = geometry::octahedron_sphere(2, 1.0);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(ellipsoid_of(m), core::Error);
  EXPECT_THROW(equivalent_ellipsoid(m.nodes, {}), core::Error);
}

// Segments must chain into closed loops: every start point is the end point of exactly one segment.
void expect_closed_contours(const std::vector<std::array<Vec<3>, 2>>& segments) {
  std::map<std::array<double, 3>, int> starts, ends;
  for (const auto& s : segments) {
    ++starts[{s[0][0], s[0][1], s[0][2]}];
    ++ends[{s[1][0], s[1][1], s[1][2]}];
  }
  EXPECT_EQ(starts.size(), segments.size());
  EXPECT_EQ(starts, ends);
}

// Signed area of the contour in (x, z) coordinates, positive counter-clockwise from +x toward +z.
double section_area(const std::vector<std::array<Vec<3>, 2>>& segments) {
  double twice = 0;
  for (const auto& s : segments) twice += s[0][0] * s[1][2] - s[1][0] * s[0][2];
  return 0.5 * twice;
}

TEST(Shape3d, SphereSectionThroughTheCentre) {
  const double r = 1.5;
  const int n = 4, N = 1 << n;
  const TriangleMesh m = geometry::octahedron_sphere(n, r);
  const auto segments = shear_plane_section(m.nodes, m.triangles, 0.0);
  // y = 0 runs along mesh edges: 4 N edges of the great circle, each once, ends on the sphere.
  EXPECT_EQ(segments.size(), static_cast<std::size_t>(4 * N));
  for (const auto& s : segments)
    for (const Vec<3>& p : s) {
      EXPECT_NEAR(p.norm(), r, 1e-14);
      EXPECT_EQ(p[1], 0.0);
    }
  expect_closed_contours(segments);
  // The contour is the polygon through the projections of the octahedron's grid points
  // (i, 0, N − i), i = 0 .. N, in each quadrant (not equally spaced).
  double polygon = 0;
  for (int i = 0; i < N; ++i) {
    const Vec<3> p = Vec<3>(i, 0, N - i).normalized(), q = Vec<3>(i + 1, 0, N - i - 1).normalized();
    polygon += 4 * 0.5 * r * r * p.cross(q).norm();
  }
  EXPECT_NEAR(section_area(segments), polygon, 1e-13);
  EXPECT_NEAR(polygon / (pi * r * r), 1.0, 1e-2);
}

TEST(Shape3d, SphereSectionOffTheMeshLines) {
  const double r = 1.0, y0 = 0.37;
  const Vec<3> c(0.2, 0.1, -0.3);
  const TriangleMesh m =
      transformed(geometry::octahedron_sphere(5, r), Vec<3>::Ones(),
                  Eigen::AngleAxisd(0.3, Vec<3>(1, 2, 3).normalized()).toRotationMatrix(), c);
  const auto segments = shear_plane_section(m.nodes, m.triangles, y0);
  ASSERT_GT(segments.size(), 50u);
  // End points lie on mesh edges (chords of length <= h): between sqrt(rho² − h²/4) and rho from the axis.
  const double rho = std::sqrt(r * r - (y0 - c[1]) * (y0 - c[1]));
  double h = 0;  // longest edge
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) h = std::max(h, (m.nodes[t[k]] - m.nodes[t[(k + 1) % 3]]).norm());
  for (const auto& s : segments)
    for (const Vec<3>& p : s) {
      const double radius = std::hypot(p[0] - c[0], p[2] - c[2]);
      EXPECT_LE(radius, rho + 1e-12);
      EXPECT_GE(radius, std::sqrt(rho * rho - h * h / 4));
      EXPECT_NEAR(p[1], y0, 1e-15);
    }
  expect_closed_contours(segments);
  EXPECT_NEAR(section_area(segments) / (pi * rho * rho), 1.0, 5e-3);
  EXPECT_TRUE(shear_plane_section(m.nodes, m.triangles, 2.0).empty());  // misses the sphere
}

TEST(Shape3d, SectionEllipseOfATiltedEllipsoid) {
  // The section y = 0 of the sphere mesh runs along mesh edges and has the octahedron's
  // four-fold symmetry, so its second moments are isotropic; scaling by (1.6, 1, 0.7) and
  // turning about y map the plane y = 0 onto itself, so the section's ellipse has exactly the
  // ratio 1.6 : 0.7 and the tilt.
  const Vec<3> semi(1.6, 1.0, 0.7), shift(0.5, -0.25, 2.0);
  const TriangleMesh sphere = geometry::octahedron_sphere(4, 1.0);
  for (double theta : {0.0, 0.3, -0.7, 1.2}) {
    const TriangleMesh m = transformed(sphere, semi, about_y(theta), shift);
    const auto e = shear_plane_section_ellipse(m.nodes, m.triangles, shift[1]);
    EXPECT_NEAR(e.taylor, (1.6 - 0.7) / (1.6 + 0.7), 1e-13) << "theta " << theta;
    EXPECT_NEAR(e.inclination, theta, 1e-13) << "theta " << theta;
    EXPECT_NEAR((e.centroid - Vec<2>(shift[0], shift[2])).norm(), 0.0, 1e-13);
    // Same angle as the ellipsoid's (x toward z).
    EXPECT_NEAR(e.inclination, ellipsoid_of(m).inclination, 1e-12);
  }
  const TriangleMesh m = transformed(sphere, semi, about_y(0.3), shift);
  EXPECT_THROW(shear_plane_section_ellipse(m.nodes, m.triangles, shift[1] + 1.5), core::Error);  // misses it
}

TEST(Shape3d, MaxAreaChange) {
  const TriangleMesh m = geometry::octahedron_sphere(3, 1.0);
  std::vector<double> A0(m.triangles.size());
  geometry::triangle_areas(m.nodes, m.triangles, A0);
  EXPECT_NEAR(max_area_change(m.nodes, m.triangles, A0), 0.0, 1e-15);
  const TriangleMesh doubled = transformed(m, Vec<3>::Constant(2.0), Eigen::Matrix3d::Identity());
  EXPECT_NEAR(max_area_change(doubled.nodes, m.triangles, A0), 3.0, 1e-13);
  A0.pop_back();
  EXPECT_THROW(max_area_change(m.nodes, m.triangles, A0), core::Error);
}

}  // namespace
}  // namespace caplab::diagnostics
