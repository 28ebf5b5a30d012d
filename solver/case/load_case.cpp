// Case files -> validated CaseSpec (see load_case.hpp for the pipeline).
#include "case/load_case.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <limits>
#include <set>

#include "case/case_consistency.hpp"
#include "case/case_diagnostics.hpp"
#include "case/case_enums.hpp"
#include "case/case_schema.hpp"
#include "core/error.hpp"

namespace caplab::cases {
namespace {

using nlohmann::json;

// ---- Reading. ----

// Tracks where the parser is, to name the place of a repeated key (nlohmann keeps the last one
// silently, which would hide a typo'd copy-paste) and of a syntax error, and bounds the nesting
// depth (copying, comparing and printing JSON values recurse: garbage nested a million levels
// deep would overflow the stack long after parsing). The parser copies its callback, so the
// frames live outside it, in a ParsePosition.
struct ParsePosition {
  struct Frame {
    bool is_array;
    std::string key;
    std::size_t index;
    std::set<std::string> seen;
  };
  std::vector<Frame> frames;

  /// The JSON pointer of the value being read ("" at the top level).
  std::string pointer() const {
    std::string p;
    for (const auto& f : frames) p = f.is_array ? child_pointer(p, f.index) : child_pointer(p, f.key);
    return p;
  }
};

class DuplicateKeyGuard {
 public:
  DuplicateKeyGuard(std::string file, ParsePosition& position) : file_(std::move(file)), at_(&position) {}

  bool operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
    auto& frames = at_->frames;
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (frames.size() >= max_case_nesting)
          throw core::InputError(
              file_, at_->pointer(),
              fmt::format("arrays and objects nested more than {} deep", max_case_nesting),
              fmt::format("at most {} levels of nesting (a case needs about 8)", max_case_nesting));
        frames.push_back({event == json::parse_event_t::array_start, "", 0, {}});
        break;
      case json::parse_event_t::key: {
        auto& top = frames.back();
        top.key = parsed.get<std::string>();
        if (!top.seen.insert(top.key).second)
          throw core::InputError(file_, at_->pointer(),
                                 "the key \"" + top.key + "\" a second time in one object",
                                 "each key at most once per object");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames.pop_back();
        [[fallthrough]];
      case json::parse_event_t::value:
        if (!frames.empty() && frames.back().is_array) ++frames.back().index;
        break;
    }
    return true;
  }

