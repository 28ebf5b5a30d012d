// Polygon shape diagnostics: exact area/centroid/moments of a rectangle, the equivalent
// ellipse of sampled circles and ellipses (Taylor parameter, semi-axes, inclination), the same
// from a region's boundary edges in any order (also a region with a hole), and rejection of
// clockwise polygons.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/error.hpp"
#include "diagnostics/shape2d.hpp"
#include "geometry/closed_curve.hpp"

namespace caplab::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

// Ellipse with semi-axes a (rotated body x) and b, sampled at equal parameter steps.
std::vector<Vec<2>> ellipse(const Vec<2>& c, double a, double b, double angle, int n) {
  std::vector<Vec<2>> X;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * pi * k / n;
    const double x = a * std::cos(t), y = b * std::sin(t);
    X.push_back(c +
                Vec<2>(std::cos(angle) * x - std::sin(angle) * y, std::sin(angle) * x + std::cos(angle) * y));
  }
  return X;
}

TEST(Shape2d, SquareAndRectangleAreExact) {
  const std::vector<Vec<2>> square = {{1, 1}, {3, 1}, {3, 3}, {1, 3}};
  EXPECT_DOUBLE_EQ(geometry::polygon_area(square), 4.0);
  EXPECT_DOUBLE_EQ(polygon_perimeter(square), 8.0);
  const auto e = equivalent_ellipse(square);
  EXPECT_DOUBLE_EQ(e.area, 4.0);
  EXPECT_NEAR((e.centroid - Vec<2>(2, 2)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(e.taylor, 0.0, 1e-15);
  // Square of side 2: J = diag(4/3, 4/3); equivalent circle radius (4/pi)^(1/4) (4/3)^(1/4).
  EXPECT_NEAR(e.length, std::pow(16.0 / (3 * pi), 0.25), 1e-14);

  // Rectangle of width w = 4 (along x) and height h = 2: Jxx = h w^3 / 12, Jyy = w h^3 / 12.
  const std::vector<Vec<2>> rect = {{-1, -1}, {3, -1}, {3, 1}, {-1, 1}};  // w = 4, h = 2, centre (1, 0)
  const auto J = area_second_moment(rect);
  EXPECT_NEAR(J(0, 0), 2.0 * 64.0 / 12.0, 1e-13);
  EXPECT_NEAR(J(1, 1), 4.0 * 8.0 / 12.0, 1e-13);
  EXPECT_NEAR(J(0, 1), 0.0, 1e-13);
  EXPECT_NEAR((polygon_centroid(rect) - Vec<2>(1, 0)).norm(), 0.0, 1e-15);
  const auto r = equivalent_ellipse(rect);
  EXPECT_NEAR(r.taylor, (std::sqrt(J(0, 0)) - std::sqrt(J(1, 1))) / (std::sqrt(J(0, 0)) + std::sqrt(J(1, 1))),
              1e-15);
  EXPECT_NEAR(r.taylor, 1.0 / 3.0, 1e-14);  // sqrt ratio of moments = w / h = 2
  EXPECT_DOUBLE_EQ(r.inclination, 0.0);
}

TEST(Shape2d, MomentsAboutTheCentroidNotTheVertexMean) {
  // Right triangle with legs b (x) and h (y) at the origin: centroid (b/3, h/3), central moments
  // Jxx = b^3 h / 36, Jyy = b h^3 / 36, Jxy = -b^2 h^2 / 72. Extra nodes on the x leg move the
  // vertex mean away from the centroid without changing the polygon.
  const double b = 3.0, h = 2.0;
  const std::vector<Vec<2>> tri = {{0, 0}, {0.5, 0}, {1, 0}, {1.5, 0}, {2, 0}, {b, 0}, {0, h}};
  EXPECT_NEAR(geometry::polygon_area(tri), 0.5 * b * h, 1e-15);
  EXPECT_NEAR((polygon_centroid(tri) - Vec<2>(b / 3, h / 3)).norm(), 0.0, 1e-15);
  const auto J = area_second_moment(tri);
  EXPECT_NEAR(J(0, 0), b * b * b * h / 36, 1e-14);
  EXPECT_NEAR(J(1, 1), b * h * h * h / 36, 1e-14);
  EXPECT_NEAR(J(0, 1), -b * b * h * h / 72, 1e-14);
  EXPECT_EQ(J(0, 1), J(1, 0));
  EXPECT_NEAR(polygon_perimeter(tri), b + h + std::hypot(b, h), 1e-14);
}

TEST(Shape2d, MaxLengthChangeIsTheLargestSegmentStretch) {
  // Square of side 2 against rest lengths 2: the edge from node 1 to node 2 stretched by 10 %,
  // the closing edge (node 3 to node 0) against a rest length 2.5 is 20 % short.
  const std::vector<Vec<2>> square = {{0, 0}, {2, 0}, {2.0, 2.2}, {0, 2}};
  const std::vector<double> rest = {2.0, 2.0, std::hypot(2.0, 0.2), 2.5};
  EXPECT_NEAR(max_length_change(square, rest), 0.2, 1e-15);
  const std::vector<double> exact = {2.0, 2.2, std::hypot(2.0, 0.2), 2.0};
  EXPECT_NEAR(max_length_change(square, exact), 0.0, 1e-15);
  EXPECT_THROW(max_length_change(square, std::vector<double>(3, 2.0)), core::Error);
}

TEST(Shape2d, CircleHasNoDeformation) {
  const int n = 160;
  const auto X = geometry::ring_nodes({geometry::RingShape::Type::circle}, Vec<2>(5, 7), 2.0, 0.3, n);
  const auto e = equivalent_ellipse(X);
  // A regular polygon has an isotropic second-moment tensor: D vanishes to round-off.
  EXPECT_LT(e.taylor, 1e-12);
  EXPECT_NEAR(e.area, pi * 4.0, 1e-12);
  EXPECT_NEAR((e.centroid - Vec<2>(5, 7)).norm(), 0.0, 1e-12);
  // Semi-axes of the circle, to O(1/N^2).
  EXPECT_NEAR(e.length, 2.0, 4.0 * std::pow(2 * pi / n, 2));
  EXPECT_NEAR(e.width, 2.0, 4.0 * std::pow(2 * pi / n, 2));
  // A 1% ellipse is rejected by the same tolerance.
  EXPECT_GT(equivalent_ellipse(ellipse(Vec<2>(0, 0), 1.01, 1.0, 0.0, n)).taylor, 1e-3);
}

TEST(Shape2d, EllipseSemiAxesTaylorAndArea) {
  const int n = 400;
  const auto X = ellipse(Vec<2>(-3, 2), 2.0, 1.0, 0.0, n);
  const auto e = equivalent_ellipse(X);
  EXPECT_NEAR(e.length, 2.0, 1e-4);
  EXPECT_NEAR(e.width, 1.0, 1e-4);
  EXPECT_NEAR(e.taylor, 1.0 / 3.0, 1e-4);
  EXPECT_NEAR(e.area, 2 * pi, 2 * pi * 1e-4);
  EXPECT_NEAR(e.inclination, 0.0, 1e-12);
  EXPECT_NEAR((e.centroid - Vec<2>(-3, 2)).norm(), 0.0, 1e-12);
  // Perimeter of the 2:1 ellipse: 9.688448220547676 (complete elliptic integral).
  EXPECT_NEAR(polygon_perimeter(X), 9.688448220547676, 1e-4);
  // A 1.9:1 ellipse must fail the same L check.
  EXPECT_GT(std::abs(equivalent_ellipse(ellipse(Vec<2>(0, 0), 1.9, 1.0, 0.0, n)).length - 2.0), 1e-2);
}

TEST(Shape2d, InclinationOfRotatedEllipses) {
  const int n = 400;
  for (double deg : {30.0, -30.0, 60.0, -75.0, 89.0}) {
    const double angle = deg * pi / 180;
    const auto e = equivalent_ellipse(ellipse(Vec<2>(1, 1), 2.0, 1.0, angle, n));
    EXPECT_NEAR(e.inclination, angle, 1e-12) << deg << " degrees";
    EXPECT_NEAR(e.taylor, 1.0 / 3.0, 1e-4);
  }
  // An ellipse at 120 degrees is the same shape as at -60: inclination in (-pi/2, pi/2].
  EXPECT_NEAR(equivalent_ellipse(ellipse(Vec<2>(0, 0), 2.0, 1.0, 2 * pi / 3, n)).inclination, -pi / 3, 1e-12);
  // Major axis exactly along y: +pi/2, not -pi/2.
  const std::vector<Vec<2>> tall = {{-1, -2}, {1, -2}, {1, 2}, {-1, 2}};
  EXPECT_DOUBLE_EQ(equivalent_ellipse(tall).inclination, pi / 2);
}

TEST(Shape2d, RejectsClockwiseAndDegeneratePolygons) {
  std::vector<Vec<2>> cw = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  EXPECT_LT(geometry::polygon_area(cw), 0.0);
  EXPECT_THROW(equivalent_ellipse(cw), core::Error);
  EXPECT_THROW(polygon_centroid(cw), core::Error);
  const std::vector<Vec<2>> line = {{0, 0}, {1, 0}, {2, 0}};
  EXPECT_THROW(equivalent_ellipse(line), core::Error);
  const std::vector<Vec<2>> two = {{0, 0}, {1, 0}};
  EXPECT_DOUBLE_EQ(geometry::polygon_area(two), 0.0);
  EXPECT_THROW(area_second_moment(two), core::Error);
}

// The polygon's edges X_i -> X_{i+1}, shuffled.
std::vector<std::array<Vec<2>, 2>> shuffled_edges(const std::vector<Vec<2>>& X, unsigned seed) {
  std::vector<std::array<Vec<2>, 2>> edges;
  for (std::size_t i = 0; i < X.size(); ++i) edges.push_back({X[i], X[(i + 1) % X.size()]});
  std::shuffle(edges.begin(), edges.end(), std::mt19937(seed));
  return edges;
}

// The ellipse of the region bounded by `edges`, accumulated one edge at a time.
EquivalentEllipse region_ellipse(const std::vector<std::array<Vec<2>, 2>>& edges) {
  RegionMoments r(edges.front()[0]);
  for (const auto& e : edges) r.add_edge(e[0], e[1]);
  return r.ellipse();
}

TEST(Shape2d, EdgesInAnyOrderGiveThePolygonsEllipse) {
  const auto X = ellipse(Vec<2>(0.3, -1), 2.0, 1.0, 0.4, 200);
  const auto p = equivalent_ellipse(X);
  const auto edges = shuffled_edges(X, 7);
  const auto e = region_ellipse(edges);
  EXPECT_NEAR(e.area, p.area, 1e-12);
  EXPECT_NEAR((e.centroid - p.centroid).norm(), 0.0, 1e-12);
  EXPECT_NEAR(e.taylor, p.taylor, 1e-12);
  EXPECT_NEAR(e.inclination, 0.4, 1e-12);
  // Reversed edges bound a clockwise region: rejected like a clockwise polygon; so are two edges.
  auto reversed = edges;
  for (auto& edge : reversed) std::swap(edge[0], edge[1]);
  EXPECT_THROW(region_ellipse(reversed), core::Error);
  EXPECT_THROW(region_ellipse({edges[0], edges[1]}), core::Error);
}

TEST(Shape2d, EdgesOfARegionWithAHole) {
  // Square [-2, 2]^2 less the square [-1, 1]^2 (the hole's edges clockwise, the region on their
  // left): area 16 - 4, centred, second moments isotropic (D = 0).
  const std::vector<Vec<2>> outer = {{-2, -2}, {2, -2}, {2, 2}, {-2, 2}};
  const std::vector<Vec<2>> inner = {{-1, -1}, {-1, 1}, {1, 1}, {1, -1}};
  auto edges = shuffled_edges(outer, 1);
  for (const auto& e : shuffled_edges(inner, 2)) edges.push_back(e);
  const auto e = region_ellipse(edges);
  EXPECT_NEAR(e.area, 12.0, 1e-14);
  EXPECT_NEAR(e.centroid.norm(), 0.0, 1e-14);
  EXPECT_NEAR(e.taylor, 0.0, 1e-14);
  // Stretched along x by 2: the moments scale by 8 (xx) and 2 (yy), D = (2 - 1)/(2 + 1).
  for (auto& edge : edges)
    for (auto& x : edge) x[0] *= 2;
  const auto s = region_ellipse(edges);
  EXPECT_NEAR(s.area, 24.0, 1e-13);
  EXPECT_NEAR(s.taylor, 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(s.inclination, 0.0, 1e-14);
}

}  // namespace
}  // namespace caplab::diagnostics
