// The scene of a case: fluid blocks, rigid bodies with direct forcing, diagnostics, guards
// and outputs, assembled once from the validated case (lifecycle: build → initialise → run
// → summarise). Templated on lattice, precision and collision operator (per-node decisions);
// everything decided per step (which bodies, which outputs) is run-time data.
//
// Order of one coarse step (thesis fig. 2.4): coarse collide-push and boundaries; then per
// fine substep the IB stage (direct forcing on the finest block from its force-free
// velocity) followed by the forced collide-push and the coupled ghost ring; restriction.
// Forces on bodies: minus the force they spread (Newton's third law); fixed bodies need no
// internal-mass correction. Capsules (sim/capsule.hpp) spread their membrane force after the
// rigid bodies and then move with the velocity of the whole force field, which the forced
// collide-push writes at their stencils' nodes (Scene::advect_capsules runs after it).
#pragma once

#include <algorithm>
#include <chrono>
#include <csignal>
#include <functional>
#include <fmt/format.h>

#include <numbers>
#include <optional>
#include <variant>

#include "case/case_spec.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/timing.hpp"
#include "case/case_consistency.hpp"
#include "diagnostics/capsule_motion.hpp"
#include "diagnostics/shape2d.hpp"
#include "diagnostics/signal.hpp"
#include "expr/rigid_kinematics.hpp"
#include "geometry/closed_curve.hpp"
#include "geometry/marker_set.hpp"
#include "ibm/direct_forcing.hpp"
#include "io/checkpoint.hpp"
#include "io/run_directory.hpp"
#include "io/series_writer.hpp"
#include "io/snapshot_writer.hpp"
#include "membrane/ring_membrane.hpp"
#include "sim/capsule.hpp"
#include "sim/capsule_track.hpp"
#include "sim/fluid.hpp"
#include "sim/units.hpp"

namespace caplab::sim {

/// Called about once a second: step, total steps, time (L/U), MLUPS and the estimated seconds
/// left, both from the steps this process has run.
using ProgressFn = std::function<void(long, long, double, double, double)>;

/// When and how a run writes checkpoint.h5 (sim/run_case.cpp fills it from the case).
struct CheckpointPolicy {
  double interval = 0;      ///< simulated time between checkpoints, L/U (0: not by time)
  double wall_seconds = 0;  ///< wall time between checkpoints (0: not by wall time)
  std::string meta;         ///< stored with the state: the case and the build (JSON text)
  /// Tests only: the process kills itself (SIGKILL) right after its n-th checkpoint, as a
  /// power cut would (CAPLAB_TEST_KILL_AFTER_CHECKPOINT, read by sim/run_case.cpp).
  int kill_after = 0;
  /// Tests only: the process sends itself SIGTERM during step n, as a batch system's stop
  /// would (CAPLAB_TEST_SIGTERM_AT_STEP).
  long sigterm_at_step = 0;
};

struct RunResult {
  long steps = 0;
  double wall_seconds = 0;
  double mlups = 0;
  nlohmann::json stage_seconds;
  nlohmann::json summary;  ///< the content of summary.json
  nlohmann::json checkpoints;  ///< count, seconds, bytes of the checkpoints written
};

/// Throws core::InputError (the file, /outputs/series/quantities, the name, what is allowed)
/// when `spec` asks for a series quantity a D-dimensional scene with its bodies cannot give: an
/// unknown name, a rigid-body quantity without rigid bodies, a capsule quantity without capsules.
/// `caplab check` applies it as the scene does, before anything runs.
template <int D>
void check_series_quantities(const cases::CaseSpec& spec) {
  const auto& bodies = spec.physics.bodies;
  const bool rigid = std::any_of(bodies.begin(), bodies.end(), [](const auto& b) { return !b.membrane; });
  const bool capsules = std::any_of(bodies.begin(), bodies.end(), [](const auto& b) { return b.membrane.has_value(); });
  for (const auto& q : spec.outputs.series.quantities) {
    auto refuse = [&](const std::string& expected) {
      throw core::InputError(spec.source_file, "/outputs/series/quantities", q, expected);
    };
    if (q == "drag_coefficient" || q == "lift_coefficient" || q == "position") {
      if (!rigid) refuse("a quantity of a scene with bodies (this case has none)");
    } else if (find_capsule_quantity<D>(q)) {
      if (!capsules) refuse("a quantity of a scene with capsules (this case has none)");
    } else if (q != "mass" && q != "kinetic_energy") {
      std::string names = "drag_coefficient, lift_coefficient, position";
      for (const auto& info : CapsuleTrack<D>::quantities) names += ", " + std::string(info.name);
      refuse(fmt::format("one of {}, mass, kinetic_energy ({}D)", names, D));
    }
  }
}

template <class L, class T, class Op>
class Scene {
 public:
  static constexpr int D = L::d;
  using FluidT = Fluid<L, T, Op>;
  using Forcing = std::variant<ibm::DirectForcing<D, ibm::Cosine4>, ibm::DirectForcing<D, ibm::Roma3>,
                               ibm::DirectForcing<D, ibm::Linear2>>;

  Scene(const cases::CaseSpec& spec, const LatticeUnits& units, const Op& coarse_op)
      : spec_(spec), units_(units), fluid_(make_setup(spec, units, coarse_op)) {
    build_bodies();
    build_series_columns();
    fluid_.initialise([&](const Vec<D>& x) {
      const auto u = imposed_velocity(spec_, std::vector<double>(x.data(), x.data() + D));
      Vec<D> ulu;
      for (int a = 0; a < D; ++a) ulu[a] = u[a] * units_.velocity_lu;
      return std::pair{1.0, Vec<D>(ulu + initial_perturbation(x))};
    });
  }

  /// Restores the state of a checkpoint written by an earlier run of the same case (the
  /// scene is built as for a fresh run first); run() then continues after its step.
  void restore(io::CheckpointReader& ar) { checkpoint(ar); }