 private:
  std::string file_;
  ParsePosition* at_;
};

// nlohmann prefixes its messages with "[json.exception.parse_error.101] "; users need the rest.
std::string without_exception_id(const std::string& what) {
  const std::size_t close = what.find("] ");
  return what.rfind("[json.exception.", 0) == 0 && close != std::string::npos ? what.substr(close + 2) : what;
}

// The word of `text` around byte `byte` (1-based, as nlohmann counts: the last byte it read),
// up to the JSON delimiters on either side: "NaN", "Infinity", "01", "0x10" as written.
std::string token_at(std::string_view text, std::size_t byte) {
  constexpr std::string_view delimiters = " \t\r\n,:[]{}\"";
  if (byte == 0 || byte > text.size()) return "";
  std::size_t i = byte - 1;
  if (delimiters.find(text[i]) != std::string_view::npos) {
    if (i == 0 || delimiters.find(text[i - 1]) != std::string_view::npos) return "";
    --i;
  }
  std::size_t begin = i, end = i + 1;
  while (begin > 0 && delimiters.find(text[begin - 1]) == std::string_view::npos && i - begin < 40) --begin;
  while (end < text.size() && delimiters.find(text[end]) == std::string_view::npos && end - i < 40) ++end;
  return std::string(text.substr(begin, end - begin));
}

// ---- Fidelity levels and overrides. ----

constexpr std::size_t max_fidelity_levels = 16;

// The fidelity levels of `doc`, after checking the "fidelity" object itself.
std::vector<std::string> checked_levels(const json& doc, const CaseDiagnostics& diag) {
  if (!doc.is_object()) diag.fail("", doc, case_schema().expected());
  const SchemaMember& member = *case_schema().member("fidelity");
  if (!doc.contains("fidelity"))
    diag.fail_text("/fidelity", "nothing (required key \"fidelity\" is missing)", member.node.expected());
  std::vector<std::string> unused;
  check_against(member.node, doc.at("fidelity"), "/fidelity", diag, unused);
  std::vector<std::string> levels;
  for (const auto& item : doc.at("fidelity").items()) levels.push_back(item.key());
  // Each level is applied to a copy of the document to check its paths: bound the copies.
  if (levels.size() > max_fidelity_levels)
    diag.fail_text(
        "/fidelity", fmt::format("{} fidelity levels", levels.size()),
        fmt::format("at most {} levels (the catalogue defines \"quick\", \"standard\" and \"thesis\")",
                    max_fidelity_levels));
  return levels;
}

// Applies every entry of fidelity level `level` to `target`; records origins when asked.
void apply_level(json& target, const json& doc, const std::string& level, CaseDiagnostics& diag,
                 bool record) {
  const std::string site = child_pointer("/fidelity", level);
  for (const auto& item : doc.at("fidelity").at(level).items()) {
    const std::string label = "\"" + item.key() + "\": " + describe(item.value());
    const std::string written =
        apply_override(target, item.key(), item.value(), label, child_pointer(site, item.key()), diag);
    if (record) diag.note_origin(written, "fidelity level \"" + level + "\"");
  }
}

// Applies one "--set path=value" override; the value is JSON if it parses, else a string.
void apply_set(json& target, const std::string& text, CaseDiagnostics& diag) {
  const std::string label = "--set " + printable(text);
  if (!is_utf8(text))
    diag.fail_text("", label, "an override written in UTF-8 (the bytes shown as \\xNN are not)");
  const std::size_t eq = text.find('=');
  std::string path = text.substr(0, eq == std::string::npos ? 0 : eq);
  const std::size_t first = path.find_first_not_of(" \t"), last = path.find_last_not_of(" \t");
  path = first == std::string::npos ? std::string() : path.substr(first, last - first + 1);
  if (eq == std::string::npos || path.empty())
    diag.fail_text("", label, "an override of the form path=value, e.g. physics.reynolds=200");
  const std::string raw = text.substr(eq + 1);
  json value;
  try {
    ParsePosition position;
    value = json::parse(raw, DuplicateKeyGuard(diag.source(), position));
  } catch (const json::exception&) {
    value = raw;                         // not JSON: the text is a string value
  } catch (const core::InputError& e) {  // a repeated key or runaway nesting inside the value
    diag.fail_text("", fmt::format("{} ({} at {} of the value)", label, e.value(), e.json_path()),
                   e.expected());
  }
  const std::string written = apply_override(target, path, std::move(value), label, "", diag);
  diag.note_origin(written, label);
}

// ---- Conversion to CaseSpec (the document has passed the schema checks). ----

/// The kinematics of a body's "motion" (fixed: at rest at shape.center). Expressions that do not
/// parse are reported at their JSON path with the parser's caret line.
expr::RigidKinematics kinematics_of(const json& body, const ShapeSpec& shape, const std::string& at,
                                    const CaseDiagnostics& diag) {
  const json& motion = body.at("motion");
  if (motion.at("type").get_ref<const std::string&>() != "prescribed")
    return expr::RigidKinematics::fixed(shape.center, shape.angle);
  const auto parameters = motion.value("parameters", std::map<std::string, double>{});
  const json& segments = motion.at("segments");
  const std::size_t dimension = shape.center.size();
  std::vector<double> until;
  std::vector<std::vector<expr::Expression>> position(dimension);
  std::vector<expr::Expression> angle;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const json& seg = segments[k];
    const std::string seg_at = child_pointer(child_pointer(at, "segments"), k);
    auto parse = [&](const std::string& text, const std::string& pointer) {
      try {
        return expr::Expression::parse(text, parameters);
      } catch (const expr::ParseError& e) {
        diag.fail(pointer, json(text), fmt::format("a formula of t (L/U): {}", e.what()));
      }
    };
    if (seg.contains("until")) until.push_back(seg.at("until").get<double>());
    for (std::size_t a = 0; a < dimension; ++a)
      position[a].push_back(parse(seg.at("position").at(a).get<std::string>(),
                                  child_pointer(child_pointer(seg_at, "position"), a)));
    if (seg.contains("angle") && dimension != 2)
      diag.fail(child_pointer(seg_at, "angle"), seg.at("angle"),
                "no \"angle\" in 3D: rotating 3D bodies are not supported; remove the key");
    angle.push_back(seg.contains("angle") ? parse(seg.at("angle").get<std::string>(), child_pointer(seg_at, "angle"))
                                          : parse(fmt::format("{:.17g}", shape.angle), seg_at));
  }
  std::vector<expr::Piecewise> x;
  for (auto& pieces : position) x.emplace_back(until, std::move(pieces));
  return expr::RigidKinematics(std::move(x), expr::Piecewise(until, std::move(angle)));
}

