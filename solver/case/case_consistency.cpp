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
// A prescribed path must start at shape.center / shape.angle and join its segments to this
// (absolute, in L or radians; relative for values above 1).
constexpr double kinematic_tolerance = 1e-9;
// Times at which a moving body's path is checked against the domain and the fine region.
constexpr int path_samples = 4000;

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
  // A far-field scheme other than the default with no far-field face would change nothing.
  const auto& faces = spec.physics.boundaries;
  if (spec.numerics.far_field != FarFieldScheme::extrapolation &&
      std::find(faces.begin(), faces.end(), BoundaryType::far_field) == faces.end())
    diag.fail("/numerics/far_field", json(enum_name(far_field_names, spec.numerics.far_field)),
              "no numerics.far_field: no face of physics.domain.boundaries is far_field");
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

bool is_3d_shape(ShapeSpec::Type t) {
  return t == ShapeSpec::Type::sphere || t == ShapeSpec::Type::oblate_spheroid ||
         t == ShapeSpec::Type::biconcave_discoid;
}

// Radius of the smallest circle (sphere) about the centre that contains the shape, in L.
double circumscribed_radius(const BodySpec& body) {
  const ShapeSpec& shape = body.shape;
  const double a_eq = shape.diameter / 2;
  switch (shape.type) {
    case ShapeSpec::Type::ellipse: return shape.semi_major();
    case ShapeSpec::Type::biconcave: return a_eq * shape.alpha / geometry::biconcave_equivalent_radius(shape.alpha);
    case ShapeSpec::Type::oblate_spheroid: return a_eq * std::cbrt(shape.aspect_ratio);  // R^3 / s = a^3
    case ShapeSpec::Type::biconcave_discoid: {
      double r = 0;
      for (const auto& x : capsule_mesh(shape, body.membrane ? body.membrane->subdivisions : 3).nodes)
        r = std::max(r, x.norm());
      return r;
    }
    default: return a_eq;
  }
}

void check_body_kind(const BodySpec& body, const std::string& at, int dimension, const CaseDiagnostics& diag) {
  if (body.motion.has_value() == body.membrane.has_value())
    diag.fail_text(at, body.motion ? "both \"motion\" and \"membrane\"" : "neither \"motion\" nor \"membrane\"",
                   fmt::format("exactly one of them for body \"{}\": \"motion\" for a rigid body, \"membrane\" "
                               "for a capsule",
                               body.name));
  const bool three_d = is_3d_shape(body.shape.type);
  if (three_d != (dimension == 3))
    diag.fail(at + "/shape/type", json(enum_name(shape_type_names, body.shape.type)),
              fmt::format("a {}D shape for body \"{}\" since physics.dimension is {}: {}", dimension, body.name,
                          dimension,
                          dimension == 2 ? "\"circle\", \"ellipse\" or \"biconcave\""
                                         : "\"sphere\", \"oblate_spheroid\" or \"biconcave_discoid\""));
  const bool capsule_only = body.shape.type == ShapeSpec::Type::biconcave ||
                            body.shape.type == ShapeSpec::Type::oblate_spheroid ||
                            body.shape.type == ShapeSpec::Type::biconcave_discoid;
  if (body.motion && capsule_only)
    diag.fail(at + "/shape/type", json(enum_name(shape_type_names, body.shape.type)),
              fmt::format("\"circle\", \"ellipse\" or \"sphere\" for the rigid body \"{}\" (the {} shape is a "
                          "capsule shape)",
                          body.name, enum_name(shape_type_names, body.shape.type)));
}

