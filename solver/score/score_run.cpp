// Scoring of a run directory; see score_run.hpp for the verdicts and the score.json layout.
#include "score/score_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "io/run_directory.hpp"
#include "io/series_writer.hpp"
#include "score/comparators.hpp"
#include "score/reference_series.hpp"
#include "score/run_files.hpp"

namespace caplab::score {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kComparisons = "relative, absolute, bracket, time_series or mode";

std::string string_or(const json* doc, const char* key) {
  if (doc && doc->contains(key) && (*doc)[key].is_string()) return (*doc)[key].get<std::string>();
  return "";
}

/// A number as JSON: null when it is not finite (JSON has no NaN).
json number_json(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string joined_keys(const json& object) {
  std::string out;
  for (const auto& [key, _] : object.items()) out += (out.empty() ? "" : ", ") + key;
  return out.empty() ? "none" : out;
}

/// A metric of summary.json as a number; NaN when it is not a number.
double metric_value(const json& metric) {
  const json& v = metric_json(metric);
  return v.is_number() ? v.get<double>() : kNaN;
}

/// A metric is sane when it is a finite number or a non-empty string (a classification such
/// as the flow regime "mode"); NaN (written as null), infinities, booleans and others are not.
bool metric_is_sane(const json& metric) {
  const json& v = metric_json(metric);
  if (v.is_string()) return !v.get_ref<const std::string&>().empty();
  return std::isfinite(metric_value(metric));
}

json check(const std::string& name, json value, json limit, bool pass, const std::string& message) {
  return {{"name", name},
          {"value", std::move(value)},
          {"limit", std::move(limit)},
          {"verdict", pass ? "pass" : "fail"},
          {"message", message}};
}

json sanity_checks(const std::string& status, const JsonFile& summary) {
  json checks = json::array();
  const bool ok = status == "ok";
  std::string status_message;
  if (status == "incomplete")
    status_message = "the run did not finish (manifest.json still says \"running\" or has no final status)";
  else if (!ok)
    status_message = "the run ended with status \"" + status + "\"";
  checks.push_back(check("status", status, "ok", ok, status_message));
  if (!summary.doc) {
    if (ok) checks.push_back(check("summary", nullptr, nullptr, false, summary.problem));
    return checks;
  }
  const json& doc = *summary.doc;
  const json metrics = doc.value("metrics", json::object());
  if (!metrics.is_object()) {
    checks.push_back(check("summary", nullptr, nullptr, false, "summary.json \"metrics\" is not an object"));
  } else {
    std::string bad;
    int count = 0;
    for (const auto& [name, metric] : metrics.items())
      if (!metric_is_sane(metric)) {
        bad += (bad.empty() ? "" : ", ") + name;
        ++count;
      }
    checks.push_back(check("metrics_finite", count, 0, count == 0,
                           count == 0 ? ""
                                      : "metrics not finite (NaN, infinite, or neither a number nor a "
                                        "non-empty string): " +
                                            bad));
  }
  const json sanity = doc.value("sanity", json::object());
  if (!sanity.is_object()) return checks;
  for (const auto& [name, value] : sanity.items()) {
    if (value.is_boolean()) {
      const bool pass = value.get<bool>();
      checks.push_back(
          check(name, pass, true, pass, pass ? "" : "summary.json sanity \"" + name + "\" is false"));
    }
  }
  if (sanity.contains("mass_drift")) {
    const double drift = sanity["mass_drift"].is_number() ? sanity["mass_drift"].get<double>() : kNaN;
    const bool pass = std::abs(drift) < kMassDriftLimit;
    checks.push_back(
        check("mass_drift", number_json(drift), kMassDriftLimit, pass,
              pass ? "" : fmt::format("|mass drift| {:.3g} is not below {:.0e}", drift, kMassDriftLimit)));
  }
  return checks;
}

/// Reads the run's series.h5 once, on first use.
class RunSeries {
 public:
  explicit RunSeries(fs::path file) : file_(std::move(file)) {}

  /// The column `name` against "t", or throws core::Error saying what is missing.
  Series column(const std::string& name, std::string& unit) {
    load();
    if (!problem_.empty()) throw core::Error(problem_);
    const auto it = columns_.find(name);
    if (it == columns_.end()) {
      std::string available;
      for (const auto& [key, _] : columns_) available += (available.empty() ? "" : ", ") + key;
      throw core::Error("series \"" + name + "\" not in series.h5 (available: " + available + ")");
    }
    if (columns_.count("t") == 0) throw core::Error("series.h5 has no \"t\" column");
    unit = units_[name];
    return {columns_.at("t"), it->second};
  }

 private:
  void load() {
    if (loaded_) return;
    loaded_ = true;
    std::error_code ec;
    if (!fs::is_regular_file(file_, ec)) {
      problem_ = "series.h5 is missing (time_series entries need it)";
      return;
    }
    try {
      columns_ = io::read_series(file_);
      for (const auto& c : io::read_series_columns(file_)) units_[c.name] = c.unit;
    } catch (const std::exception& e) {
      problem_ = std::string("series.h5 cannot be read: ") + e.what();
    }
  }

  fs::path file_;
  bool loaded_ = false;
  std::string problem_;
  std::map<std::string, std::vector<double>> columns_;
  std::map<std::string, std::string> units_;
};

/// Everything an acceptance entry is scored against.
struct Context {
  fs::path run_dir;
  const ScoreOptions& options;
  std::string fidelity;
  json metrics;  // summary.json "metrics" (an object)
  RunSeries series;
};

/// Thrown inside score_entry for an entry that cannot be scored; its message is the entry's.
struct EntryFailure {
  std::string message;
};

const json& require(const json& entry, const std::string& at, const char* key, json::value_t type,
                    const char* expected) {
  if (!entry.contains(key))
    throw EntryFailure{fmt::format("{}/{} is missing: expected {}", at, key, expected)};
  const json& v = entry[key];
  const bool ok = type == json::value_t::number_float ? v.is_number() : v.type() == type;
  if (!ok) throw EntryFailure{fmt::format("{}/{} is {}: expected {}", at, key, v.dump(), expected)};
  return v;
}

/// The tolerance for the run's fidelity; `optional_margin` makes a missing "tolerance" object 0.
double tolerance_for(const json& entry, const std::string& at, const Context& ctx, bool optional_margin) {
  if (optional_margin && !entry.contains("tolerance")) return 0.0;
  const json& tol =
      require(entry, at, "tolerance", json::value_t::object, "an object {fidelity level: number}");
  if (ctx.fidelity.empty())
    throw EntryFailure{"the run's fidelity level is unknown (manifest.json has no \"fidelity\")"};
  if (!tol.contains(ctx.fidelity))
    throw EntryFailure{fmt::format("no tolerance for fidelity \"{}\" in {}/tolerance (defined for: {})",
                                   ctx.fidelity, at, joined_keys(tol))};
  if (!tol[ctx.fidelity].is_number())
    throw EntryFailure{
        fmt::format("{}/tolerance/{} is {}: expected a number", at, ctx.fidelity, tol[ctx.fidelity].dump())};
  return tol[ctx.fidelity].get<double>();
}

/// A summary metric (its unit copied to `out`), or an EntryFailure naming the available metrics.
const json& find_metric(const std::string& metric, const Context& ctx, json& out) {
  if (!ctx.metrics.contains(metric))
    throw EntryFailure{"metric " + metric + " not in summary.json (available: " + joined_keys(ctx.metrics) +
                       ")"};
  const json& m = ctx.metrics[metric];
  if (m.is_object() && m.contains("unit")) out["unit"] = m["unit"];
  return m;
}

/// Value and unit of a numeric summary metric; a string metric (a classification) is an
/// EntryFailure that points to the mode comparison.
double summary_metric(const std::string& metric, const std::string& comparison, const Context& ctx,
                      json& out) {
  const json& v = metric_json(find_metric(metric, ctx, out));
  if (v.is_string()) {
    out["value"] = v;
    throw EntryFailure{fmt::format(
        "metric {} is the string {}: a {} comparison needs a number (a classification is scored with "
        "the comparison \"mode\")",
        metric, v.dump(), comparison)};
  }
  const double value = metric_value(v);
  out["value"] = number_json(value);
  return value;
}

/// The allowed modes of a mode entry: "reference_mode" is a name or a non-empty array of names.
std::vector<std::string> reference_modes(const json& entry, const std::string& at) {
  const char* expected = "a mode name such as \"tumbling\" or a non-empty array of mode names";
  if (!entry.contains("reference_mode"))
    throw EntryFailure{fmt::format("{}/reference_mode is missing: expected {}", at, expected)};
  const json& r = entry["reference_mode"];
  std::vector<std::string> modes;
  if (r.is_string()) modes.push_back(r.get<std::string>());
  if (r.is_array())
    for (const auto& m : r) modes.push_back(m.is_string() ? m.get<std::string>() : "");
  const bool named = std::none_of(modes.begin(), modes.end(), [](const auto& m) { return m.empty(); });
  if (modes.empty() || !named)
    throw EntryFailure{fmt::format("{}/reference_mode is {}: expected {}", at, r.dump(), expected)};
  return modes;
}

/// A mode entry: the summary metric's string against "reference_mode"; no tolerance (exact).
Comparison score_mode(const json& entry, const std::string& at, const std::string& metric, const Context& ctx,
                      json& out) {
  const std::vector<std::string> modes = reference_modes(entry, at);
  out["reference_value"] = entry["reference_mode"];
  const json& v = metric_json(find_metric(metric, ctx, out));
  out["value"] = v;
  if (!v.is_string())
    throw EntryFailure{
        fmt::format("metric {} is {}: a mode comparison needs a string naming a mode (e.g. \"tumbling\")",
                    metric, v.is_number() ? "the number " + v.dump() : v.dump())};
  return compare_mode(v.get<std::string>(), modes);
}

Series series_from_json(const json& s, const std::string& at) {
  if (!s.is_object() || !s.contains("t") || !s.contains("value") || !s["t"].is_array() ||
      !s["value"].is_array())
    throw EntryFailure{at + "/reference_series: expected {\"t\": [numbers], \"value\": [numbers]}"};
  Series out;
  for (const auto& v : s["t"]) out.t.push_back(v.is_number() ? v.get<double>() : kNaN);
  for (const auto& v : s["value"]) out.y.push_back(v.is_number() ? v.get<double>() : kNaN);
  return out;
}

Series reference_series(const json& entry, const std::string& at, const Context& ctx) {
  if (entry.contains("reference_series")) return series_from_json(entry["reference_series"], at);
  const std::string& reference =
      require(entry, at, "reference", json::value_t::string, "a CSV file \"file.csv#t_column:value_column\"")
          .get_ref<const std::string&>();
  const ReferenceLocation loc = split_reference(reference);
  std::string t_column, value_column = loc.key;
  if (const auto colon = loc.key.find(':'); colon != std::string::npos) {
    t_column = loc.key.substr(0, colon);
    value_column = loc.key.substr(colon + 1);
  } else if (!loc.key.empty()) {
    t_column = "t";
  }
  try {
    return read_reference_series(resolve_reference_file(loc.file, ctx.run_dir, ctx.options.reference_root),
                                 t_column, value_column);
  } catch (const core::Error& e) {
    throw EntryFailure{e.what()};
  }
}

Comparison score_time_series(const json& entry, const std::string& at, Context& ctx, json& out) {
  out["value"] = nullptr;
  out["reference_value"] = nullptr;
  const double tolerance = tolerance_for(entry, at, ctx, false);
  out["tolerance"] = tolerance;
  std::optional<Window> window;
  if (entry.contains("window")) {
    const json& w = entry["window"];
    if (!w.is_array() || w.size() != 2 || !w[0].is_number() || !w[1].is_number())
      throw EntryFailure{at + "/window is " + w.dump() + ": expected [from, to]"};
    window = Window{w[0].get<double>(), w[1].get<double>()};
  }
  const Series reference = reference_series(entry, at, ctx);
  std::string unit;
  Series run;
  try {
    run = ctx.series.column(out["metric"].get<std::string>(), unit);
  } catch (const core::Error& e) {
    throw EntryFailure{e.what()};
  }
  if (!unit.empty()) out["unit"] = unit;
  SeriesDistance detail;
  const Comparison c = compare_time_series(run, reference, tolerance, window, &detail);
  if (detail.points > 0)
    out["compared"] = {{"from", detail.from}, {"to", detail.to}, {"points", detail.points}};
  return c;
}

json score_entry(const json& entry, std::size_t index, Context& ctx) {
  const std::string at = fmt::format("/acceptance/{}", index);
  json out = {{"metric", nullptr},          {"value", nullptr},     {"unit", nullptr},
              {"reference_value", nullptr}, {"reference", nullptr}, {"comparison", nullptr},
              {"error", nullptr},           {"tolerance", nullptr}, {"justification", nullptr},
              {"verdict", "fail"}};
  try {
    if (!entry.is_object()) throw EntryFailure{at + " is " + entry.dump() + ": expected an object"};
    for (const char* key : {"metric", "reference", "comparison", "justification"})
      if (entry.contains(key)) out[key] = entry[key];
    const std::string metric =
        require(entry, at, "metric", json::value_t::string, "a metric name").get<std::string>();
    const std::string comparison =
        require(entry, at, "comparison", json::value_t::string, kComparisons).get<std::string>();
    Comparison c;
    if (comparison == "relative" || comparison == "absolute") {
      const double reference =
          require(entry, at, "reference_value", json::value_t::number_float, "a number").get<double>();
      out["reference_value"] = reference;
      const double value = summary_metric(metric, comparison, ctx, out);
      const double tolerance = tolerance_for(entry, at, ctx, false);
      out["tolerance"] = tolerance;
      c = comparison == "relative" ? compare_relative(value, reference, tolerance)
                                   : compare_absolute(value, reference, tolerance);
    } else if (comparison == "bracket") {
      const json& b = require(entry, at, "bracket", json::value_t::array, "[lo, hi]");
      if (b.size() != 2 || !b[0].is_number() || !b[1].is_number())
        throw EntryFailure{at + "/bracket is " + b.dump() + ": expected [lo, hi]"};
      out["reference_value"] = b;
      const double value = summary_metric(metric, comparison, ctx, out);
      const double margin = tolerance_for(entry, at, ctx, true);
      out["tolerance"] = margin;
      c = compare_bracket(value, b[0].get<double>(), b[1].get<double>(), margin);
    } else if (comparison == "time_series") {
      c = score_time_series(entry, at, ctx, out);
    } else if (comparison == "mode") {
      c = score_mode(entry, at, metric, ctx, out);
    } else {
      throw EntryFailure{at + "/comparison is \"" + comparison + "\": expected " + kComparisons};
    }
    out["error"] = number_json(c.error);
    out["verdict"] = c.pass ? "pass" : "fail";
    if (!c.pass) out["message"] = c.message;
  } catch (const EntryFailure& f) {
    out["verdict"] = "fail";
    out["message"] = f.message;
  }
  return out;
}

json accuracy(const std::string& status, const JsonFile& case_file, const JsonFile& summary, Context& ctx) {
  json result = {{"verdict", "none"}, {"entries", json::array()}};
  if (status != "ok") {
    result["reason"] = "run status is \"" + status + "\", not \"ok\": accuracy is not scored";
    return result;
  }
  if (!case_file.doc) {
    result["verdict"] = "fail";
    result["reason"] = case_file.problem + ": the acceptance entries cannot be read";
    return result;
  }
  const json acceptance = case_file.doc->value("acceptance", json::array());
  if (!acceptance.is_array()) {
    result["verdict"] = "fail";
    result["reason"] = "case.json \"acceptance\" is not an array";
    return result;
  }
  if (acceptance.empty()) {
    result["reason"] = "the case has no acceptance entries";
    return result;
  }
  if (summary.doc && (*summary.doc).contains("metrics") && (*summary.doc)["metrics"].is_object())
    ctx.metrics = (*summary.doc)["metrics"];
  bool pass = true;
  for (std::size_t i = 0; i < acceptance.size(); ++i) {
    json entry = score_entry(acceptance[i], i, ctx);
    pass = pass && entry["verdict"] == "pass";
    result["entries"].push_back(std::move(entry));
  }
  result["verdict"] = pass ? "pass" : "fail";
  if (!summary.doc) result["reason"] = summary.problem;
  return result;
}

/// The performance verdict: the manifest's wall time against the case's budget at the run's level.
json performance(const std::string& status, const json* manifest, const json* case_doc, const std::string& fidelity) {
  static const json none;
  const json& m = manifest ? *manifest : none;
  json perf = json::object();
  for (const char* key : {"wall_time_s", "mlups", "steps", "threads"}) perf[key] = member(m, key);
  const json& spec = member(case_doc ? *case_doc : none, "performance");
  const json& budget = member(member(spec, "wall_time_budget_s"), fidelity.c_str());
  perf["budget_s"] = budget.is_number() ? budget : json(nullptr);
  if (spec.contains("justification")) perf["justification"] = spec["justification"];
  const json& wall = perf["wall_time_s"];
  if (!budget.is_number()) {
    perf["verdict"] = "not judged";
    perf["reason"] = fmt::format("the case states no wall-time budget at level {}", fidelity.empty() ? "?" : fidelity);
  } else if (status != "ok" || !wall.is_number()) {
    perf["verdict"] = "not judged";
    perf["reason"] = status != "ok" ? "the run did not finish (" + status + ")" : "manifest.json has no wall_time_s";
  } else {
    const double w = wall.get<double>(), b = budget.get<double>();
    perf["verdict"] = w <= b ? "pass" : "fail";
    perf["reason"] = fmt::format("wall time {:.4g} s {} the budget of {:.4g} s on {} thread(s); never part of the "
                                 "run's verdict: it depends on the machine and its load",
                                 w, w <= b ? "within" : "over", b, perf["threads"].dump());
  }
  return perf;
}

}  // namespace

json evaluate_run(const fs::path& run_dir, const ScoreOptions& options) {
  if (!io::RunDirectory::is_run_directory(run_dir))
    throw core::InputError("'" + run_dir.string() +
                           "' is not a caplab run directory (no manifest.json with a \"status\"); "
                           "give the directory that `caplab run` wrote");
  const JsonFile manifest = read_json(run_dir / "manifest.json");
  const JsonFile case_file = read_json(run_dir / "case.json");
  const JsonFile summary = read_json(run_dir / "summary.json");
  const json* m = manifest.doc ? &*manifest.doc : nullptr;
  const json* c = case_file.doc ? &*case_file.doc : nullptr;
  const json* s = summary.doc ? &*summary.doc : nullptr;

  std::string status = io::RunDirectory::run_status(run_dir);
  std::string fidelity = string_or(m, "fidelity");
  if (fidelity.empty()) fidelity = string_or(c, "fidelity_applied");
  if (fidelity.empty()) fidelity = string_or(s, "fidelity");
  std::string case_id = string_or(m, "case_id");
  if (case_id.empty()) case_id = string_or(c, "id");
  if (case_id.empty()) case_id = string_or(s, "case_id");

  json score;
  score["case_id"] = case_id.empty() ? json(nullptr) : json(case_id);
  score["fidelity"] = fidelity.empty() ? json(nullptr) : json(fidelity);

  json checks = sanity_checks(status, summary);
  bool sane = true;
  for (const auto& ch : checks) sane = sane && ch["verdict"] == "pass";
  score["sanity"] = {{"verdict", sane ? "pass" : "fail"}, {"checks", std::move(checks)}};

  Context ctx{run_dir, options, fidelity, json::object(), RunSeries(run_dir / "series.h5")};
  score["accuracy"] = accuracy(status, case_file, summary, ctx);

  score["performance"] = performance(status, m, c, fidelity);

  const bool pass = sane && score["accuracy"]["verdict"] != "fail";
  score["verdict"] = pass ? "pass" : "fail";
  return score;
}

json score_run(const fs::path& run_dir, const ScoreOptions& options) {
  json score = evaluate_run(run_dir, options);
  io::write_file_atomically(run_dir / "score.json", score.dump(2) + "\n");
  return score;
}

int exit_code(const json& score, bool strict) {
  if (!strict) return 0;
  auto verdict = [&](const char* part) -> std::string {
    if (!score.is_object() || !score.contains(part) || !score[part].is_object()) return "fail";
    const json& v = score[part].value("verdict", json("fail"));
    return v.is_string() ? v.get<std::string>() : "fail";
  };
  return verdict("sanity") == "fail" || verdict("accuracy") == "fail" ? 1 : 0;
}

}  // namespace caplab::score
