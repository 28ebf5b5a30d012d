// Hydrodynamic load on a rigid immersed body, with the internal-mass correction.
//
// The direct-forcing IB force f acts on all the fluid, including the (fictitious) fluid
// that fills the body. The momentum balance of that inner fluid gives the hydrodynamic
// force and torque on the body (Uhlmann 2005, J. Comput. Phys. 209; Suzuki & Inamuro
// 2011, Comput. Fluids 49; see also Kempe & Froehlich 2012):
//   F_body = - sum_m F_m w_m              + d/dt integral_{V_body} rho u dV          (1)
//   T_body = - sum_m (X_m - X_c) x F_m w_m + d/dt integral_{V_body} rho (x - X_c) x u dV (2)
// The first terms are minus the load on the fluid (DirectForcing::total_force_on_fluid,
// DirectForcing::torque_on_fluid). Without the second terms the drag history of an
// accelerating body is wrong by the inertia of its inner fluid.
//
// Two ways to evaluate the inner-momentum term:
//   * general (Suzuki & Inamuro 2011): integrate rho u over the body on the grid (with a
//     solid volume fraction per cell) at two successive steps and difference in time:
//     body_load_from_internal_momentum();
//   * rigid approximation (Uhlmann 2005): the inner fluid moves with the body, so the term
//     is rho V dU_c/dt for the force and rho (I dOmega/dt + Omega x (I Omega)) for the torque,
//     with V the body volume and I its second-moment (unit-density inertia) tensor:
//     rigid_body_force(), rigid_body_torque(). In 2D, V is the area and I = integral r^2 dA.
// Everything is in the lattice units of the block (dx = dt = 1, rho in lattice units).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <numbers>
#include <type_traits>

#include "core/vec.hpp"

namespace caplab::ibm {

/// Torque type: a scalar (z component) in 2D, a vector in 3D.
template <int D>
using Torque = std::conditional_t<D == 2, double, Vec<3>>;

/// r x F: the scalar r_x F_y - r_y F_x in 2D, the cross product in 3D.
template <int D>
Torque<D> cross(const Vec<D>& r, const Vec<D>& force) {
  if constexpr (D == 2)
    return r[0] * force[1] - r[1] * force[0];
  else
    return r.cross(force);
}

/// Eq. (1)/(2), general form: load on the body = -(load on the fluid) + (P_now - P_before)/dt,
/// with P the momentum (or angular momentum) of the fluid inside the body integrated on the
/// grid at the current and the previous step. Works for forces (Vec<D>) and torques.
template <class T>
T body_load_from_internal_momentum(const T& load_on_fluid, const T& internal_momentum_now,
                                   const T& internal_momentum_before, double dt = 1.0) {
  return -load_on_fluid + (internal_momentum_now - internal_momentum_before) / dt;
}

/// Eq. (1), rigid approximation: F_body = -F_fluid + rho V dU_c/dt.
template <int D>
Vec<D> rigid_body_force(const Vec<D>& force_on_fluid, double rho_fluid, double volume,
                        const Vec<D>& body_acceleration) {
  return -force_on_fluid + rho_fluid * volume * body_acceleration;
}

/// Eq. (2), rigid approximation in 2D: T_body = -T_fluid + rho I dOmega/dt, I = integral r^2 dA.
inline double rigid_body_torque(double torque_on_fluid, double rho_fluid, double second_moment,
                                double angular_acceleration) {
  return -torque_on_fluid + rho_fluid * second_moment * angular_acceleration;
}

/// Eq. (2), rigid approximation in 3D: T_body = -T_fluid + rho (I dOmega/dt + Omega x (I Omega)),
/// I = integral (r^2 1 - r r^T) dV in the lab frame (the gyroscopic term vanishes for a sphere).
inline Vec<3> rigid_body_torque(const Vec<3>& torque_on_fluid, double rho_fluid,
                                const Eigen::Matrix3d& second_moment, const Vec<3>& angular_acceleration,
                                const Vec<3>& angular_velocity) {
  const Vec<3> l_dot =
      second_moment * angular_acceleration + angular_velocity.cross(Vec<3>(second_moment * angular_velocity));
  return -torque_on_fluid + rho_fluid * l_dot;
}

/// Volume of a disk (D = 2, area) or ball (D = 3) of radius r.
template <int D>
double ball_volume(double r) {
  if constexpr (D == 2)
    return std::numbers::pi * r * r;
  else
    return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}

/// Unit-density second moment about the centre: pi r^4 / 2 (disk), 8 pi r^5 / 15 (ball, each
/// diagonal entry of the isotropic tensor).
template <int D>
double ball_second_moment(double r) {
  if constexpr (D == 2)
    return 0.5 * std::numbers::pi * r * r * r * r;
  else
    return 8.0 / 15.0 * std::numbers::pi * r * r * r * r * r;
}

}  // namespace caplab::ibm