CaseSpec to_spec(const json& doc, const CaseDiagnostics& diag) {
  CaseSpec spec;
  spec.id = doc.at("id").get<std::string>();
  spec.title = doc.at("title").get<std::string>();
  spec.description = doc.at("description").get<std::string>();

  const json& p = doc.at("physics");
  PhysicsSpec& physics = spec.physics;
  physics.dimension = p.at("dimension").get<int>();
  const json& flow = p.at("flow");
  physics.flow.type = enum_value(flow_type_names, flow.at("type").get<std::string>());
  physics.flow.direction = flow.value("direction", physics.flow.direction);
  physics.flow.body_force = flow.value("body_force", physics.flow.body_force);
  physics.flow.perturbation = flow.value("perturbation", physics.flow.perturbation);
  physics.reynolds = p.at("reynolds").get<double>();
  physics.domain_size = p.at("domain").at("size").get<std::vector<double>>();
  for (const auto& b : p.at("domain").at("boundaries")) {
    physics.boundaries.push_back(enum_value(boundary_names, b.get<std::string>()));
  }
  for (const auto& b : p.at("bodies")) {
    BodySpec body;
    body.name = b.at("name").get<std::string>();
    body.shape.type = enum_value(shape_type_names, b.at("shape").at("type").get<std::string>());
    body.shape.center = b.at("shape").at("center").get<std::vector<double>>();
    body.shape.diameter = b.at("shape").at("diameter").get<double>();
    body.shape.aspect_ratio = b.at("shape").value("aspect_ratio", body.shape.aspect_ratio);
    body.shape.alpha = b.at("shape").value("alpha", body.shape.alpha);
    body.shape.angle = b.at("shape").value("angle", body.shape.angle);
    if (b.contains("motion")) {
      RigidMotionSpec motion;
      motion.type = enum_value(motion_type_names, b.at("motion").at("type").get<std::string>());
      motion.kinematics = kinematics_of(b, body.shape, child_pointer(child_pointer("/physics/bodies", physics.bodies.size()), "motion"), diag);
      body.motion = std::move(motion);
    }
    if (b.contains("membrane")) {
      const json& m = b.at("membrane");
      check_membrane_keys(m, child_pointer(child_pointer("/physics/bodies", physics.bodies.size()), "membrane"),
                          body.name, physics.dimension, diag);
      MembraneSpec membrane;
      membrane.law = enum_value(membrane_law_names, m.at("law").get<std::string>());
      membrane.capillary = m.at("capillary").get<double>();
      membrane.bending_ratio = m.value("bending_ratio", membrane.bending_ratio);
      if (m.contains("reference_curvature"))
        membrane.reference_curvature =
            enum_value(reference_curvature_names, m.at("reference_curvature").get<std::string>());
      membrane.area_dilation = m.value("area_dilation", membrane.area_dilation);
      membrane.nodes = m.value("nodes", 0);
      membrane.subdivisions = m.value("subdivisions", 0);
      body.membrane = membrane;
    }
    physics.bodies.push_back(std::move(body));
  }

  // Optional keys fall back to the defaults written in case_spec.hpp.
  const json& n = doc.at("numerics");
  NumericsSpec& numerics = spec.numerics;
  const json& grid = n.at("grid");
  numerics.grid.refinement = enum_value(refinement_names, grid.at("refinement").get<std::string>());
  numerics.grid.fine_spacing = grid.at("fine_spacing").get<double>();
  if (grid.contains("fine_region")) {
    numerics.grid.fine_min = grid.at("fine_region").at("min").get<std::vector<double>>();
    numerics.grid.fine_max = grid.at("fine_region").at("max").get<std::vector<double>>();
  }
  const json& collision = n.at("collision");
  numerics.collision.op = enum_value(collision_names, collision.at("operator").get<std::string>());
  numerics.collision.magic = collision.value("magic", numerics.collision.magic);
  if (collision.contains("bulk_viscosity_ratio"))
    numerics.collision.bulk_viscosity_ratio = collision.at("bulk_viscosity_ratio").get<double>();
  numerics.precision = enum_value(precision_names, n.at("precision").get<std::string>());
  const json ib = n.value("ib", json::object());
  if (ib.contains("kernel"))
    numerics.ib.kernel = enum_value(kernel_names, ib.at("kernel").get<std::string>());
  numerics.ib.marker_spacing = ib.value("marker_spacing", numerics.ib.marker_spacing);
  numerics.ib.forcing_iterations = ib.value("forcing_iterations", numerics.ib.forcing_iterations);
  if (n.contains("far_field")) numerics.far_field = enum_value(far_field_names, n.at("far_field").get<std::string>());
  numerics.lattice_velocity = n.at("lattice_velocity").get<double>();
  numerics.end_time = n.at("end_time").get<double>();
  numerics.threads = n.value("threads", numerics.threads);
  const json guards = n.value("guards", json::object());
  auto& g = numerics.guards;
  g.every = guards.value("every", g.every);
  g.max_mach = guards.value("max_mach", g.max_mach);
  g.max_density_deviation = guards.value("max_density_deviation", g.max_density_deviation);
  g.max_volume_change = guards.value("max_volume_change", g.max_volume_change);
  g.min_area_ratio = guards.value("min_area_ratio", g.min_area_ratio);

  const json& o = doc.at("outputs");
  spec.outputs.series.interval = o.at("series").at("interval").get<double>();
  spec.outputs.series.quantities = o.at("series").at("quantities").get<std::vector<std::string>>();
  if (o.contains("snapshots")) {
    spec.outputs.snapshots.times = o.at("snapshots").at("times").get<std::vector<double>>();
    spec.outputs.snapshots.fields = o.at("snapshots").at("fields").get<std::vector<std::string>>();
  }
  spec.outputs.average_from = o.value("average_from", spec.outputs.average_from);
  spec.outputs.oscillation_threshold_deg = o.value("oscillation_threshold", spec.outputs.oscillation_threshold_deg);
  const json checkpoint = o.value("checkpoint", json::object());
  spec.outputs.checkpoint.interval = checkpoint.value("interval", spec.outputs.checkpoint.interval);
  spec.outputs.checkpoint.wall_seconds = checkpoint.value("wall_seconds", spec.outputs.checkpoint.wall_seconds);

  for (const auto& a : doc.value("acceptance", json::array())) {
    AcceptanceSpec entry;
    entry.metric = a.at("metric").get<std::string>();
    entry.reference = a.at("reference").get<std::string>();
    entry.comparison = a.at("comparison").get<std::string>();
    if (a.contains("reference_mode")) {
      const json& m = a.at("reference_mode");
      entry.reference_modes = m.is_array() ? m.get<std::vector<std::string>>() : std::vector<std::string>{m};
    } else {
      entry.reference_value = a.value("reference_value", 0.0);  // time_series: the reference file
      entry.tolerance = a.at("tolerance").get<std::map<std::string, double>>();
      entry.window = a.value("window", std::vector<double>{});
    }
    entry.justification = a.at("justification").get<std::string>();
    spec.acceptance.push_back(std::move(entry));
  }
  if (doc.contains("performance")) {
    const json& perf = doc.at("performance");
    spec.performance = PerformanceSpec{perf.at("wall_time_budget_s").get<std::map<std::string, double>>(),
                                       perf.at("justification").get<std::string>()};
  }
  return spec;
}

