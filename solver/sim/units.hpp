// Lattice parameters derived from a case: the one place where physical (thesis) units meet
// lattice units.
//
// Units of a case: lengths in L (D or a), velocities in U (U∞ or k·a), time in L/U. With the
// characteristic velocity U_lu in lattice units (the same on every block: acoustic scaling,
// Δt ∝ Δx) a block of spacing h (in L) has Δt = U_lu·h (in L/U), and the viscosity
// ν = factor/Re (in U·L; factor 4 for the 2D shear-flow Reynolds number ρ(2ka)(2a)/μ, else 1)
// becomes ν_lu = ν·U_lu/h, τ = ½ + ν_lu/cs² (thesis eq. 2.6), τ_f = ½ + m(τ_c − ½) (eq. 2.10).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "case/case_spec.hpp"

namespace caplab::sim {

struct BlockUnits {
  std::string name;          ///< "coarse", "fine" or "uniform"
  double dx = 0;             ///< spacing, in L
  double dt = 0;             ///< time step, in L/U
  double tau = 0;            ///< relaxation time
  double nu_lu = 0;          ///< kinematic viscosity, lattice units
  std::vector<int> nodes;    ///< interior nodes per axis
  std::vector<double> origin;  ///< position of node 0, in L
  double node_count() const;
};

struct LatticeUnits {
  double velocity_lu = 0;       ///< U in lattice units
  double mach = 0;              ///< largest imposed speed / cs
  double viscosity = 0;         ///< ν in U·L
  std::string reynolds_definition;
  std::vector<BlockUnits> blocks;  ///< coarse first; one entry for a uniform grid
  long coarse_steps = 0;        ///< steps of the coarsest block to reach end_time
  double node_updates = 0;      ///< total node updates of the run
  double memory_bytes = 0;      ///< estimate_memory_bytes of the blocks
  double estimated_seconds(double mlups) const { return node_updates / (mlups * 1e6); }
  nlohmann::json to_json() const;
};

/// Most coarse time steps a run may take (beyond it end_time or the spacing is surely a typo).
inline constexpr double max_coarse_steps = 1e11;
/// What check_memory keeps free for the system and what does not scale with the lattice: this
/// share of the machine's memory, and at least this many bytes.
inline constexpr double memory_margin_share = 0.1;
inline constexpr double memory_margin_bytes = 512.0 * 1024 * 1024;

/// Derives the lattice parameters of a validated case. Throws core::InputError for
/// combinations that are valid JSON but not a usable lattice (τ ≤ ½, Mach too high, more than
/// max_coarse_steps steps).
LatticeUnits derive_units(const cases::CaseSpec& spec);

/// Why a block whose tau is close to 1/2 (below 0.55) diverged and what to change, as the cause
/// sentence of a numerical-instability error. BGK: use TRT. TRT with a magic parameter above
/// (tau - 1/2)/2: lower it to that value, which gives tau- = 1 (the message quotes the chapter 4
/// measurement behind it). Always: a finer grid or a higher lattice velocity, which move tau away
/// from 1/2.
std::string tau_near_half_cause(const cases::CollisionSpec& collision, double tau);

/// Bytes a run of `spec` on `blocks` allocates for what scales with the lattice: populations
/// (one buffer updated in place, Q values of the case's precision per node), the force density of the finest
/// block when it carries bodies (of every block with a body-force flow), the forced-node
/// bookkeeping, and the fields of one block while a snapshot is written.
double estimate_memory_bytes(const cases::CaseSpec& spec, const std::vector<BlockUnits>& blocks);

/// Physical memory of this machine (sysconf pages × page size), or the cgroup memory limit of
/// this process when that is lower; 0 when unknown.
double machine_memory_bytes();

/// What a run may allocate on a machine with `machine_bytes` of memory: all of it less a
/// margin (memory_margin_share of it, at least memory_margin_bytes).
double usable_memory_bytes(double machine_bytes);

/// Throws core::InputError (at /numerics/grid/fine_spacing) when `units.memory_bytes` exceeds
/// usable_memory_bytes(machine_bytes), naming the estimate, the machine's memory and the fixes.
/// Coarse steps between two rows of series.h5 (outputs.series.interval rounded to whole steps, at
/// least one); the run also writes a row at its last step.
long series_sample_every(const cases::CaseSpec& spec, const LatticeUnits& units);
/// Rows of series.h5 at or after outputs.average_from: the summary's window statistics (mean,
/// amplitude, period, mode) need at least min_window_rows of them.
long series_rows_in_window(const cases::CaseSpec& spec, const LatticeUnits& units);
inline constexpr long min_window_rows = 3;

/// Called before anything is allocated or written; does nothing when machine_bytes is 0.
void check_memory(const cases::CaseSpec& spec, const LatticeUnits& units, double machine_bytes);

/// The explicit membrane-fluid coupling is stable while a membrane's modulus in lattice units
/// of the finest block, E_lu = nu_lu U_lu / G, stays below about this (measured by make stress:
/// the 2D boundary at 5-6.7 on every line of the G x U maps, the 3D NH sphere at 2-4). Without
/// bending stiffness: bending adds its own limit (the E_b x U map), so a stiff-bending
/// membrane can blow up below it.
inline double membrane_stiffness_limit(int dimension) { return dimension == 2 ? 5.0 : 2.0; }

/// How much stiffer than a neo-Hookean membrane of the same E a membrane law is at small
/// strain, in its stiffest in-plane mode (the one the explicit coupling's limit is set by).
/// With I1 = l1^2 + l2^2 - 2, I2 = l1^2 l2^2 - 1, an isotropic stretch l = 1 + e gives the
/// area modulus d2W/dl2 = 4 W1 + 12 W2 + 16 (W11 + 2 W12 + W22) at l = 1: 4E for NH and ZT
/// (eq. 5.1-5.2), (2 + 4C) E for Skalak (eq. 5.3); the shear moduli are E/3 (NH, ZT) and E/2
/// (Skalak, E = 2 G_s). Factor: 1 for NH, ZT and the 2D Hooke ring, max(3/2, (1 + 2C)/2) for
/// Skalak. Measured (ch6 biconcave cells at quick, 2026-12-03): Skalak C = 23 at nu U / G
/// = 0.28 (factor 23.5, 6.5 in NH units) blew up within 83 steps, C = 120 at 0.027 (3.2) after
/// 3500 steps; C = 190 at 0.013 (2.5) and C = 4.6 at 0.5 (2.55) ran through.
double membrane_stiffness_factor(const cases::MembraneSpec& membrane);

/// E_lu = nu_lu U_lu / G times membrane_stiffness_factor: a capsule body's stiffest membrane
/// modulus in lattice units of the finest block, in the units of a neo-Hookean membrane (those
/// of membrane_stiffness_limit).
double membrane_lattice_modulus(const LatticeUnits& units, const cases::BodySpec& body);

/// Imposed (unperturbed) velocity of the case's flow at position x (in L), in units of U.
std::vector<double> imposed_velocity(const cases::CaseSpec& spec, const std::vector<double>& x);

}  // namespace caplab::sim
