// Cross-value checks of a case (see case_consistency.hpp).
//
// Geometry conventions: the domain is [0, size_a] along each axis a; the coarse spacing is
// 2·fine_spacing for two_level refinement, and the coarsest spacing (the one domain faces
// and fine-block faces must lie on) is called `coarse` below for both refinements.
#include "case/case_consistency.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "case/case_enums.hpp"

namespace caplab::cases {
namespace {

using nlohmann::json;

constexpr const char* axis_names[] = {"x", "y", "z"};

// True when x/step is a whole number (within the relative tolerance); `n` gets the nearest one.
bool is_multiple(double x, double step, double& n) {
  const double r = x / step;
  n = std::round(r);
  return std::abs(r - n) <= spacing_tolerance * std::max(1.0, std::abs(r));
}

double coarsest_spacing(const GridSpec& grid) {
  return grid.refinement == GridSpec::Refinement::two_level ? 2 * grid.fine_spacing : grid.fine_spacing;
}

void check_flow(const CaseSpec& spec, const CaseDiagnostics& diag) {
  const FlowSpec& flow = spec.physics.flow;
  if (flow.type == FlowSpec::Type::uniform && !flow.direction.empty()) {
    double norm2 = 0;
    for (double c : flow.direction) norm2 += c * c;
    if (!(norm2 > 0))
      diag.fail("/physics/flow/direction", json(flow.direction),
                "a non-zero vector (it is normalised on loading)");
  }
  if (flow.type == FlowSpec::Type::body_force && flow.body_force == 0)
    diag.fail("/physics/flow/body_force", json(flow.body_force),
              "a non-zero force density (along x, in rho U^2/L)");
}

void check_grid(const CaseSpec& spec, const CaseDiagnostics& diag) {
  const GridSpec& grid = spec.numerics.grid;
  const auto& size = spec.physics.domain_size;
  const bool two_level = grid.refinement == GridSpec::Refinement::two_level;
  const double h = grid.fine_spacing, coarse = coarsest_spacing(grid);

  // Size first: an absurd spacing would otherwise show up as a divisibility problem.
  double coarse_nodes = 1, fine_nodes = two_level ? 1 : 0;
  for (std::size_t a = 0; a < size.size(); ++a) {
    coarse_nodes *= size[a] / coarse;
    if (two_level) fine_nodes *= std::clamp(grid.fine_max[a] - grid.fine_min[a], 0.0, size[a]) / h;
  }
  if (coarse_nodes + fine_nodes > max_lattice_nodes)
    diag.fail("/numerics/grid/fine_spacing", json(h),
              fmt::format("a spacing giving at most {:g} lattice nodes; this one gives {:.3g}",
                          max_lattice_nodes, coarse_nodes + fine_nodes));

  const char* step_name = two_level ? "2*fine_spacing (the coarse spacing)" : "fine_spacing";
  for (std::size_t a = 0; a < size.size(); ++a) {
    double n = 0;
    if (!is_multiple(size[a], coarse, n) || n < 1) {
      // Nearest valid: size / (n · coarse/h), written as a fraction because it is rarely a short decimal.
      const double parts = std::max(1.0, n) * (coarse / h);
      diag.fail(
          "/numerics/grid/fine_spacing", json(h),
          fmt::format("a spacing such that the domain size along {} ({}) is a whole multiple of {}, but "
                      "{} / {} = {:.9g}; the nearest valid fine_spacing for this axis is {}/{} = {:.6g}",
                      axis_names[a], size[a], step_name, size[a], coarse, size[a] / coarse, size[a], parts,
                      size[a] / parts));
    }
  }
  if (!two_level) return;

  const double margin = fine_region_margin_coarse * coarse;
  for (std::size_t a = 0; a < size.size(); ++a) {
    const double lo = grid.fine_min[a], hi = grid.fine_max[a];
    if (!(lo < hi))
      diag.fail("/numerics/grid/fine_region", json{{"min", grid.fine_min}, {"max", grid.fine_max}},
                fmt::format("min < max along every axis, but along {} min = {} and max = {}", axis_names[a],
                            lo, hi));
    const bool min_ok = lo >= margin, max_ok = hi <= size[a] - margin;
    if (!min_ok || !max_ok)
      diag.fail(
          fmt::format("/numerics/grid/fine_region/{}/{}", min_ok ? "max" : "min", a), json(min_ok ? hi : lo),
          fmt::format("the fine region inside the domain [0, {}] along {}, at least {} coarse spacings ({}) "
                      "from the domain faces: min >= {} and max <= {}",
                      size[a], axis_names[a], fine_region_margin_coarse, margin, margin, size[a] - margin));
    for (const char* end : {"min", "max"}) {
      const double c = end[1] == 'i' ? lo : hi;
      double n = 0;
      if (!is_multiple(c, coarse, n))
        diag.fail(fmt::format("/numerics/grid/fine_region/{}/{}", end, a), json(c),
                  fmt::format("a fine-region face on a coarse node, i.e. a multiple of the coarse spacing "
                              "2*fine_spacing = {}; the nearest is {}",
                              coarse, n * coarse));
    }
  }
}

void check_bodies(const CaseSpec& spec, const CaseDiagnostics& diag) {
  const PhysicsSpec& physics = spec.physics;
  const GridSpec& grid = spec.numerics.grid;
  const bool two_level = grid.refinement == GridSpec::Refinement::two_level;
  const double margin = body_margin_fine * grid.fine_spacing;
  std::set<std::string> names;
  for (std::size_t i = 0; i < physics.bodies.size(); ++i) {
    const BodySpec& body = physics.bodies[i];
    const std::string at = fmt::format("/physics/bodies/{}", i);
    if (!names.insert(body.name).second)
      diag.fail(at + "/name", json(body.name), "a body name not used by another body");

    const int shape_dimension = body.shape.type == ShapeSpec::Type::circle ? 2 : 3;
    if (shape_dimension != physics.dimension)
      diag.fail(
          at + "/shape/type", json(enum_name(shape_type_names, body.shape.type)),
          fmt::format("a {}D shape for body \"{}\" since physics.dimension is {}: \"{}\"", physics.dimension,
                      body.name, physics.dimension, physics.dimension == 2 ? "circle" : "sphere"));

    const double r = body.shape.diameter / 2;
    for (std::size_t a = 0; a < body.shape.center.size(); ++a) {
      const double lo = body.shape.center[a] - r, hi = body.shape.center[a] + r;
      if (!(lo > 0 && hi < physics.domain_size[a]))
        diag.fail(at + "/shape/center", json(body.shape.center),
                  fmt::format("body \"{}\" (diameter {}) inside the domain, but along {} it spans [{}, {}], "
                              "not inside (0, {})",
                              body.name, body.shape.diameter, axis_names[a], lo, hi, physics.domain_size[a]));
      if (!two_level) continue;
      const double min = grid.fine_min[a] + margin, max = grid.fine_max[a] - margin;
      if (!(lo >= min && hi <= max))
        diag.fail(
            at + "/shape/center", json(body.shape.center),
            fmt::format(
                "body \"{}\" (diameter {}) inside the fine region with a margin of at least {} fine "
                "spacings ({}, the IB kernel support), i.e. within [{}, {}] along {}; it spans [{}, {}]",
                body.name, body.shape.diameter, body_margin_fine, margin, min, max, axis_names[a], lo, hi));
    }
  }
}

void check_outputs(const CaseSpec& spec, const CaseDiagnostics& diag) {
  const double end = spec.numerics.end_time;
  const auto& times = spec.outputs.snapshots.times;
  for (std::size_t i = 0; i < times.size(); ++i)
    if (times[i] > end)
      diag.fail(fmt::format("/outputs/snapshots/times/{}", i), json(times[i]),
                fmt::format("a snapshot time in [0, end_time] = [0, {}]", end));
  if (!(spec.outputs.average_from < end))
    diag.fail("/outputs/average_from", json(spec.outputs.average_from),
              fmt::format("a time in [0, end_time) = [0, {}): the averaging window must not be empty", end));
}

void check_acceptance(const CaseSpec& spec, const std::vector<std::string>& levels,
                      const CaseDiagnostics& diag) {
  std::set<std::string> metrics;
  for (std::size_t i = 0; i < spec.acceptance.size(); ++i) {
    const AcceptanceSpec& entry = spec.acceptance[i];
    const std::string at = fmt::format("/acceptance/{}", i);
    if (!metrics.insert(entry.metric).second)
      diag.fail(at + "/metric", json(entry.metric), "a metric not scored by another acceptance entry");
    for (const auto& [level, tolerance] : entry.tolerance)
      if (std::find(levels.begin(), levels.end(), level) == levels.end())
        diag.fail_text(at + "/tolerance/" + level, "tolerance for fidelity level \"" + level + "\"",
                       "a level the case defines: " + quoted_list(levels) + did_you_mean(level, levels));
    for (const auto& level : levels)
      if (entry.tolerance.count(level) == 0)
        diag.fail_text(at + "/tolerance", "no tolerance for fidelity level \"" + level + "\"",
                       "a tolerance for every fidelity level the case defines: " + quoted_list(levels));
  }
}

}  // namespace

void check_axis_lengths(const json& doc, int dimension, const std::vector<std::string>& per_axis_pointers,
                        const CaseDiagnostics& diag) {
  for (const auto& pointer : per_axis_pointers) {
    const json& value = doc.at(json::json_pointer(pointer));
    if (value.size() != static_cast<std::size_t>(dimension))
      diag.fail(pointer, value,
                fmt::format("{} entries, one per axis (physics.dimension is {})", dimension, dimension));
  }
}

void check_consistency(const CaseSpec& spec, const std::vector<std::string>& levels,
                       const CaseDiagnostics& diag) {
  check_flow(spec, diag);
  check_grid(spec, diag);
  check_bodies(spec, diag);
  check_outputs(spec, diag);
  check_acceptance(spec, levels, diag);
}

}  // namespace caplab::cases