// Mean distance between neighbouring membrane nodes, in fine spacings, from the rest shape.
void check_membrane_resolution(const BodySpec& body, const std::string& at, double fine_spacing,
                               const CaseDiagnostics& diag) {
  const MembraneSpec& m = *body.membrane;
  if (body.shape.center.size() == 2) {
    const auto nodes =
        geometry::ring_nodes(ring_shape(body.shape), Vec<2>::Zero(), body.shape.diameter / 2, body.shape.angle, m.nodes);
    double perimeter = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) perimeter += (nodes[(i + 1) % nodes.size()] - nodes[i]).norm();
    const double spacing = perimeter / m.nodes / fine_spacing;
    if (spacing > max_membrane_spacing_fine)
      diag.fail(at + "/membrane/nodes", json(m.nodes),
                fmt::format("at least {} nodes for body \"{}\": with {} the membrane nodes are {:.3g} fine spacings "
                            "apart, above {}, and fluid leaks through the membrane",
                            static_cast<int>(std::ceil(perimeter / (max_membrane_spacing_fine * fine_spacing))),
                            body.name, m.nodes, spacing, max_membrane_spacing_fine));
    return;
  }
  const auto mesh = capsule_mesh(body.shape, m.subdivisions);
  double edges = 0;  // each interior edge counted twice, once per triangle: the mean is the same
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) edges += (mesh.nodes[t[(k + 1) % 3]] - mesh.nodes[t[k]]).norm();
  const double spacing = edges / (3.0 * mesh.triangles.size()) / fine_spacing;
  if (spacing > max_membrane_spacing_fine)
    diag.fail(at + "/membrane/subdivisions", json(m.subdivisions),
              fmt::format("at least {} subdivisions for body \"{}\": with {} the mean membrane edge is {:.3g} fine "
                          "spacings, above {}, and fluid leaks through the membrane (each subdivision halves it)",
                          m.subdivisions + static_cast<int>(std::ceil(std::log2(spacing / max_membrane_spacing_fine))),
                          body.name, m.subdivisions, spacing, max_membrane_spacing_fine));
}

// A prescribed motion starts where the shape is and never jumps: the centre at t = 0 is
// shape.center, the orientation shape.angle, and each breakpoint joins its pieces.
void check_motion_start(const BodySpec& body, const std::string& at, const CaseDiagnostics& diag) {
  const auto& k = *body.motion->kinematics;
  const auto start = k.at(0.0);
  const std::string motion_at = at + "/motion/segments";
  for (std::size_t a = 0; a < body.shape.center.size(); ++a)
    if (!(std::abs(start.x[a] - body.shape.center[a]) <= kinematic_tolerance))
      diag.fail(motion_at, json(k.position()[a].pieces().front().text()),
                fmt::format("a path of body \"{}\" that starts at its shape.center: at t = 0 the {} position is "
                            "{:.10g}, shape.center has {:.10g}; change one of them",
                            body.name, axis_names[a], start.x[a], body.shape.center[a]));
  if (!(std::abs(start.angle - body.shape.angle) <= kinematic_tolerance))
    diag.fail(motion_at, json(k.angle().pieces().front().text()),
              fmt::format("an orientation of body \"{}\" that starts at its shape.angle: at t = 0 the angle is "
                          "{:.10g} rad, shape.angle is {:.10g}; set shape.angle to the angle at t = 0",
                          body.name, start.angle, body.shape.angle));
  auto check_joins = [&](const expr::Piecewise& f, const std::string& what) {
    const auto& bp = f.breakpoints();
    for (std::size_t j = 0; j < bp.size(); ++j) {
      const double before = f.pieces()[j].value(bp[j]), after = f.pieces()[j + 1].value(bp[j]);
      if (!(std::abs(after - before) <= kinematic_tolerance * std::max(1.0, std::abs(before))))
        diag.fail(fmt::format("{}/{}", motion_at, j + 1), json(f.pieces()[j + 1].text()),
                  fmt::format("the {} of body \"{}\" continuous at t = {}: the segment before ends at {:.10g}, "
                              "this one starts at {:.10g} (a jump would move the body in one step)",
                              what, body.name, bp[j], before, after));
    }
  };
  for (std::size_t a = 0; a < k.position().size(); ++a) check_joins(k.position()[a], std::string(axis_names[a]) + " position");
  check_joins(k.angle(), "orientation");
}

