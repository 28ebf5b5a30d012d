#include "io/compare_runs.hpp"

#include <hdf5.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace caplab::io {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kProblemsPerFile = 5;

/// Every dataset of an HDF5 file, read as doubles, by path.
std::map<std::string, std::vector<double>> read_datasets(const fs::path& file) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t h5 = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (h5 < 0) throw core::Error("compare: cannot open '" + file.string() + "'");
  std::map<std::string, std::vector<double>> out;
  auto visit = [](hid_t obj, const char* name, const H5O_info_t* info, void* data) -> herr_t {
    if (info->type != H5O_TYPE_DATASET) return 0;
    auto& sets = *static_cast<std::map<std::string, std::vector<double>>*>(data);
    const hid_t ds = H5Dopen2(obj, name, H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    const herr_t rc = v.empty() ? 0 : H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(space);
    H5Dclose(ds);
    if (rc < 0) return -1;
    sets[std::string("/") + name] = std::move(v);
    return 0;
  };
  const herr_t rc = H5Ovisit(h5, H5_INDEX_NAME, H5_ITER_NATIVE, visit, &out);
  H5Fclose(h5);
  if (rc < 0) throw core::Error("compare: cannot read the datasets of '" + file.string() + "'");
  return out;
}

class Comparer {
 public:
  explicit Comparer(double tolerance) : tolerance_(tolerance) {}

  void values(const std::string& where, double a, double b) {
    ++r_.values;
    if (a == b || (std::isnan(a) && std::isnan(b))) return;
    ++r_.differing;
    const double rel = std::abs(a - b) / std::max(std::abs(a), std::abs(b));
    if (!(rel <= r_.max_relative)) r_.max_relative = rel, r_.worst = where;
    if (!(rel <= tolerance_)) problem(fmt::format("{}: {:.17g} against {:.17g} (relative {:.3g})", where, a, b, rel));
  }

  void problem(const std::string& text) {
    if (++in_file_ <= kProblemsPerFile) r_.problems.push_back(text);
  }

  void hdf5_file(const fs::path& a, const fs::path& b, const std::string& name) {
    in_file_ = 0;
    const auto A = read_datasets(a), B = read_datasets(b);
    for (const auto& [path, va] : A) {
      const auto it = B.find(path);
      if (it == B.end()) {
        problem(fmt::format("{}:{} only in the first run", name, path));
        continue;
      }
      if (it->second.size() != va.size()) {
        problem(fmt::format("{}:{} has {} values against {}", name, path, va.size(), it->second.size()));
        continue;
      }
      for (std::size_t k = 0; k < va.size(); ++k) values(fmt::format("{}:{}[{}]", name, path, k), va[k], it->second[k]);
    }
    for (const auto& [path, vb] : B)
      if (!A.count(path)) problem(fmt::format("{}:{} only in the second run", name, path));
  }

  void json_value(const std::string& where, const nlohmann::json& a, const nlohmann::json& b) {
    if (a.is_number() && b.is_number()) return values(where, a.get<double>(), b.get<double>());
    if (a.type() != b.type()) return problem(where + ": of another type");
    if (a.is_object()) {
      for (const auto& [k, v] : a.items()) {
        if (!b.contains(k)) {
          problem(where + "/" + k + " only in the first run");
          continue;
        }
        json_value(where + "/" + k, v, b.at(k));
      }
      for (const auto& [k, v] : b.items())
        if (!a.contains(k)) problem(where + "/" + k + " only in the second run");
    } else if (a.is_array()) {
      if (a.size() != b.size()) return problem(where + ": arrays of different lengths");
      for (std::size_t k = 0; k < a.size(); ++k) json_value(fmt::format("{}/{}", where, k), a[k], b[k]);
    } else if (a != b) {
      problem(where + ": " + a.dump() + " against " + b.dump());
    }
  }

  void json_file(const fs::path& a, const fs::path& b, const std::string& name) {
    in_file_ = 0;
    auto read = [](const fs::path& p) {
      std::ifstream in(p);
      if (!in) throw core::Error("compare: cannot read '" + p.string() + "'");
      return nlohmann::json::parse(in);
    };
    json_value(name + ":", read(a), read(b));
  }

  RunComparison result() const { return r_; }

 private:
  double tolerance_;
  RunComparison r_;
  std::size_t in_file_ = 0;
};

}  // namespace

RunComparison compare_runs(const fs::path& a, const fs::path& b, double relative_tolerance) {
  Comparer c(relative_tolerance);
  c.hdf5_file(a / "series.h5", b / "series.h5", "series.h5");
  std::error_code ec;
  const bool snap_a = fs::exists(a / "snapshots.h5", ec), snap_b = fs::exists(b / "snapshots.h5", ec);
  if (snap_a && snap_b)
    c.hdf5_file(a / "snapshots.h5", b / "snapshots.h5", "snapshots.h5");
  else if (snap_a != snap_b)
    c.problem("snapshots.h5 exists in only one of the runs");
  c.json_file(a / "summary.json", b / "summary.json", "summary.json");
  return c.result();
}

}  // namespace caplab::io
