// The case-file format as data, and the walker that checks documents against it
// (see case_schema.hpp).
#include "case/case_schema.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "case/case_enums.hpp"

namespace caplab::cases {
namespace {

using nlohmann::json;

// ---- Builders: keep the description below readable as a tree. ----

SchemaMember req(std::string key, SchemaNode node) { return {std::move(key), true, std::move(node)}; }
SchemaMember opt(std::string key, SchemaNode node) { return {std::move(key), false, std::move(node)}; }

SchemaNode object(std::vector<SchemaMember> members) {
  SchemaNode n;
  n.kind = ValueKind::object;
  n.members = std::move(members);
  return n;
}
SchemaNode map_of(SchemaNode element) {
  SchemaNode n;
  n.kind = ValueKind::map;
  n.element.push_back(std::move(element));
  return n;
}
SchemaNode array_of(SchemaNode element) {
  SchemaNode n;
  n.kind = ValueKind::array;
  n.element.push_back(std::move(element));
  return n;
}
SchemaNode per_axis(SchemaNode element) {
  SchemaNode n = array_of(std::move(element));
  n.per_axis = true;
  return n;
}
SchemaNode number(Range range = {}) {
  SchemaNode n;
  n.kind = ValueKind::number;
  n.range = range;
  return n;
}
SchemaNode integer(Range range) {
  SchemaNode n = number(range);
  n.kind = ValueKind::integer;
  return n;
}
SchemaNode text() {
  SchemaNode n;
  n.kind = ValueKind::string;
  return n;
}
SchemaNode choice(std::vector<std::string> choices) {
  SchemaNode n = text();
  n.choices = std::move(choices);
  return n;
}
SchemaNode any() { return SchemaNode{}; }

constexpr double inf = std::numeric_limits<double>::infinity();
constexpr Range positive{0, inf, true, false};
constexpr Range at_least(double lo) { return {lo, inf, false, false}; }
constexpr Range closed(double lo, double hi) { return {lo, hi, false, false}; }

// ---- Acceptance entries whose keys depend on the comparison. ----

/// The comparison of an acceptance entry whose reference is a flow regime, not a number.
constexpr std::string_view mode_comparison = "mode";

/// The comparison of a series column against a reference history (score/comparators.hpp).
constexpr std::string_view series_comparison = "time_series";

/// Allowed `acceptance[].comparison`: the numeric ones (case_enums.hpp), "time_series" and "mode".
std::vector<std::string> acceptance_comparisons() {
  std::vector<std::string> names{comparison_names.begin(), comparison_names.end()};
  names.emplace_back(series_comparison);
  names.emplace_back(mode_comparison);
  return names;
}

/// The flow regimes a "reference_mode" may name: the values of the summary metric "mode".
const std::vector<std::string>& mode_names() {
  static const std::vector<std::string> names{"steady_tank_treading", "oscillating_tank_treading",
                                              "tumbling"};
  return names;
}

// ---- The format (DESIGN.md section 5). Units are in catalogue/schema.json. ----

SchemaNode build_case_schema() {
  // A rigid body has "motion", a capsule "membrane" (exactly one: case_consistency.cpp).
  const SchemaNode body = object({
      req("name", text()),
      req("shape", object({req("type", choice(enum_names(shape_type_names))),
                           req("center", per_axis(number())), req("diameter", number(positive)),
                           opt("aspect_ratio", number(at_least(1))),  // ellipse, oblate_spheroid only
                           opt("alpha", number(positive)),            // biconcave only
                           opt("angle", number())})),                 // 2D only
      // prescribed only: "segments" (required there), "parameters" (case_consistency.cpp).
      opt("motion", object({req("type", choice(enum_names(motion_type_names))),
                            opt("parameters", map_of(number())),
                            opt("segments", array_of(object({opt("until", number()),
                                                             req("position", per_axis(text())),
                                                             opt("angle", text())})))})),
      opt("membrane", object({req("law", choice(enum_names(membrane_law_names))),
                              req("capillary", number(positive)), opt("bending_ratio", number(at_least(0))),
                              opt("reference_curvature", choice(enum_names(reference_curvature_names))),
                              opt("area_dilation", number(positive)),       // skalak only (required there)
                              opt("nodes", integer(closed(8, 1e6))),        // 2D only (required there)
                              opt("subdivisions", integer(closed(1, 7)))})),  // 3D only (required there)
  });
  const SchemaNode physics = object({
      req("dimension", integer(closed(2, 3))),
      req("flow", object({req("type", choice(enum_names(flow_type_names))),
                          opt("direction", per_axis(number())),  // uniform only
                          opt("perturbation", number(closed(0, 1))),  // uniform only
                          opt("body_force", number())})),        // body_force only (required there)
      req("reynolds", number(positive)),
      req("domain", object({req("size", per_axis(number(positive))),
                            req("boundaries", per_axis(choice(enum_names(boundary_names))))})),
      req("bodies", array_of(body)),
  });
  const SchemaNode numerics = object({
      req("grid", object({req("refinement", choice(enum_names(refinement_names))),
                          req("fine_spacing", number(positive)),
                          opt("fine_region",  // two_level only (required there)
                              object({req("min", per_axis(number())), req("max", per_axis(number()))}))})),
      req("collision", object({req("operator", choice(enum_names(collision_names))),
                               opt("magic", number(positive)),  // trt only
                               opt("bulk_viscosity_ratio", number(Range{0, 1e4, true, false}))})),
      req("precision", choice(enum_names(precision_names))),
      opt("ib",
          object({opt("kernel", choice(enum_names(kernel_names))), opt("marker_spacing", number(closed(0.05, 2))),
                  opt("forcing_iterations", integer(closed(1, 100)))})),
      opt("far_field", choice(enum_names(far_field_names))),
      req("lattice_velocity", number(Range{0, 0.4, true, false})),
      req("end_time", number(positive)),
      opt("threads", integer(closed(0, 4096))),
      opt("guards", object({opt("every", integer(closed(1, 1e9))), opt("max_mach", number(positive)),
                            opt("max_density_deviation", number(positive)),
                            opt("max_volume_change", number(positive)),
                            opt("min_area_ratio", number(Range{0, 1, true, true}))})),
  });
  const SchemaNode outputs = object({
      req("series", object({req("interval", number(positive)), req("quantities", array_of(text()))})),
      opt("snapshots",
          object({req("times", array_of(number(at_least(0)))),
                  req("fields", array_of(choice({"density", "velocity", "vorticity"})))})),  // sim/scene.hpp
      opt("average_from", number(at_least(0))),
      opt("oscillation_threshold", number(Range{0, 45, true, false})),
      opt("checkpoint", object({opt("interval", number(at_least(0))), opt("wall_seconds", number(at_least(0)))})),
  });
  // Numeric comparisons need "reference_value" and "tolerance", "mode" needs "reference_mode"
  // instead (a mode name or an array of them): check_acceptance_entries.
  const SchemaNode acceptance = object({
      req("metric", text()),
      req("reference", text()),
      opt("reference_value", number()),
      opt("reference_mode", any()),
      req("comparison", choice(acceptance_comparisons())),
      opt("tolerance", map_of(number(positive))),
      opt("window", array_of(number())),  // time_series only: [from, to] in L/U
      req("justification", text()),
  });
  // A wall-time budget per fidelity level (some levels may have none): the scorer's performance
  // verdict, kept out of the run's verdict (timings depend on the machine and its load).
  const SchemaNode performance = object({
      req("wall_time_budget_s", map_of(number(positive))),
      req("justification", text()),
  });
  return object({
      req("id", text()),
      req("title", text()),
      req("description", text()),
      req("physics", physics),
      req("numerics", numerics),
      // level name -> {dotted path -> value}; entries are checked where they are applied.
      req("fidelity", map_of(map_of(any()))),
      req("outputs", outputs),
      opt("acceptance", array_of(acceptance)),
      opt("performance", performance),
  });
}

/// A key whose presence depends on the string value at `controller`: allowed only when that
/// value is one of `enabling`, and then required or optional.
struct ConditionalKey {
  std::string target;
  std::string controller;
  std::vector<std::string> enabling;
  bool required;
};

const std::vector<ConditionalKey>& conditional_keys() {
  static const std::vector<ConditionalKey> rules{
      {"/physics/flow/direction", "/physics/flow/type", {"uniform"}, false},
      {"/physics/flow/perturbation", "/physics/flow/type", {"uniform"}, false},
      {"/physics/flow/body_force", "/physics/flow/type", {"body_force"}, true},
      {"/numerics/grid/fine_region", "/numerics/grid/refinement", {"two_level"}, true},
      {"/numerics/collision/magic", "/numerics/collision/operator", {"trt"}, false},
  };
  return rules;
}

// Per rigid body: "prescribed" motion needs a non-empty "segments" list in which every segment
// but the last ends at an "until" time, strictly increasing; "fixed" takes neither "segments"
// nor "parameters".
void check_motion_entries(const json& doc, const CaseDiagnostics& diag) {
  const json& bodies = doc.at("physics").at("bodies");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies[i].contains("motion")) continue;
    const json& motion = bodies[i].at("motion");
    const std::string base = child_pointer(child_pointer("/physics/bodies", i), "motion");
    const bool prescribed = motion.at("type").get_ref<const std::string&>() == "prescribed";
    if (!prescribed) {
      for (const char* key : {"segments", "parameters"})
        if (motion.contains(key))
          diag.fail(child_pointer(base, key), motion.at(key),
                    fmt::format("no \"{}\" key: it applies only when {}/type is \"prescribed\"; remove it or "
                                "set the type to \"prescribed\"",
                                key, base));
      continue;
    }
    const std::string segments_at = child_pointer(base, "segments");
    if (!motion.contains("segments") || motion.at("segments").empty())
      diag.fail_text(segments_at, "nothing (no motion segments)",
                     "a non-empty array of segments {\"until\": t_end, \"position\": [x(t), y(t)], \"angle\": "
                     "theta(t)} when " + base + "/type is \"prescribed\"; the last segment has no \"until\"");
    const json& segments = motion.at("segments");
    double previous = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < segments.size(); ++k) {
      const bool last = k + 1 == segments.size();
      const std::string until_at = child_pointer(child_pointer(segments_at, k), "until");
      if (last && segments[k].contains("until"))
        diag.fail(until_at, segments[k].at("until"),
                  "no \"until\" on the last segment: it lasts to the end of the run");
      if (last) break;
      if (!segments[k].contains("until"))
        diag.fail_text(until_at, "nothing (required key \"until\" is missing)",
                       "the time (L/U) at which this segment ends and the next begins");
      const double until = segments[k].at("until").get<double>();
      if (!(until > previous))
        diag.fail(until_at, segments[k].at("until"),
                  fmt::format("an end time after the previous segment's ({}): segments run in time order",
                              previous));
      previous = until;
    }
  }
}