// The body stays inside the domain and, with two levels, inside the fine region with the IB
// margin, over the whole run: the path is sampled at `path_samples` times and at every
// breakpoint. A fixed body is one sample.
void check_path(const CaseSpec& spec, const BodySpec& body, const std::string& at, const CaseDiagnostics& diag) {
  const PhysicsSpec& physics = spec.physics;
  const GridSpec& grid = spec.numerics.grid;
  const bool two_level = grid.refinement == GridSpec::Refinement::two_level;
  const double margin = body_margin_fine * grid.fine_spacing;
  const double r = circumscribed_radius(body);
  std::vector<double> times{0.0};
  if (body.is_moving()) {
    const double end = spec.numerics.end_time;
    for (int i = 1; i <= path_samples; ++i) times.push_back(end * i / path_samples);
    for (double b : body.motion->kinematics->angle().breakpoints())
      if (b > 0 && b < end) times.push_back(b);
  }
  const std::string where_at = body.is_moving() ? at + "/motion/segments" : at + "/shape/center";
  for (double t : times) {
    std::vector<double> c = body.shape.center;
    if (body.is_moving()) {
      const auto pose = body.motion->kinematics->at(t);
      for (std::size_t a = 0; a < c.size(); ++a) c[a] = pose.x[a];
      const bool finite = std::all_of(c.begin(), c.end(), [](double x) { return std::isfinite(x); }) &&
                          std::isfinite(pose.angle) && std::isfinite(pose.omega) &&
                          std::all_of(pose.v.begin(), pose.v.end(), [](double x) { return std::isfinite(x); });
      if (!finite)
        diag.fail_text(where_at, fmt::format("a path that is not finite at t = {:.6g}", t),
                       fmt::format("formulas of body \"{}\" that are finite, with finite derivatives, over the whole "
                                   "run [0, {}]",
                                   body.name, spec.numerics.end_time));
    }
    const std::string when = body.is_moving() ? fmt::format(" at t = {:.6g}", t) : "";
    for (std::size_t a = 0; a < c.size(); ++a) {
      const double lo = c[a] - r, hi = c[a] + r;
      if (!(lo > 0 && hi < physics.domain_size[a]))
        diag.fail(where_at, body.is_moving() ? json(fmt::format("centre {:.6g}", c[a])) : json(body.shape.center),
                  fmt::format("body \"{}\" (reaching {:.4g} from its centre) inside the domain, but{} along {} it "
                              "spans [{:.4g}, {:.4g}], not inside (0, {})",
                              body.name, r, when, axis_names[a], lo, hi, physics.domain_size[a]));
      if (!two_level) continue;
      const double min = grid.fine_min[a] + margin, max = grid.fine_max[a] - margin;
      if (!(lo >= min && hi <= max))
        diag.fail(
            where_at, body.is_moving() ? json(fmt::format("centre {:.6g}", c[a])) : json(body.shape.center),
            fmt::format(
                "body \"{}\" (reaching {:.4g} from its centre) inside the fine region with a margin of at least {} "
                "fine spacings ({}, the IB kernel support), i.e. within [{}, {}] along {}; it spans [{:.4g}, "
                "{:.4g}]{}",
                body.name, r, body_margin_fine, margin, min, max, axis_names[a], lo, hi, when));
    }
  }
}

