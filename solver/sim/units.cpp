#include "sim/units.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "collision/operators.hpp"
#include "core/error.hpp"

namespace caplab::sim {

using cases::BoundaryType;
using cases::CaseSpec;
using cases::FlowSpec;
using cases::GridSpec;

double BlockUnits::node_count() const {
  double n = 1;
  for (int k : nodes) n *= k;
  return n;
}

namespace {

/// Interior nodes and origin of the coarsest grid along one axis of length `len`.
/// Far field: nodes on both faces; periodic: one face; wall: half a spacing inside each wall.
void place_axis(BoundaryType b, double len, double h, int& n, double& origin) {
  const int cells = static_cast<int>(std::lround(len / h));
  switch (b) {
    case BoundaryType::far_field: n = cells + 1, origin = 0.0; break;
    case BoundaryType::periodic: n = cells, origin = 0.0; break;
    case BoundaryType::wall: n = cells, origin = 0.5 * h; break;
  }
}

double reynolds_factor(const CaseSpec& spec, std::string& definition) {
  if (spec.physics.flow.type == FlowSpec::Type::shear && spec.physics.dimension == 2) {
    definition = "Re = rho (2 k a)(2 a) / mu (thesis chapters 2-4)";
    return 4.0;
  }
  if (spec.physics.flow.type == FlowSpec::Type::shear) {
    definition = "Re = rho k a^2 / mu (thesis chapters 5-6)";
    return 1.0;
  }
  definition = "Re = rho U L / mu";
  return 1.0;
}

}  // namespace

std::vector<double> imposed_velocity(const CaseSpec& spec, const std::vector<double>& x) {
  const int D = spec.physics.dimension;
  std::vector<double> u(D, 0.0);
  switch (spec.physics.flow.type) {
    case FlowSpec::Type::uniform:
      for (int a = 0; a < D; ++a) u[a] = spec.physics.flow.direction.empty() ? (a == 0) : spec.physics.flow.direction[a];
      break;
    case FlowSpec::Type::shear: {
      const int g = D - 1;  // 2D: u = (k y, 0); 3D: u = (k z, 0, 0), centred in the domain
      u[0] = x[g] - 0.5 * spec.physics.domain_size[g];
      break;
    }
    default: break;
  }
  return u;
}

LatticeUnits derive_units(const CaseSpec& spec) {
  const int D = spec.physics.dimension;
  const auto& grid = spec.numerics.grid;
  LatticeUnits lu;
  lu.velocity_lu = spec.numerics.lattice_velocity;
  lu.viscosity = reynolds_factor(spec, lu.reynolds_definition) / spec.physics.reynolds;
  const bool two_level = grid.refinement == GridSpec::Refinement::two_level;
  const double h_c = two_level ? 2.0 * grid.fine_spacing : grid.fine_spacing;

  auto make_block = [&](const std::string& name, double h) {
    BlockUnits b;
    b.name = name;
    b.dx = h;
    b.dt = lu.velocity_lu * h;
    b.nu_lu = lu.viscosity * lu.velocity_lu / h;
    b.tau = 0.5 + 3.0 * b.nu_lu;
    return b;
  };
  BlockUnits coarse = make_block(two_level ? "coarse" : "uniform", h_c);
  coarse.nodes.resize(D);
  coarse.origin.resize(D);
  for (int a = 0; a < D; ++a)
    place_axis(spec.physics.boundaries[a], spec.physics.domain_size[a], h_c, coarse.nodes[a], coarse.origin[a]);
  lu.blocks.push_back(coarse);
  if (two_level) {
    BlockUnits fine = make_block("fine", grid.fine_spacing);
    fine.nodes.resize(D);
    fine.origin.resize(D);
    for (int a = 0; a < D; ++a) {
      // The ghost ring (thesis line MN) sits on the coarse nodes nearest the requested faces.
      const long lo = std::lround((grid.fine_min[a] - coarse.origin[a]) / h_c);
      const long hi = std::lround((grid.fine_max[a] - coarse.origin[a]) / h_c);
      fine.nodes[a] = static_cast<int>(2 * (hi - lo) - 1);
      fine.origin[a] = coarse.origin[a] + lo * h_c + grid.fine_spacing;
    }
    lu.blocks.push_back(fine);
  }
  for (const auto& b : lu.blocks)
    if (!(b.tau > 0.5 + 1e-9 && std::isfinite(b.tau)))  // a tiny Re overflows the viscosity to inf
      throw core::InputError(spec.source_file, "/physics/reynolds", fmt::format("{}", spec.physics.reynolds),
                             fmt::format("a Reynolds number giving a finite tau > 0.5 on block {} (got tau = {:.6f})",
                                         b.name, b.tau));

  // Largest imposed speed: uniform flow 1, shear k·(half height), else 1 (a scale).
  double umax = 1.0;
  if (spec.physics.flow.type == FlowSpec::Type::shear) umax = 0.5 * spec.physics.domain_size[D - 1];
  lu.mach = umax * lu.velocity_lu * std::sqrt(3.0);
  if (lu.mach > 0.7)
    throw core::InputError(spec.source_file, "/numerics/lattice_velocity", fmt::format("{}", lu.velocity_lu),
                           fmt::format("a lattice velocity giving a Mach number below 0.7 (largest imposed "
                                       "speed is {:.3g} U, Mach {:.3f}); lower lattice_velocity",
                                       umax, lu.mach));

  // In double first: end_time / dt can exceed every integer type (the cast would be undefined).
  const double steps = std::ceil(spec.numerics.end_time / lu.blocks[0].dt - 1e-9);
  if (!(steps >= 1))
    throw core::InputError(spec.source_file, "/numerics/end_time", fmt::format("{}", spec.numerics.end_time),
                           fmt::format("an end time of at least one coarse time step, {:.4g} L/U", lu.blocks[0].dt));
  if (!(steps <= max_coarse_steps))
    throw core::InputError(
        spec.source_file, "/numerics/end_time", fmt::format("{}", spec.numerics.end_time),
        fmt::format("an end time of at most {:g} coarse time steps of {:.4g} L/U (this one needs "
                    "{:.3g}); shorten the run or coarsen the grid",
                    max_coarse_steps, lu.blocks[0].dt, steps));
  lu.coarse_steps = static_cast<long>(steps);
  // Checked here, not at the end of the run, where the window statistics would fail after all the work.
  if (const long rows = series_rows_in_window(spec, lu); rows < min_window_rows)
    throw core::InputError(
        spec.source_file, "/outputs/average_from", fmt::format("{}", spec.outputs.average_from),
        fmt::format("an averaging window holding at least {} rows of the series (this one holds {}: rows every {:.4g} "
                    "L/U up to end_time {}); lower average_from, raise end_time or shorten outputs.series.interval",
                    min_window_rows, rows, series_sample_every(spec, lu) * lu.blocks[0].dt, spec.numerics.end_time));
  double per_step = lu.blocks[0].node_count();
  if (two_level) per_step += 2.0 * lu.blocks[1].node_count();
  lu.node_updates = per_step * static_cast<double>(lu.coarse_steps);
  lu.memory_bytes = estimate_memory_bytes(spec, lu.blocks);
  return lu;
}

double estimate_memory_bytes(const CaseSpec& spec, const std::vector<BlockUnits>& blocks) {
  // What scales with the lattice (sim/fluid.hpp, sim/scene.hpp); every field includes the ghost
  // layer. Markers, membrane meshes, the multi-block interface and the boundary lists grow with
  // surfaces, not volumes, and are left to the margin of check_memory.
  const int D = spec.physics.dimension;
  const double value = spec.numerics.precision == cases::Precision::single ? 4.0 : 8.0;
  const double q = D == 2 ? 9 : 19;
  const bool body_force = spec.physics.flow.type == FlowSpec::Type::body_force;
  const bool bodies = !spec.physics.bodies.empty();
  const bool snapshots = !spec.outputs.snapshots.times.empty() && !spec.outputs.snapshots.fields.empty();
  double bytes = 0, largest = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    double n = 1;
    for (int k : blocks[b].nodes) n *= k + 2.0;
    largest = std::max(largest, n);
    bytes += n * q * value;  // populations, one buffer (in place, field/populations.hpp)
    const bool finest = b + 1 == blocks.size();
    if (body_force || (finest && bodies)) bytes += n * D * 8.0;  // force density (double)
    if (finest && bodies) bytes += n * 8.0;                      // forced-node slot and stamp (int32 each)
  }
  // A snapshot holds density, velocity and vorticity (1 or 3 components) of one block at a
  // time, in double, plus the copy of one field that the HDF5 writer makes.
  if (snapshots) bytes += largest * 8.0 * (1 + D + (D == 2 ? 1 : 3) + 1);
  return bytes;
}

