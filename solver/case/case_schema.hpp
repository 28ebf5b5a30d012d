// The case-file format as data: which keys each object allows or requires, the type, range
// or allowed strings of each value, and which keys depend on another value. One generic
// walker checks a document against it, and the same description resolves the dotted paths
// of fidelity levels and `--set` overrides, so the format is written down exactly once in
// C++ (catalogue/schema.json publishes it; a unit test keeps the two in agreement).
//
// What the description cannot say — lengths that depend on the dimension, and geometric
// consistency — is checked in case_consistency.cpp, after this pass.
//
// Invariant: after check_against(case_schema(), doc) and check_conditional_keys(doc) pass,
// every value the loader reads exists and has the expected type, and every number is finite.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "case/case_diagnostics.hpp"

namespace caplab::cases {

enum class ValueKind {
  object,   ///< fixed set of keys (SchemaNode::members)
  map,      ///< free keys, each value described by SchemaNode::element (e.g. tolerance per fidelity)
  array,    ///< entries described by SchemaNode::element
  number,   ///< finite number, within SchemaNode::range
  integer,  ///< integer, within SchemaNode::range
  string,   ///< non-empty string; one of SchemaNode::choices when those are given
  any       ///< not checked here (fidelity entries: checked where they are applied)
};

/// An interval of allowed numbers; open or closed at either end.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  bool contains(double x) const;
  /// "> 0", ">= 1", "in (0, 0.4]"; empty when unbounded.
  std::string text() const;
};

struct SchemaMember;

/// One value of the format.
struct SchemaNode {
  ValueKind kind = ValueKind::any;
  std::vector<SchemaMember> members;  ///< object: keys in the order they are checked
  std::vector<SchemaNode> element;    ///< array / map: exactly one entry, the entries' format
  std::vector<std::string> choices;   ///< string: allowed values (empty: any non-empty string)
  Range range;                        ///< number / integer
  bool per_axis = false;              ///< array: one entry per spatial dimension

  /// What a value of this node must be, in words ("a number > 0", "one of ...").
  std::string expected() const;
  const SchemaMember* member(std::string_view key) const;
  std::vector<std::string> member_keys() const;
};

struct SchemaMember {
  std::string key;
  bool required = true;
  SchemaNode node;
};

/// The case-file format (DESIGN.md section 5).
const SchemaNode& case_schema();

/// Checks `value` (found at JSON pointer `pointer`) against `node`, recursively; throws
/// core::InputError at the first problem. The pointers of arrays marked per_axis are appended
/// to `per_axis` so that the caller can check their length once the dimension is known.
void check_against(const SchemaNode& node, const nlohmann::json& value, const std::string& pointer,
                   const CaseDiagnostics& diag, std::vector<std::string>& per_axis);

/// Checks the keys whose presence depends on another value (e.g. `fine_region` is required for
/// two_level refinement and rejected for uniform). Requires a document that passed check_against.
void check_conditional_keys(const nlohmann::json& doc, const CaseDiagnostics& diag);

/// Writes `value` at the dotted path `dotted` ("numerics.grid.fine_spacing", array entries by
/// index: "physics.bodies.0.shape.center.1"), creating optional objects on the way. Every
/// segment must exist in the schema; array indices must exist in `doc`. `label` is how the
/// override appears in messages; errors are reported at `site` (the override's own place in
/// the file) or, when `site` is empty, at the path being set. Returns the JSON pointer written.
std::string apply_override(nlohmann::json& doc, std::string_view dotted, nlohmann::json value,
                           const std::string& label, const std::string& site, const CaseDiagnostics& diag);

/// One key of the format, for comparing with catalogue/schema.json: dotted path with "*" for
/// array entries, whether the object requires it, and its allowed strings (or those of its entries).
struct SchemaKey {
  std::string path;
  bool required = true;
  std::vector<std::string> choices;
};

/// Every key of the format, depth first (free-key maps are not entered).
std::vector<SchemaKey> schema_keys();

}  // namespace caplab::cases
