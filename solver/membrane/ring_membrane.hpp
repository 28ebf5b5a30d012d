// 2D capsule membrane: a closed ring of nodes with Hooke tension and bending (thesis ch. 3,
// eq. 3.1-3.8; Breyiannis & Pozrikidis 2000; Pozrikidis 2003a).
//
// Discretisation (nodes i = 0..N-1 counter-clockwise, segment i joins node i to node i+1, all
// indices cyclic):
//   segment length l_i, unit tangent t_i, outward normal n_i = (t_i.y, -t_i.x);
//   Hooke tension        tau_i = E (l_i / l0_i - 1)                          (eq. 3.6)
//   node curvature       kappa_i = (signed turning angle from t_{i-1} to t_i) / ((l_{i-1} + l_i)/2),
//                        positive on a convex counter-clockwise ring
//   bending moment       m_i = E_B (kappa_i - kappa0_i)                       (eq. 3.8)
//   transverse shear     q_i = (m_{i+1} - m_i) / l_i on segment i             (eq. 3.7)
//   segment tension      T_i = tau_i t_i + q_i n_i
//   force on the fluid   F_i = T_i - T_{i-1}, i.e. dT/dl integrated over the node's arc, the
//                        opposite of the load Delta F = -dT/dl of eq. 3.1: a stretched ring pulls
//                        the fluid inwards.
// With E_B == 0 the bending part is skipped entirely (no cost, forces bit-identical to the
// Hooke-only ring whatever kappa0 is).
//
// Energy: sum_i 1/2 E l0_i (l_i/l0_i - 1)^2 + sum_i 1/2 E_B (kappa_i - kappa0_i)^2 (l_{i-1} + l_i)/2.
// The Hooke forces are exactly minus the gradient of the Hooke energy. The bending forces of
// the thesis's (Pozrikidis's) m/q model are NOT the exact variational derivative of the
// bending energy: e.g. a circle with a flat reference (kappa0 = 0) has a uniform moment, hence
// q = 0 and no bending force, although its bending energy is not stationary under a change of
// radius. They relax bending (energy decreases along F for small steps on smooth shapes).
//
// Invariants: the total force sum_i F_i and the total torque sum_i X_i x F_i vanish
// identically (up to round-off): the forces telescope, and the torque reduces to
// -sum_i l_i t_i x (q_i n_i) = sum_i (m_{i+1} - m_i) = 0. The reference shape (with
// kappa0 = initial) carries exactly zero force.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/vec.hpp"
#include "membrane/membrane.hpp"

namespace caplab::membrane {

/// Curvature of the minimum bending-energy shape, kappa0 of eq. 3.8.
enum class ReferenceCurvature {
  initial,  ///< the discrete curvature of the rest shape
  circle,   ///< uniform 1/a_eq, a_eq = (rest polygon area / pi)^0.5, the circle of equal area
  flat      ///< 0
};

/// Hookean ring with bending stiffness. forces() and energy() use mutable scratch buffers
/// sized at construction (no allocation per call), so one object must not be used from
/// several threads at once.
class RingMembrane final : public Membrane<2> {
 public:
  /// `rest`: the unstressed (reference) node positions, counter-clockwise, >= 3 nodes, no two
  /// consecutive nodes coincident. `hooke_modulus` E (tension units) and `bending_modulus`
  /// E_B (tension x length^2) must be finite and >= 0. Throws core::Error otherwise.
  RingMembrane(std::span<const Vec<2>> rest, double hooke_modulus, double bending_modulus,
               ReferenceCurvature reference);

  std::size_t node_count() const override { return rest_lengths_.size(); }

  /// F_i = T_i - T_{i-1} (see the file header). X and F have node_count() entries (checked).
  void forces(std::span<const Vec<2>> X, std::span<Vec<2>> F) const override;

  /// Hooke + bending energy (see the file header). X has node_count() entries (checked).
  double energy(std::span<const Vec<2>> X) const override;

  /// The shortest segment relative to its rest length; a segment is folded when it points
  /// against both of its neighbours.
  ElementHealth<2> health(std::span<const Vec<2>> X) const override;

  /// Rest segment lengths l0_i (segment i joins node i to node i+1).
  std::span<const double> rest_lengths() const { return rest_lengths_; }
  /// Reference curvature kappa0_i at each node.
  std::span<const double> kappa0() const { return kappa0_; }
  /// Hooke modulus E.
  double hooke_modulus() const { return E_; }
  /// Bending modulus E_B.
  double bending_modulus() const { return E_B_; }

  /// Discrete node curvatures of the closed ring X (the kappa_i of the file header) into
  /// `kappa` (same size as X, checked).
  static void curvatures(std::span<const Vec<2>> X, std::span<double> kappa);
  /// Same, returned as a new vector.
  static std::vector<double> curvatures(std::span<const Vec<2>> X);

 private:
  // Segment lengths and unit tangents of X into l and t.
  static void segments(std::span<const Vec<2>> X, std::span<double> l, std::span<Vec<2>> t);
  // Node curvatures from segment lengths and unit tangents.
  static void node_curvatures(std::span<const double> l, std::span<const Vec<2>> t, std::span<double> kappa);
  void check_size(const char* what, std::size_t size) const;

  std::vector<double> rest_lengths_;
  std::vector<double> kappa0_;
  double E_;
  double E_B_;
  // Scratch (per call of forces()/energy()): segment lengths, tangents, node curvatures/moments.
  mutable std::vector<double> l_;
  mutable std::vector<Vec<2>> t_;
  mutable std::vector<double> m_;
};

}  // namespace caplab::membrane
