// A liquid-filled capsule of a scene: its membrane (solver/membrane, lattice-free) coupled to
// the finest fluid block by the immersed boundary (thesis section 2.1.3 and 2.2.4).
//
// One finest-block step, inside the fluid's forcing hook (thesis fig. 2.4: the IB
// subroutine runs before streaming and collision), for membrane nodes X(t):
//   1. F_m = membrane force on the fluid at X(t) (Hooke tension and bending, eq. 3.1-3.8);
//   2. f(x) += sum_m F_m phi(x - X_m)                       (spreading, eq. 2.16);
//   3. U_m = sum_x [u*(x) + f(x) / (2 rho(x))] phi(x - X_m)  (interpolation, eq. 2.19,
//      of the velocity the Guo-forced collision uses, eq. 2.25);
//   4. X(t + dt) = X(t) + U_m dt                           (no slip, eq. 2.15; explicit Euler,
//      first order in time, the scheme of the thesis).
// Step 3 runs after every body has spread its force, so U sees the whole force field: the
// forced collision of the sweep writes u* + f / (2 rho) at the stencils' nodes (from the
// populations before it collides them), and steps 3 and 4 follow the sweep (Scene::advect_capsules).
// The membrane is massless: the force it exerts on the fluid is the whole story (Newton's
// third law), and there is no internal-mass correction.
//
// Units: node positions in L (physical); membrane moduli in lattice units of the finest
// block (so forces come out as lattice forces per unit depth in 2D); F_m is spread with unit
// weight because it is a node force, not a density per marker measure.
//
// Invariants: buffers are sized once at construction (no allocation in the time loop); the
// scene sets the nodes of the last stencils back to the uniform body force before spread()
// of the next step (see Fluid::ForcingHook and Scene::apply_ib).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "core/vec.hpp"
#include "field/grid.hpp"
#include "ibm/kernels.hpp"
#include "ibm/transfer.hpp"
#include "membrane/membrane.hpp"

namespace caplab::sim {

template <int D>
class Capsule {
 public:
  using Transfers = std::variant<ibm::Transfer<D, ibm::Cosine4>, ibm::Transfer<D, ibm::Roma3>,
                                 ibm::Transfer<D, ibm::Linear2>>;

  /// `rest` are the node positions of the unstressed membrane (in L), which the capsule starts from.
  Capsule(std::string name, std::vector<Vec<D>> rest, std::unique_ptr<membrane::Membrane<D>> membrane,
          Transfers transfer)
      : name_(std::move(name)),
        X_(std::move(rest)),
        membrane_(std::move(membrane)),
        transfer_(std::move(transfer)),
        F_(X_.size(), Vec<D>::Zero()),
        U_(X_.size(), Vec<D>::Zero()),
        unit_weight_(X_.size(), 1.0) {
    CAPLAB_CHECK(membrane_ && membrane_->node_count() == X_.size(),
                 "capsule: the membrane must have one node per marker");
  }

  const std::string& name() const { return name_; }
  std::span<const Vec<D>> positions() const { return X_; }
  const membrane::Membrane<D>& membrane() const { return *membrane_; }
  /// Membrane forces on the fluid of the last step (lattice units).
  std::span<const Vec<D>> forces() const { return F_; }
  /// Node velocities of the last advect() (lattice units).
  std::span<const Vec<D>> velocities() const { return U_; }

  /// Marks the nodes of the stencils of the last spread() in `nodes`.
  void mark_stencil_nodes(ibm::StencilUnion& nodes) const {
    std::visit([&](const auto& tr) { tr.mark_stencil_nodes(nodes); }, transfer_);
  }

  /// Step 1: the membrane forces at the current positions.
  void compute_forces() { membrane_->forces(X_, F_); }

  /// Step 2: stencils at the current positions on `grid`, and the spreading of the forces
  /// into f. Throws core::Error when a stencil leaves a non-periodic block (the capsule has
  /// left the fine block) or a position is not finite.
  void spread(const field::Grid<D>& grid, const std::array<bool, D>& periodic, field::VectorField<D>& f) {
    std::visit(
        [&](auto& tr) {
          tr.update(grid, periodic, X_);
          tr.spread(F_, unit_weight_, f);
        },
        transfer_);
  }

  /// The node positions (io/checkpoint.hpp archive); forces and velocities are recomputed
  /// by the next step before anything reads them.
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    ar(prefix + "X", std::span<double>(X_.data()->data(), X_.size() * D));
  }

  /// Steps 3 and 4: interpolates the velocity field `u` (lattice units, on the grid of the
  /// last spread(); only the stencil nodes are read) at the nodes and moves them by one time
  /// step of the block of spacing `dx` (in L): X += U dx.
  void advect(const field::VectorField<D>& u, double dx) {
    std::visit([&](const auto& tr) { tr.interpolate_field(u, std::span<Vec<D>>(U_)); }, transfer_);
    for (std::size_t m = 0; m < X_.size(); ++m) X_[m] += U_[m] * dx;
  }

 private:
  std::string name_;
  std::vector<Vec<D>> X_;
  std::unique_ptr<membrane::Membrane<D>> membrane_;
  Transfers transfer_;
  std::vector<Vec<D>> F_, U_;
  std::vector<double> unit_weight_;
};

}  // namespace caplab::sim
