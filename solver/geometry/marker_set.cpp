#include "geometry/marker_set.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/error.hpp"

namespace caplab::geometry {
namespace {

void check_shape_arguments(const char* shape, double size, double target_spacing) {
  std::ostringstream msg;
  msg << shape << " markers: size " << size << " and target spacing " << target_spacing
      << " must both be positive and finite";
  CAPLAB_CHECK(std::isfinite(size) && std::isfinite(target_spacing) && size > 0 && target_spacing > 0,
               msg.str());
}

// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> gl_x = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                        0.9061798459386640};
constexpr std::array<double, 5> gl_w = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                        0.4786286704993665, 0.2369268850561891};

// |dX/dt| of X(t) = (a cos t, b sin t).
double speed(double a, double b, double t) { return std::hypot(a * std::sin(t), b * std::cos(t)); }

// Arc length from t0 to t1 (one 5-point Gauss-Legendre panel).
double arc_panel(double a, double b, double t0, double t1) {
  const double h = 0.5 * (t1 - t0), m = 0.5 * (t1 + t0);
  double s = 0.0;
  for (int q = 0; q < 5; ++q) s += gl_w[q] * speed(a, b, m + h * gl_x[q]);
  return h * s;
}

// Panels per quadrant: the integrand is smooth and periodic, so 5-point panels converge fast.
constexpr int panels = 256;

// Cumulative arc length at t_j = j * 2 pi / panels_total, j = 0..panels_total.
std::vector<double> cumulative_arc(double a, double b) {
  const int total = 4 * panels;
  const double dt = 2.0 * std::numbers::pi / total;
  std::vector<double> s(total + 1, 0.0);
  for (int j = 0; j < total; ++j) s[j + 1] = s[j] + arc_panel(a, b, j * dt, (j + 1) * dt);
  return s;
}

}  // namespace

MarkerSet<2> circle_markers(const Vec<2>& center, double diameter, double target_spacing) {
  check_shape_arguments("circle", diameter, target_spacing);
  const double perimeter = std::numbers::pi * diameter;
  const int n = std::max(3, static_cast<int>(std::ceil(perimeter / target_spacing)));
  MarkerSet<2> m;
  m.X.reserve(n);
  m.weight.assign(n, perimeter / n);
  const double r = 0.5 * diameter;
  for (int k = 0; k < n; ++k) {
    const double theta = 2.0 * std::numbers::pi * k / n;
    m.X.push_back(center + r * Vec<2>(std::cos(theta), std::sin(theta)));
  }
  return m;
}

double ellipse_perimeter(double a, double b) {
  check_shape_arguments("ellipse", std::min(a, b), 1.0);
  return cumulative_arc(a, b).back();
}

MarkerSet<2> ellipse_markers(const Vec<2>& center, double a, double b, double angle, double target_spacing) {
  check_shape_arguments("ellipse", std::min(a, b), target_spacing);
  CAPLAB_CHECK(std::isfinite(angle), "ellipse markers: the angle must be finite");
  const std::vector<double> s = cumulative_arc(a, b);
  const int total = static_cast<int>(s.size()) - 1;
  const double dt = 2.0 * std::numbers::pi / total;
  const double perimeter = s.back();
  const int n = std::max(3, static_cast<int>(std::ceil(perimeter / target_spacing)));

  MarkerSet<2> m;
  m.X.reserve(n);
  m.weight.assign(n, perimeter / n);
  const double c = std::cos(angle), sn = std::sin(angle);
  int j = 0;  // panel containing the current target arc length (targets increase with k)
  for (int k = 0; k < n; ++k) {
    const double target = perimeter * k / n;
    while (j < total - 1 && s[j + 1] <= target) ++j;
    // Newton on g(t) = s_j + arc(t_j, t) - target, g' = speed > 0 (speed >= min(a, b)).
    const double tj = j * dt;
    double t = tj + dt * (target - s[j]) / (s[j + 1] - s[j]);
    for (int it = 0; it < 20; ++it) {
      const double g = s[j] + arc_panel(a, b, tj, t) - target;
      const double step = g / speed(a, b, t);
      t -= step;
      if (std::abs(step) < 1e-15) break;
    }
    const Vec<2> body(a * std::cos(t), b * std::sin(t));
    m.X.push_back(center + Vec<2>(c * body[0] - sn * body[1], sn * body[0] + c * body[1]));
  }
  return m;
}

MarkerSet<3> sphere_markers(const Vec<3>& center, double diameter, double target_spacing) {
  check_shape_arguments("sphere", diameter, target_spacing);
  const double area = std::numbers::pi * diameter * diameter;
  const double area_per_marker = 0.5 * std::sqrt(3.0) * target_spacing * target_spacing;
  const int n = std::max(4, static_cast<int>(std::ceil(area / area_per_marker)));
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double r = 0.5 * diameter;
  MarkerSet<3> m;
  m.X.reserve(n);
  m.weight.assign(n, area / n);
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * k;
    m.X.push_back(center + r * Vec<3>(rho * std::cos(phi), rho * std::sin(phi), z));
  }
  return m;
}

}  // namespace caplab::geometry
