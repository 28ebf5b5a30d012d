// Thesis statements about moving rigid bodies; see motion_claims.hpp for the checks and the layout.
#include "score/motion_claims.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <regex>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "io/series_writer.hpp"
#include "score/comparators.hpp"
#include "score/run_files.hpp"

namespace caplab::score {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A check that cannot be evaluated as written (claims.json is wrong, not the runs).
struct Malformed : std::runtime_error {
  using std::runtime_error::runtime_error;
};



std::string text_or(const json& v, const std::string& fallback) {
  return v.is_string() ? v.get<std::string>() : fallback;
}


/// "12.34 %" of a fraction; "–" when it is not finite.
std::string pct(double x) { return std::isfinite(x) ? fmt::format("{:.2f} %", 100 * x) : "–"; }

/// `x` with `digits` significant digits; "–" when it is not finite.
std::string num(double x, int digits = 4) {
  return std::isfinite(x) ? fmt::format("{:.{}g}", x, digits) : "–";
}

/// "upper.drag_coefficient" -> "upper C_d".
std::string symbol(const std::string& column) {
  const auto dot = column.rfind('.');
  const std::string body = dot == std::string::npos ? "" : column.substr(0, dot);
  const std::string quantity = dot == std::string::npos ? column : column.substr(dot + 1);
  const std::string sym = quantity == "drag_coefficient"   ? "C_d"
                          : quantity == "lift_coefficient" ? "C_l"
                                                           : quantity;
  return (body.empty() ? "" : body + " ") + sym;
}

// ---- the case and the manifest -----------------------------------------------------------------

const json& grid_of(const json& case_doc) { return member(member(case_doc, "numerics"), "grid"); }

std::string grid_refinement(const ClaimRun& run) {
  const json& r = member(grid_of(run.case_doc), "refinement");
  return r.is_string() ? r.get<std::string>() : "";
}

/// numerics.grid.fine_spacing when finite and positive.
std::optional<double> fine_spacing(const ClaimRun& run) {
  const json& s = member(grid_of(run.case_doc), "fine_spacing");
  if (!finite(s) || s.get<double>() <= 0) return std::nullopt;
  return s.get<double>();
}

bool close(double a, double b, double rel) {
  return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b));
}

/// The uniform-grid twin of a two-level run among `runs` (motion_claims.hpp), or null.
ClaimRun* twin_of(const ClaimRun& run, std::vector<ClaimRun>& runs) {
  const auto spacing = fine_spacing(run);
  if (grid_refinement(run) != "two_level" || !spacing) return nullptr;
  const json& physics = member(run.case_doc, "physics");
  std::vector<ClaimRun*> found;
  for (auto& r : runs) {
    const auto s = fine_spacing(r);
    if (&r != &run && r.fidelity == run.fidelity && grid_refinement(r) == "uniform" &&
        member(r.case_doc, "physics") == physics && s && close(*s, *spacing, 1e-9))
      found.push_back(&r);
  }
  if (found.empty()) return nullptr;
  const std::string named = run.case_id + "_uniform";
  return *std::min_element(found.begin(), found.end(), [&](const ClaimRun* a, const ClaimRun* b) {
    return std::make_tuple(a->status != "ok", a->case_id != named, a->case_id) <
           std::make_tuple(b->status != "ok", b->case_id != named, b->case_id);
  });
}

/// Keys of numerics other than grid and threads in which the two runs differ, sorted.
std::vector<std::string> numerics_differences(const ClaimRun& a, const ClaimRun& b) {
  const json &na = member(a.case_doc, "numerics"), &nb = member(b.case_doc, "numerics");
  std::set<std::string> keys;
  for (const json* n : {&na, &nb})
    if (n->is_object())
      for (const auto& [k, v] : n->items()) keys.insert(k);
  std::vector<std::string> out;
  for (const auto& k : keys)
    if (k != "grid" && k != "threads" && member(na, k.c_str()) != member(nb, k.c_str())) out.push_back(k);
  return out;
}

/// Area of numerics.grid.fine_region over that of physics.domain.size.
std::optional<double> fine_fraction(const json& case_doc) {
  const json& region = member(grid_of(case_doc), "fine_region");
  const json &size = member(member(member(case_doc, "physics"), "domain"), "size"),
             &lo = member(region, "min"), &hi = member(region, "max");
  if (!size.is_array() || !lo.is_array() || !hi.is_array() || size.size() != lo.size() ||
      size.size() != hi.size())
    return std::nullopt;
  double domain = 1, fine = 1;
  for (std::size_t i = 0; i < size.size(); ++i) {
    if (!finite(size[i]) || !finite(lo[i]) || !finite(hi[i])) return std::nullopt;
    domain *= size[i].get<double>();
    fine *= hi[i].get<double>() - lo[i].get<double>();
  }
  if (!(domain > 0)) return std::nullopt;
  return fine / domain;
}

