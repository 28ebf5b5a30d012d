// Reference series for time-series acceptance entries; see reference_series.hpp.
#include "score/reference_series.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "core/error.hpp"

namespace caplab::score {

namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\"");
  if (first == std::string::npos) return "";
  const auto last = s.find_last_not_of(" \t\r\"");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    fields.push_back(
        trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

ReferenceLocation split_reference(const std::string& reference) {
  const auto hash = reference.rfind('#');
  if (hash == std::string::npos) return {reference, ""};
  return {reference.substr(0, hash), reference.substr(hash + 1)};
}

fs::path resolve_reference_file(const std::string& file, const fs::path& run_dir,
                                const fs::path& reference_root) {
  std::error_code ec;
  const fs::path rel(file);
  if (rel.is_absolute()) {
    if (fs::is_regular_file(rel, ec)) return rel;
    throw core::InputError("reference file '" + file + "' does not exist");
  }
  std::vector<fs::path> candidates;
  if (!reference_root.empty()) {
    candidates.push_back(reference_root / rel);
  } else {
    for (fs::path dir = fs::absolute(run_dir, ec); !dir.empty(); dir = dir.parent_path()) {
      candidates.push_back(dir / rel);
      if (dir == dir.root_path()) break;
    }
    candidates.push_back(fs::current_path(ec) / rel);
  }
  for (const auto& c : candidates)
    if (fs::is_regular_file(c, ec)) return c;
  std::string looked;
  for (const auto& c : candidates) looked += (looked.empty() ? "" : ", ") + c.string();
  throw core::InputError("reference file '" + file + "' not found (looked at: " + looked +
                         "); run from the repository root or pass the reference root");
}

Series read_reference_series(const fs::path& file, const std::string& t_column,
                             const std::string& value_column) {
  std::ifstream in(file);
  if (!in) throw core::InputError("cannot read reference file '" + file.string() + "'");
  std::vector<std::string> header;
  std::size_t it = 0, iy = 1;
  Series s;
  std::string line;
  for (std::size_t line_no = 1; std::getline(in, line); ++line_no) {
    const std::string stripped = trim(line);
    if (stripped.empty() || stripped[0] == '#') continue;
    std::vector<std::string> fields = split_fields(line);
    if (header.empty()) {
      header = std::move(fields);
      auto find = [&](const std::string& name, std::size_t fallback) {
        if (name.empty()) return fallback;
        for (std::size_t i = 0; i < header.size(); ++i)
          if (header[i] == name) return i;
        throw core::InputError(fmt::format("reference file '{}' has no column '{}' (columns: {})",
                                           file.string(), name, joined(header)));
      };
      it = find(t_column, 0);
      iy = find(value_column, 1);
      if (std::max(it, iy) >= header.size())
        throw core::InputError(fmt::format("reference file '{}' needs at least two columns (columns: {})",
                                           file.string(), joined(header)));
      continue;
    }
    auto number = [&](std::size_t i) {
      const std::string& f = i < fields.size() ? fields[i] : std::string();
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(f.c_str(), &end);
      if (f.empty() || end != f.c_str() + f.size() || errno == ERANGE)
        throw core::InputError(
            fmt::format("reference file '{}' line {}: column '{}' is '{}', expected a number", file.string(),
                        line_no, header[i], f));
      return v;
    };
    s.t.push_back(number(it));
    s.y.push_back(number(iy));
  }
  if (header.empty()) throw core::InputError("reference file '" + file.string() + "' has no header line");
  return s;
}

}  // namespace caplab::score