// Per entry: a mode entry has "reference_mode" (a known mode or a non-empty array of them) and
// no "reference_value" or "tolerance"; every other entry the reverse.
void check_acceptance_entries(const json& doc, const CaseDiagnostics& diag) {
  if (!doc.contains("acceptance")) return;
  const SchemaNode& format = case_schema().member("acceptance")->node.element.front();
  const std::string modes_expected =
      "a mode name, one of " + quoted_list(mode_names()) + ", or a non-empty array of them";
  const json& entries = doc.at("acceptance");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const json& entry = entries[i];
    const std::string at = child_pointer("/acceptance", i);
    const std::string& comparison = entry.at("comparison").get_ref<const std::string&>();
    const bool mode = comparison == mode_comparison;
    const bool series = comparison == series_comparison;
    const std::string when = at + "/comparison is \"" + comparison + "\"";
    using Keys = std::vector<std::string>;
    const Keys needed = mode ? Keys{"reference_mode"} : series ? Keys{"tolerance"} : Keys{"reference_value", "tolerance"};
    const Keys unused = mode     ? Keys{"reference_value", "tolerance", "window"}
                        : series ? Keys{"reference_value", "reference_mode"}
                                 : Keys{"reference_mode", "window"};
    for (const auto& key : needed)
      if (!entry.contains(key))
        diag.fail_text(child_pointer(at, key), "nothing (required key \"" + key + "\" is missing)",
                       (key == "reference_mode" ? modes_expected : format.member(key)->node.expected()) +
                           ", which is required when " + when);
    for (const auto& key : unused)
      if (entry.contains(key))
        diag.fail(child_pointer(at, key), entry.at(key),
                  "no \"" + key + "\" key when " + when +
                      (mode     ? ": a mode is matched exactly against \"reference_mode\"; remove it"
                       : series ? ": the reference history is the file named by \"reference\"; remove it"
                                : ": it belongs to the comparison \"mode\" or \"time_series\"; remove it"));
    if (series && entry.contains("window")) {
      const json& w = entry.at("window");
      if (w.size() != 2 || !(w[0].get<double>() < w[1].get<double>()))
        diag.fail(child_pointer(at, "window"), w, "[from, to] with from < to, in L/U");
    }
    if (!mode) continue;
    const std::string pointer = child_pointer(at, "reference_mode");
    const json& reference = entry.at("reference_mode");
    if (!reference.is_string() && !(reference.is_array() && !reference.empty()))
      diag.fail(pointer, reference, modes_expected);
    const json listed = reference.is_array() ? reference : json::array({reference});
    for (std::size_t k = 0; k < listed.size(); ++k) {
      const std::string where = reference.is_array() ? child_pointer(pointer, k) : pointer;
      if (!listed[k].is_string()) diag.fail(where, listed[k], modes_expected);
      const std::string& name = listed[k].get_ref<const std::string&>();
      if (std::find(mode_names().begin(), mode_names().end(), name) == mode_names().end())
        diag.fail(where, listed[k], "one of " + quoted_list(mode_names()) + did_you_mean(name, mode_names()));
    }
  }
}

