// The terminal scorecard; see scorecard.hpp.
#include "score/scorecard.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

namespace caplab::score {

using json = nlohmann::json;

namespace {

const json& field(const json& j, const char* key) {
  static const json null_value;  // immutable: a shared "absent" value, not configuration
  return j.is_object() && j.contains(key) ? j[key] : null_value;
}

std::string text(const json& j) {
  if (j.is_string()) return j.get<std::string>();
  if (j.is_number_integer() || j.is_number_unsigned()) return j.dump();
  if (j.is_number()) return fmt::format("{:.6g}", j.get<double>());
  if (j.is_null()) return "-";
  if (j.is_array() && j.size() == 2) return fmt::format("[{}, {}]", text(j[0]), text(j[1]));
  return j.dump();
}

/// The reference of a mode entry: one name, or the allowed names joined by " or ".
std::string modes_text(const json& j) {
  if (!j.is_array() || j.empty()) return text(j);
  std::string out;
  for (const auto& m : j) out += (out.empty() ? "" : " or ") + text(m);
  return out;
}

std::string percent_or_text(const json& j, bool relative) {
  if (relative && j.is_number()) return fmt::format("{:.3g}%", 100.0 * j.get<double>());
  return text(j);
}

}  // namespace

std::string format_scorecard(const json& score) {
  std::string out = fmt::format("score  {}  (fidelity {})\n", text(field(score, "case_id")),
                                text(field(score, "fidelity")));

  const json& sanity = field(score, "sanity");
  out += fmt::format("sanity: {}\n", text(field(sanity, "verdict")));
  const json& checks = field(sanity, "checks");
  if (checks.is_array())
    for (const auto& c : checks)
      if (field(c, "verdict") != "pass")
        out += fmt::format("  FAIL {}: {}\n", text(field(c, "name")), text(field(c, "message")));

  const json& accuracy = field(score, "accuracy");
  out += fmt::format("accuracy: {}", text(field(accuracy, "verdict")));
  if (field(accuracy, "reason").is_string())
    out += fmt::format(" ({})", field(accuracy, "reason").get<std::string>());
  out += "\n";

  const json& entries = field(accuracy, "entries");
  if (entries.is_array() && !entries.empty()) {
    const std::vector<std::string> header = {"metric", "value", "reference", "error", "tolerance", "verdict"};
    std::vector<std::vector<std::string>> rows;
    for (const auto& e : entries) {
      const bool relative = field(e, "comparison") == "relative";
      std::string value = text(field(e, "value"));
      if (field(e, "unit").is_string() && field(e, "value").is_number() && field(e, "unit") != "1")
        value += fmt::format(" {}", field(e, "unit").get<std::string>());
      std::string reference =
          field(e, "comparison") == "time_series" ? "series" : text(field(e, "reference_value"));
      if (field(e, "comparison") == "mode") reference = modes_text(field(e, "reference_value"));
      rows.push_back({text(field(e, "metric")), value, reference,
                      percent_or_text(field(e, "error"), relative),
                      percent_or_text(field(e, "tolerance"), relative), text(field(e, "verdict"))});
    }
    std::vector<std::size_t> width(header.size());
    for (std::size_t i = 0; i < header.size(); ++i) {
      width[i] = header[i].size();
      for (const auto& r : rows) width[i] = std::max(width[i], r[i].size());
    }
    auto line = [&](const std::vector<std::string>& cells) {
      std::string l = " ";
      for (std::size_t i = 0; i < cells.size(); ++i)
        l += " " + cells[i] + std::string(width[i] - cells[i].size() + (i + 1 < cells.size() ? 1 : 0), ' ');
      while (!l.empty() && l.back() == ' ') l.pop_back();
      return l + "\n";
    };
    out += line(header);
    for (const auto& r : rows) out += line(r);
    for (const auto& e : entries)
      if (field(e, "message").is_string())
        out += fmt::format("  {}: {}\n", text(field(e, "metric")), field(e, "message").get<std::string>());
  }

  const json& perf = field(score, "performance");
  out += fmt::format("performance: {} ({}); {} MLUPS, {} steps\n", text(field(perf, "verdict")),
                     text(field(perf, "reason")), text(field(perf, "mlups")), text(field(perf, "steps")));
  out += fmt::format("verdict: {}\n", text(field(score, "verdict")));
  return out;
}

}  // namespace caplab::score