/// Extent of the fine block's nodes over the coarse block's (manifest lattice.blocks).
std::optional<double> built_fine_fraction(const json& manifest) {
  const json& blocks = member(member(manifest, "lattice"), "blocks");
  json fine, coarse;  // the last block of each name, as a lookup by name would find it
  if (blocks.is_array())
    for (const auto& b : blocks) {
      if (member(b, "name") == "fine") fine = b;
      if (member(b, "name") == "coarse") coarse = b;
    }
  if (fine.is_null() || coarse.is_null()) return std::nullopt;
  auto area = [](const json& b) {
    const json &nodes = member(b, "nodes"), &dx = member(b, "dx");
    if (!nodes.is_array() || !finite(dx)) return kNaN;
    double a = 1;
    for (const auto& n : nodes) a *= finite(n) ? (n.get<double>() - 1) * dx.get<double>() : kNaN;
    return a;
  };
  const double a_fine = area(fine), a_coarse = area(coarse);
  if (!std::isfinite(a_fine) || !std::isfinite(a_coarse) || !(a_coarse > 0)) return std::nullopt;
  return a_fine / a_coarse;
}

/// The number at `key` of the manifest's lattice, or NaN.
double node_updates(const ClaimRun& run) {
  const json& v = member(member(run.manifest, "lattice"), "node_updates");
  return finite(v) ? v.get<double>() : kNaN;
}

/// wall_time_s of score.json "performance", else of the manifest; NaN if neither.
double wall_time(const ClaimRun& run) {
  const json& scored = member(member(run.score, "performance"), "wall_time_s");
  const json& v = scored.is_null() ? member(run.manifest, "wall_time_s") : scored;
  return finite(v) ? v.get<double>() : kNaN;
}

std::string threads(const ClaimRun& run) {
  const json& t = member(run.manifest, "threads");
  const json& v = t.is_null() ? member(member(run.manifest, "environment"), "threads") : t;
  return v.is_null() ? "–" : v.is_string() ? v.get<std::string>() : v.dump();
}

/// b / a when both are finite and a > 0, else NaN (twin over two-block: "ratio").
double ratio(double a, double b) { return std::isfinite(a) && std::isfinite(b) && a > 0 ? b / a : kNaN; }

/// 1 − 1/ratio, NaN unless ratio is finite and positive.
double saving(double r) { return std::isfinite(r) && r > 0 ? 1.0 - 1.0 / r : kNaN; }

// ---- series ------------------------------------------------------------------------------------

const std::map<std::string, std::vector<double>>& series_of(ClaimRun& run) {
  if (run.series) return *run.series;
  run.series.emplace();
  const fs::path file = run.dir / "series.h5";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    run.series_problem = "no series.h5";
    return *run.series;
  }
  try {
    auto all = io::read_series(file);
    const auto t = all.find("t");
    if (t == all.end()) {
      run.series_problem = "series.h5 has no column t";
      return *run.series;
    }
    const std::size_t rows = t->second.size();
    for (auto& [name, values] : all)
      if (values.size() == rows) run.series->emplace(name, std::move(values));
  } catch (const std::exception& e) {
    run.series->clear();
    run.series_problem = std::string("series.h5 unreadable: ") + e.what();
  }
  return *run.series;
}

/// Why `columns` (and "t") cannot be read from the run's series, or "".
std::string column_problem(ClaimRun& run, const std::vector<std::string>& columns) {
  const auto& data = series_of(run);
  if (data.empty()) return run.series_problem;
  std::vector<std::string> missing;
  for (const auto& c : columns)
    if (!data.count(c)) missing.push_back(c);
  return missing.empty() ? "" : "series.h5 has no column " + join(missing, ", ");
}

// ---- windows of the relative position ----------------------------------------------------------

/// An interval of dx: lo < x < hi with each end open or closed.
struct Interval {
  double lo = 0, hi = 0;
  bool lo_open = false, hi_open = false;

  bool contains(double x) const { return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi); }
  std::string text() const {
    return fmt::format("{:g} {} dx {} {:g}", lo, lo_open ? "<" : "≤", hi_open ? "<" : "≤", hi);
  }
};

/// "(0, 3]" -> 0 < x <= 3; throws Malformed for anything else.
Interval parse_interval(const json& spec) {
  static const std::regex pattern(R"(^\s*([\[(])\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*([\])])\s*$)");
  const std::string text = spec.is_string() ? spec.get<std::string>() : spec.dump();
  std::smatch m;
  auto number = [&](const std::string& s) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size()) throw Malformed(fmt::format("not an interval: '{}'", text));
    return v;
  };
  if (!std::regex_match(text, m, pattern))
    throw Malformed(fmt::format("not an interval: '{}' (expected e.g. \"(0, 3]\")", text));
  Interval i{number(m[2]), number(m[3]), m[1] == "(", m[4] == ")"};
  if (!(i.lo < i.hi)) throw Malformed(fmt::format("empty interval: '{}'", text));
  return i;
}