  RunResult run(io::RunDirectory& dir, const ProgressFn& progress, const CheckpointPolicy& policy = {}) {
    start_ = clock::now();
    const bool resumed = step_ > 0;
    const double dt = units_.blocks[0].dt;
    const long total = units_.coarse_steps;
    const long sample_every = series_sample_every(spec_, units_);
    const long guard_every = spec_.numerics.guards.every;
    const long track_every = std::max(1L, static_cast<long>(capsule_track_interval / dt));
    std::vector<long> snapshot_steps;
    for (double ts : spec_.outputs.snapshots.times) snapshot_steps.push_back(std::lround(std::ceil(ts / dt - 1e-9)));

    // A resumed run rewrites the series it had at its checkpoint and continues the snapshot file.
    io::SeriesWriter series(dir.partial_path("series.h5"), columns_, {{"case_id", spec_.id}, {"fidelity", spec_.fidelity}});
    const std::size_t width = columns_.size();
    for (std::size_t r = 0; r < series_rows_.size(); r += width)
      series.append(std::span<const double>(series_rows_).subspan(r, width));
    std::optional<io::SnapshotWriter<D>> snapshots;
    if (!snapshot_steps.empty()) {
      if (resumed)
        snapshots.emplace(io::SnapshotWriter<D>::reopen(dir.partial_path("snapshots.h5"), dir.path("snapshots.xdmf"),
                                                        "snapshots.h5", nlohmann::json::parse(snapshot_index_)));
      else
        snapshots.emplace(dir.partial_path("snapshots.h5"), dir.path("snapshots.xdmf"), "snapshots.h5",
                          nlohmann::json{{"case_id", spec_.id}});
    }

    if (!resumed) {
      mass0_ = total_mass();
      // A snapshot at t = 0 is the initial state (the rest shape of the capsules, the imposed flow).
      if (snapshots && std::find(snapshot_steps.begin(), snapshot_steps.end(), 0L) != snapshot_steps.end())
        core::timed(seconds_output_, [&] { write_snapshot(*snapshots, 0.0); });
    }
    const long every_steps = policy.interval > 0 ? std::max(1L, std::lround(policy.interval / dt)) : 0;
    auto last_checkpoint = clock::now();
    auto last_report = clock::now();
    auto hook = [&](const typename FluidT::Pop& pop, typename FluidT::Force& f) { return apply_ib(pop, f); };
    auto swept = [&] { advect_capsules(); };
    std::vector<double> row(width);
    try {
      for (long step = step_ + 1; step <= total; ++step) {
        step_ = step;
        core::timed(seconds_fluid_, [&] { fluid_.step(hook, swept); });
        const double t = step * dt;
        if (step == policy.sigterm_at_step) std::raise(SIGTERM);
        // A stop request (core/interrupt.hpp) ends the run after this step and its checkpoint.
        const bool stop = step < total && core::stop_signal() != 0;
        const bool checkpoint_due =
            step < total && (stop || (every_steps > 0 && step % every_steps == 0) ||
                             (policy.wall_seconds > 0 && seconds_since(last_checkpoint) >= policy.wall_seconds));
        // A checkpoint is always a state that passed the guards (the last good state).
        const bool guard_due = step % guard_every == 0 || step == total || checkpoint_due;
        const bool sample_due = step % sample_every == 0 || step == total;
        // The capsules' shapes at every step that reads them, and often enough in between to
        // keep their angles continuous (track_every).
        if (!capsules_.empty() && (step % track_every == 0 || guard_due || sample_due))
          core::timed(seconds_diagnostics_, [&] { track_capsules(); });
        if (guard_due) core::timed(seconds_diagnostics_, [&] { check_guards(step); });
        if (sample_due) {
          core::timed(seconds_diagnostics_, [&] { sample(t, row); });
          core::timed(seconds_output_, [&] { series.append(row); });
          series_rows_.insert(series_rows_.end(), row.begin(), row.end());
        }
        if (snapshots && std::find(snapshot_steps.begin(), snapshot_steps.end(), step) != snapshot_steps.end())
          core::timed(seconds_output_, [&] { write_snapshot(*snapshots, t); });
        if (checkpoint_due) {
          write_checkpoint(dir, snapshots ? &*snapshots : nullptr, policy);
          last_checkpoint = clock::now();
        }
        if (stop) {
          series.close();
          if (snapshots) snapshots->close();
          const int signal = core::stop_signal();
          throw core::Interrupted(
              signal, step,
              fmt::format("stopped by {} after step {} of {} (t = {:.6g} L/U); the state is in {}: continue with "
                          "`caplab run --resume {}`. The series so far is in series.h5.partial (not a result)",
                          core::signal_name(signal), step, total, t, dir.path("checkpoint.h5").string(),
                          dir.root().string()));
        }
        if (progress && clock::now() - last_report > std::chrono::seconds(1)) {
          const double per_step = seconds_since(start_) / static_cast<double>(step - first_step_);
          progress(step, total, t, fluid_.updates_per_step() / per_step / 1e6, per_step * static_cast<double>(total - step));
          last_report = clock::now();
        }
      }
    } catch (const core::NumericalError& e) {
      // What the run wrote stays readable as .partial files (never a result), and the message
      // says where the last good state is.
      series.close();
      if (snapshots) snapshots->close();
      const std::string kept =
          checkpoints_.count > 0
              ? fmt::format(" The last good state (step {}, t = {:.6g} L/U) is kept in {}.", checkpoints_.last_step,
                            checkpoints_.last_step * dt, dir.path("checkpoint.h5").string())
              : std::string(" No checkpoint was written before the failure.");
      throw core::NumericalError(e.step(), e.where(), e.quantity(),
                                 e.cause() + ". The series up to the failure is in series.h5.partial." + kept);
    }
    series.close();
    dir.commit_file("series.h5");
    if (snapshots) {
      snapshots->close();
      dir.commit_file("snapshots.h5");
    }

    RunResult r;
    r.steps = total;
    r.wall_seconds = wall_before_ + seconds_since(start_);
    r.mlups = fluid_.updates_per_step() * total / r.wall_seconds / 1e6;
    r.checkpoints = {{"count", checkpoints_.count},
                     {"seconds", checkpoints_.seconds},
                     {"bytes", checkpoints_.bytes},
                     {"interval", policy.interval},
                     {"wall_seconds", policy.wall_seconds}};
    const double coupling = fluid_.coupling_seconds();
    // The IB hook runs inside the fluid step: report it apart from the fluid update.
    r.stage_seconds = {{"fluid", seconds_fluid_ - coupling - seconds_ib_ - seconds_membrane_},
                       {"coupling", coupling},
                       {"ib", seconds_ib_},
                       {"membrane", seconds_membrane_},
                       {"diagnostics", seconds_diagnostics_},
                       {"output", seconds_output_}};
    r.summary = summarise(dir);
    return r;
  }

 private:
  using clock = std::chrono::steady_clock;
  static double seconds_since(clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); }

  /// Everything that evolves (io/checkpoint.hpp archive). What is not here is rebuilt from the
  /// case by the constructor or recomputed by the next step before it is read: the force fields
  /// (see Fluid::checkpoint), the IB stencils, membrane forces and node velocities, the shapes
  /// of the capsule tracks, the poses of moving bodies (exact functions of time).
  template <class Archive>
  void checkpoint(Archive& ar) {
    ar("scene/step", step_);
    ar("scene/fine_steps", fine_steps_);
    ar("scene/mass0", mass0_);
    double wall = wall_before_ + (Archive::loading ? 0.0 : seconds_since(start_));
    ar("scene/wall_seconds", wall);
    const std::initializer_list<std::pair<const char*, double*>> stages = {
        {"fluid", &seconds_fluid_}, {"ib", &seconds_ib_}, {"membrane", &seconds_membrane_},
        {"diagnostics", &seconds_diagnostics_}, {"output", &seconds_output_}};
    for (const auto& [name, value] : stages)
      ar(std::string("scene/seconds/") + name, *value);
    fluid_.checkpoint(ar);
    for (std::size_t c = 0; c < capsules_.size(); ++c) {
      const std::string prefix = "capsules/" + std::to_string(c) + "/";
      capsules_[c].checkpoint(ar, prefix);
      capsule_tracks_[c].checkpoint(ar, prefix + "track/");
    }
    ar("series/rows", series_rows_);
    ar("snapshots/index", snapshot_index_);
    ar("checkpoints/count", checkpoints_.count);
    ar("checkpoints/seconds", checkpoints_.seconds);
    if constexpr (Archive::loading) {
      wall_before_ = wall;
      first_step_ = step_;
      checkpoints_.last_step = step_;
    }
  }

  /// Writes checkpoint.h5 atomically (complete or absent) after `step_`; `policy.meta` (the case
  /// and the build) is stored with the state. Counts its cost.
  void write_checkpoint(io::RunDirectory& dir, const io::SnapshotWriter<D>* snapshots, const CheckpointPolicy& policy) {
    const auto t0 = clock::now();
    snapshot_index_ = snapshots ? snapshots->index().dump() : "[]";
    ++checkpoints_.count;
    {
      io::CheckpointWriter w(dir.partial_path("checkpoint.h5"));
      std::string meta = policy.meta;
      w("meta", meta);
      checkpoint(w);
      w.close();
      checkpoints_.bytes = static_cast<double>(w.file_bytes());
    }
    dir.commit_file("checkpoint.h5");
    checkpoints_.last_step = step_;
    const double spent = seconds_since(t0);
    checkpoints_.seconds += spent;
    seconds_output_ += spent;
    if (policy.kill_after > 0 && ++checkpoints_this_process_ == policy.kill_after) std::raise(SIGKILL);
  }