double machine_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  double bytes = pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0;
  // A container may be given less than the machine has: cgroup v2, then v1 ("max" or a huge
  // number when there is no limit).
  for (const char* file : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(file);
    std::string text;
    if (!(in >> text) || text == "max") continue;
    char* end = nullptr;
    const double limit = std::strtod(text.c_str(), &end);
    if (end != text.c_str() && limit > 0 && (bytes == 0 || limit < bytes)) bytes = limit;
    break;
  }
  return bytes;
}

double usable_memory_bytes(double machine_bytes) {
  return machine_bytes - std::max(memory_margin_share * machine_bytes, memory_margin_bytes);
}

long series_sample_every(const CaseSpec& spec, const LatticeUnits& units) {
  return std::max(1L, std::lround(spec.outputs.series.interval / units.blocks[0].dt));
}

long series_rows_in_window(const CaseSpec& spec, const LatticeUnits& units) {
  // Rows at steps k·every (k >= 1) and at the last step; a row at step s has t = s·dt.
  const double dt = units.blocks[0].dt;
  const long total = units.coarse_steps, every = series_sample_every(spec, units);
  long first = static_cast<long>(std::ceil(spec.outputs.average_from / dt - 1e-9));  // first step in the window
  first = std::max(first, 1L);
  while (first > 1 && (first - 1) * dt >= spec.outputs.average_from) --first;
  while (first <= total && first * dt < spec.outputs.average_from) ++first;
  if (first > total) return 0;
  const long multiples = total / every - (first - 1) / every;  // k·every in [first, total]
  return multiples + (total % every != 0 ? 1 : 0);
}