/// The time at which dx first changes sign (linear interpolation), if it does.
std::optional<double> encounter_time(const std::vector<double>& t_all, const std::vector<double>& dx_all) {
  std::vector<double> t, dx;
  for (std::size_t i = 0; i < t_all.size(); ++i)
    if (std::isfinite(t_all[i]) && std::isfinite(dx_all[i])) {
      t.push_back(t_all[i]);
      dx.push_back(dx_all[i]);
    }
  auto sign = [](double v) { return (v > 0) - (v < 0); };
  std::size_t first = 0;
  while (first < dx.size() && dx[first] == 0) ++first;
  if (first == dx.size()) return std::nullopt;
  for (std::size_t i = first + 1; i < dx.size(); ++i) {
    if (sign(dx[i]) == sign(dx[first])) continue;
    if (dx[i] == 0) return t[i];
    return t[i - 1] + (t[i] - t[i - 1]) * dx[i - 1] / (dx[i - 1] - dx[i]);
  }
  return std::nullopt;
}

/// Sum of `v` in numpy's pairwise order (blocks of eight partial sums below 128 values, halves
/// above), so that a window mean equal to the baseline's compares equal here as in the report.
double pairwise_sum(const double* v, std::size_t n) {
  if (n < 8) {
    double s = 0;
    for (std::size_t i = 0; i < n; ++i) s += v[i];
    return s;
  }
  if (n <= 128) {
    double r[8];
    for (std::size_t j = 0; j < 8; ++j) r[j] = v[j];
    std::size_t i = 8;
    for (; i < n - n % 8; i += 8)
      for (std::size_t j = 0; j < 8; ++j) r[j] += v[i + j];
    double s = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; ++i) s += v[i];
    return s;
  }
  std::size_t half = n / 2;
  half -= half % 8;
  return pairwise_sum(v, half) + pairwise_sum(v + half, n - half);
}

double mean(const std::vector<double>& v) {
  return pairwise_sum(v.data(), v.size()) / static_cast<double>(v.size());
}

/// dx/dt: second-order differences inside (non-uniform spacing), first order at the ends.
std::vector<double> gradient(const std::vector<double>& x, const std::vector<double>& t) {
  const std::size_t n = t.size();
  std::vector<double> g(n, 0.0);
  if (n < 2) return g;
  g[0] = (x[1] - x[0]) / (t[1] - t[0]);
  g[n - 1] = (x[n - 1] - x[n - 2]) / (t[n - 1] - t[n - 2]);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double h1 = t[i] - t[i - 1], h2 = t[i + 1] - t[i];
    g[i] =
        -h2 / (h1 * (h1 + h2)) * x[i - 1] + (h2 - h1) / (h1 * h2) * x[i] + h1 / (h2 * (h1 + h2)) * x[i + 1];
  }
  return g;
}

struct WindowMean {
  std::string name;
  Interval interval;
  std::string phase;
  std::string expect;  // "above" | "below"; "" for the baseline (or a window that is only shown)
  std::optional<double> mean;
  std::size_t samples = 0;
  double t_first = kNaN, t_last = kNaN;
  double peak = kNaN, peak_dx = kNaN, trough = kNaN, trough_dx = kNaN;
  std::optional<bool> ok;

  std::string text() const { return interval.text() + ", " + phase; }
};

WindowMean window_of(const json& spec, const std::string& name) {
  const json& phase = member(spec, "phase");
  if (phase != "approaching" && phase != "separating")
    throw Malformed(
        fmt::format("window {}: phase must be approaching or separating (got {})", name, phase.dump()));
  const json& expect = member(spec, "expect");
  if (!expect.is_null() && expect != "above" && expect != "below")
    throw Malformed(fmt::format("window {}: expect must be above or below (got {})", name, expect.dump()));
  WindowMean w;
  w.name = name;
  w.interval = parse_interval(spec.is_object() && spec.contains("dx") ? spec["dx"] : json(""));
  w.phase = phase.get<std::string>();
  w.expect = text_or(expect, "");
  return w;
}

/// The drag-trend check on one run.
struct Proximity {
  WindowMean baseline;
  std::vector<WindowMean> windows;
  double sign = 1.0;  // C_d times this opposes the body's motion
  std::optional<double> encounter;
  std::string problem;

  std::optional<bool> ok() const {
    if (!problem.empty()) return std::nullopt;
    bool all = true;
    for (const auto& w : windows) {
      if (!w.ok) return std::nullopt;
      all = all && *w.ok;
    }
    return all;
  }
};

/// The windows of `check` (proximity_means), parsed; throws Malformed.
Proximity proximity_windows(const json& check) {
  Proximity p;
  p.baseline = window_of(member(check, "baseline"), "baseline");
  const json& windows = member(check, "windows");
  if (!windows.is_null() && !windows.is_array()) throw Malformed("\"windows\" must be an array");
  for (std::size_t i = 0; windows.is_array() && i < windows.size(); ++i)
    p.windows.push_back(
        window_of(windows[i], text_or(member(windows[i], "name"), fmt::format("window {}", i + 1))));
  return p;
}