  struct RigidBody {
    std::string name;
    cases::ShapeSpec shape;
    geometry::MarkerSet<D> markers;
    std::vector<double> weight_lu;
    std::vector<Vec<D>> desired_lu;
    Forcing forcing;
    Vec<D> force_on_body_lu = Vec<D>::Zero();
    double coefficient_scale = 1.0;  // 1 / (½ ρ U_lu² A_lu)
    // Kinematics (a fixed body's is constant). A moving body keeps its markers relative to the
    // centre at the initial orientation, and what the internal-mass correction needs
    // (ibm/internal_mass.hpp, rigid form).
    std::optional<expr::RigidKinematics> kinematics;  // always set; optional only for default construction
    bool moving = false;
    std::vector<Vec<D>> offsets;
    double angle0 = 0.0;
    double volume_lu = 0.0;
    expr::RigidPose pose;
  };

  static typename FluidT::Setup make_setup(const cases::CaseSpec& spec, const LatticeUnits& units, const Op& op) {
    typename FluidT::Setup s;
    auto grid_of = [](const BlockUnits& b) {
      Index<D> n;
      Vec<D> o;
      for (int a = 0; a < D; ++a) n[a] = b.nodes[a], o[a] = b.origin[a];
      return field::Grid<D>(n, o, b.dx);
    };
    s.coarse = grid_of(units.blocks[0]);
    if (units.blocks.size() == 2) s.fine = grid_of(units.blocks[1]);
    for (int a = 0; a < D; ++a) {
      switch (spec.physics.boundaries[a]) {
        case cases::BoundaryType::periodic: s.boundaries[a] = boundary::Kind::periodic; break;
        case cases::BoundaryType::far_field: s.boundaries[a] = boundary::Kind::far_field; break;
        case cases::BoundaryType::wall: s.boundaries[a] = boundary::Kind::wall; break;
      }
    }
    s.far_field = spec.numerics.far_field == cases::FarFieldScheme::equilibrium ? boundary::FarField::equilibrium
                                                                               : boundary::FarField::extrapolation;
    const double ulu = units.velocity_lu;
    s.imposed_velocity_lu = [spec, ulu](const Vec<D>& x) {
      const auto u = imposed_velocity(spec, std::vector<double>(x.data(), x.data() + D));
      Vec<D> v;
      for (int a = 0; a < D; ++a) v[a] = u[a] * ulu;
      return v;
    };
    s.coarse_op = op;
    if (spec.physics.flow.type == cases::FlowSpec::Type::body_force)
      s.body_force_lu[0] = spec.physics.flow.body_force * ulu * ulu * units.blocks[0].dx;
    s.finest_forced = !spec.physics.bodies.empty();
    return s;
  }

  void build_bodies() {
    const auto& fine = fluid_.finest().pop.grid();
    const double h = fine.dx();
    const double spacing = spec_.numerics.ib.marker_spacing * h;
    for (const auto& b : spec_.physics.bodies) {
      if (b.is_capsule()) {
        build_capsule(b);
        continue;
      }
      RigidBody body;
      body.name = b.name;
      body.shape = b.shape;
      body.forcing = make_forcing();
      Vec<D> c;
      for (int a = 0; a < D; ++a) c[a] = b.shape.center[a];
      // Coefficients per unit span over the reference length (2D: the diameter, the chord of
      // an ellipse) or over the frontal area pi D^2/4 (3D).
      double reference_lu = 0;
      if constexpr (D == 2) {
        if (b.shape.type == cases::ShapeSpec::Type::ellipse) {
          body.markers =
              geometry::ellipse_markers(c, b.shape.semi_major(), b.shape.semi_minor(), b.shape.angle, spacing);
          reference_lu = 2 * b.shape.semi_major() / h;
        } else {
          body.markers = geometry::circle_markers(c, b.shape.diameter, spacing);
          reference_lu = b.shape.diameter / h;
        }
      } else {
        body.markers = geometry::sphere_markers(c, b.shape.diameter, spacing);
        const double r = 0.5 * b.shape.diameter / h;
        reference_lu = std::numbers::pi * r * r;
      }
      body.coefficient_scale = 1.0 / (0.5 * units_.velocity_lu * units_.velocity_lu * reference_lu);
      for (double w : body.markers.weight) body.weight_lu.push_back(ibm::measure_to_lattice<D>(w, h));
      body.desired_lu.assign(body.markers.X.size(), Vec<D>::Zero());  // at rest until moved
      CAPLAB_CHECK(b.motion && b.motion->kinematics, "rigid body '" + b.name + "' has no kinematics (load_case builds them)");
      body.kinematics = b.motion->kinematics;
      if (b.is_moving()) {
        body.moving = true;
        body.angle0 = b.shape.angle;
        for (const auto& X : body.markers.X) body.offsets.push_back(X - c);
        const double r_eq = 0.5 * b.shape.diameter / h;  // equivalent radius: same area/volume
        body.volume_lu = D == 2 ? std::numbers::pi * r_eq * r_eq : 4.0 / 3.0 * std::numbers::pi * r_eq * r_eq * r_eq;
        move_body(body, 0.0);
      }
      bodies_.push_back(std::move(body));
    }
    if (fluid_.two_level()) {
      periodic_.fill(false);
    } else {
      for (int a = 0; a < D; ++a) periodic_[a] = spec_.physics.boundaries[a] == cases::BoundaryType::periodic;
    }
  }

  void build_capsule(const cases::BodySpec& b) {
    const auto& m = *b.membrane;
    const double a = 0.5 * b.shape.diameter;  // equivalent radius, in L
    // Moduli in lattice units of the finest block: E = mu k a / G with mu = rho nu (rho = 1)
    // and k a = U (the lattice velocity).
    const double E = units_.blocks.back().nu_lu * units_.velocity_lu / m.capillary;
    Vec<D> c;
    for (int k = 0; k < D; ++k) c[k] = b.shape.center[k];
    if constexpr (D == 2) {
      // Positions are in L: E_B = E_b a^2 E with a in L.
      const double E_B = m.bending_ratio * a * a * E;
      auto rest = geometry::ring_nodes(cases::ring_shape(b.shape), c, a, b.shape.angle, m.nodes);
      auto kappa0 = membrane::ReferenceCurvature::initial;
      if (m.reference_curvature == cases::MembraneSpec::ReferenceCurvature::circle)
        kappa0 = membrane::ReferenceCurvature::circle;
      else if (m.reference_curvature == cases::MembraneSpec::ReferenceCurvature::flat)
        kappa0 = membrane::ReferenceCurvature::flat;
      auto ring = std::make_unique<membrane::RingMembrane>(rest, E, E_B, kappa0);
      const auto& ring_ref = *ring;
      capsules_.emplace_back(b.name, std::move(rest), std::move(ring), make_transfer());
      capsule_tracks_.emplace_back(capsules_.back(), ring_ref);
    } else {
      // Node forces of a surface modulus scale with length (f ~ E A0 / l): with positions in L
      // the modulus E / h gives forces in lattice units (h = fine spacing in L).
      auto mesh = cases::capsule_mesh(b.shape, m.subdivisions);
      for (auto& x : mesh.nodes) x += c;
      const double E_L = E / fluid_.finest().pop.grid().dx();
      membrane::MembraneLaw law = membrane::NeoHookean{E_L};
      if (m.law == cases::MembraneSpec::Law::zero_thickness) law = membrane::ZeroThickness{E_L};
      if (m.law == cases::MembraneSpec::Law::skalak) law = membrane::Skalak{E_L, m.area_dilation};
      auto fem = std::make_unique<membrane::FemMembrane>(mesh, law);
      const auto& fem_ref = *fem;
      capsules_.emplace_back(b.name, std::move(mesh.nodes), std::move(fem), make_transfer());
      const auto& q = spec_.outputs.series.quantities;
      capsule_tracks_.emplace_back(capsules_.back(), fem_ref,
                                   std::find(q.begin(), q.end(), "section_inclination") != q.end());
    }
  }