void check_memory(const CaseSpec& spec, const LatticeUnits& units, double machine_bytes) {
  if (!(machine_bytes > 0)) return;  // unknown: nothing to compare with
  const double usable = usable_memory_bytes(machine_bytes);
  if (units.memory_bytes <= usable) return;
  constexpr double gib = 1024.0 * 1024.0 * 1024.0;
  double nodes = 0;
  for (const auto& b : units.blocks) nodes += b.node_count();
  throw core::InputError(
      spec.source_file, "/numerics/grid/fine_spacing",
      fmt::format("{} (the run needs about {:.3g} GiB of memory for {:.3g} lattice nodes)",
                  spec.numerics.grid.fine_spacing, units.memory_bytes / gib, nodes),
      fmt::format(
          "a case that fits in the memory of this machine: {:.3g} GiB, of which a run may use {:.3g} GiB; "
          "use a coarser resolution (a larger numerics.grid.fine_spacing or a lower fidelity level), a "
          "smaller domain or fine region, or numerics.precision \"single\" (halves the populations)",
          machine_bytes / gib, std::max(0.0, usable) / gib));
}

nlohmann::json LatticeUnits::to_json() const {
  nlohmann::json j;
  j["velocity_lu"] = velocity_lu;
  j["mach"] = mach;
  j["viscosity"] = {{"value", viscosity}, {"unit", "U L"}};
  j["reynolds_definition"] = reynolds_definition;
  j["coarse_steps"] = coarse_steps;
  j["node_updates"] = node_updates;
  j["memory_bytes"] = memory_bytes;
  for (const auto& b : blocks)
    j["blocks"].push_back({{"name", b.name},
                           {"dx", b.dx},
                           {"dt", b.dt},
                           {"tau", b.tau},
                           {"nu_lu", b.nu_lu},
                           {"nodes", b.nodes},
                           {"origin", b.origin}});
  return j;
}

double membrane_stiffness_factor(const cases::MembraneSpec& membrane) {
  if (membrane.law != cases::MembraneSpec::Law::skalak) return 1.0;
  return std::max(1.5, 0.5 * (1.0 + 2.0 * membrane.area_dilation));
}

double membrane_lattice_modulus(const LatticeUnits& units, const cases::BodySpec& body) {
  return units.blocks.back().nu_lu * units.velocity_lu / body.membrane->capillary *
         membrane_stiffness_factor(*body.membrane);
}

std::string tau_near_half_cause(const cases::CollisionSpec& collision, double tau) {
  // At a fixed Re and grid, tau - 1/2 = 3 U_lu (L/dx) / Re: a lower lattice velocity moves tau
  // closer to 1/2, a higher one (Mach allowing) or a finer grid moves it away.
  const double tau_minus = collision::Trt{tau, collision.magic}.tau_minus();
  const double magic_for_unit_tau_minus = (tau - 0.5) / 2;
  std::string remedy;
  if (collision.op == cases::CollisionSpec::Operator::bgk)
    remedy = "use the TRT operator (numerics.collision.operator = \"trt\"), ";
  else if (collision.magic > magic_for_unit_tau_minus)
    remedy = fmt::format(
        "with TRT the odd moments relax with tau- = 1/2 + magic / (tau - 1/2) = {:.3g}, slowly, and the errors the "
        "refinement interface or the immersed boundary put there persist: a smaller numerics.collision.magic, down to "
        "(tau - 1/2)/2 = {:.3g}, which gives tau- = 1 (measured: chapter 4 at Re 100, tau = 0.512, diverged with magic "
        "1/4 and 1/12, tau- = 21 and 7.4, and runs with 0.01, tau- = 1.3), ",
        tau_minus, magic_for_unit_tau_minus);
  else
    remedy = fmt::format("TRT's odd moments already relax fast here (magic {:.3g}, tau- = {:.3g}); what is left is ",
                         collision.magic, tau_minus);
  return fmt::format("tau = {:.4f} on this block is close to 1/2 for this Reynolds number and grid; {}a finer grid or "
                     "a higher numerics.lattice_velocity (tau - 1/2 grows with it at a fixed Re, as far as the Mach "
                     "number allows)",
                     tau, remedy);
}

}  // namespace caplab::sim