/// Means of `values` over the windows of dx = x_body − x_other (motion_claims.hpp).
Proximity proximity_means(const std::vector<double>& t, const std::vector<double>& x_body,
                          const std::vector<double>& x_other, const std::vector<double>& values,
                          const json& check) {
  Proximity result = proximity_windows(check);
  if (result.windows.empty()) {
    result.problem = "the check names no window";
    return result;
  }
  const std::size_t n = t.size();
  std::vector<double> dx(n);
  for (std::size_t i = 0; i < n; ++i) dx[i] = x_body[i] - x_other[i];
  result.encounter = encounter_time(t, dx);
  if (!result.encounter) {
    result.problem = "dx never changes sign: the bodies do not pass each other in this run";
    return result;
  }
  const std::vector<double> u_x = gradient(x_body, t);
  std::vector<WindowMean*> all{&result.baseline};
  for (auto& w : result.windows) all.push_back(&w);
  auto selected = [&](const WindowMean& w, std::size_t i) {
    const bool phase = w.phase == "approaching" ? t[i] < *result.encounter : t[i] > *result.encounter;
    return phase && w.interval.contains(dx[i]) && std::isfinite(values[i]);
  };
  std::vector<double> u_selected;
  for (std::size_t i = 0; i < n; ++i)
    if (std::any_of(all.begin(), all.end(), [&](const WindowMean* w) { return selected(*w, i); }))
      u_selected.push_back(u_x[i]);
  const double mean_u = u_selected.empty() ? 0.0 : mean(u_selected);
  if (!(std::abs(mean_u) > 1e-9)) {
    result.problem = "the body does not move along x in the windows: no drag direction";
    return result;
  }
  result.sign = -std::copysign(1.0, mean_u);
  for (WindowMean* w : all) {
    std::vector<double> in_window;
    for (std::size_t i = 0; i < n; ++i) {
      if (!selected(*w, i)) continue;
      const double v = result.sign * values[i];
      in_window.push_back(v);
      if (w->samples++ == 0) {
        w->t_first = w->t_last = t[i];
        w->peak = w->trough = v;
        w->peak_dx = w->trough_dx = dx[i];
      }
      w->t_first = std::min(w->t_first, t[i]);
      w->t_last = std::max(w->t_last, t[i]);
      if (v > w->peak) std::tie(w->peak, w->peak_dx) = std::pair(v, dx[i]);  // the first extreme wins
      if (v < w->trough) std::tie(w->trough, w->trough_dx) = std::pair(v, dx[i]);
    }
    if (w->samples >= kMinSamples) w->mean = mean(in_window);
  }
  if (!result.baseline.mean) {
    result.problem =
        fmt::format("fewer than {} samples in the baseline window ({})", kMinSamples, result.baseline.text());
    return result;
  }
  const double base = *result.baseline.mean;
  for (auto& w : result.windows)
    if (w.mean && !w.expect.empty()) w.ok = w.expect == "above" ? *w.mean > base : *w.mean < base;
  return result;
}

// ---- differences between runs ------------------------------------------------------------------

struct Difference {
  std::string column;
  double rms = kNaN, peak = kNaN;
  std::size_t samples = 0;

  double relative() const { return peak > 0 ? rms / peak : kNaN; }
};

/// `s` from its last sample at or before `t_from` on (what interpolation after t_from can touch).
Series from_time(const std::vector<double>& t, const std::vector<double>& y, double t_from) {
  std::size_t k = 0;
  while (k + 1 < t.size() && t[k + 1] <= t_from) ++k;
  return {{t.begin() + static_cast<std::ptrdiff_t>(k), t.end()},
          {y.begin() + static_cast<std::ptrdiff_t>(k), y.end()}};
}

/// Relative RMS of `run` against `ref` over t >= t_from (motion_claims.hpp); nullopt when the
/// series do not overlap there.
std::optional<Difference> relative_rms(const std::vector<double>& t_run, const std::vector<double>& y_run,
                                       const std::vector<double>& t_ref, const std::vector<double>& y_ref,
                                       double t_from, const std::string& column) {
  if (t_run.size() < 2 || t_ref.size() < 2) return std::nullopt;
  const Series a = from_time(t_run, y_run, t_from), b = from_time(t_ref, y_ref, t_from);
  auto all_finite = [](const Series& s) {
    return std::all_of(s.t.begin(), s.t.end(), [](double v) { return std::isfinite(v); }) &&
           std::all_of(s.y.begin(), s.y.end(), [](double v) { return std::isfinite(v); });
  };
  Difference d;
  d.column = column;
  const Window after{t_from, std::numeric_limits<double>::infinity()};
  try {
    const SeriesDistance ab = rms_distance(a, b, after), ba = rms_distance(b, a, after);
    d.rms = std::max(ab.rms, ba.rms);
    d.samples = std::min(ab.points, ba.points);
  } catch (const core::Error&) {
    if (all_finite(a) && all_finite(b)) return std::nullopt;  // no overlap after t_from
    // A non-finite sample: rms_distance refuses it, the difference is NaN (never a pass).
    const double lo = std::max({t_from, a.t.front(), b.t.front()}), hi = std::min(a.t.back(), b.t.back());
    if (!(lo <= hi)) return std::nullopt;
    std::size_t in_a = 0, in_b = 0;
    for (double t : a.t) in_a += t >= lo && t <= hi;
    for (double t : b.t) in_b += t >= lo && t <= hi;
    if (in_a == 0 || in_b == 0) return std::nullopt;
    d.samples = std::min(in_a, in_b);
  }
  bool any = false;
  double peak = 0;
  for (std::size_t i = 0; i < t_ref.size(); ++i)
    if (t_ref[i] >= t_from) {
      any = true;
      peak = std::isnan(y_ref[i]) || std::isnan(peak) ? kNaN : std::max(peak, std::abs(y_ref[i]));
    }
  d.peak = any ? peak : kNaN;
  return d;
}