  typename Capsule<D>::Transfers make_transfer() const {
    switch (spec_.numerics.ib.kernel) {
      case cases::IbSpec::Kernel::roma3: return ibm::Transfer<D, ibm::Roma3>();
      case cases::IbSpec::Kernel::linear2: return ibm::Transfer<D, ibm::Linear2>();
      default: return ibm::Transfer<D, ibm::Cosine4>();
    }
  }

  /// Shape of each capsule after a coarse step (capsule_track.hpp), at the steps that read it
  /// and at least every capsule_track_interval of time (Scene::run). A surface the shape
  /// diagnostics reject (it encloses no volume, a non-finite node) is a membrane that has
  /// diverged: exit 3, like the guards, not a failure of the program.
  void track_capsules() {
    for (std::size_t c = 0; c < capsules_.size(); ++c) {
      try {
        capsule_tracks_[c].update(capsules_[c]);
      } catch (const core::Error& e) {
        throw core::NumericalError(step_, fmt::format("capsule '{}'", capsules_[c].name()), e.what(),
                                   diverged_membrane(capsules_[c]));
      }
    }
  }

  /// Transverse velocity blob (lattice units) 1.5 D downstream of each body, width D/2
  /// (physics.flow.perturbation; see case_spec.hpp).
  Vec<D> initial_perturbation(const Vec<D>& x) const {
    Vec<D> du = Vec<D>::Zero();
    const double amp = spec_.physics.flow.perturbation;
    if (amp == 0.0) return du;
    const auto& dir = spec_.physics.flow.direction;
    for (const auto& b : spec_.physics.bodies) {
      Vec<D> c;
      for (int a = 0; a < D; ++a) c[a] = b.shape.center[a] + 1.5 * b.shape.diameter * dir[a];
      const double w = 0.5 * b.shape.diameter;
      const double g = std::exp(-(x - c).squaredNorm() / (2 * w * w));
      du[0] += -amp * dir[1] * g * units_.velocity_lu;
      du[1] += amp * dir[0] * g * units_.velocity_lu;
    }
    return du;
  }

  Forcing make_forcing() const {
    const int it = spec_.numerics.ib.forcing_iterations;
    switch (spec_.numerics.ib.kernel) {
      case cases::IbSpec::Kernel::roma3: return ibm::DirectForcing<D, ibm::Roma3>(it);
      case cases::IbSpec::Kernel::linear2: return ibm::DirectForcing<D, ibm::Linear2>(it);
      default: return ibm::DirectForcing<D, ibm::Cosine4>(it);
    }
  }

  /// The IB stage of one finest-block step: adds the bodies' force density to f.
  /// Returns the nodes where it wrote a force (the union of the stencils, see ForcingHook).
  collision::ForcedRegion apply_ib(const typename FluidT::Pop& pop, typename FluidT::Force& f) {
    if (bodies_.empty() && capsules_.empty()) return {};
    core::timed(seconds_ib_, [&] { restore_forced_nodes(f); });
    if (!bodies_.empty()) core::timed(seconds_ib_, [&] { force_bodies(pop, f); });
    if (!capsules_.empty()) spread_capsules(pop, f);
    core::timed(seconds_ib_, [&] {
      if (capsules_.empty()) collect_forced_nodes(pop.grid());  // spread_capsules collected them
    });
    ++fine_steps_;
    collision::ForcedRegion region = forced_region();
    if (!capsules_.empty())  // for the markers' move after the sweep (advect_capsules)
      for (int a = 0; a < D; ++a) region.velocity[a] = forced_velocity_.comp[a].data();
    return region;
  }

  /// After the sweep of the finest block: the markers move with the velocity the forced
  /// collision found at their stencils' nodes (capsule.hpp, steps 3 and 4).
  void advect_capsules() {
    if (capsules_.empty()) return;
    core::timed(seconds_ib_, [&] {
      const double dx = fluid_.finest().pop.grid().dx();
      for (auto& c : capsules_) c.advect(forced_velocity_, dx);
    });
  }

  /// Sets the nodes the IB wrote last step (forced_nodes_, each once) back to the uniform body
  /// force: the field is that force everywhere else (see Fluid::ForcingHook).
  void restore_forced_nodes(typename FluidT::Force& f) const {
    const auto& base = fluid_.body_force(fluid_.block_count() - 1);
    const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(forced_nodes_.size());
#pragma omp parallel for schedule(static) if (count > 1024)
    for (std::ptrdiff_t k = 0; k < count; ++k)
      for (int a = 0; a < D; ++a) f.comp[a][forced_nodes_[k]] = base[a];
  }

  /// forced_nodes_ = the union of the current stencils of all bodies and capsules, each node
  /// once and in memory order (ibm::StencilUnion), and forced_spans_ the row spans that cover
  /// it (collision::cover_with_spans), which the forced collision (and the velocity it writes
  /// for the capsules) walks. Memory order lets it walk the block's rows instead of jumping
  /// between the rows of each stencil (measured: unsorted, the forced collision of a 3D
  /// capsule's ~10k stencil nodes cost five unforced updates per node).
  void collect_forced_nodes(const field::Grid<D>& grid) {
    stencil_union_.begin(grid);
    for (const auto& b : bodies_)
      std::visit([&](const auto& forcing) { forcing.transfer().mark_stencil_nodes(stencil_union_); }, b.forcing);
    for (const auto& c : capsules_) c.mark_stencil_nodes(stencil_union_);
    stencil_union_.collect(forced_nodes_);
    collision::cover_with_spans<collision::simd_chunk<T>>(grid, forced_nodes_, forced_spans_);
  }
  collision::ForcedRegion forced_region() const { return {forced_nodes_, forced_spans_}; }

  /// Membrane forces and spreading (capsule.hpp, steps 1 and 2); the forced collision then finds
  /// the velocity at the stencils' nodes and advect_capsules moves the markers.
  void spread_capsules(const typename FluidT::Pop& pop, typename FluidT::Force& f) {
    core::timed(seconds_membrane_, [&] {
      for (auto& c : capsules_) c.compute_forces();
    });
    core::timed(seconds_ib_, [&] {
      for (auto& c : capsules_) guarded(c, [&] { c.spread(pop.grid(), periodic_, f); });
      collect_forced_nodes(pop.grid());
      // The velocity goes into a block-sized field (only at the stencil nodes, which are all
      // the interpolation reads), so that the interpolation reads rows of consecutive nodes.
      if (static_cast<std::ptrdiff_t>(forced_velocity_.comp[0].size()) != pop.grid().size())
        forced_velocity_ = field::VectorField<D>(pop.grid().size());
    });
  }

  /// Whether the membrane of `c` has blown up: an element stretched 3 times its rest size,
  /// collapsed below numerics.guards.min_area_ratio, or folded.
  bool blown_up(const Capsule<D>& c) const {
    const auto h = c.membrane().health(c.positions());
    return !(h.max_ratio < 3.0) || !(h.min_ratio > spec_.numerics.guards.min_area_ratio) || h.folded >= 0;
  }

  /// The state of the elements of `c`'s membrane, for the failure messages.
  static std::string element_state(const Capsule<D>& c) {
    const auto h = c.membrane().health(c.positions());
    return fmt::format("elements at {:.3g} to {:.3g} times their rest size, {}", h.min_ratio, h.max_ratio,
                       h.folded >= 0 ? "folded" : "none folded");
  }

  /// The likely cause of a membrane that has blown up, with the state of its elements.
  static std::string diverged_membrane(const Capsule<D>& c) {
    return fmt::format("the membrane nodes diverged ({}): the explicit membrane-fluid coupling is too stiff for the "
                       "time step, which happens at small capillary numbers G; lower numerics.lattice_velocity (a "
                       "smaller time step; at a fixed Reynolds number the membrane's lattice modulus falls as its "
                       "square)",
                       element_state(c));
  }

