// Direct forcing for rigid bodies with prescribed marker velocities (thesis eq. 2.22).
//
// Feng & Michaelides 2005 (J. Comput. Phys. 202) impose U(X_m, t+dt) = U_d at the markers
// through the force density (eq. 2.22). In the lattice Boltzmann form with Guo forcing, the
// fluid velocity seen by the collision is u = u* + f dt / (2 rho) (thesis eq. 2.25), where
// u* = sum_i e_i f_i / rho is the velocity without this body's force, so the marker force
// that makes the interpolated velocity equal U_d is
//   F_m = 2 rho_m (U_d - U*(X_m)) / dt,   U*(X_m) = sum_x u*(x) phi(x - X_m)           (3)
// with rho_m the density interpolated at the marker, spread as f(x) = sum_m F_m phi w_m.
// Because neighbouring stencils overlap, one pass leaves a slip; the multi-direct forcing
// of Wang, Fan & Luo 2008 (Int. J. Multiphase Flow 34) iterates (iterations > 1):
//   u(x)   <- u*(x) + f(x) / (2 rho(x))        on the stencil nodes
//   dF_m    = 2 rho_m (U_d - U(X_m)) / dt,  F_m += dF_m,  f += spread(dF_m)
// The slip e = U_d - U(X_m) is multiplied by (I - A) each iteration, A = interpolation of
// the spread of 2 rho_m e / (2 rho): for marker spacing ~ w_m, a smooth slip contracts by
// ~1 - sum_i phi_i^2 (5/8 with Cosine4, 1/2 with Roma3), so one pass leaves ~60% of the
// slip and 5 iterations ~10% (tested).
//
// Lattice units throughout (dx = dt = 1). F_m is a force per unit marker measure, w_m the
// marker measure in lattice units (ibm::measure_to_lattice). The force on the body is minus
// total_force_on_fluid(), plus the internal-mass term of ibm/internal_mass.hpp for a moving
// body.
//
// Invariants and choices:
//   * The iterations work on a gathered copy of u*, rho and f on the union of the marker
//     stencils, not on the whole grid; the result is added to the Eulerian field f once.
//   * f passed to apply() receives += this body's force density (zero it once per step
//     before all IB contributions). u* must not contain this body's force.
//   * All buffers are members that only grow: no allocation in the time loop once the
//     marker count is stable. Gathers and interpolations are OpenMP-parallel for many
//     markers (callables must be safe to call concurrently); spreading is serial.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/vec.hpp"
#include "field/grid.hpp"
#include "ibm/internal_mass.hpp"
#include "ibm/kernels.hpp"
#include "ibm/transfer.hpp"

namespace caplab::ibm {

/// Direct forcing of one rigid body (a marker set with prescribed velocities) on a block.
/// Lifecycle per step: apply(...), then read marker_force(), total_force_on_fluid(),
/// torque_on_fluid(), max_slip().
template <int D, class Kernel = Cosine4>
class DirectForcing {
 public:
  /// `iterations` = 1 is the direct forcing of Feng & Michaelides 2005; > 1 the multi-direct
  /// forcing of Wang, Fan & Luo 2008.
  explicit DirectForcing(int iterations = 1) : iterations_(iterations) {
    CAPLAB_CHECK(iterations >= 1, "direct forcing needs at least one iteration");
  }

  int iterations() const { return iterations_; }

