#include "geometry/closed_curve.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"

namespace caplab::geometry {
namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> gl_x = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                        0.9061798459386640};
constexpr std::array<double, 5> gl_w = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                        0.4786286704993665, 0.2369268850561891};

// Panels of the arc-length table over one period of the parameter.
constexpr int panels = 1024;

// The curves: position X(u) and derivative dX/du, u in [0, 2 pi), counter-clockwise,
// X(0) the rightmost point on the body x axis.
struct Circle {
  Vec<2> point(double u) const { return {std::cos(u), std::sin(u)}; }
  Vec<2> derivative(double u) const { return {-std::sin(u), std::cos(u)}; }
};

struct Ellipse {
  double r;  // semi-axis along x; the one along y is 1
  Vec<2> point(double u) const { return {r * std::cos(u), std::sin(u)}; }
  Vec<2> derivative(double u) const { return {-r * std::sin(u), std::cos(u)}; }
};

// Eq. 3.12 with a = 1 and chi = pi/2 - u: sin chi = cos u, cos chi = sin u, so
// x = alpha cos u, y = (alpha/2) P(cos^2 u) sin u with P(w) = 0.207 + 2.003 w - 1.123 w^2.
struct Biconcave {
  double alpha;
  static double p(double w) { return 0.207 + 2.003 * w - 1.123 * w * w; }
  static double dp(double w) { return 2.003 - 2.0 * 1.123 * w; }
  Vec<2> point(double u) const {
    const double c = std::cos(u), s = std::sin(u);
    return {alpha * c, 0.5 * alpha * p(c * c) * s};
  }
  Vec<2> derivative(double u) const {
    const double c = std::cos(u), s = std::sin(u);
    return {-alpha * s, 0.5 * alpha * c * (p(c * c) - 2.0 * s * s * dp(c * c))};
  }
};

// Arc length of the curve from u0 to u1 (one Gauss-Legendre panel).
template <class Curve>
double arc_panel(const Curve& curve, double u0, double u1) {
  const double h = 0.5 * (u1 - u0), mid = 0.5 * (u1 + u0);
  double s = 0.0;
  for (int q = 0; q < 5; ++q) s += gl_w[q] * curve.derivative(mid + h * gl_x[q]).norm();
  return h * s;
}

// Area enclosed by the curve, 1/2 closed integral of (x y' - y x') du.
template <class Curve>
double curve_area(const Curve& curve) {
  const double du = two_pi / panels;
  double area = 0.0;
  for (int j = 0; j < panels; ++j) {
    const double mid = (j + 0.5) * du;
    for (int q = 0; q < 5; ++q) {
      const double u = mid + 0.5 * du * gl_x[q];
      const Vec<2> x = curve.point(u), dx = curve.derivative(u);
      area += gl_w[q] * 0.5 * du * 0.5 * (x[0] * dx[1] - x[1] * dx[0]);
    }
  }
  return area;
}

// n points equally spaced in arc length, the first at u = 0.
template <class Curve>
std::vector<Vec<2>> equal_arc_points(const Curve& curve, int n) {
  const double du = two_pi / panels;
  std::vector<double> s(panels + 1, 0.0);  // s[j]: arc length from u = 0 to u_j = j du
  for (int j = 0; j < panels; ++j) s[j + 1] = s[j] + arc_panel(curve, j * du, (j + 1) * du);
  const double perimeter = s.back();

  std::vector<Vec<2>> X;
  X.reserve(n);
  int j = 0;  // panel holding the current target (targets increase with k)
  for (int k = 0; k < n; ++k) {
    const double target = perimeter * k / n;
    while (j < panels - 1 && s[j + 1] <= target) ++j;
    // g(u) = s_j + arc(u_j, u) - target is increasing (speed > 0) with a root in [lo, hi].
    const double uj = j * du;
    double lo = uj, hi = uj + du;
    double u = uj + du * (target - s[j]) / (s[j + 1] - s[j]);
    for (int it = 0; it < 60; ++it) {
      const double g = s[j] + arc_panel(curve, uj, u) - target;
      if (g == 0.0) break;
      (g > 0.0 ? hi : lo) = u;
      double next = u - g / curve.derivative(u).norm();
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket: bisect
      const double step = std::abs(next - u);
      u = next;
      if (step < 1e-15 * two_pi) break;
    }
    X.push_back(curve.point(u));
  }
  return X;
}

void check_positive(const char* what, double value) {
  std::ostringstream msg;
  msg << "ring nodes: " << what << " is " << value << ", expected positive and finite";
  CAPLAB_CHECK(std::isfinite(value) && value > 0.0, msg.str());
}

}  // namespace

double polygon_area(std::span<const Vec<2>> X) {
  const std::size_t n = X.size();
  if (n < 3) return 0.0;
  Vec<2> c = Vec<2>::Zero();  // shoelace about the vertex mean: less round-off far from the origin
  for (const auto& x : X) c += x;
  c /= static_cast<double>(n);
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> a = X[i] - c, b = X[(i + 1) % n] - c;
    twice += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * twice;
}

std::vector<Vec<2>> ring_nodes(const RingShape& shape, const Vec<2>& center, double equivalent_radius,
                               double angle, int nodes) {
  check_positive("the equivalent radius", equivalent_radius);
  CAPLAB_CHECK(std::isfinite(angle), "ring nodes: the angle must be finite");
  CAPLAB_CHECK(std::isfinite(center[0]) && std::isfinite(center[1]), "ring nodes: the centre must be finite");
  CAPLAB_CHECK(nodes >= 3, "ring nodes: a ring needs at least 3 nodes, got " + std::to_string(nodes));

  std::vector<Vec<2>> X;
  switch (shape.type) {
    case RingShape::Type::circle:
      X = equal_arc_points(Circle{}, nodes);
      break;
    case RingShape::Type::ellipse:
      check_positive("the ellipse aspect ratio", shape.aspect_ratio);
      X = equal_arc_points(Ellipse{shape.aspect_ratio}, nodes);
      break;
    case RingShape::Type::biconcave:
      check_positive("the biconcave radius ratio alpha", shape.alpha);
      X = equal_arc_points(Biconcave{shape.alpha}, nodes);
      break;
  }
  const double scale = std::sqrt(std::numbers::pi * equivalent_radius * equivalent_radius / polygon_area(X));
  const double c = std::cos(angle), s = std::sin(angle);
  for (Vec<2>& x : X) {
    const Vec<2> body = scale * x;
    x = center + Vec<2>(c * body[0] - s * body[1], s * body[0] + c * body[1]);
  }
  return X;
}

double biconcave_equivalent_radius(double alpha) {
  CAPLAB_CHECK(std::isfinite(alpha) && alpha > 0.0,
               "biconcave equivalent radius: alpha must be positive and finite");
  return std::sqrt(curve_area(Biconcave{alpha}) / std::numbers::pi);
}

}  // namespace caplab::geometry
