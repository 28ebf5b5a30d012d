// Error reporting for case files (see case_diagnostics.hpp).
#include "case/case_diagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.hpp"

namespace caplab::cases {
namespace {

// True when pointer `a` equals `b` or one lies inside the other (segment-wise prefix).
bool related(const std::string& a, const std::string& b) {
  auto inside = [](const std::string& inner, const std::string& outer) {
    return inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
           inner[outer.size()] == '/';
  };
  return a == b || inside(a, b) || inside(b, a);
}

// Levenshtein distance, case-insensitive (keys are lower case; users type anything).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  auto lower = [](char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c); };
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), std::size_t{0});
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t substitute = diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      row[j] = std::min({above + 1, row[j - 1] + 1, substitute});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

void CaseDiagnostics::note_origin(std::string pointer, std::string origin) {
  origins_.emplace_back(std::move(pointer), std::move(origin));
}

void CaseDiagnostics::fail(const std::string& pointer, const nlohmann::json& value,
                           const std::string& expected) const {
  fail_text(pointer, describe(value), expected);
}

void CaseDiagnostics::fail_text(const std::string& pointer, std::string value_text,
                                const std::string& expected) const {
  for (auto it = origins_.rbegin(); it != origins_.rend(); ++it) {
    if (related(pointer, it->first)) {
      value_text += " (set by " + it->second + ")";
      break;
    }
  }
  throw core::InputError(source_, pointer, std::move(value_text), expected);
}

std::string child_pointer(const std::string& pointer, std::string_view key) {
  std::string escaped;
  for (char c : key) {
    if (c == '~')
      escaped += "~0";
    else if (c == '/')
      escaped += "~1";
    else
      escaped += c;
  }
  return pointer + "/" + escaped;
}

std::string child_pointer(const std::string& pointer, std::size_t index) {
  return pointer + "/" + std::to_string(index);
}

std::string describe(const nlohmann::json& value) {
  constexpr std::size_t max_length = 80;
  // Non-finite numbers only reach here from programmatic documents; nlohmann writes them as null.
  if (value.is_number_float() && !std::isfinite(value.get<double>()))
    return std::to_string(value.get<double>());
  std::string text = value.is_discarded() ? "nothing" : value.dump();
  if (text.size() > max_length) text = text.substr(0, max_length - 3) + "...";
  return text;
}

std::string quoted_list(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "\"" : ", \"") + w + "\"";
  return out;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates) {
  const std::string* best = nullptr;
  std::size_t best_distance = 0;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (best == nullptr || d < best_distance) {
      best = &c;
      best_distance = d;
    }
  }
  // A plausible typo: at most a third of the longer word changed (and at least 2 edits allowed).
  const std::size_t limit = best ? std::max<std::size_t>(2, std::max(word.size(), best->size()) / 3) : 0;
  if (best == nullptr || best_distance > limit) return "";
  return " (did you mean \"" + *best + "\"?)";
}

}  // namespace caplab::cases