// ---- one claim ---------------------------------------------------------------------------------

/// A claim being checked: its rows and whether an unjudged row waits for a partner run.
class Check {
 public:
  Check(const json& claim, std::vector<ClaimRun>& runs, double t_from)
      : claim_(claim), spec_(claim["check"]), runs_(runs), t_from_(t_from) {}

  json rows = json::array();
  bool waits_for_runs = false;
  std::vector<std::string> failures;  // "<label>: <note>" of the failing rows

  /// A row of `run` (not judged, no value yet).
  json& row(const ClaimRun& run, const std::string& part = "") {
    json r = {{"run", run.case_id},
              {"fidelity", run.fidelity},
              {"directory", run.dir.string()},
              {"status", run.status},
              {"parameter", nullptr},
              {"value", nullptr},
              {"verdict", nullptr},
              {"note", ""},
              {"details", json::array()}};
    if (!part.empty()) r["part"] = part;
    rows.push_back(std::move(r));
    return rows.back();
  }
  /// A row not judged, with why.
  void unjudged(const ClaimRun& run, const std::string& note, const std::string& part = "",
                bool wait = false) {
    row(run, part)["note"] = note;
    waits_for_runs = waits_for_runs || wait;
  }
  /// Sets the verdict of `r`; a failure is recorded with the row's note.
  void judge(json& r, bool pass, const std::string& fail_note = "") {
    r["verdict"] = pass ? "pass" : "fail";
    if (pass) return;
    r["note"] = fail_note;
    const std::string part = r.contains("part") ? ": " + r["part"].get<std::string>() : "";
    failures.push_back(fmt::format("{} ({}){}: {}", r["run"].get<std::string>(),
                                   r["fidelity"].get<std::string>(), part, fail_note));
  }

  /// The string at `key` of the check; throws Malformed when absent.
  std::string spec_text(const char* key) const {
    const json& v = member(spec_, key);
    if (!v.is_string() || v.get_ref<const std::string&>().empty())
      throw Malformed(fmt::format("check.{} must be a name", key));
    return v.get<std::string>();
  }
  /// The number at `key` of `object`; throws Malformed when absent.
  static double number(const json& object, const char* key, const char* where) {
    const json& v = member(object, key);
    if (!finite(v)) throw Malformed(fmt::format("{}{} must be a number", where, key));
    return v.get<double>();
  }
  std::vector<std::string> columns() const {
    std::vector<std::string> out;
    const json& c = member(spec_, "columns");
    if (c.is_array())
      for (const auto& x : c)
        if (x.is_string()) out.push_back(x.get<std::string>());
    if (out.empty() || !c.is_array() || out.size() != c.size())
      throw Malformed("check.columns must list the series columns to compare");
    return out;
  }

  void proximity(const std::vector<ClaimRun*>& about);
  void twin(const std::vector<ClaimRun*>& about);
  void refinement(const std::vector<ClaimRun*>& about);
  void fraction(const std::vector<ClaimRun*>& about);

 private:
  void difference(ClaimRun& run, ClaimRun& ref, const std::vector<std::string>& columns, double tolerance,
                  const std::string& what, const std::string& first_detail = "");

  const json& claim_;
  const json& spec_;
  std::vector<ClaimRun>& runs_;
  double t_from_;
};

std::string run_status_note(const ClaimRun& run) { return "run " + run.status; }

