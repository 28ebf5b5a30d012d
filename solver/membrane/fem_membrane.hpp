// 3D capsule membrane: flat linear triangles with a hyperelastic strain energy (thesis section
// 5.1, eq. 5.1-5.3 for the laws and 5.6 for the node forces; Charrier et al. 1989, Shrivastava &
// Tang 1993, Ramanujan & Pozrikidis 1998).
//
// Laws: W(I1, I2) per unit reference area, I1 = lambda1^2 + lambda2^2 - 2, I2 = lambda1^2 lambda2^2 - 1,
// in the thesis's units (README of shared/refdata, "Conventions"):
//   NeoHookean    W = E/6 (I1 - 1 + 1/(I2 + 1))                     (eq. 5.1, E = 3 G_s)
//   ZeroThickness W = E/6 [I1 - ln(I2 + 1) + 1/2 ln^2(I2 + 1)]      (eq. 5.2, as NH at small strain)
//   Skalak        W = E/4 (1/2 I1^2 + I1 - I2) + C E/8 I2^2          (eq. 5.3, E = 2 G_s, C the
//                                                                     area-dilation ratio)
// With C = 1 and E_SK = 2/3 E_NH (equal G_s) the three laws share the same linear response.
//
// Element e with rest nodes x0, x1, x2 has a local orthonormal frame in its rest plane, the
// reference edge matrix D0 = [X1 - X0, X2 - X0] (2x2, local coordinates) and the shape-function
// gradients grad N_1, grad N_2 = rows of D0^-1, grad N_0 = -(grad N_1 + grad N_2). In the current
// configuration x_a the 3x2 deformation gradient is F = sum_a x_a grad N_a^T, C = F^T F,
// I1 = tr C - 2, I2 = det C - 1, and the force on the fluid at node a (exactly -d(A0 W)/dx_a,
// the elastic force on the massless membrane, see membrane.hpp) is
//   f_a = -A0 F S grad N_a,   S = 2 dW/dI1 Id + 2 dW/dI2 det C C^-1 = 2 dW/dI1 Id + 2 dW/dI2 adj C,
// since dI1/dF = 2F and d(det C)/dF = 2 det C F C^-1. This is eq. 5.6 written without the
// principal directions (no eigen-decomposition, no rotation to the element plane).
//
// Invariants: zero force and zero energy in the rest configuration and after any rigid motion
// of it; total force and total torque vanish for any configuration (W depends on C only);
// forces = -grad(energy) to round-off. forces() is deterministic whatever the thread count:
// per-element corner forces go to a buffer, then each node sums its corners in a fixed order
// (a node -> corner incidence list built in the constructor).
//
// det C = J^2 with J the area ratio of the element; it cannot be negative for a surface
// triangle, so a folded element is not detected element-locally; J -> 0 (a collapsing element)
// makes NH and ZT forces blow up and ends in inf/NaN, caught by the run's NaN guards.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/vec.hpp"
#include "geometry/triangle_mesh.hpp"
#include "membrane/membrane.hpp"

