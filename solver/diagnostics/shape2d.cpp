#include "diagnostics/shape2d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace caplab::diagnostics {
namespace {

// Area integrals of the polygon relative to a reference point p: A, int r dA, int r r^T dA.
struct Moments {
  double area = 0;
  Vec<2> first = Vec<2>::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
};

Moments moments_about(std::span<const Vec<2>> X, const Vec<2>& p) {
  Moments m;
  const std::size_t n = X.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> a = X[i] - p, b = X[(i + 1) % n] - p;
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

Vec<2> vertex_mean(std::span<const Vec<2>> X) {
  Vec<2> s = Vec<2>::Zero();
  for (const Vec<2>& x : X) s += x;
  return X.empty() ? s : Vec<2>(s / static_cast<double>(X.size()));
}

// Moments about the vertex mean, checked to enclose a positive area.
Moments checked_moments(std::span<const Vec<2>> X, Vec<2>& reference) {
  reference = vertex_mean(X);
  const Moments m = moments_about(X, reference);
  std::ostringstream msg;
  msg << "shape diagnostics: the polygon of " << X.size() << " nodes has signed area " << m.area
      << "; expected a counter-clockwise polygon (positive area) with at least 3 nodes";
  CAPLAB_CHECK(X.size() >= 3 && m.area > 0.0, msg.str());
  return m;
}

// Second moments about the centroid (parallel-axis theorem) and the centroid itself.
Eigen::Matrix2d central_second_moment(std::span<const Vec<2>> X, double& area, Vec<2>& centroid) {
  Vec<2> p;
  const Moments m = checked_moments(X, p);
  const Vec<2> d = m.first / m.area;  // centroid relative to p
  area = m.area;
  centroid = p + d;
  Eigen::Matrix2d J = m.second - m.area * d * d.transpose();
  J(1, 0) = J(0, 1);  // exactly symmetric (contracted multiply-adds may differ in the last bit)
  return J;
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
  double area;
  Vec<2> centroid;
  return central_second_moment(X, area, centroid);
}

EquivalentEllipse equivalent_ellipse(std::span<const Vec<2>> X) {
  EquivalentEllipse e;
  const Eigen::Matrix2d J = central_second_moment(X, e.area, e.centroid);
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

}  // namespace caplab::diagnostics