  /// The likely cause of a capsule that reached the fine block's edge with no element over the
  /// blow-up limits. Those limits miss a thin spike of nodes each stretched less than 3 times, so
  /// the message gives the element state and where to look rather than calling the membrane healthy.
  static std::string reached_block_edge(const Capsule<D>& c) {
    return fmt::format("the capsule reached the fine block's edge with its {}: if it moved or deformed that far (the "
                       "last rows of series.h5.partial show a smooth deformation), enlarge the fine region "
                       "(numerics.grid.fine_region) or move the capsule away from its edge; if its deformation jumps "
                       "in those rows, the membrane diverged locally (a smaller numerics.lattice_velocity)",
                       element_state(c));
  }

  /// Runs f() for capsule `c`; a core::Error from the IB stage (a stencil off the block, a
  /// non-finite position) becomes a NumericalError naming the capsule, the step and, from the
  /// state of its membrane, which of the two usual causes it is.
  template <class F>
  void guarded(const Capsule<D>& c, F&& f) const {
    try {
      f();
    } catch (const core::NumericalError&) {
      throw;
    } catch (const core::Error& e) {
      throw core::NumericalError(step_, fmt::format("immersed boundary of capsule '{}'", c.name()), e.what(),
                                 blown_up(c) ? diverged_membrane(c) : reached_block_edge(c));
    }
  }

  void force_bodies(const typename FluidT::Pop& pop, typename FluidT::Force& f) {
    auto u_star = [&](const Index<D>&, std::ptrdiff_t n) {
      const auto m = collision::node_moments<L, T>(pop, n);
      Vec<D> u;
      for (int a = 0; a < D; ++a) u[a] = m.u[a];
      return u;
    };
    auto rho = [&](const Index<D>&, std::ptrdiff_t n) { return collision::node_moments<L, T>(pop, n).rho; };
    const double t = fine_steps_ * units_.blocks.back().dt;
    for (auto& b : bodies_)
      if (b.moving) move_body(b, t);
    for (auto& b : bodies_) {
      try {
        std::visit(
            [&](auto& forcing) {
              forcing.apply(pop.grid(), periodic_, b.markers.X, b.desired_lu, b.weight_lu, u_star, rho, f);
              // Moving: plus the inertia of the fluid inside (rigid form, rho = 1), exact a(t).
              b.force_on_body_lu = -forcing.total_force_on_fluid();
              if (b.moving) b.force_on_body_lu += b.volume_lu * acceleration_lu(b.pose);
            },
            b.forcing);
      } catch (const core::NumericalError&) {
        throw;
      } catch (const core::Error& e) {
        // The IB stage sees a diverged flow first (it checks every stencil node every step).
        throw core::NumericalError(step_, fmt::format("immersed boundary of body '{}'", b.name), e.what(),
                                   "the flow diverged next to the body; the usual fixes move tau away from 1/2 "
                                   "(a finer grid, or a higher numerics.lattice_velocity at the same Re as far as the "
                                   "Mach number allows) or damp the odd moments (BGK: the TRT operator; TRT: a "
                                   "smaller numerics.collision.magic)");
      }
    }
  }

  /// Places the markers of a moving body at time t (L/U) and sets their velocities: centre
  /// velocity plus omega x r (2D), exact from the kinematics.
  void move_body(RigidBody& b, double t) const {
    b.pose = b.kinematics->at(t);
    Vec<D> c, v;
    for (int a = 0; a < D; ++a) c[a] = b.pose.x[a], v[a] = b.pose.v[a];
    const double turn = b.pose.angle - b.angle0, cs = std::cos(turn), sn = std::sin(turn);
    for (std::size_t m = 0; m < b.offsets.size(); ++m) {
      Vec<D> r = b.offsets[m];
      Vec<D> u = v;
      if constexpr (D == 2) {
        r = Vec<2>(cs * r[0] - sn * r[1], sn * r[0] + cs * r[1]);
        u += b.pose.omega * Vec<2>(-r[1], r[0]);
      }
      b.markers.X[m] = c + r;
      b.desired_lu[m] = u * units_.velocity_lu;
    }
  }

  /// Centre acceleration in lattice units of the finest block: a (U^2/L) * U_lu^2 * dx (L).
  Vec<D> acceleration_lu(const expr::RigidPose& p) const {
    const double scale = units_.velocity_lu * units_.velocity_lu * fluid_.finest().pop.grid().dx();
    Vec<D> a;
    for (int k = 0; k < D; ++k) a[k] = p.a[k] * scale;
    return a;
  }

  /// Drag along the flow direction, lift perpendicular to it (in the x–y plane).
  std::pair<double, double> coefficients(const RigidBody& b) const {
    Vec<D> e_drag = Vec<D>::Zero();
    e_drag[0] = 1.0;
    if (spec_.physics.flow.type == cases::FlowSpec::Type::uniform && !spec_.physics.flow.direction.empty())
      for (int a = 0; a < D; ++a) e_drag[a] = spec_.physics.flow.direction[a];
    Vec<D> e_lift = Vec<D>::Zero();
    e_lift[0] = -e_drag[1];
    e_lift[1] = e_drag[0];
    return {b.force_on_body_lu.dot(e_drag) * b.coefficient_scale, b.force_on_body_lu.dot(e_lift) * b.coefficient_scale};
  }

  void build_series_columns() {
    check_series_quantities<D>(spec_);
    columns_.push_back({"t", "L/U", "time in units of the reference length over the reference velocity"});
    const bool many = bodies_.size() > 1;
    for (const auto& q : spec_.outputs.series.quantities) {
      if (q == "drag_coefficient" || q == "lift_coefficient") {
        const std::string over = " / (0.5 rho U^2 D) (2D: per unit span, D the diameter or an ellipse's chord; 3D: "
                                 "over the area pi D^2/4); moving bodies include the inertia of their inner fluid";
        for (const auto& b : bodies_)
          columns_.push_back({many ? b.name + "." + q : q, "1",
                              (q == "drag_coefficient" ? "C_d = F_drag" : "C_l = F_lift") + over});
      } else if (q == "position") {
        for (const auto& b : bodies_) {
          const std::string prefix = many ? b.name + "." : "";
          for (int a = 0; a < D; ++a)
            columns_.push_back({prefix + "xyz"[a], "L", "centre of the body along " + std::string(1, "xyz"[a])});
          if constexpr (D == 2) columns_.push_back({prefix + "angle", "rad", "orientation of the body's long axis from x"});
        }
      } else if (is_capsule_quantity(q)) {
        const auto& info = capsule_quantity(q);
        for (const auto& c : capsules_)
          columns_.push_back({capsules_.size() > 1 ? c.name() + "." + q : q, std::string(info.unit),
                              std::string(info.definition)});
      } else if (q == "mass") {
        columns_.push_back({"mass", "1", "total fluid mass over its initial value"});
      } else {  // kinetic_energy (check_series_quantities refused any other name)
        columns_.push_back({"kinetic_energy", "rho U^2 L^D", "integral of rho u^2 / 2 over the domain"});
      }
    }
  }

  static bool is_capsule_quantity(const std::string& q) { return find_capsule_quantity<D>(q) != nullptr; }
  /// A capsule quantity's unit and definition (q is one: the series columns were checked).
  static const CapsuleQuantity& capsule_quantity(const std::string& q) { return *find_capsule_quantity<D>(q); }