// ---- The walker. ----

// " (a string)" etc.: what kind of value was given, for type mismatches.
std::string kind_note(const json& value, ValueKind wanted) {
  if (value.is_string() && (wanted == ValueKind::number || wanted == ValueKind::integer)) {
    const std::string& s = value.get_ref<const std::string&>();
    char* end = nullptr;
    const double x = std::strtod(s.c_str(), &end);
    if (!s.empty() && end == s.c_str() + s.size())
      return std::isfinite(x) ? " (a string; write numbers without quotes)"
                              : " (a string; NaN and infinity are not allowed)";
  }
  if (value.is_number_float() && wanted == ValueKind::integer) return " (not an integer)";
  switch (value.type()) {
    case json::value_t::object:
      return " (an object)";
    case json::value_t::array:
      return " (an array)";
    case json::value_t::string:
      return " (a string)";
    case json::value_t::boolean:
      return " (a boolean)";
    case json::value_t::null:
      return " (null)";
    default:
      return " (a number)";
  }
}

void check_object(const SchemaNode& node, const json& value, const std::string& pointer,
                  const CaseDiagnostics& diag, std::vector<std::string>& per_axis) {
  const std::string where = pointer.empty() ? "/" : pointer;
  for (const auto& item : value.items()) {
    if (node.member(item.key()) == nullptr) {
      diag.fail_text(child_pointer(pointer, item.key()), "unknown key \"" + item.key() + "\"",
                     "one of the keys of " + where + ": " + quoted_list(node.member_keys()) +
                         did_you_mean(item.key(), node.member_keys()));
    }
  }
  for (const auto& m : node.members) {
    const std::string at = child_pointer(pointer, m.key);
    if (!value.contains(m.key)) {
      if (m.required)
        diag.fail_text(at, "nothing (required key \"" + m.key + "\" is missing)", m.node.expected());
      continue;
    }
    check_against(m.node, value.at(m.key), at, diag, per_axis);
  }
}

