// The fluid of a scene: one block (uniform grid) or two (two-level multi-block), advanced
// one coarse step at a time in the order of thesis fig. 2.4.
//
// The finest block carries the immersed boundary: before each of its steps a forcing hook
// may fill its force density (lattice units of that block); the kernel with Guo forcing is
// used exactly when the hook reports a force, otherwise the unforced kernel. A uniform body
// force (e.g. Poiseuille) is given in lattice units of the coarse block and converted to
// the fine one (acoustic scaling: a_f = a_c / m).
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <span>

#include "boundary/boundary_set.hpp"
#include "core/timing.hpp"
#include "collision/stream_collide.hpp"
#include "refinement/two_level.hpp"

namespace caplab::sim {

template <class L, class T, class Op>
class Fluid {
 public:
  static constexpr int D = L::d;
  using Pop = field::Populations<L, T>;
  using Force = field::VectorField<D, double>;
  /// Adds the finest block's force density for its next step and returns the nodes where the
  /// field now differs from the uniform body force (empty: none). The field holds the uniform
  /// body force everywhere except at the nodes the hook changed in its previous call, which
  /// the hook restores first: the IB touches only its stencils, so nothing here sweeps the
  /// whole field every substep. Without a uniform body force only the returned region takes
  /// the forced kernel (stream_collide_forced_at); with one, the whole block does. A region
  /// that asks for the velocity (ForcedRegion::velocity) finds it written after the sweep.
  using ForcingHook = std::function<collision::ForcedRegion(const Pop&, Force&)>;

  struct Block {
    Pop pop;
    Op op;
    Force force;          // allocated when the block is ever forced
    bool has_body_force = false;
    field::Box<D> skip;  // nodes its sweep leaves alone: the covered nodes of a coarse block
    int row_start = 0;   // the sweep's x0: on a fine block collision::ghost_row_start (−1 or 0)
  };

  struct Setup {
    field::Grid<D> coarse;
    std::optional<field::Grid<D>> fine;  // two-level when present
    std::array<boundary::Kind, D> boundaries{};
    boundary::FarField far_field = boundary::FarField::extrapolation;
    std::function<Vec<D>(const Vec<D>&)> imposed_velocity_lu;  // at a physical position
    Op coarse_op;                        // its tau is the coarse relaxation time
    Vec<D> body_force_lu = Vec<D>::Zero();  // coarse lattice units
    bool finest_forced = false;          // allocate a force field for the IB
  };

  explicit Fluid(const Setup& s) {
    blocks_.push_back(make_block(s.coarse, s.coarse_op));
    if (s.fine) {
      Op fine_op = s.coarse_op;
      fine_op.tau = 0.5 + 2.0 * (s.coarse_op.tau - 0.5);  // thesis eq. 2.10, m = 2
      blocks_.push_back(make_block(*s.fine, fine_op));
      coupling_ = refinement::TwoLevel<L, T>(
          s.coarse, *s.fine, {s.coarse_op.tau, s.coarse_op.tau_minus(), s.coarse_op.tau_bulk(D)},
          {fine_op.tau, fine_op.tau_minus(), fine_op.tau_bulk(D)}, collision::has_bulk_mode<Op>);
      blocks_[0].skip = coupling_.idle_coarse();
      // Nothing reads the fine block's ghost layer: the fill overwrites what its ghosts push in.
      blocks_[1].row_start = collision::ghost_row_start<T>(s.fine->n()[0]);
    }
    coarse_bc_ = boundary::BoundarySet<L, T>(s.coarse, s.boundaries, s.imposed_velocity_lu, s.far_field);
    const bool body = s.body_force_lu.norm() > 0;
    double scale = 1.0;
    for (std::size_t b = 0; b < blocks_.size(); ++b, scale *= 0.5) {
      auto& blk = blocks_[b];
      body_force_[b] = s.body_force_lu * scale;
      blk.has_body_force = body;
      if (body || (s.finest_forced && b + 1 == blocks_.size())) {
        blk.force = Force(blk.pop.grid().size());
        for (int a = 0; a < D; ++a) std::fill(blk.force.comp[a].begin(), blk.force.comp[a].end(), body_force_[b][a]);
      }
    }
  }

  /// Sets every block to the equilibrium of (ρ, u) from init(physical position) -> pair(ρ, Vec u_lu).
  template <class Init>
  void initialise(Init&& init) {
    for (auto& blk : blocks_) {
      const auto& g = blk.pop.grid();
      collision::initialise_equilibrium(blk.pop, [&](const Index<D>& ijk) { return init(g.position(ijk)); });
    }
    if (two_level()) coupling_.template capture_coarse<Op>(blocks_[0].pop);
  }

