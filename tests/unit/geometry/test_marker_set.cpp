// Marker sets: weights sum to the perimeter / area, points lie on the shape, spacing close
// to the target; bad arguments are rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/error.hpp"
#include "geometry/marker_set.hpp"

namespace caplab::geometry {
namespace {

constexpr double pi = std::numbers::pi;

TEST(CircleMarkers, CountWeightsAndPositions) {
  const Vec<2> c(1.5, -2.0);
  const double d = 20.0, spacing = 0.79;
  const auto m = circle_markers(c, d, spacing);
  const int n = static_cast<int>(std::ceil(pi * d / spacing));
  ASSERT_EQ(m.size(), static_cast<std::size_t>(n));
  ASSERT_EQ(m.weight.size(), m.size());
  EXPECT_NEAR(m.total_weight(), pi * d, 1e-12 * pi * d);
  for (std::size_t k = 0; k < m.size(); ++k) {
    EXPECT_NEAR((m.X[k] - c).norm(), 0.5 * d, 1e-12);
    EXPECT_DOUBLE_EQ(m.weight[k], pi * d / n);
    const double chord = (m.X[(k + 1) % m.size()] - m.X[k]).norm();
    EXPECT_LE(chord, spacing);
    EXPECT_GT(chord, 0.97 * spacing);
  }
}

double ramanujan_perimeter(double a, double b) {
  const double h = (a - b) * (a - b) / ((a + b) * (a + b));
  return pi * (a + b) * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
}

TEST(EllipseMarkers, PerimeterMatchesRamanujanAndCircle) {
  EXPECT_NEAR(ellipse_perimeter(3.0, 3.0), 6.0 * pi, 1e-12);
  // Ramanujan's second approximation is accurate to ~1e-10 relative at b/a = 1/2.
  EXPECT_NEAR(ellipse_perimeter(20.0, 10.0) / ramanujan_perimeter(20.0, 10.0), 1.0, 1e-9);
  // A case the comparator must reject: a 1% different ellipse.
  EXPECT_GT(std::abs(ellipse_perimeter(20.0, 10.1) / ramanujan_perimeter(20.0, 10.0) - 1.0), 1e-3);
}

TEST(EllipseMarkers, OnShapeEquallySpacedInArcLength) {
  const Vec<2> c(4.0, 5.0);
  const double a = 20.0, b = 10.0, angle = 0.3, spacing = 0.8;
  const auto m = ellipse_markers(c, a, b, angle, spacing);
  const double p = ellipse_perimeter(a, b);
  ASSERT_EQ(m.size(), static_cast<std::size_t>(std::ceil(p / spacing)));
  EXPECT_NEAR(m.total_weight(), p, 1e-12 * p);
  const double h = p / m.size();
  const double ca = std::cos(angle), sa = std::sin(angle);
  for (std::size_t k = 0; k < m.size(); ++k) {
    const Vec<2> r = m.X[k] - c;
    const double xb = ca * r[0] + sa * r[1], yb = -sa * r[0] + ca * r[1];
    EXPECT_NEAR(xb * xb / (a * a) + yb * yb / (b * b), 1.0, 1e-12);
    EXPECT_DOUBLE_EQ(m.weight[k], h);
    // Arc between neighbours by a fine polyline, compared with h.
    const Vec<2> p0 = m.X[k], p1 = m.X[(k + 1) % m.size()];
    const double t0 =
        std::atan2((-sa * (p0 - c)[0] + ca * (p0 - c)[1]) / b, (ca * (p0 - c)[0] + sa * (p0 - c)[1]) / a);
    double t1 =
        std::atan2((-sa * (p1 - c)[0] + ca * (p1 - c)[1]) / b, (ca * (p1 - c)[0] + sa * (p1 - c)[1]) / a);
    if (t1 < t0) t1 += 2.0 * pi;
    double arc = 0.0;
    const int sub = 2000;
    for (int q = 0; q < sub; ++q) {
      const double ta = t0 + (t1 - t0) * q / sub, tb = t0 + (t1 - t0) * (q + 1) / sub;
      arc += std::hypot(a * (std::cos(tb) - std::cos(ta)), b * (std::sin(tb) - std::sin(ta)));
    }
    EXPECT_NEAR(arc, h, 1e-6 * h);
  }
  // First marker at the end of the rotated a axis.
  EXPECT_NEAR((m.X[0] - c - a * Vec<2>(ca, sa)).norm(), 0.0, 1e-12);
}

TEST(SphereMarkers, AreaOnSphereAndSpacing) {
  const Vec<3> c(1.0, 2.0, 3.0);
  const double d = 20.0, spacing = 0.9;
  const auto m = sphere_markers(c, d, spacing);
  ASSERT_EQ(m.weight.size(), m.size());
  EXPECT_NEAR(m.total_weight(), pi * d * d, 1e-10 * pi * d * d);
  for (std::size_t k = 0; k < m.size(); ++k) EXPECT_NEAR((m.X[k] - c).norm(), 0.5 * d, 1e-12);
  // The golden spiral is not a hexagonal packing: at the hexagonal density the distance to
  // the nearest neighbour is 0.81..0.93 of the target and the mean distance to the six
  // nearest neighbours (the typical mesh edge) is within a few percent of it.
  double mean_nn = 0.0, mean_six = 0.0, lo = std::numeric_limits<double>::max(), hi = 0.0;
  std::vector<double> dist;
  for (std::size_t k = 0; k < m.size(); ++k) {
    dist.clear();
    for (std::size_t l = 0; l < m.size(); ++l)
      if (l != k) dist.push_back((m.X[k] - m.X[l]).norm());
    std::partial_sort(dist.begin(), dist.begin() + 6, dist.end());
    mean_nn += dist[0];
    for (int q = 0; q < 6; ++q) mean_six += dist[q] / 6.0;
    lo = std::min(lo, dist[0]);
    hi = std::max(hi, dist[0]);
  }
  mean_nn /= m.size();
  mean_six /= m.size();
  EXPECT_NEAR(mean_six / spacing, 1.0, 0.05);
  EXPECT_NEAR(mean_nn / spacing, 0.89, 0.03);
  EXPECT_GT(lo, 0.75 * spacing);
  EXPECT_LT(hi, spacing);
}

TEST(MarkerShapes, RejectBadArguments) {
  EXPECT_THROW(circle_markers(Vec<2>::Zero(), -1.0, 0.5), core::Error);
  EXPECT_THROW(circle_markers(Vec<2>::Zero(), 1.0, 0.0), core::Error);
  EXPECT_THROW(ellipse_markers(Vec<2>::Zero(), 1.0, 0.0, 0.0, 0.5), core::Error);
  EXPECT_THROW(sphere_markers(Vec<3>::Zero(), std::nan(""), 0.5), core::Error);
}

}  // namespace
}  // namespace caplab::geometry