void check_number(const SchemaNode& node, const json& value, const std::string& pointer,
                  const CaseDiagnostics& diag) {
  const bool type_ok = node.kind == ValueKind::integer ? value.is_number_integer() : value.is_number();
  if (!type_ok) diag.fail_text(pointer, describe(value) + kind_note(value, node.kind), node.expected());
  const double x = value.get<double>();
  if (!std::isfinite(x)) diag.fail(pointer, value, node.expected());
  if (!node.range.contains(x)) diag.fail(pointer, value, node.expected());
}

void check_string(const SchemaNode& node, const json& value, const std::string& pointer,
                  const CaseDiagnostics& diag) {
  if (!value.is_string())
    diag.fail_text(pointer, describe(value) + kind_note(value, node.kind), node.expected());
  const std::string& s = value.get_ref<const std::string&>();
  if (s.empty()) diag.fail(pointer, value, node.expected());
  if (!node.choices.empty() && std::find(node.choices.begin(), node.choices.end(), s) == node.choices.end())
    diag.fail(pointer, value, node.expected() + did_you_mean(s, node.choices));
}

void collect_keys(const SchemaNode& node, const std::string& path, std::vector<SchemaKey>& out) {
  if (node.kind == ValueKind::array) return collect_keys(node.element.front(), path + ".*", out);
  if (node.kind != ValueKind::object) return;
  for (const auto& m : node.members) {
    const std::string p = path.empty() ? m.key : path + "." + m.key;
    const SchemaNode& leaf = m.node.kind == ValueKind::array ? m.node.element.front() : m.node;
    out.push_back({p, m.required, leaf.choices});
    collect_keys(m.node, p, out);
  }
}

