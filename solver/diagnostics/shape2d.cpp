#include "diagnostics/shape2d.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace caplab::diagnostics {
namespace {

// Area integrals of a region relative to a reference point p: A, int r dA, int r r^T dA.
struct Moments {
  double area = 0;
  Vec<2> first = Vec<2>::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
};

}  // namespace

// The finished integrals of a RegionMoments, checked to enclose a positive area.
struct RegionMomentsAccess {
  static Moments checked(const RegionMoments& r, const char* what) {
    Moments m;
    m.area = 0.5 * r.area_;
    m.first = r.first_ / 6.0;
    m.second(0, 0) = r.second_(0, 0) / 12.0;
    m.second(1, 1) = r.second_(1, 1) / 12.0;
    m.second(0, 1) = m.second(1, 0) = r.second_(0, 1) / 24.0;
    std::ostringstream msg;
    msg << "shape diagnostics: the " << what << " of " << r.edges_ << " edges has signed area " << m.area
        << "; expected a counter-clockwise boundary (positive area) with at least 3 edges";
    CAPLAB_CHECK(r.edges_ >= 3 && m.area > 0.0, msg.str());
    return m;
  }
};

void RegionMoments::add_edge(const Vec<2>& A, const Vec<2>& B) {
  const Vec<2> a = A - reference_, b = B - reference_;
  const double c = a[0] * b[1] - b[0] * a[1];
  area_ += c;
  first_ += c * (a + b);
  second_(0, 0) += c * (a[0] * a[0] + a[0] * b[0] + b[0] * b[0]);
  second_(1, 1) += c * (a[1] * a[1] + a[1] * b[1] + b[1] * b[1]);
  second_(0, 1) += c * (2 * a[0] * a[1] + a[0] * b[1] + b[0] * a[1] + 2 * b[0] * b[1]);
  ++edges_;
}

namespace {

// Moments of the closed polygon X (edges X_i -> X_{i+1}, the last joining the first) about its
// vertex mean `reference` (against cancellation), checked to enclose a positive area.
Moments checked_moments(std::span<const Vec<2>> X, Vec<2>& reference) {
  reference = Vec<2>::Zero();
  for (const Vec<2>& x : X) reference += x;
  if (!X.empty()) reference /= static_cast<double>(X.size());
  RegionMoments r(reference);
  for (std::size_t i = 0; i < X.size(); ++i) r.add_edge(X[i], X[(i + 1) % X.size()]);
  return RegionMomentsAccess::checked(r, "polygon");
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

EquivalentEllipse RegionMoments::ellipse(const char* what) const {
  return ellipse_of(central(RegionMomentsAccess::checked(*this, what), reference_));
}

}  // namespace caplab::diagnostics
