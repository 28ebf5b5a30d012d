// Reading the files of a run directory for scoring: the JSON files (content, or why they could
// not be read), the value of a summary.json metric and small JSON accessors. Shared by score_run,
// claims and motion_claims.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace caplab::score {

/// A JSON file of the run directory: its content, or why it could not be read.
struct JsonFile {
  std::optional<nlohmann::json> doc;
  std::string problem;
};

/// Reads `file` as a JSON object; never throws.
JsonFile read_json(const std::filesystem::path& file);

/// The value of a summary.json metric: `x` of {"value": x, ...}, or the metric itself.
const nlohmann::json& metric_json(const nlohmann::json& metric);

/// `object[key]`, or null when `object` is not an object or lacks the key (never throws).
const nlohmann::json& member(const nlohmann::json& object, const char* key);

/// True for a JSON number that is finite.
bool finite(const nlohmann::json& v);

/// `parts` joined with `separator`.
std::string join(const std::vector<std::string>& parts, const char* separator);

}  // namespace caplab::score