// Normalises the flow direction and writes every default that was used back into `resolved`,
// so that the case.json of a run states every value it ran with (DESIGN.md section 6).
void complete(CaseSpec& spec, json& resolved) {
  FlowSpec& flow = spec.physics.flow;
  if (flow.type == FlowSpec::Type::uniform) {
    if (flow.direction.empty()) {
      flow.direction.assign(static_cast<std::size_t>(spec.physics.dimension), 0.0);
      flow.direction[0] = 1.0;
    }
    double norm2 = 0;
    for (double c : flow.direction) norm2 += c * c;
    for (double& c : flow.direction) c /= std::sqrt(norm2);
    resolved["physics"]["flow"]["direction"] = flow.direction;
  }
  const NumericsSpec& numerics = spec.numerics;
  if (numerics.collision.op == CollisionSpec::Operator::trt)
    resolved["numerics"]["collision"]["magic"] = numerics.collision.magic;
  resolved["numerics"]["ib"] = {{"kernel", enum_name(kernel_names, numerics.ib.kernel)},
                                {"marker_spacing", numerics.ib.marker_spacing},
                                {"forcing_iterations", numerics.ib.forcing_iterations}};
  resolved["numerics"]["threads"] = numerics.threads;
  const GuardSpec& g = numerics.guards;
  resolved["numerics"]["guards"] = {{"every", g.every},
                                    {"max_mach", g.max_mach},
                                    {"max_density_deviation", g.max_density_deviation},
                                    {"max_volume_change", g.max_volume_change},
                                    {"min_area_ratio", g.min_area_ratio}};
  for (std::size_t i = 0; i < spec.physics.bodies.size(); ++i) {
    const BodySpec& body = spec.physics.bodies[i];
    json& b = resolved["physics"]["bodies"][i];
    if (body.shape.type == ShapeSpec::Type::ellipse || body.shape.type == ShapeSpec::Type::oblate_spheroid)
      b["shape"]["aspect_ratio"] = body.shape.aspect_ratio;
    if (body.shape.type == ShapeSpec::Type::biconcave) b["shape"]["alpha"] = body.shape.alpha;
    if (spec.physics.dimension == 2) b["shape"]["angle"] = body.shape.angle;
    if (body.membrane && spec.physics.dimension == 2) {
      b["membrane"]["bending_ratio"] = body.membrane->bending_ratio;
      b["membrane"]["reference_curvature"] =
          enum_name(reference_curvature_names, body.membrane->reference_curvature);
    }
  }
  resolved["outputs"]["snapshots"] = {{"times", spec.outputs.snapshots.times},
                                      {"fields", spec.outputs.snapshots.fields}};
  resolved["outputs"]["average_from"] = spec.outputs.average_from;
  resolved["outputs"]["oscillation_threshold"] = spec.outputs.oscillation_threshold_deg;
  resolved["outputs"]["checkpoint"] = {{"interval", spec.outputs.checkpoint.interval},
                                       {"wall_seconds", spec.outputs.checkpoint.wall_seconds}};
  if (!resolved.contains("acceptance")) resolved["acceptance"] = json::array();
  spec.resolved = std::move(resolved);
}

}  // namespace

