// Reading the files of a run directory for scoring: the JSON files (content, or why they could
// not be read) and the value of a summary.json metric. Shared by score_run and claims.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

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

}  // namespace caplab::score