  /// Computes the marker forces of eq. (3) (with the multi-direct iterations) for markers at
  /// the physical positions `positions` with desired velocities `desired_velocity_lu` and
  /// measures `weight_lu` (lattice units), from the force-free velocity
  /// u_star(const Index<D>&, std::ptrdiff_t) -> Vec<D> and the density
  /// rho(const Index<D>&, std::ptrdiff_t) -> double, and adds their spread force density to
  /// f. Returns the marker forces F_m (force per unit marker measure, lattice units).
  template <class VelocityAt, class DensityAt>
  std::span<const Vec<D>> apply(const field::Grid<D>& grid, const std::array<bool, D>& periodic,
                                std::span<const Vec<D>> positions,
                                std::span<const Vec<D>> desired_velocity_lu,
                                std::span<const double> weight_lu, VelocityAt&& u_star, DensityAt&& rho,
                                field::VectorField<D>& f) {
    const std::size_t m_count = positions.size();
    CAPLAB_CHECK(desired_velocity_lu.size() == m_count && weight_lu.size() == m_count,
                 "direct forcing: need one desired velocity and one weight per marker");
    CAPLAB_CHECK(static_cast<std::ptrdiff_t>(f.comp[0].size()) == grid.size(),
                 "direct forcing: the force field is not sized for the grid");
    transfer_.update(grid, periodic, positions);
    weight_.assign(weight_lu.begin(), weight_lu.end());
    build_local_nodes();
    gather_local(u_star, rho);

    constexpr int S = Transfer<D, Kernel>::stencil_size;
    force_.assign(m_count, Vec<D>::Zero());
    rho_m_.resize(m_count);
    velocity_.resize(m_count);
    for (std::size_t m = 0; m < m_count; ++m) {
      double r = 0.0;
      for (int e = 0; e < S; ++e) r += w_[m * S + e] * rho_loc_[slot_[m * S + e]];
      rho_m_[m] = r;
    }
    for (int it = 0; it < iterations_; ++it) {
      interpolate_corrected();
      for (std::size_t m = 0; m < m_count; ++m) {
        const Vec<D> d_force = 2.0 * rho_m_[m] * (desired_velocity_lu[m] - velocity_[m]);
        force_[m] += d_force;
        const Vec<D> fm = d_force * weight_[m];
        for (int e = 0; e < S; ++e) f_loc_[slot_[m * S + e]] += w_[m * S + e] * fm;
      }
    }
    interpolate_corrected();
    max_slip_ = 0.0;
    for (std::size_t m = 0; m < m_count; ++m)
      max_slip_ = std::max(max_slip_, (desired_velocity_lu[m] - velocity_[m]).norm());

    for (std::size_t s = 0; s < local_.size(); ++s)
      for (int a = 0; a < D; ++a) f.comp[a][local_[s].id] += f_loc_[s][a];
    return force_;
  }

  /// Marker forces F_m of the last apply() (per unit marker measure, lattice units).
  std::span<const Vec<D>> marker_force() const { return force_; }
  /// Velocity u* + f / (2 rho) interpolated at the markers after the last iteration.
  std::span<const Vec<D>> marker_velocity() const { return velocity_; }
  /// max_m |U_d - U(X_m)| after the last iteration (the residual slip).
  double max_slip() const { return max_slip_; }
  /// Force of the body on the fluid, sum_m F_m w_m (lattice units); minus the hydrodynamic
  /// force on the body before the internal-mass correction. Equals the sum of the spread
  /// force density over the grid.
  Vec<D> total_force_on_fluid() const {
    Vec<D> s = Vec<D>::Zero();
    for (std::size_t m = 0; m < force_.size(); ++m) s += force_[m] * weight_[m];
    return s;
  }
  /// Torque of the body on the fluid about `point` (physical position), sum_m (X_m - p) x F_m w_m
  /// with lever arms in lattice units (lattice units; scalar z component in 2D).
  Torque<D> torque_on_fluid(const Vec<D>& point) const {
    const Vec<D> p = transfer_.grid().to_lattice(point);
    Torque<D> t;
    if constexpr (D == 2)
      t = 0.0;
    else
      t = Vec<3>::Zero();
    for (std::size_t m = 0; m < force_.size(); ++m)
      t += cross<D>(transfer_.lattice_position(m) - p, Vec<D>(force_[m] * weight_[m]));
    return t;
  }
  /// The stencils of the last apply().
  const Transfer<D, Kernel>& transfer() const { return transfer_; }

 private:
  struct LocalNode {
    std::ptrdiff_t id;
    Index<D> ijk;
  };

