#include "score/run_files.hpp"

#include <cmath>
#include <fstream>
#include <system_error>

namespace caplab::score {

namespace fs = std::filesystem;
using nlohmann::json;

JsonFile read_json(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return {std::nullopt, file.filename().string() + " is missing"};
  std::ifstream in(file);
  json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return {std::nullopt, file.filename().string() + " is not valid JSON"};
  if (!doc.is_object()) return {std::nullopt, file.filename().string() + " is not a JSON object"};
  return {std::move(doc), ""};
}

const json& metric_json(const json& metric) {
  return metric.is_object() && metric.contains("value") ? metric["value"] : metric;
}

const nlohmann::json& member(const nlohmann::json& object, const char* key) {
  static const nlohmann::json null;
  return object.is_object() && object.contains(key) ? object[key] : null;
}

bool finite(const nlohmann::json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

std::string join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

}  // namespace caplab::score
