#include "diagnostics/shape2d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>

#include "core/error.hpp"

namespace caplab::diagnostics {
namespace {

// Area integrals of a region relative to a reference point p: A, int r dA, int r r^T dA, from
// its boundary edges {a, b} (Green's theorem on each edge; the region on the left of every edge).
struct Moments {
  double area = 0;
  Vec<2> first = Vec<2>::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
};

// `edge(i)` returns edge i of `n` as a pair of end points.
template <class EdgeAt>
Moments moments_about(std::size_t n, EdgeAt edge, const Vec<2>& p) {
  Moments m;
  for (std::size_t i = 0; i < n; ++i) {
    const auto [A, B] = edge(i);
    const Vec<2> a = A - p, b = B - p;
    const double c = a[0] * b[1] - b[0] * a[1];
    m.area += c;
    m.first += c * (a + b);
    m.second(0, 0) += c * (a[0] * a[0] + a[0] * b[0] + b[0] * b[0]);
    m.second(1, 1) += c * (a[1] * a[1] + a[1] * b[1] + b[1] * b[1]);
    m.second(0, 1) += c * (2 * a[0] * a[1] + a[0] * b[1] + b[0] * a[1] + 2 * b[0] * b[1]);
  }
  m.area *= 0.5;
  m.first /= 6.0;
  m.second(0, 0) /= 12.0;
  m.second(1, 1) /= 12.0;
  m.second(0, 1) /= 24.0;
  m.second(1, 0) = m.second(0, 1);
  return m;
}

// Moments about the mean of the edges' start points (against cancellation), checked to enclose
// a positive area.
template <class EdgeAt>
Moments checked_moments(std::size_t n, EdgeAt edge, Vec<2>& reference, const char* what) {
  reference = Vec<2>::Zero();
  for (std::size_t i = 0; i < n; ++i) reference += edge(i).first;
  if (n > 0) reference /= static_cast<double>(n);
  const Moments m = moments_about(n, edge, reference);
  std::ostringstream msg;
  msg << "shape diagnostics: the " << what << " of " << n << " edges has signed area " << m.area
      << "; expected a counter-clockwise boundary (positive area) with at least 3 edges";
  CAPLAB_CHECK(n >= 3 && m.area > 0.0, msg.str());
  return m;
}

// The closed polygon X as edges X_i -> X_{i+1}, the last joining the first.
auto polygon_edges(std::span<const Vec<2>> X) {
  return [X](std::size_t i) { return std::pair<Vec<2>, Vec<2>>(X[i], X[(i + 1) % X.size()]); };
}

Moments checked_moments(std::span<const Vec<2>> X, Vec<2>& reference) {
  return checked_moments(X.size(), polygon_edges(X), reference, "polygon");
}

// Area, centroid and second moments about the centroid.
struct Central {
  double area = 0;
  Vec<2> centroid = Vec<2>::Zero();
  Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
};

// The moments `m` about `p` moved to the centroid (parallel-axis theorem).
Central central(const Moments& m, const Vec<2>& p) {
  const Vec<2> d = m.first / m.area;  // centroid relative to p
  Central c{m.area, p + d, m.second - m.area * d * d.transpose()};
  c.J(1, 0) = c.J(0, 1);  // exactly symmetric (contracted multiply-adds may differ in the last bit)
  return c;
}

// The equivalent ellipse of a region (see the header).
EquivalentEllipse ellipse_of(const Central& c) {
  const Eigen::Matrix2d& J = c.J;
  EquivalentEllipse e;
  e.area = c.area;
  e.centroid = c.centroid;
  const double mean = 0.5 * (J(0, 0) + J(1, 1));
  const double half_diff = 0.5 * (J(0, 0) - J(1, 1));
  const double radius = std::hypot(half_diff, J(0, 1));
  const double lambda1 = mean + radius, lambda2 = mean - radius;
  CAPLAB_CHECK(lambda2 > 0.0, "shape diagnostics: the second-moment tensor is not positive definite");
  const double k = std::pow(4.0 / std::numbers::pi, 0.25);
  e.length = k * std::pow(lambda1, 0.375) * std::pow(lambda2, -0.125);
  e.width = k * std::pow(lambda2, 0.375) * std::pow(lambda1, -0.125);
  const double s1 = std::sqrt(lambda1), s2 = std::sqrt(lambda2);
  e.taylor = (s1 - s2) / (s1 + s2);
  // Major-axis angle: tan(2 theta) = 2 Jxy / (Jxx - Jyy); atan2 gives 2 theta in [-pi, pi].
  double theta = 0.5 * std::atan2(J(0, 1), half_diff);
  if (theta <= -0.5 * std::numbers::pi) theta += std::numbers::pi;
  e.inclination = theta;
  return e;
}

}  // namespace

double polygon_perimeter(std::span<const Vec<2>> X) {
  double p = 0.0;
  const std::size_t n = X.size();
  for (std::size_t i = 0; i < n; ++i) p += (X[(i + 1) % n] - X[i]).norm();
  return p;
}

double max_length_change(std::span<const Vec<2>> X, std::span<const double> rest_lengths) {
  CAPLAB_CHECK(rest_lengths.size() == X.size(), "max length change: " + std::to_string(rest_lengths.size()) +
                                                    " rest lengths for " + std::to_string(X.size()) + " nodes");
  double worst = 0.0;
  const std::size_t n = X.size();
  for (std::size_t i = 0; i < n; ++i)
    worst = std::max(worst, std::abs((X[(i + 1) % n] - X[i]).norm() / rest_lengths[i] - 1.0));
  return worst;
}

Vec<2> polygon_centroid(std::span<const Vec<2>> X) {
  Vec<2> p;
  const Moments m = checked_moments(X, p);
  return p + m.first / m.area;
}

Eigen::Matrix2d area_second_moment(std::span<const Vec<2>> X) {
  Vec<2> p;
  const Moments m = checked_moments(X, p);
  return central(m, p).J;
}

EquivalentEllipse equivalent_ellipse(std::span<const Vec<2>> X) {
  Vec<2> p;
  const Moments m = checked_moments(X, p);
  return ellipse_of(central(m, p));
}

EquivalentEllipse equivalent_ellipse(std::span<const std::array<Vec<2>, 2>> edges) {
  const auto edge = [edges](std::size_t i) { return std::pair<Vec<2>, Vec<2>>(edges[i][0], edges[i][1]); };
  Vec<2> p;
  const Moments m = checked_moments(edges.size(), edge, p, "region bounded by edges");
  return ellipse_of(central(m, p));
}

}  // namespace caplab::diagnostics