void Check::proximity(const std::vector<ClaimRun*>& about) {
  const std::string body = spec_text("body"), other = spec_text("other");
  const std::string column = text_or(member(spec_, "column"), "drag_coefficient");
  proximity_windows(spec_);  // a malformed window is the claim's fault, whatever the runs
  const std::vector<std::string> names{body + ".x", other + ".x", body + "." + column};
  for (ClaimRun* run : about) {
    if (run->status != "ok") {
      unjudged(*run, run_status_note(*run));
      continue;
    }
    if (const std::string problem = column_problem(*run, names); !problem.empty()) {
      unjudged(*run, problem);
      continue;
    }
    const auto& d = series_of(*run);
    const Proximity prox = proximity_means(d.at("t"), d.at(names[0]), d.at(names[1]), d.at(names[2]), spec_);
    if (!prox.problem.empty()) {
      unjudged(*run, prox.problem);
      continue;
    }
    const WindowMean& base = prox.baseline;
    json& r = row(*run);
    json& details = r["details"];
    details.push_back(fmt::format("baseline ({}): mean {:.4g} over {} samples, t = {:g}–{:g}", base.text(),
                                  *base.mean, base.samples, base.t_first, base.t_last));
    std::vector<std::string> value{"baseline: " + num(*base.mean)}, wrong, unjudged_windows;
    for (const auto& w : prox.windows) {
      value.push_back(w.name + ": " + (w.mean ? num(*w.mean) : "–"));
      if (!w.mean) {
        details.push_back(fmt::format("{} ({}): fewer than {} samples", w.name, w.text(), kMinSamples));
        unjudged_windows.push_back(fmt::format("{}: fewer than {} samples", w.name, kMinSamples));
        continue;
      }
      const char* side = *w.mean > *base.mean ? "above" : "below";
      details.push_back(
          fmt::format("{} ({}): mean {:.4g} over {} samples, t = {:g}–{:g}, {} the baseline ({:+.3g}; the "
                      "statement: {}) {}; "
                      "max {:.4g} at dx = {:.3g}, min {:.4g} at dx = {:.3g}",
                      w.name, w.text(), *w.mean, w.samples, w.t_first, w.t_last, side, *w.mean - *base.mean,
                      w.expect.empty() ? "None" : w.expect, w.ok.value_or(false) ? "✓" : "✗", w.peak,
                      w.peak_dx, w.trough, w.trough_dx));
      if (w.expect.empty()) unjudged_windows.push_back(w.name + ": no \"expect\"");
      if (w.ok == false)
        wrong.push_back(fmt::format("{}: mean {:.4g} is not {} the baseline mean {:.4g}", w.name, *w.mean,
                                    w.expect, *base.mean));
    }
    details.push_back(
        fmt::format("closest approach (dx = 0) at t = {:.4g}; the drag opposing the motion is {} (the {} "
                    "body moves along {}x)",
                    *prox.encounter, prox.sign > 0 ? "C_d" : "−C_d", body, prox.sign > 0 ? "−" : "+"));
    r["value"] = join(value, ", ");
    if (!wrong.empty()) {
      judge(r, false, join(wrong, "; "));
    } else if (prox.ok()) {
      judge(r, true);
    } else {
      r["note"] = "not judged: " + join(unjudged_windows, "; ");
    }
  }
}

void Check::difference(ClaimRun& run, ClaimRun& ref, const std::vector<std::string>& columns,
                       double tolerance, const std::string& what, const std::string& first_detail) {
  json& r = row(run);
  r["against"] = ref.label();
  for (ClaimRun* x : {&run, &ref})
    if (const std::string problem = column_problem(*x, columns); !problem.empty()) {
      r["note"] = (x == &ref ? ref.label() + ": " : "") + problem;
      return;
    }
  const auto &a = series_of(run), &b = series_of(ref);
  std::vector<Difference> diffs;
  for (const auto& c : columns) {
    const auto d = relative_rms(a.at("t"), a.at(c), b.at("t"), b.at(c), t_from_, c);
    if (!d) {
      r["note"] = fmt::format("the series of the {} do not overlap after t = {:g}", what, t_from_);
      return;
    }
    diffs.push_back(*d);
  }
  std::vector<std::string> value, lines, above;
  for (const auto& d : diffs) {
    value.push_back(symbol(d.column) + " " + pct(d.relative()));
    lines.push_back(fmt::format("{}: RMS {:.3g} over peak {:.4g} = {} ({} samples)", symbol(d.column), d.rms,
                                d.peak, pct(d.relative()), d.samples));
    if (!std::isfinite(d.relative()))
      above.push_back(symbol(d.column) + " is not a number");
    else if (d.relative() > tolerance)
      above.push_back(symbol(d.column) + " " + pct(d.relative()) + " is above " + pct(tolerance));
  }
  r["value"] = join(value, "; ") + " (at most " + pct(tolerance) + ")";
  if (!first_detail.empty()) r["details"].push_back(first_detail);
  r["details"].push_back(fmt::format("against {}, t ≥ {:g}: {}", ref.label(), t_from_, join(lines, "; ")));
  const auto differs = numerics_differences(run, ref);
  if (!differs.empty())
    r["details"].push_back("the runs also differ in numerics." + join(differs, ", numerics."));
  judge(r, above.empty(), join(above, ", "));
}

void Check::twin(const std::vector<ClaimRun*>& about) {
  const std::vector<std::string> cols = columns();
  const double tolerance = number(claim_, "upper", "");
  for (ClaimRun* run : about) {
    if (run->status != "ok") {
      unjudged(*run, run_status_note(*run));
      continue;
    }
    ClaimRun* twin = twin_of(*run, runs_);
    if (!twin) {
      unjudged(*run, "no uniform-grid twin run at fidelity " + run->fidelity, "", true);
    } else if (twin->status != "ok") {
      unjudged(*run, "twin " + twin->case_id + ": " + run_status_note(*twin), "", true);
    } else {
      difference(*run, *twin, cols, tolerance, "twin");
    }
  }
}