  /// One coarse time step (and m = 2 fine substeps). `hook` forces the finest block;
  /// `swept` runs after each sweep of it (when the hook's region asked for the velocity, it is
  /// there then).
  void step(const ForcingHook& hook = {}, const std::function<void()>& swept = {}) {
    auto& c = blocks_[0];
    auto coarse_before = [&] { coarse_bc_.prepare(c.pop, c.op); };
    auto coarse_after = [&] { coarse_bc_.apply(c.pop); };
    if (!two_level()) {
      advance_block(c, hook, coarse_before, coarse_after);
      if (swept) swept();
      return;
    }
    auto& f = blocks_[1];
    auto coarse_and_band_before = [&] {
      coarse_before();
      core::timed(coupling_seconds_, [&] {
        T F[D];
        for (int a = 0; a < D; ++a) F[a] = T(body_force_[0][a]);
        if (c.has_body_force)
          coupling_.template collide_band<true>(c.pop, f.pop, c.op, F);
        else
          coupling_.template collide_band<false>(c.pop, f.pop, c.op, F);
      });
    };
    advance_block(c, {}, coarse_and_band_before, coarse_after);
    core::timed(coupling_seconds_, [&] { coupling_.template capture_coarse<Op>(c.pop); });
    for (int sub = 0; sub < 2; ++sub) {
      advance_block(f, hook, [] {}, [&] {
        core::timed(coupling_seconds_, [&] { coupling_.fill_fine_ghosts(f.pop, f.op, 0.5 * sub); });
      });
      if (swept) swept();
    }
  }

  /// The evolving state (io/checkpoint.hpp archive): populations of every block and the coarse
  /// history of the coupling. Force fields are not part of it: between steps they hold the
  /// uniform body force except at the nodes of the last IB stencils, and a restored scene starts
  /// with no stencil, i.e. the field as built (see ForcingHook).
  template <class Archive>
  void checkpoint(Archive& ar) {
    for (std::size_t b = 0; b < blocks_.size(); ++b) blocks_[b].pop.checkpoint(ar, "fluid/block" + std::to_string(b) + "/");
    if (two_level()) coupling_.checkpoint(ar, "fluid/coupling/");
    ar("fluid/coupling_seconds", coupling_seconds_);
  }

  /// Wall time spent in the multi-block coupling so far (part of the step time).
  double coupling_seconds() const { return coupling_seconds_; }

  bool two_level() const { return blocks_.size() == 2; }
  Block& finest() { return blocks_.back(); }
  const Block& finest() const { return blocks_.back(); }
  Block& coarse() { return blocks_.front(); }
  const Block& coarse() const { return blocks_.front(); }
  std::size_t block_count() const { return blocks_.size(); }
  const Block& block(std::size_t b) const { return blocks_[b]; }
  const refinement::TwoLevel<L, T>& coupling() const { return coupling_; }
  /// The uniform body force of block b in its lattice units.
  const Vec<D>& body_force(std::size_t b) const { return body_force_[b]; }

  /// Node updates per coarse step (for MLUPS): not the covered coarse nodes, for which the fine
  /// block stands.
  double updates_per_step() const {
    double u = static_cast<double>(blocks_[0].pop.grid().interior_size() - blocks_[0].skip.size());
    if (two_level()) u += 2.0 * static_cast<double>(blocks_[1].pop.grid().interior_size());
    return u;
  }

 private:
  static Block make_block(const field::Grid<D>& g, const Op& op) { return Block{Pop(g), op, Force(0), false, {}}; }

  /// One step of a block: forcing hook, then the boundaries' stage before the in-place sweep
  /// (what reads the state at time t), the sweep, and the stage that fills the entering slots.
  template <class Before, class After>
  void advance_block(Block& blk, const ForcingHook& hook, Before&& before_sweep, After&& apply_boundaries) {
    const std::size_t b = &blk - blocks_.data();
    collision::ForcedRegion forced;
    if (hook) {
      if (blk.force.comp[0].empty()) {  // once: a hook on a block built without a force field
        blk.force = Force(blk.pop.grid().size());
        for (int a = 0; a < D; ++a) std::fill(blk.force.comp[a].begin(), blk.force.comp[a].end(), body_force_[b][a]);
      }
      forced = hook(blk.pop, blk.force);
    }
    before_sweep();
    if (blk.has_body_force) {
      if (forced.wants_velocity()) collision::forced_velocity_at(blk.pop, blk.force, forced);
      collision::stream_collide<true>(blk.pop, blk.op, &blk.force, blk.skip, blk.row_start);
    } else if (!forced.empty()) {
      collision::stream_collide_forced_at(blk.pop, blk.op, blk.force, forced, blk.row_start);
    } else {
      collision::stream_collide<false>(blk.pop, blk.op, nullptr, blk.skip, blk.row_start);
    }
    apply_boundaries();
  }

  std::vector<Block> blocks_;
  double coupling_seconds_ = 0;
  std::array<Vec<D>, 2> body_force_{Vec<D>::Zero(), Vec<D>::Zero()};
  boundary::BoundarySet<L, T> coarse_bc_;
  refinement::TwoLevel<L, T> coupling_;
};

}  // namespace caplab::sim