json read_case_json(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw core::InputError(
        fmt::format("{}: cannot read the case file: {}", file.string(),
                    std::filesystem::exists(file, ec) ? "not a regular file" : "no such file"));
  const auto bytes = std::filesystem::file_size(file, ec);
  if (!ec && bytes > max_case_file_bytes)
    throw core::InputError(
        fmt::format("{}: cannot read the case file: it has {} bytes, more than the {} MiB a case "
                    "file may have; is it a case file?",
                    file.string(), bytes, max_case_file_bytes >> 20));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::InputError(fmt::format("{}: cannot open the case file for reading", file.string()));
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad())
    throw core::InputError(fmt::format("{}: cannot read the case file: read error", file.string()));
  return parse_case_text(text, file.string());
}

json parse_case_text(std::string_view text, const std::string& source_name) {
  if (text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    throw core::InputError(fmt::format("{}: malformed JSON: the case file is {}; expected a JSON object",
                                       source_name, text.empty() ? "empty" : "blank"));
  ParsePosition position;
  try {
    return json::parse(text, DuplicateKeyGuard(source_name, position));
  } catch (const json::exception& e) {  // parse_error carries line and column in its message
    const std::string at = position.pointer();
    const auto* parse_error = dynamic_cast<const json::parse_error*>(&e);
    const std::string token = parse_error ? token_at(text, parse_error->byte) : "";
    throw core::InputError(fmt::format("{}: malformed JSON{}{}: {}", source_name,
                                       at.empty() ? " near / (the top level)" : " near " + at,
                                       token.empty() ? "" : " at `" + printable(token, 40) + "`",
                                       printable(without_exception_id(e.what()))));
  }
}

CaseSpec parse_case(const json& doc, const std::string& source_name, const std::string& fidelity,
                    const std::vector<std::string>& overrides) {
  CaseDiagnostics diag(source_name);
  const std::vector<std::string> levels = checked_levels(doc, diag);
  if (std::find(levels.begin(), levels.end(), fidelity) == levels.end())
    diag.fail_text(
        "/fidelity", "fidelity level \"" + fidelity + "\"",
        "a level this case defines: " + (levels.empty() ? std::string("(none)") : quoted_list(levels)) +
            did_you_mean(fidelity, levels));

  json resolved = doc;
  apply_level(resolved, doc, fidelity, diag, true);
  for (const auto& text : overrides) apply_set(resolved, text, diag);

  std::vector<std::string> per_axis;
  check_against(case_schema(), resolved, "", diag, per_axis);
  check_conditional_keys(resolved, diag);
  check_axis_lengths(resolved, resolved.at("physics").at("dimension").get<int>(), per_axis, diag);
  // Every level's paths must exist, even those not applied now, so that a typo in "thesis"
  // is found by a "quick" run (after the case itself is checked: a key missing from the case
  // is reported as missing, not as a path of another level that leads nowhere).
  for (const auto& level : levels) {
    if (level == fidelity) continue;
    json scratch = doc;
    apply_level(scratch, doc, level, diag, false);
  }

  CaseSpec spec = to_spec(resolved, diag);
  spec.source_file = source_name;
  spec.fidelity = fidelity;
  spec.document = doc;
  spec.overrides = overrides;
  check_consistency(spec, levels, diag);
  complete(spec, resolved);
  return spec;
}

CaseSpec load_case(const std::filesystem::path& file, const std::string& fidelity,
                   const std::vector<std::string>& overrides) {
  return parse_case(read_case_json(file), file.string(), fidelity, overrides);
}

CaseSpec load_case_text(std::string_view text, const std::string& source_name, const std::string& fidelity,
                        const std::vector<std::string>& overrides) {
  return parse_case(parse_case_text(text, source_name), source_name, fidelity, overrides);
}

std::vector<std::string> fidelity_levels(const json& doc, const std::string& source_name) {
  return checked_levels(doc, CaseDiagnostics(source_name));
}

std::vector<std::string> fidelity_levels(const std::filesystem::path& file) {
  return fidelity_levels(read_case_json(file), file.string());
}

}  // namespace caplab::cases