void Check::refinement(const std::vector<ClaimRun*>& about) {
  const std::vector<std::string> cols = columns();
  const double tolerance = number(claim_, "upper", "");
  const json& statement = member(spec_, "fine_spacing");
  if (!statement.is_null() && !(finite(statement) && statement.get<double>() > 0))
    throw Malformed("check.fine_spacing must be a positive number (the fine spacing the statement is about)");
  const double about_spacing = statement.is_null() ? 0.0 : statement.get<double>();  // 0: any grid
  const std::string about_note =
      about_spacing > 0 ? fmt::format("; the statement is about Δx_f = {:g}", about_spacing) : std::string();
  const auto coarser = [](double h, double than) { return h > than * (1 + 1e-9); };
  // One grid study per fidelity: the claim's cases differ only in the grid, and a level's
  // numerics are the same for all of them, so runs of one level differ in the grid alone.
  std::vector<std::pair<std::string, std::vector<ClaimRun*>>> by_level;  // in the order of `about`
  for (ClaimRun* run : about) {
    if (run->status != "ok") {
      unjudged(*run, run_status_note(*run));
      continue;
    }
    if (grid_refinement(*run) != "two_level" || !fine_spacing(*run)) continue;
    auto it = std::find_if(by_level.begin(), by_level.end(),
                           [&](const auto& c) { return c.first == run->fidelity; });
    if (it == by_level.end()) it = by_level.insert(by_level.end(), {run->fidelity, {}});
    it->second.push_back(run);
  }
  for (auto& [level, members] : by_level) {
    std::stable_sort(members.begin(), members.end(), [](const ClaimRun* a, const ClaimRun* b) {
      return *fine_spacing(*a) > *fine_spacing(*b);
    });
    ClaimRun& finest = *members.back();
    const double h = *fine_spacing(finest);
    bool compared = false;
    for (ClaimRun* run : members) {
      const double hr = *fine_spacing(*run);
      if (!coarser(hr, h)) continue;
      if (about_spacing > 0 && coarser(hr, about_spacing)) {
        unjudged(*run, fmt::format("Δx_f = {:g} is coarser than the grid the statement is about "
                                   "(Δx_f = {:g})",
                                   hr, about_spacing));
        continue;
      }
      difference(*run, finest, cols, tolerance, "grids",
                 fmt::format("Δx_f = {:g} against the finer Δx_f = {:g} at fidelity {} (self-reference)", hr,
                             h, level));
      compared = true;
    }
    if (!compared) {
      std::vector<std::string> grids;
      for (const ClaimRun* m : members)
        grids.push_back(fmt::format("Δx_f = {:g} ({})", *fine_spacing(*m), m->case_id));
      unjudged(finest,
               fmt::format("no finer grid at fidelity {} to refine against ({}){}", level, join(grids, ", "),
                           about_note),
               "", true);
    }
  }
}

void Check::fraction(const std::vector<ClaimRun*>& about) {
  const double value = number(claim_, "value", ""), tolerance = number(spec_, "tolerance", "check.");
  const json& compare_with = member(spec_, "compare_with");
  if (!compare_with.is_null() && !compare_with.is_string())
    throw Malformed("check.compare_with must be a case id");
  const std::string other_id = text_or(compare_with, "");
  const std::string less_part = "saving less than " + other_id;
  for (ClaimRun* run : about) {
    if (run->status != "ok") {
      unjudged(*run, run_status_note(*run));
      continue;
    }
    const auto f = fine_fraction(run->case_doc);
    const auto built = built_fine_fraction(run->manifest);
    if (!f) {
      unjudged(*run, "the case has no fine block (numerics.grid.fine_region)", "fine fraction");
    } else {
      json& r = row(*run, "fine fraction");
      r["value"] = fmt::format("{} as set, {} as built (thesis {:g} %, within {:g} %)", pct(*f),
                               built ? pct(*built) : "–", 100 * value, 100 * tolerance);
      r["details"].push_back(
          "as set: numerics.grid.fine_region over physics.domain.size; as built: the fine block's node "
          "extent over "
          "the coarse block's (manifest lattice.blocks)");
      judge(r, std::abs(*f - value) <= tolerance,
            fmt::format("{} is not within {:g} % of {:g} %", pct(*f), 100 * tolerance, 100 * value));
    }
    ClaimRun* twin = twin_of(*run, runs_);
    if (!twin || twin->status != "ok") {
      unjudged(*run, "no finished uniform-grid twin at fidelity " + run->fidelity, "effort saved", true);
      continue;
    }
    const double here_ratio = ratio(node_updates(*run), node_updates(*twin));
    if (!std::isfinite(here_ratio)) {
      unjudged(*run, "no lattice.node_updates in the manifests", "effort saved");
      continue;
    }
    const double wall_ratio = ratio(wall_time(*run), wall_time(*twin));
    json& r = row(*run, "effort saved");
    r["against"] = twin->label();
    r["value"] = fmt::format(
        "node updates twin/two-block {:.3g} (saving {}); wall time {} (saving {}, not judged: noisy)",
        here_ratio, pct(saving(here_ratio)), num(wall_ratio, 3), pct(saving(wall_ratio)));
    r["details"].push_back(
        fmt::format("node updates {:.4g} (two-block) and {:.4g} ({}); wall time {} s and {} s on {} and {} "
                    "thread(s): wall time "
                    "depends on the machine and its load",
                    node_updates(*run), node_updates(*twin), twin->case_id, num(wall_time(*run)),
                    num(wall_time(*twin)), threads(*run), threads(*twin)));
    judge(r, here_ratio > 1.0,
          fmt::format("no saving: the twin takes {:.3g} times the node updates", here_ratio));
    if (other_id.empty()) continue;
    ClaimRun* other = nullptr;
    for (auto& x : runs_)
      if (!other && x.case_id == other_id && x.fidelity == run->fidelity && x.status == "ok") other = &x;
    ClaimRun* other_twin = other ? twin_of(*other, runs_) : nullptr;
    const double there_ratio = other_twin && other_twin->status == "ok"
                                   ? ratio(node_updates(*other), node_updates(*other_twin))
                                   : kNaN;
    if (!std::isfinite(there_ratio)) {
      unjudged(*run,
               fmt::format("no finished pair {} + uniform twin at fidelity {}", other_id, run->fidelity),
               less_part, true);
      continue;
    }
    const double here = saving(here_ratio), there = saving(there_ratio);
    json& less = row(*run, less_part);
    less["against"] = other->label();
    less["value"] =
        fmt::format("saving {} against {} for {} (node updates)", pct(here), pct(there), other_id);
    judge(less, here < there,
          fmt::format("the saving {} is not below the {} of {}", pct(here), pct(there), other_id));
  }
}

}  // namespace