const char* kind_name(ValueKind kind) {
  switch (kind) {
    case ValueKind::object:
      return "an object";
    case ValueKind::map:
      return "an object";
    case ValueKind::array:
      return "an array";
    case ValueKind::number:
      return "a number";
    case ValueKind::integer:
      return "an integer";
    case ValueKind::string:
      return "a string";
    case ValueKind::any:
      return "a value";
  }
  return "a value";
}

}  // namespace

bool Range::contains(double x) const { return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi); }

std::string Range::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) return fmt::format("in {}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
  if (has_lo) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
  if (has_hi) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
  return "";
}

std::string SchemaNode::expected() const {
  switch (kind) {
    case ValueKind::object:
      return "an object with keys " + quoted_list(member_keys());
    case ValueKind::map:
      return element.front().kind == ValueKind::any
                 ? "an object"
                 : "an object whose values are each " + element.front().expected();
    case ValueKind::array:
      return std::string(per_axis ? "an array with one entry per axis" : "an array") + ", each entry " +
             element.front().expected();
    case ValueKind::number:
    case ValueKind::integer: {
      const std::string r = range.text();
      return std::string(kind == ValueKind::integer ? "an integer" : "a finite number") +
             (r.empty() ? "" : " " + r);
    }
    case ValueKind::string:
      return choices.empty() ? "a non-empty string" : "one of " + quoted_list(choices);
    case ValueKind::any:
      return "any value";
  }
  return "";
}

const SchemaMember* SchemaNode::member(std::string_view key) const {
  for (const auto& m : members)
    if (m.key == key) return &m;
  return nullptr;
}

std::vector<std::string> SchemaNode::member_keys() const {
  std::vector<std::string> keys;
  for (const auto& m : members) keys.push_back(m.key);
  return keys;
}

const SchemaNode& case_schema() {
  static const SchemaNode schema = build_case_schema();
  return schema;
}

void check_against(const SchemaNode& node, const json& value, const std::string& pointer,
                   const CaseDiagnostics& diag, std::vector<std::string>& per_axis) {
  switch (node.kind) {
    case ValueKind::object:
      if (!value.is_object())
        diag.fail_text(pointer, describe(value) + kind_note(value, node.kind), node.expected());
      return check_object(node, value, pointer, diag, per_axis);
    case ValueKind::map:
      if (!value.is_object())
        diag.fail_text(pointer, describe(value) + kind_note(value, node.kind), node.expected());
      for (const auto& item : value.items())
        check_against(node.element.front(), item.value(), child_pointer(pointer, item.key()), diag, per_axis);
      return;
    case ValueKind::array:
      if (!value.is_array())
        diag.fail_text(pointer, describe(value) + kind_note(value, node.kind), node.expected());
      if (node.per_axis) per_axis.push_back(pointer);
      for (std::size_t i = 0; i < value.size(); ++i)
        check_against(node.element.front(), value[i], child_pointer(pointer, i), diag, per_axis);
      return;
    case ValueKind::number:
    case ValueKind::integer:
      return check_number(node, value, pointer, diag);
    case ValueKind::string:
      return check_string(node, value, pointer, diag);
    case ValueKind::any:
      return;
  }
}

