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
  std::string text =
      value.is_discarded() ? "nothing" : value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > max_length) text = printable(text, max_length);
  return text;
}

namespace {

// Length of the UTF-8 sequence starting at text[i], or 0 when it is ill-formed there.
std::size_t utf8_sequence(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b = byte(i);
  if (b < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (b >= 0xC2 && b <= 0xDF)
    n = 2;
  else if (b == 0xE0)
    n = 3, lo = 0xA0;
  else if (b == 0xED)
    n = 3, hi = 0x9F;  // no UTF-16 surrogates
  else if (b >= 0xE1 && b <= 0xEF)
    n = 3;
  else if (b == 0xF0)
    n = 4, lo = 0x90;
  else if (b >= 0xF1 && b <= 0xF3)
    n = 4;
  else if (b == 0xF4)
    n = 4, hi = 0x8F;
  else
    return 0;
  if (i + n > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}

}  // namespace

bool is_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence(text, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

std::string printable(std::string_view text, std::size_t max_length) {
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  std::size_t fits = 0;  // length of `out` up to the last piece that leaves room for "..."
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = utf8_sequence(text, i);
    const auto b = static_cast<unsigned char>(text[i]);
    if (n == 0 || b < 0x20 || b == 0x7F)
      out += {'\\', 'x', hex[b >> 4], hex[b & 15]};
    else
      out.append(text.substr(i, n));
    i += n == 0 ? 1 : n;
    if (out.size() + 3 <= max_length) fits = out.size();
    if (out.size() > max_length) break;
  }
  if (out.size() > max_length) out.resize(fits), out += "...";
  return out;
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