  void sample(double t, std::vector<double>& row) {
    std::size_t k = 0;
    row[k++] = t;
    for (const auto& q : spec_.outputs.series.quantities) {
      if (q == "drag_coefficient" || q == "lift_coefficient") {
        for (const auto& b : bodies_) {
          const auto [cd, cl] = coefficients(b);
          row[k++] = q == "drag_coefficient" ? cd : cl;
        }
      } else if (q == "position") {
        for (const auto& b : bodies_) {
          // At the row's time (b.pose is that of the last IB stage, one fine step earlier).
          const auto pose = b.kinematics->at(t);
          for (int a = 0; a < D; ++a) row[k++] = pose.x[a];
          if constexpr (D == 2) row[k++] = pose.angle;
        }
      } else if (is_capsule_quantity(q)) {
        for (std::size_t c = 0; c < capsules_.size(); ++c)
          row[k++] = capsule_tracks_[c].value(q, capsules_[c], units_.velocity_lu);
      } else if (q == "mass") {
        row[k++] = total_mass() / mass0_;
      } else if (q == "kinetic_energy") {
        row[k++] = integrate([](double rho, const Vec<D>& u) { return 0.5 * rho * u.squaredNorm(); }) /
                   (units_.velocity_lu * units_.velocity_lu);
      }
    }
  }

  /// ∫ g(ρ, u_lu) dV over the domain (in L^D), fine block where it exists.
  template <class G>
  double integrate(G&& g) const {
    double sum = 0;
    for (std::size_t b = 0; b < fluid_.block_count(); ++b) {
      const auto& blk = fluid_.block(b);
      const auto& grid = blk.pop.grid();
      const double vol = std::pow(grid.dx(), D);
      double s = 0;
      field::for_each_interior<D>(grid, [&](const Index<D>& ijk) {
        if (b == 0 && fluid_.two_level() && fluid_.coupling().covered(ijk)) return;
        const auto m = collision::node_moments<L, T>(blk.pop, grid.index(ijk));
        Vec<D> u;
        for (int a = 0; a < D; ++a) u[a] = m.u[a];
        s += g(m.rho, u);
      });
      sum += s * vol;
    }
    return sum;
  }

  double total_mass() const {
    return integrate([](double rho, const Vec<D>&) { return rho; });
  }

  /// The likely cause of a flow that left the guards' range: a membrane that blew up first (the
  /// usual case with capsules: make stress measures the explicit-coupling limit), tau close to
  /// 1/2, or a lattice velocity too high for the Reynolds number.
  std::string flow_divergence_cause(double tau) const {
    for (const auto& c : capsules_)
      if (blown_up(c)) return fmt::format("capsule '{}' first: {}", c.name(), diverged_membrane(c));
    const double limit = membrane_stiffness_limit(D);
    for (const auto& b : spec_.physics.bodies)
      if (b.membrane) {
        const double E_lu = membrane_lattice_modulus(units_, b);
        if (E_lu > limit)
          return fmt::format("the membrane of '{}' is too stiff for the time step: its lattice modulus E_lu = nu U / G "
                             "(times the law's stiffness factor, Skalak: (1 + 2C)/2) = {:.3g} is above the "
                             "explicit-coupling limit measured by make stress (about {:g} in {}D); lower "
                             "numerics.lattice_velocity (E_lu grows as its square; a finer grid at the same lattice "
                             "velocity raises it)",
                             b.name, E_lu, limit, D);
      }
    if (tau < 0.55) return tau_near_half_cause(spec_.numerics.collision, tau);
    return fmt::format("the lattice velocity {:.3g} is too high for this flow (compressibility): lower "
                       "numerics.lattice_velocity",
                       units_.velocity_lu);
  }

  static std::string position_text(const Vec<D>& x) {
    std::string pos = fmt::format("{:.4g}", x[0]);
    for (int a = 1; a < D; ++a) pos += fmt::format(", {:.4g}", x[a]);
    return pos;
  }

  /// Stops the run with the step, the place and the likely cause when it has left the range
  /// where the method is valid (numerics.guards): non-finite, Mach or density on any block;
  /// a capsule's volume drift, a collapsed or folded membrane element. Markers leaving the
  /// fine block are caught by the IB stage itself (guarded()).
  void check_guards(long step) const {
    const auto& g = spec_.numerics.guards;
    // What is wrong with a node's moments, or nothing.
    auto problem_of = [&](const auto& m) -> std::string {
      double u2 = 0;
      for (int a = 0; a < D; ++a) u2 += m.u[a] * m.u[a];
      if (!std::isfinite(m.rho) || !std::isfinite(u2)) return "non-finite density or velocity";
      if (std::sqrt(3.0 * u2) > g.max_mach)
        return fmt::format("local Mach number {:.3f} above numerics.guards.max_mach = {}", std::sqrt(3.0 * u2),
                           g.max_mach);
      if (std::abs(m.rho - 1.0) > g.max_density_deviation)
        return fmt::format("density {:.4f} deviates from 1 by more than numerics.guards.max_density_deviation = {}",
                           m.rho, g.max_density_deviation);
      return {};
    };
    for (std::size_t b = 0; b < fluid_.block_count(); ++b) {
      const auto& blk = fluid_.block(b);
      const auto& grid = blk.pop.grid();
      const Index<D> n = grid.n();
      // The first offending node in memory order (the same whatever the thread count), planes
      // (the last axis) in parallel; its message is written afterwards.
      const int planes = n[D - 1];
      const std::ptrdiff_t per_plane = grid.interior_size() / planes;
      std::ptrdiff_t first = grid.interior_size();
#pragma omp parallel for schedule(static) reduction(min : first)
      for (int p = 0; p < planes; ++p) {
        for (std::ptrdiff_t k = 0; k < per_plane && k + p * per_plane < first; ++k) {
          Index<D> ijk;
          ijk[0] = static_cast<int>(k % n[0]);
          if constexpr (D == 3) ijk[1] = static_cast<int>(k / n[0]);
          ijk[D - 1] = p;
          // Coarse nodes under the fine block are restricted from it (outermost layer) or evolve
          // unread (deeper): the fine node is checked.
          if (b == 0 && fluid_.two_level() && fluid_.coupling().covered(ijk)) continue;
          if (!problem_of(collision::node_moments<L, T>(blk.pop, grid.index(ijk))).empty()) {
            first = std::min(first, k + p * per_plane);
            break;
          }
        }
      }
      if (first == grid.interior_size()) continue;
      Index<D> where;
      for (int a = 0; a < D; ++a) {
        where[a] = static_cast<int>(first % n[a]);
        first /= n[a];
      }
      throw core::NumericalError(
          step, fmt::format("{} block, node at ({}) L", units_.blocks[b].name, position_text(grid.position(where))),
          problem_of(collision::node_moments<L, T>(blk.pop, grid.index(where))),
          flow_divergence_cause(units_.blocks[b].tau));
    }
    for (std::size_t c = 0; c < capsules_.size(); ++c) {
      const auto& cap = capsules_[c];
      const double dv = capsule_tracks_[c].volume_change();
      const char* volume = D == 2 ? "enclosed area" : "volume";
      if (!(std::abs(dv) <= g.max_volume_change))
        throw core::NumericalError(
            step, fmt::format("capsule '{}'", cap.name()),
            fmt::format("{} changed by {:.3g} % (numerics.guards.max_volume_change = {:.3g} %)", volume, 100 * dv,
                        100 * g.max_volume_change),
            "fluid crosses the membrane: the membrane nodes are too far apart for the IB kernel (more nodes or "
            "subdivisions), the capsule is too coarse on the grid, or tau is large (slip through the diffuse "
            "interface); if this drift is expected, raise numerics.guards.max_volume_change");
      const auto h = cap.membrane().health(cap.positions());
      const char* element = D == 2 ? "segment" : "element";
      if (h.folded >= 0)
        throw core::NumericalError(
            step, fmt::format("capsule '{}', membrane {} {} at ({}) L", cap.name(), element, h.folded,
                              position_text(h.folded_at)),
            fmt::format("the {} is folded over its neighbours (inverted)", element), folded_cause(cap));
      if (!(h.min_ratio >= g.min_area_ratio))
        throw core::NumericalError(
            step, fmt::format("capsule '{}', membrane {} {} at ({}) L", cap.name(), element, h.worst,
                              position_text(h.worst_at)),
            fmt::format("the {} has shrunk to {:.3g} of its rest {} (numerics.guards.min_area_ratio = {})", element,
                        h.min_ratio, D == 2 ? "length" : "area", g.min_area_ratio),
            "the membrane is compressed far beyond its rest state: the explicit coupling is too stiff for the time "
            "step (small G: lower numerics.lattice_velocity), or the deformation is larger than the mesh resolves "
            "(large G: a finer membrane; for Skalak a larger area_dilation C)");
    }
  }