void check_conditional_keys(const json& doc, const CaseDiagnostics& diag) {
  for (const auto& rule : conditional_keys()) {
    const json::json_pointer target(rule.target);
    const std::string key = target.back();
    const std::string& control = doc.at(json::json_pointer(rule.controller)).get_ref<const std::string&>();
    const bool enabled =
        std::find(rule.enabling.begin(), rule.enabling.end(), control) != rule.enabling.end();
    const bool present = doc.contains(target);
    const std::string when = rule.controller + " is " + quoted_list(rule.enabling);
    if (enabled && rule.required && !present)
      diag.fail_text(rule.target, "nothing (required key \"" + key + "\" is missing)",
                     "\"" + key + "\", which is required when " + when);
    if (!enabled && present)
      diag.fail(rule.target, doc.at(target),
                "no \"" + key + "\" key: it applies only when " + when + ", and " + rule.controller +
                    " is \"" + control + "\" here; remove it or change " + rule.controller);
  }
  check_acceptance_entries(doc, diag);
  check_motion_entries(doc, diag);
}

std::string apply_override(json& doc, std::string_view dotted, json value, const std::string& label,
                           const std::string& site, const CaseDiagnostics& diag) {
  std::vector<std::string> segments;
  for (std::size_t start = 0;;) {
    const std::size_t dot = dotted.find('.', start);
    segments.emplace_back(dotted.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  const SchemaNode* node = &case_schema();
  json* current = &doc;
  std::string pointer;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const std::string& seg = segments[i];
    const std::string where = pointer.empty() ? "/" : pointer;
    const std::string next = child_pointer(pointer, seg);
    const std::string at = site.empty() ? next : site;
    if (seg.empty()) diag.fail_text(at, label, "a dotted path of keys such as physics.reynolds");
    if (current->is_null() && (node->kind == ValueKind::object || node->kind == ValueKind::map))
      *current = json::object();  // an optional object that the override creates
    const SchemaNode* child = nullptr;
    switch (node->kind) {
      case ValueKind::object: {
        const SchemaMember* m = node->member(seg);
        if (m == nullptr)
          diag.fail_text(at, label,
                         "a path in the case format, but \"" + seg + "\" is not a key of " + where +
                             " (keys: " + quoted_list(node->member_keys()) + ")" +
                             did_you_mean(seg, node->member_keys()));
        if (pointer.empty() && seg == "fidelity")
          diag.fail_text(at, label,
                         "a path outside \"fidelity\": levels are applied before overrides; choose one "
                         "with the fidelity option instead");
        child = &m->node;
        break;
      }
      case ValueKind::map:
        child = &node->element.front();
        break;
      case ValueKind::array: {
        const bool digits = !seg.empty() && seg.size() < 10 &&
                            std::all_of(seg.begin(), seg.end(), [](char c) { return c >= '0' && c <= '9'; });
        const std::size_t size = current->is_array() ? current->size() : 0;
        if (!digits || std::stoul(seg) >= size)
          diag.fail_text(
              at, label,
              !current->is_array() && !current->is_null()
                  ? fmt::format("an index of an entry of the array at {}, but that is {}, not an array", where,
                                describe(*current))
              : size == 0 ? fmt::format("an index of an existing entry, but the array at {} is empty or absent",
                                        where)
                          : fmt::format("an index 0..{} of the array at {} (it has {} entries)", size - 1,
                                      where, size));
        child = &node->element.front();
        break;
      }
      default:
        diag.fail_text(at, label,
                       fmt::format("a path in the case format, but {} is {} and has no member \"{}\"", where,
                                   kind_name(node->kind), seg));
    }
    if (node->kind == ValueKind::array) {
      json& entry = (*current)[std::stoul(seg)];
      if (i + 1 == segments.size()) entry = std::move(value);
      current = &entry;
    } else {
      if (!current->is_object())
        diag.fail_text(at, label,
                       fmt::format("{} to be an object so that \"{}\" can be set in it; it is {}", where, seg,
                                   describe(*current)));
      json& entry = (*current)[seg];
      if (i + 1 == segments.size()) entry = std::move(value);
      current = &entry;
    }
    node = child;
    pointer = next;
  }
  return pointer;
}

std::vector<SchemaKey> schema_keys() {
  std::vector<SchemaKey> keys;
  collect_keys(case_schema(), "", keys);
  return keys;
}

}  // namespace caplab::cases
