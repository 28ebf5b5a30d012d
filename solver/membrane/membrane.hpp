// The interface the scene uses for any elastic membrane: 2D rings (thesis ch. 3) now, 3D
// finite-element meshes (ch. 5) later.
//
// A membrane is a fixed set of Lagrangian nodes with a stress-free reference configuration
// held by the implementation. Given the current node positions it returns the force each
// node exerts on the fluid (which the IB transfer spreads) and its stored energy. It knows
// nothing of the lattice: positions and moduli are in any consistent units.
#pragma once

#include <cstddef>
#include <span>

#include "core/vec.hpp"

namespace caplab::membrane {

/// The worst element of a configuration (for the guards of a run): the smallest ratio of an
/// element's size to its rest size (3D: triangle area A/A0 = J; 2D: segment length l/l0), the
/// element where it occurs (index and centre), and the first element folded over its
/// neighbours (-1: none).
template <int D>
struct ElementHealth {
  double min_ratio = 1.0;
  std::size_t worst = 0;
  Vec<D> worst_at = Vec<D>::Zero();
  double max_ratio = 1.0;  ///< the largest ratio (an over-stretched or exploding element)
  long folded = -1;
  Vec<D> folded_at = Vec<D>::Zero();
};

template <int D>
class Membrane {
 public:
  virtual ~Membrane() = default;

  /// Number of nodes; X and F passed to forces() and energy() have this size.
  virtual std::size_t node_count() const = 0;

  /// Force each node exerts on the fluid (= minus the load the fluid exerts on the membrane),
  /// F[i], in the units of the moduli; positions in any length unit consistent with the moduli.
  virtual void forces(std::span<const Vec<D>> X, std::span<Vec<D>> F) const = 0;

  /// Elastic + bending energy of configuration X (for tests and diagnostics).
  virtual double energy(std::span<const Vec<D>> X) const = 0;

  /// The worst element of configuration X (see ElementHealth).
  virtual ElementHealth<D> health(std::span<const Vec<D>> X) const = 0;
};

}  // namespace caplab::membrane