  // The weights of every stencil entry (marker m at [m S, (m + 1) S)), the union of the
  // stencil nodes (sorted, unique) and each entry's slot in it.
  void build_local_nodes() {
    constexpr int S = Transfer<D, Kernel>::stencil_size;
    const std::size_t m_count = transfer_.marker_count();
    local_.resize(m_count * S);
    w_.resize(m_count * S);
    slot_.resize(m_count * S);
    for (std::size_t m = 0; m < m_count; ++m) {
      std::size_t e = m * S;
      transfer_.for_each_stencil_node(m, [&](const Index<D>& ijk, std::ptrdiff_t id, double w) {
        local_[e] = LocalNode{id, ijk};
        slot_[e] = id;  // the node for now, its slot below
        w_[e++] = w;
      });
    }
    auto by_id = [](const LocalNode& a, const LocalNode& b) { return a.id < b.id; };
    std::sort(local_.begin(), local_.end(), by_id);
    local_.erase(std::unique(local_.begin(), local_.end(),
                             [](const LocalNode& a, const LocalNode& b) { return a.id == b.id; }),
                 local_.end());
    for (auto& s : slot_)
      s = std::lower_bound(local_.begin(), local_.end(), LocalNode{s, {}}, by_id) - local_.begin();
  }

  template <class VelocityAt, class DensityAt>
  void gather_local(VelocityAt& u_star, DensityAt& rho) {
    const std::ptrdiff_t n_local = static_cast<std::ptrdiff_t>(local_.size());
    u_loc_.resize(n_local);
    rho_loc_.resize(n_local);
    f_loc_.assign(n_local, Vec<D>::Zero());
    std::ptrdiff_t bad = n_local;
#pragma omp parallel for schedule(static) if (n_local > detail::parallel_threshold) reduction(min : bad)
    for (std::ptrdiff_t s = 0; s < n_local; ++s) {
      u_loc_[s] = u_star(local_[s].ijk, local_[s].id);
      rho_loc_[s] = rho(local_[s].ijk, local_[s].id);
      if (!(rho_loc_[s] > 0.0) || !std::isfinite(rho_loc_[s]) || !u_loc_[s].allFinite())
        bad = std::min(bad, s);
    }
    if (bad < n_local) {
      std::ostringstream msg;
      msg << "direct forcing: non-positive or non-finite density " << rho_loc_[bad] << " or velocity ("
          << u_loc_[bad].transpose() << ") at node " << local_[bad].ijk[0];
      for (int a = 1; a < D; ++a) msg << ", " << local_[bad].ijk[a];
      msg << " next to the body (the flow has diverged)";
      core::check_failed("rho > 0 and finite", __FILE__, __LINE__, msg.str());
    }
  }

  // velocity_[m] = sum_x (u*(x) + f_loc(x) / (2 rho(x))) phi(x - X_m) on the local copy.
  void interpolate_corrected() {
    constexpr int S = Transfer<D, Kernel>::stencil_size;
    const std::ptrdiff_t m_count = static_cast<std::ptrdiff_t>(transfer_.marker_count());
#pragma omp parallel for schedule(static) if (m_count > detail::parallel_threshold)
    for (std::ptrdiff_t m = 0; m < m_count; ++m) {
      Vec<D> u = Vec<D>::Zero();
      for (int e = 0; e < S; ++e) {
        const std::ptrdiff_t s = slot_[m * S + e];
        u += w_[m * S + e] * (u_loc_[s] + f_loc_[s] / (2.0 * rho_loc_[s]));
      }
      velocity_[m] = u;
    }
  }

  int iterations_;
  Transfer<D, Kernel> transfer_;
  std::vector<double> weight_;
  std::vector<LocalNode> local_;
  std::vector<double> w_;  // stencil weights per entry
  std::vector<std::ptrdiff_t> slot_;
  std::vector<Vec<D>> u_loc_, f_loc_;
  std::vector<double> rho_loc_;
  std::vector<double> rho_m_;
  std::vector<Vec<D>> force_, velocity_;
  double max_slip_ = 0.0;
};

}  // namespace caplab::ibm
