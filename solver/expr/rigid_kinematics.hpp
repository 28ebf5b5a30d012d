// Prescribed rigid-body motion: the centre along each axis and the orientation (2D: the angle
// of the body's long axis from x, counter-clockwise) as piecewise expressions of t, with the
// exact velocity and acceleration of the jets (thesis eq. 2.28-2.30).
#pragma once

#include <array>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "expr/expression.hpp"

namespace caplab::expr {

/// Position, velocity and acceleration of the centre (unused axes zero), orientation, angular
/// velocity and angular acceleration at one time.
struct RigidPose {
  std::array<double, 3> x{}, v{}, a{};
  double angle = 0, omega = 0, alpha = 0;
};

class RigidKinematics {
 public:
  /// One piecewise function per axis for the centre, one for the orientation.
  RigidKinematics(std::vector<Piecewise> position, Piecewise angle)
      : position_(std::move(position)), angle_(std::move(angle)) {
    CAPLAB_CHECK(position_.size() == 2 || position_.size() == 3,
                 "rigid kinematics: 2 or 3 position components");
  }

  /// A body at rest at `center` with orientation `angle`.
  static RigidKinematics fixed(const std::vector<double>& center, double angle) {
    std::vector<Piecewise> position;
    for (double c : center) position.push_back(constant(c));
    return RigidKinematics(std::move(position), constant(angle));
  }

  int dimension() const { return static_cast<int>(position_.size()); }

  RigidPose at(double t) const {
    RigidPose p;
    for (std::size_t a = 0; a < position_.size(); ++a) {
      const Jet j = position_[a].at(t);
      p.x[a] = j.v, p.v[a] = j.d1, p.a[a] = j.d2;
    }
    const Jet th = angle_.at(t);
    p.angle = th.v, p.omega = th.d1, p.alpha = th.d2;
    return p;
  }

  const std::vector<Piecewise>& position() const { return position_; }
  const Piecewise& angle() const { return angle_; }

 private:
  static Piecewise constant(double value) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", value);
    return Piecewise({}, {Expression::parse(text)});
  }

  std::vector<Piecewise> position_;
  Piecewise angle_;
};

}  // namespace caplab::expr