void check_bodies(const CaseSpec& spec, const CaseDiagnostics& diag) {
  const PhysicsSpec& physics = spec.physics;
  const GridSpec& grid = spec.numerics.grid;
  std::set<std::string> names;
  for (std::size_t i = 0; i < physics.bodies.size(); ++i) {
    const BodySpec& body = physics.bodies[i];
    const std::string at = fmt::format("/physics/bodies/{}", i);
    if (!names.insert(body.name).second)
      diag.fail(at + "/name", json(body.name), "a body name not used by another body");
    check_body_kind(body, at, physics.dimension, diag);
    if (body.membrane) check_membrane_resolution(body, at, grid.fine_spacing, diag);

    if (body.is_moving()) check_motion_start(body, at, diag);
    check_path(spec, body, at, diag);
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
  std::set<std::pair<std::string, std::string>> scored;
  for (std::size_t i = 0; i < spec.acceptance.size(); ++i) {
    const AcceptanceSpec& entry = spec.acceptance[i];
    const std::string at = fmt::format("/acceptance/{}", i);
    if (!scored.insert({entry.metric, entry.reference}).second)
      diag.fail(at + "/metric", json(entry.metric),
                "a metric not scored against the same reference by another acceptance entry");
    if (!entry.window.empty() && !(entry.window[0] >= 0 && entry.window[1] <= spec.numerics.end_time * (1 + 1e-12)))
      diag.fail(at + "/window", json(entry.window),
                fmt::format("a window inside the run [0, end_time] = [0, {}]", spec.numerics.end_time));
    if (entry.comparison == "mode") continue;  // an exact match: no tolerance per level
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

// A budget may leave levels out (not judged there), but must not name a level the case lacks.
void check_performance(const CaseSpec& spec, const std::vector<std::string>& levels,
                       const CaseDiagnostics& diag) {
  if (!spec.performance) return;
  for (const auto& [level, budget] : spec.performance->wall_time_budget_s)
    if (std::find(levels.begin(), levels.end(), level) == levels.end())
      diag.fail_text("/performance/wall_time_budget_s/" + level, "budget for fidelity level \"" + level + "\"",
                     "a level the case defines: " + quoted_list(levels) + did_you_mean(level, levels));
}

}  // namespace

geometry::RingShape ring_shape(const ShapeSpec& shape) {
  geometry::RingShape r;
  switch (shape.type) {
    case ShapeSpec::Type::ellipse: r.type = geometry::RingShape::Type::ellipse; break;
    case ShapeSpec::Type::biconcave: r.type = geometry::RingShape::Type::biconcave; break;
    default: r.type = geometry::RingShape::Type::circle; break;
  }
  r.aspect_ratio = shape.aspect_ratio;
  r.alpha = shape.alpha;
  return r;
}

// The membrane keys that belong to the dimension and the law, each required where it applies:
// 2D rings take "nodes" and the bending keys, 3D meshes "subdivisions", Skalak "area_dilation".
void check_membrane_keys(const json& raw, const std::string& at, const std::string& body, int dimension,
                         const CaseDiagnostics& diag) {
  const std::string law = raw.at("law").get<std::string>();
  const bool ring_law = law == "hooke";
  if (ring_law != (dimension == 2))
    diag.fail(at + "/law", json(law),
              dimension == 2 ? std::string("\"hooke\" in 2D (the finite-element laws are for 3D membranes)")
                             : std::string("\"neo_hookean\", \"zero_thickness\" or \"skalak\" in 3D (\"hooke\" is the "
                                           "2D ring law)"));
  auto given = [&](const char* key) { return raw.contains(key); };
  auto only = [&](const char* key, bool allowed, const std::string& where) {
    if (given(key) && !allowed)
      diag.fail(at + "/" + key, raw.at(key), fmt::format("no \"{}\" here: it applies {}", key, where));
    if (!given(key) && allowed)
      diag.fail_text(at, fmt::format("no \"{}\"", key),
                     fmt::format("a \"{}\" for body \"{}\": it is required {}", key, body, where));
  };
  only("nodes", dimension == 2, "to 2D capsules (3D membranes take \"subdivisions\")");
  only("subdivisions", dimension == 3, "to 3D capsules (2D membranes take \"nodes\")");
  only("area_dilation", law == "skalak", "to the \"skalak\" law (C of thesis eq. 5.3)");
  if (dimension == 3)
    for (const char* key : {"bending_ratio", "reference_curvature"})
      if (given(key))
        diag.fail(at + "/" + key, raw.at(key),
                  fmt::format("no \"{}\" in 3D: the finite-element membranes of thesis ch. 5 have no bending "
                              "stiffness",
                              key));
}

geometry::TriangleMesh capsule_mesh(const ShapeSpec& shape, int subdivisions) {
  const double a = shape.diameter / 2;
  switch (shape.type) {
    case ShapeSpec::Type::oblate_spheroid: return geometry::oblate_spheroid(subdivisions, 1.0 / shape.aspect_ratio, a);
    case ShapeSpec::Type::biconcave_discoid: return geometry::biconcave_discoid(subdivisions, a);
    default: return geometry::octahedron_sphere(subdivisions, a);
  }
}

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
  check_performance(spec, levels, diag);
}

}  // namespace caplab::cases
