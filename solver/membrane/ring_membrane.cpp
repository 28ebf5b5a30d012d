#include "membrane/ring_membrane.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "core/error.hpp"
#include "geometry/closed_curve.hpp"

namespace caplab::membrane {
namespace {

void check_modulus(const char* what, double value) {
  std::ostringstream msg;
  msg << "ring membrane: the " << what << " is " << value << ", expected finite and >= 0";
  CAPLAB_CHECK(std::isfinite(value) && value >= 0.0, msg.str());
}

}  // namespace

RingMembrane::RingMembrane(std::span<const Vec<2>> rest, double hooke_modulus, double bending_modulus,
                           ReferenceCurvature reference)
    : E_(hooke_modulus), E_B_(bending_modulus) {
  const std::size_t n = rest.size();
  CAPLAB_CHECK(n >= 3, "ring membrane: a ring needs at least 3 nodes, got " + std::to_string(n));
  for (const Vec<2>& x : rest)
    CAPLAB_CHECK(std::isfinite(x[0]) && std::isfinite(x[1]), "ring membrane: rest positions must be finite");
  check_modulus("Hooke modulus E", E_);
  check_modulus("bending modulus E_B", E_B_);
  const double area = geometry::polygon_area(rest);
  CAPLAB_CHECK(area > 0.0, "ring membrane: the rest nodes enclose a signed area " + std::to_string(area) +
                               "; expected counter-clockwise nodes (positive area)");

  rest_lengths_.resize(n);
  kappa0_.resize(n);
  l_.resize(n);
  t_.resize(n);
  m_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    rest_lengths_[i] = (rest[(i + 1) % n] - rest[i]).norm();
    CAPLAB_CHECK(rest_lengths_[i] > 0.0, "ring membrane: rest nodes " + std::to_string(i) + " and " +
                                             std::to_string((i + 1) % n) + " coincide");
  }
  switch (reference) {
    case ReferenceCurvature::initial:
      curvatures(rest, kappa0_);
      break;
    case ReferenceCurvature::circle:
      kappa0_.assign(n, 1.0 / std::sqrt(area / std::numbers::pi));
      break;
    case ReferenceCurvature::flat:
      kappa0_.assign(n, 0.0);
      break;
  }
}

void RingMembrane::segments(std::span<const Vec<2>> X, std::span<double> l, std::span<Vec<2>> t) {
  const std::size_t n = X.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> d = X[i + 1 == n ? 0 : i + 1] - X[i];
    l[i] = d.norm();
    t[i] = d / l[i];
  }
}

void RingMembrane::node_curvatures(std::span<const double> l, std::span<const Vec<2>> t,
                                   std::span<double> kappa) {
  const std::size_t n = l.size();
  for (std::size_t i = 0, prev = n - 1; i < n; prev = i++) {
    const double cross = t[prev][0] * t[i][1] - t[prev][1] * t[i][0];
    const double dot = t[prev].dot(t[i]);
    kappa[i] = std::atan2(cross, dot) / (0.5 * (l[prev] + l[i]));
  }
}

void RingMembrane::curvatures(std::span<const Vec<2>> X, std::span<double> kappa) {
  CAPLAB_CHECK(X.size() >= 3 && kappa.size() == X.size(),
               "ring curvatures: need >= 3 nodes and one curvature entry per node");
  std::vector<double> l(X.size());
  std::vector<Vec<2>> t(X.size());
  segments(X, l, t);
  node_curvatures(l, t, kappa);
}

std::vector<double> RingMembrane::curvatures(std::span<const Vec<2>> X) {
  std::vector<double> kappa(X.size());
  curvatures(X, kappa);
  return kappa;
}

void RingMembrane::check_size(const char* what, std::size_t size) const {
  if (size == node_count()) return;
  std::ostringstream msg;
  msg << "ring membrane: " << what << " has " << size << " entries, the ring has " << node_count()
      << " nodes";
  CAPLAB_CHECK(false, msg.str());
}

void RingMembrane::forces(std::span<const Vec<2>> X, std::span<Vec<2>> F) const {
  check_size("X", X.size());
  check_size("F", F.size());
  const std::size_t n = X.size();
  segments(X, l_, t_);
  const bool bending = E_B_ != 0.0;
  if (bending) {
    node_curvatures(l_, t_, m_);
    for (std::size_t i = 0; i < n; ++i) m_[i] = E_B_ * (m_[i] - kappa0_[i]);  // eq. 3.8
  }
  // T_i = tau_i t_i + q_i n_i, tau_i = E (l_i / l0_i - 1) (eq. 3.6), q_i = (m_{i+1} - m_i) / l_i (eq. 3.7).
  auto tension = [&](std::size_t i) -> Vec<2> {
    const double tau = E_ * (l_[i] / rest_lengths_[i] - 1.0);
    Vec<2> T = tau * t_[i];
    if (bending) {
      const double q = (m_[i + 1 == n ? 0 : i + 1] - m_[i]) / l_[i];
      T += q * Vec<2>(t_[i][1], -t_[i][0]);
    }
    return T;
  };
  Vec<2> T_prev = tension(n - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2> T = tension(i);
    F[i] = T - T_prev;
    T_prev = T;
  }
}

double RingMembrane::energy(std::span<const Vec<2>> X) const {
  check_size("X", X.size());
  const std::size_t n = X.size();
  segments(X, l_, t_);
  double hooke = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double strain = l_[i] / rest_lengths_[i] - 1.0;
    hooke += 0.5 * E_ * rest_lengths_[i] * strain * strain;
  }
  if (E_B_ == 0.0) return hooke;
  node_curvatures(l_, t_, m_);
  double bend = 0.0;
  for (std::size_t i = 0, prev = n - 1; i < n; prev = i++) {
    const double dk = m_[i] - kappa0_[i];
    bend += 0.5 * E_B_ * dk * dk * 0.5 * (l_[prev] + l_[i]);
  }
  return hooke + bend;
}

ElementHealth<2> RingMembrane::health(std::span<const Vec<2>> X) const {
  check_size("X", X.size());
  const std::size_t n = X.size();
  segments(X, l_, t_);
  ElementHealth<2> h;
  h.min_ratio = std::numeric_limits<double>::infinity();
  h.max_ratio = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ratio = l_[i] / rest_lengths_[i];
    if (ratio < h.min_ratio) h.min_ratio = ratio, h.worst = i;
    h.max_ratio = std::max(h.max_ratio, ratio);
    const Vec<2>& before = t_[i == 0 ? n - 1 : i - 1];
    const Vec<2>& after = t_[i + 1 == n ? 0 : i + 1];
    if (h.folded < 0 && t_[i].dot(before) < 0 && t_[i].dot(after) < 0) h.folded = static_cast<long>(i);
  }
  auto centre = [&](std::size_t i) { return Vec<2>(0.5 * (X[i] + X[i + 1 == n ? 0 : i + 1])); };
  h.worst_at = centre(h.worst);
  if (h.folded >= 0) h.folded_at = centre(static_cast<std::size_t>(h.folded));
  return h;
}

}  // namespace caplab::membrane