namespace caplab::membrane {

/// Neo-Hookean law, thesis eq. 5.1: W = E/6 (I1 - 1 + 1/(I2 + 1)); E = 3 G_s.
struct NeoHookean {
  double E;
  /// W per unit reference area.
  double energy(double I1, double I2) const { return E / 6.0 * (I1 - 1.0 + 1.0 / (I2 + 1.0)); }
  /// {dW/dI1, dW/dI2}.
  std::array<double, 2> derivatives(double /*I1*/, double I2) const {
    const double J2 = I2 + 1.0;
    return {E / 6.0, -E / (6.0 * J2 * J2)};
  }
};

/// Zero-thickness shell law of Ramanujan & Pozrikidis 1998, thesis eq. 5.2:
/// W = E/6 [I1 - ln(I2 + 1) + 1/2 ln^2(I2 + 1)]; scaled as NH (E = 3 G_s).
struct ZeroThickness {
  double E;
  double energy(double I1, double I2) const {
    const double L = std::log(I2 + 1.0);
    return E / 6.0 * (I1 - L + 0.5 * L * L);
  }
  std::array<double, 2> derivatives(double /*I1*/, double I2) const {
    const double J2 = I2 + 1.0;
    return {E / 6.0, E / 6.0 * (std::log(J2) - 1.0) / J2};
  }
};

/// Skalak law, thesis eq. 5.3: W = E/4 (1/2 I1^2 + I1 - I2) + C E/8 I2^2; E = 2 G_s, C the
/// ratio of the area-dilation to the shear modulus.
struct Skalak {
  double E;
  double C;
  double energy(double I1, double I2) const {
    return E / 4.0 * (0.5 * I1 * I1 + I1 - I2) + C * E / 8.0 * I2 * I2;
  }
  std::array<double, 2> derivatives(double I1, double I2) const {
    return {E / 4.0 * (I1 + 1.0), E / 4.0 * (C * I2 - 1.0)};
  }
};

/// The membrane laws of the 3D capsules; chosen once per run, dispatched once per forces() call.
using MembraneLaw = std::variant<NeoHookean, ZeroThickness, Skalak>;

/// "neo-Hookean", "zero-thickness" or "Skalak (C = ...)", for messages and logs.
std::string law_name(const MembraneLaw& law);

/// Principal stretches of one element, lambda1 >= lambda2 >= 0 (square roots of the eigenvalues
/// of C = F^T F).
struct ElementStrain {
  double lambda1, lambda2;
};

/// Finite-element membrane of a closed (or open) triangulated surface. forces() uses a mutable
/// scratch buffer sized at construction (no allocation per call), so one object must not be
/// used from several threads at once; forces() itself runs its loops with OpenMP.
class FemMembrane final : public Membrane<3> {
 public:
  /// `rest`: the unstressed mesh (nodes finite, triangle indices in range, every triangle with
  /// a positive area). The law's moduli must be finite and > 0 (E; and C for Skalak). Throws
  /// core::Error naming the offending triangle, node or modulus.
  FemMembrane(const geometry::TriangleMesh& rest, MembraneLaw law);

  std::size_t node_count() const override { return node_offsets_.size() - 1; }
  std::size_t element_count() const { return triangles_.size(); }

  /// f_a = -A0 F S grad N_a summed over the triangles of each node (file header). X and F have
  /// node_count() entries (checked).
  void forces(std::span<const Vec<3>> X, std::span<Vec<3>> F) const override;

  /// sum_e A0_e W(I1_e, I2_e). X has node_count() entries (checked).
  double energy(std::span<const Vec<3>> X) const override;

  /// Principal stretches of every element into `out` (element_count() entries, checked).
  void element_strains(std::span<const Vec<3>> X, std::span<ElementStrain> out) const;

  /// Smallest area ratio J = A/A0 = sqrt(det C) over the elements; J -> 0 is a collapsing element
  /// (J cannot be negative for a surface triangle; see the file header).
  double min_area_ratio(std::span<const Vec<3>> X) const { return health(X).min_ratio; }

  /// The smallest J and its element; an element is folded (inverted) when its normal points
  /// against the summed normals of the triangles around its three nodes.
  ElementHealth<3> health(std::span<const Vec<3>> X) const override;

  /// The rest mesh's triangles (outward orientation as given).
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  /// Reference areas A0_e.
  std::span<const double> reference_areas() const { return A0_; }
  /// The strain-energy law.
  const MembraneLaw& law() const { return law_; }

 private:
  // The deformation gradient F = [F1 F2] of element e in configuration X and C = F^T F.
  struct Deformation {
    Vec<3> F1, F2;
    double c11, c12, c22;
    double det_c() const { return c11 * c22 - c12 * c12; }
  };
  Deformation deformation(std::size_t e, std::span<const Vec<3>> X) const;
  // Per-element corner forces into corner_forces_ (the loop of forces(), one instance per law).
  template <class Law>
  void element_forces(const Law& law, std::span<const Vec<3>> X) const;
  void check_size(const char* what, std::size_t size, std::size_t expected) const;

  MembraneLaw law_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<double> A0_;
  // {grad N_1, grad N_2} of each element in its local rest frame: (g1x, g1y, g2x, g2y).
  std::vector<std::array<double, 4>> shape_gradients_;
  // Node -> corner incidence (CSR): the corners 3 e + k of node i are
  // node_corners_[node_offsets_[i] .. node_offsets_[i + 1]), in increasing order.
  std::vector<int> node_offsets_;
  std::vector<int> node_corners_;
  // Scratch of forces(): the force of element e on its corner k at 3 e + k.
  mutable std::vector<Vec<3>> corner_forces_;
  // Scratch of health(): area-weighted element normals and their sums around each node.
  mutable std::vector<Vec<3>> element_normals_, node_normals_;
};

}  // namespace caplab::membrane