bool is_moving(const json& case_doc) {
  const json& bodies = member(member(case_doc, "physics"), "bodies");
  if (!bodies.is_array()) return false;
  return std::any_of(bodies.begin(), bodies.end(), [](const json& b) {
    return member(member(b, "motion"), "type") == "prescribed" && !member(b, "membrane").is_object();
  });
}

double start_left_out(const json& consistency) {
  const json& from = member(member(consistency, "twin_difference"), "from");
  return finite(from) ? from.get<double>() : 0.0;
}

CheckOutcome check_motion_claim(const json& claim, std::vector<ClaimRun>& runs, const json& consistency) {
  const json& spec = member(claim, "check");
  const std::string type = text_or(member(spec, "type"), "");
  std::set<std::string> cases;
  for (const auto& c : member(claim, "cases").is_array() ? claim["cases"] : json::array())
    if (c.is_string()) cases.insert(c.get<std::string>());
  std::vector<ClaimRun*> about;
  for (auto& r : runs)
    if (cases.count(r.case_id)) about.push_back(&r);
  std::stable_sort(about.begin(), about.end(), [](const ClaimRun* a, const ClaimRun* b) {
    return std::tie(a->case_id, a->fidelity) < std::tie(b->case_id, b->fidelity);
  });

  CheckOutcome out;
  Check check(claim, runs, start_left_out(consistency));
  try {
    if (type == "proximity_means") {
      check.proximity(about);
    } else if (type == "twin") {
      check.twin(about);
    } else if (type == "refinement") {
      check.refinement(about);
    } else if (type == "fine_fraction") {
      check.fraction(about);
    } else {
      out.verdict = "not checked";
      out.message = fmt::format("unknown check type {} (proximity_means, twin, refinement, fine_fraction)",
                                member(spec, "type").dump());
      return out;
    }
  } catch (const Malformed& e) {
    out.verdict = "not checked";
    out.message = std::string("malformed check in claims.json: ") + e.what();
    return out;
  }

  out.rows = std::move(check.rows);
  std::vector<std::string> unjudged;
  bool judged = false;
  for (const auto& r : out.rows) {
    judged = judged || !r["verdict"].is_null();
    if (r["verdict"].is_null())
      unjudged.push_back(fmt::format(
          "{} ({}){}: {}", r["run"].get<std::string>(), r["fidelity"].get<std::string>(),
          r.contains("part") ? ": " + r["part"].get<std::string>() : "", r["note"].get<std::string>()));
  }
  const bool any_ok =
      std::any_of(about.begin(), about.end(), [](const ClaimRun* r) { return r->status == "ok"; });
  if (!check.failures.empty()) {
    out.verdict = "inconsistent";
    out.message = join(check.failures, "; ");
  } else if (judged) {
    out.verdict = "consistent";
    out.message = unjudged.empty() ? "" : "not judged: " + join(unjudged, "; ");
  } else if (!any_ok) {
    out.verdict = "no run";
    out.message = about.empty()
                      ? "no run of " + join(std::vector<std::string>(cases.begin(), cases.end()), ", ")
                      : "no run about this claim finished \"ok\"";
  } else {
    out.verdict = check.waits_for_runs ? "not enough runs" : "not checked";
    out.message = join(unjudged, "; ");
  }
  return out;
}

}  // namespace caplab::score