  /// The likely cause of a folded membrane element: the explicit coupling too stiff for the time
  /// step, or, when the membrane's lattice modulus is far below the coupling's limit (what
  /// `caplab check` prints), the membrane buckling under compression below its mesh's scale.
  std::string folded_cause(const Capsule<D>& cap) const {
    const auto& bodies = spec_.physics.bodies;
    const auto body = std::find_if(bodies.begin(), bodies.end(), [&](const auto& b) { return b.name == cap.name(); });
    CAPLAB_CHECK(body != bodies.end() && body->membrane, "a capsule is built from a body with a membrane");
    const double E_lu = membrane_lattice_modulus(units_, *body);
    const double limit = membrane_stiffness_limit(D);
    const std::string modulus = fmt::format("the membrane's lattice modulus E_lu = {:.3g} against the explicit "
                                            "coupling's limit of about {:g} (`caplab check`)",
                                            E_lu, limit);
    // A factor 10 below the limit: the stress maps (make stress) found the blow-up near it, not there.
    if (E_lu < 0.1 * limit) {
      const double bending = D == 2 ? body->membrane->bending_ratio : 0.0;
      return fmt::format(
          "the membrane buckles or wrinkles below what its mesh resolves: compressed somewhere along it with {} "
          "bending stiffness{}, it folds at the scale of its nodes. Not the time step: {}. More membrane nodes "
          "(physics.bodies.{}.membrane.{}) resolve the wrinkles, some bending stiffness suppresses them",
          bending > 0.0 ? "little" : "no", D == 2 ? fmt::format(" (E_b = {:g})", bending) : "", modulus,
          body - bodies.begin(), D == 2 ? "nodes" : "subdivisions");
    }
    return fmt::format("either the explicit coupling is too stiff for the time step ({}; a small capillary number G: "
                       "lower numerics.lattice_velocity), or the membrane buckles or wrinkles below what its mesh "
                       "resolves (the thesis reports wrinkles in long runs: a finer membrane or bending stiffness)",
                       modulus);
  }

  void write_snapshot(io::SnapshotWriter<D>& w, double t) const {
    for (std::size_t b = 0; b < fluid_.block_count(); ++b) {
      const auto& blk = fluid_.block(b);
      const auto& grid = blk.pop.grid();
      const std::ptrdiff_t N = grid.size();
      std::vector<double> rho(N, 1.0);
      std::array<std::vector<double>, D> u;
      for (auto& c : u) c.assign(N, 0.0);
      // Coarse nodes under the fine block show the fine node they coincide with (the value the
      // restriction would give them: it keeps ρ and u).
      const bool under_fine = b == 0 && fluid_.two_level();
      field::for_each_interior<D>(grid, [&](const Index<D>& ijk) {
        const auto n = grid.index(ijk);
        const auto m = under_fine && fluid_.coupling().covered(ijk)
                           ? collision::node_moments<L, T>(fluid_.finest().pop, fluid_.coupling().fine_node_under(ijk))
                           : collision::node_moments<L, T>(blk.pop, n);
        rho[n] = m.rho;
        for (int a = 0; a < D; ++a) u[a][n] = m.u[a] / units_.velocity_lu;  // in U
      });
      typename io::SnapshotWriter<D>::ScalarFields scalars;
      typename io::SnapshotWriter<D>::GridVectorFields vectors;
      std::vector<double> vort;
      std::array<std::vector<double>, 3> vort3;
      const auto& fields = spec_.outputs.snapshots.fields;
      auto wants = [&](const char* f) { return std::find(fields.begin(), fields.end(), f) != fields.end(); };
      if (wants("density")) scalars["density"] = rho;
      if (wants("velocity")) {
        std::array<std::span<const double>, D> spans;
        for (int a = 0; a < D; ++a) spans[a] = u[a];
        vectors["velocity"] = spans;
      }
      if (wants("vorticity")) {
        // Central differences in the interior, one-sided next to the ghost layer; in U/L.
        auto d = [&](int comp, int axis, const Index<D>& ijk) {
          Index<D> lo = ijk, hi = ijk;
          lo[axis] = std::max(ijk[axis] - 1, 0);
          hi[axis] = std::min(ijk[axis] + 1, grid.n()[axis] - 1);
          return (u[comp][grid.index(hi)] - u[comp][grid.index(lo)]) / ((hi[axis] - lo[axis]) * grid.dx());
        };
        if constexpr (D == 2) {
          vort.assign(N, 0.0);
          field::for_each_interior<2>(grid, [&](const Index<2>& ijk) { vort[grid.index(ijk)] = d(1, 0, ijk) - d(0, 1, ijk); });
          scalars["vorticity"] = vort;
        } else {
          for (auto& c : vort3) c.assign(N, 0.0);
          field::for_each_interior<3>(grid, [&](const Index<3>& ijk) {
            const auto n = grid.index(ijk);
            vort3[0][n] = d(2, 1, ijk) - d(1, 2, ijk);
            vort3[1][n] = d(0, 2, ijk) - d(2, 0, ijk);
            vort3[2][n] = d(1, 0, ijk) - d(0, 1, ijk);
          });
          vectors["vorticity"] = {std::span<const double>(vort3[0]), std::span<const double>(vort3[1]),
                                  std::span<const double>(vort3[2])};
        }
      }
      w.add_grid_field_step(t, grid, units_.blocks[b].name, scalars, vectors);
    }
    if constexpr (D == 2) {
      for (const auto& b : bodies_) {
        const auto segs = io::closed_ring_segments(static_cast<int>(b.markers.X.size()));
        w.add_mesh_step(t, b.name, b.markers.X, segs);
      }
    }
    for (std::size_t c = 0; c < capsules_.size(); ++c) capsule_tracks_[c].add_to_snapshot(w, t, capsules_[c]);
  }

  nlohmann::json summarise(const io::RunDirectory& dir) const {
    nlohmann::json metrics = nlohmann::json::object();
    const auto series = io::read_series(dir.path("series.h5"));
    const auto& tt = series.at("t");
    const double from = spec_.outputs.average_from;
    for (const auto& col : columns_) {
      if (col.name == "t") continue;
      const auto& v = series.at(col.name);
      metrics[col.name + "_final"] = {{"value", v.back()}, {"unit", col.unit}, {"definition", "value at the end of the run: " + col.definition}};
      const bool coefficient = col.name.ends_with("drag_coefficient") || col.name.ends_with("lift_coefficient");
      if (!coefficient) continue;
      const auto s = diagnostics::analyse_signal(tt, v, from);
      const std::string window = fmt::format(" over t >= {} L/U", from);
      metrics[col.name + "_mean"] = {{"value", s.mean}, {"unit", "1"}, {"definition", "time average" + window}};
      metrics[col.name + "_amplitude"] = {{"value", s.amplitude}, {"unit", "1"}, {"definition", "(max - min)/2" + window}};
      // A Strouhal number only from a real oscillation (|C_l| amplitude above 1e-3), never
      // from round-off: without shedding the metric is absent and its acceptance fails.
      if (col.name.ends_with("lift_coefficient") && s.frequency && s.amplitude > 1e-3) {
        const std::string prefix = col.name.substr(0, col.name.size() - std::string("lift_coefficient").size());
        double diameter = 1.0;
        for (const auto& b : bodies_)
          if (prefix.empty() || prefix == b.name + ".") diameter = b.shape.diameter;
        metrics[prefix + "strouhal_number"] = {
            {"value", *s.frequency * diameter},
            {"unit", "1"},
            {"definition", fmt::format("St = f D / U, f from {} periods of the lift signal", s.periods) + window}};
      }
    }
    for (const auto& c : capsules_) summarise_capsule(c.name(), series, metrics);
    nlohmann::json sanity = {{"finite", true}};
    if (series.count("mass")) sanity["mass_drift"] = std::abs(series.at("mass").back() - 1.0);
    return {{"case_id", spec_.id}, {"fidelity", spec_.fidelity}, {"metrics", metrics}, {"sanity", sanity}};
  }

