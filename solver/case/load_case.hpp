// Case files -> validated CaseSpec (DESIGN.md section 5).
//
// Pipeline: read and parse the JSON (rejecting malformed text with line and column, and
// duplicate keys) -> apply the chosen fidelity level -> apply the `--set` overrides in order
// -> check the document against the case format (case_schema.hpp: keys, types, ranges,
// enumerations, keys that depend on another value) -> check per-axis lengths -> convert to
// CaseSpec -> check cross-value consistency (case_consistency.hpp) -> normalise and record
// defaults in CaseSpec::resolved.
//
// Every rejection is a core::InputError naming the file, the JSON pointer, the offending value
// (and the override that set it, if any) and what is expected. Nothing is read from JSON
// after this module: the rest of caplab sees only CaseSpec.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "case/case_spec.hpp"

namespace caplab::cases {

/// Reads `file`, applies fidelity level `fidelity` (the object at "fidelity"/<level>: a map
/// from dotted path to value, applied as overrides), then each override "a.b.c=value" (value
/// parsed as JSON if it parses, else taken as a string; array entries addressed as a.b.0),
/// validates, and returns the spec. Throws core::InputError naming the file, the JSON path
/// (JSON-pointer style, e.g. /physics/reynolds), the bad value and what is expected (and, for
/// unknown keys, the closest known key as a "did you mean").
CaseSpec load_case(const std::filesystem::path& file, const std::string& fidelity = "standard",
                   const std::vector<std::string>& overrides = {});

/// As load_case, for a document already in memory; `source_name` stands for the file in messages.
CaseSpec parse_case(const nlohmann::json& doc, const std::string& source_name, const std::string& fidelity,
                    const std::vector<std::string>& overrides);

/// As load_case, for the text of a case file already in memory (one code path with load_case:
/// parse_case_text, then parse_case); `source_name` stands for the file in messages.
CaseSpec load_case_text(std::string_view text, const std::string& source_name,
                        const std::string& fidelity = "standard",
                        const std::vector<std::string>& overrides = {});

/// Case files larger than this are refused unread (the catalogue's largest is about 10 kB).
inline constexpr std::uintmax_t max_case_file_bytes = std::uintmax_t{16} << 20;
/// Objects and arrays nested deeper than this are refused while parsing (the format needs 8).
inline constexpr std::size_t max_case_nesting = 64;

/// Reads and parses a case file without validating it; throws core::InputError for a missing
/// file, a directory or other non-regular file, a file over max_case_file_bytes, and whatever
/// parse_case_text rejects.
nlohmann::json read_case_json(const std::filesystem::path& file);

/// Parses the text of a case file without validating it; throws core::InputError for empty
/// text, malformed JSON (with line and column and the JSON path where the parser stopped,
/// e.g. for NaN, Infinity or a number too large for a double such as 1e999), ill-formed UTF-8,
/// nesting deeper than max_case_nesting, or a key repeated within one object.
nlohmann::json parse_case_text(std::string_view text, const std::string& source_name);

/// Lists the fidelity levels a case defines (names sorted); throws core::InputError when the
/// file cannot be read or has no valid "fidelity" object.
std::vector<std::string> fidelity_levels(const std::filesystem::path& file);
/// As above, for a document already in memory.
std::vector<std::string> fidelity_levels(const nlohmann::json& doc, const std::string& source_name);

}  // namespace caplab::cases