  /// Capsule metrics from its series columns: D_xy and inclination statistics, the largest
  /// area change, and the motion mode with its rates (diagnostics/capsule_motion.hpp).
  void summarise_capsule(const std::string& name, const std::map<std::string, std::vector<double>>& series,
                         nlohmann::json& metrics) const {
    const std::string prefix = capsules_.size() > 1 ? name + "." : "";
    const double from = spec_.outputs.average_from;
    const std::string window = fmt::format(" over k t >= {}", from);
    const auto& t = series.at("t");
    auto column = [&](const std::string& q) -> const std::vector<double>* {
      const auto it = series.find(prefix + q);
      return it == series.end() ? nullptr : &it->second;
    };
    for (const char* q : {"taylor_deformation", "inclination", "section_inclination"}) {
      const auto* v = column(q);
      if (!v) continue;
      const auto s = diagnostics::analyse_signal(t, *v, from);
      const std::string unit(capsule_quantity(q).unit);
      metrics[prefix + q + "_mean"] = {{"value", s.mean}, {"unit", unit}, {"definition", "time average" + window}};
      metrics[prefix + q + "_amplitude"] = {{"value", s.amplitude}, {"unit", unit}, {"definition", "(max - min)/2" + window}};
    }
    for (const char* q : {"area_change", "volume_change", "surface_area_change", "max_area_change", "length_change",
                          "max_length_change"}) {
      const auto* v = column(q);
      if (!v) continue;
      double worst = 0;
      for (double x : *v) worst = std::max(worst, std::abs(x));
      metrics[prefix + q + "_max"] = {
          {"value", worst}, {"unit", "1"},
          {"definition", "largest absolute value over the run of: " + std::string(capsule_quantity(q).definition)}};
    }
    for (const char* q : {"length", "width", "thickness"}) {
      const auto* v = column(q);
      if (!v) continue;
      const auto s = diagnostics::analyse_signal(t, *v, from);
      metrics[prefix + q + "_mean"] = {{"value", s.mean}, {"unit", "L"}, {"definition", "time average" + window}};
      metrics[prefix + q + "_amplitude"] = {{"value", s.amplitude}, {"unit", "L"}, {"definition", "(max - min)/2" + window}};
    }
    const auto* theta = column("inclination");
    if (!theta) return;
    const double threshold_deg = spec_.outputs.oscillation_threshold_deg;
    const auto motion = diagnostics::classify_capsule_motion(t, *theta, from, threshold_deg * std::numbers::pi / 180);
    metrics[prefix + "mode"] = {
        {"value", motion.mode},
        {"unit", ""},
        {"definition", fmt::format("tumbling when the inclination turns through more than pi over the run (it "
                                   "turned {:.3f} rad); else oscillating_tank_treading when it reverses{} by more "
                                   "than {:g} degrees (outputs.oscillation_threshold, twice; it reversed {} times; "
                                   "(max - min)/2 = {:.4f} rad), else steady_tank_treading",
                                   motion.inclination_turn, window, 2 * threshold_deg, motion.inclination_reversals,
                                   motion.inclination_amplitude)}};
    if (motion.mode == "tumbling") {
      if (motion.tumbling_period)
        metrics[prefix + "tumbling_period"] = {
            {"value", *motion.tumbling_period},
            {"unit", "1/k"},
            {"definition", "time for the inclination to turn through pi, averaged" + window}};
    } else if (const auto* period = column("tank_treading_period")) {
      // From the tangential membrane velocity, not from the tracked node's phase: the phase
      // turns unevenly around a deformed contour, so its mean rate over a window shorter than
      // a revolution (about 20/k) is biased.
      const double T_tt = diagnostics::analyse_signal(t, *period, from).mean;
      metrics[prefix + "tank_treading_frequency"] = {
          {"value", 4.0 * std::numbers::pi / T_tt},
          {"unit", "1"},
          {"definition", "f = 4 pi / (k T), T the tank-treading period (series tank_treading_period) averaged" +
                             window + " (thesis ch. 3 normalisation; 1 for a rigid circle rotating at k/2)"}};
      metrics[prefix + "tank_treading_frequency_per_k"] = {
          {"value", 2.0 * std::numbers::pi / T_tt},
          {"unit", "1"},
          {"definition", "f / k = 2 pi / (k T)" + window + " (thesis ch. 4 normalisation)"}};
    } else if (const auto* phase = column("tank_treading_phase")) {
      // 3D: whole revolutions of the tracked node only (a part revolution on a deformed shape
      // turns unevenly, see above).
      if (const auto f = diagnostics::tank_treading_frequency_per_k(t, *phase, from))
        metrics[prefix + "tank_treading_frequency_per_k"] = {
            {"value", *f},
            {"unit", "1"},
            {"definition", "f / k = 2 pi / (k T), T the mean time of a whole revolution of the tracked node (series "
                           "tank_treading_phase)" + window + " (thesis 6.3.1 normalisation)"}};
    }
  }

  const cases::CaseSpec& spec_;
  LatticeUnits units_;
  FluidT fluid_;
  std::vector<RigidBody> bodies_;
  long fine_steps_ = 0;  // finest-block steps done: the IB stage of step k works at t = k dt_fine
  std::vector<Capsule<D>> capsules_;
  // The union of the IB stencils of the current step (collect_forced_nodes) and, for capsules,
  // the forced velocity at those nodes; buffers only grow.
  std::vector<std::ptrdiff_t> forced_nodes_;
  std::vector<collision::NodeSpan> forced_spans_;
  ibm::StencilUnion stencil_union_;
  // u* + f / (2 rho) at forced_nodes_ (stale elsewhere): D doubles per node of the finest
  // block, for interpolation by rows (24 bytes per 3D node, against 76 for the float
  // populations)
  field::VectorField<D> forced_velocity_;
  std::vector<CapsuleTrack<D>> capsule_tracks_;
  std::array<bool, D> periodic_{};
  std::vector<io::SeriesColumn> columns_;
  double mass0_ = 1.0;
  long step_ = 0;  // the coarse step in progress (for messages); after restore(), the last one done
  long first_step_ = 0;  // step_ when this process started running (MLUPS of the progress line)
  clock::time_point start_ = clock::now();
  double wall_before_ = 0;  // wall time of the earlier processes of a resumed run
  std::vector<double> series_rows_;  // every row written so far (a resumed run rewrites them)
  std::string snapshot_index_ = "[]";  // SnapshotWriter::index() at the last checkpoint
  struct {
    long count = 0, last_step = 0;
    double seconds = 0, bytes = 0;
  } checkpoints_;
  int checkpoints_this_process_ = 0;
  double seconds_fluid_ = 0, seconds_ib_ = 0, seconds_membrane_ = 0, seconds_diagnostics_ = 0, seconds_output_ = 0;
};

}  // namespace caplab::sim
