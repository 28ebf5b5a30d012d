// Cross-run check of thesis statements; see claims.hpp for the semantics and the layout.
#include "score/claims.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <utility>

#include "core/error.hpp"
#include "diagnostics/capsule_motion.hpp"
#include "diagnostics/turning_points.hpp"
#include "io/run_directory.hpp"
#include "io/series_writer.hpp"
#include "score/comparators.hpp"
#include "score/motion_claims.hpp"
#include "score/run_files.hpp"

namespace caplab::score {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// The capsule parameters a claim can restrict, in the order of the trend series keys.
constexpr std::array<const char*, 8> kKeys{"shape",     "aspect_ratio",  "alpha",    "reference_curvature",
                                           "capillary", "bending_ratio", "reynolds", "law"};
// Keys a claim may restrict but that do not split a trend into series: the biconcave cells of
// chapter 6 take their area dilation C from G (a rule of the case files), so a sweep over G
// varies C too.
constexpr std::array<const char*, 1> kMatchOnlyKeys{"area_dilation"};
/// Capsule columns of series.h5 that a "statistic" can be taken of.
constexpr std::array<const char*, 4> kSeries{"taylor_deformation", "inclination", "area_change",
                                             "tank_treading_phase"};
/// Regimes in the order of the stages of thesis section 3.2.2 (more bending, less shear).
const std::map<std::string, double> kModeOrder{
    {"steady_tank_treading", 0}, {"oscillating_tank_treading", 1}, {"tumbling", 2}};
const std::vector<std::string> kTankTreading{"steady_tank_treading", "oscillating_tank_treading"};


/// `object[key]` as a double when it is a finite number, else `fallback`.
json number_or(const json& object, const char* key, json fallback) {
  return object.is_object() && object.contains(key) && finite(object[key]) ? json(object[key].get<double>())
                                                                           : fallback;
}


/// `v` when it is an array, else an empty array (for loops over optional fields).
const json& array_or_empty(const json& v) {
  static const json empty = json::array();
  return v.is_array() ? v : empty;
}

json string_or_null(const std::string& s) { return s.empty() ? json(nullptr) : json(s); }

/// A JSON file of the run directory, or {} when it is missing or unreadable.
json read_object(const fs::path& file) { return read_json(file).doc.value_or(json::object()); }

/// A run directory as the claims see it.
struct Run {
  fs::path dir;
  std::string case_id, fidelity, status;
  json case_doc, summary, score, manifest, params;
  json fine_spacing;                                                 // numerics.grid.fine_spacing, or null
  std::optional<std::map<std::string, std::vector<double>>> series;  // capsule columns, read on use

  std::string label() const { return fmt::format("{} ({})", case_id, fidelity); }
};

/// The first body of the case with a "membrane" object, or null.
json capsule_body(const json& case_doc) {
  const json& bodies = member(member(case_doc, "physics"), "bodies");
  if (bodies.is_array())
    for (const auto& b : bodies)
      if (b.is_object() && member(b, "membrane").is_object()) return b;
  return nullptr;
}

/// summary.json metric `name` as written: x of {"value": x, ...}, or the metric itself; null if absent.
json summary_value(const json& summary, const std::string& name) {
  const json& metrics = member(summary, "metrics");
  if (!metrics.is_object() || !metrics.contains(name)) return nullptr;
  return metric_json(metrics[name]);
}

std::string mode_of(const Run& run) {
  const json v = summary_value(run.summary, "mode");
  return v.is_string() ? v.get<std::string>() : "";
}

/// The run's capsule in the keys of the claims, with the case-file defaults (claims.hpp).
json parameters(const json& case_doc) {
  const json body = capsule_body(case_doc);
  const json& shape = member(body, "shape");
  const json& membrane = member(body, "membrane");
  const json kind = member(shape, "type");
  json p = {{"shape", kind},
            {"capillary", number_or(membrane, "capillary", nullptr)},
            {"bending_ratio", number_or(membrane, "bending_ratio", 0.0)},
            {"reference_curvature", membrane.is_object() && membrane.contains("reference_curvature")
                                        ? membrane["reference_curvature"]
                                        : json("initial")},
            {"reynolds", number_or(member(case_doc, "physics"), "reynolds", nullptr)},
            {"angle", number_or(shape, "angle", 0.0)},
            {"aspect_ratio", kind == "ellipse"           ? number_or(shape, "aspect_ratio", 2.0)
                             : kind == "oblate_spheroid" ? number_or(shape, "aspect_ratio", nullptr)
                                                         : json(nullptr)},
            {"law", membrane.is_object() && membrane.contains("law") ? membrane["law"] : json(nullptr)},
            {"area_dilation", number_or(membrane, "area_dilation", nullptr)},
            {"alpha", kind == "biconcave" ? number_or(shape, "alpha", 1.39) : json(nullptr)}};
  if (kind == "circle" && p["reference_curvature"] == "circle") p["reference_curvature"] = "initial";
  return p;
}

Run load_run(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw core::InputError("run directory '" + dir.string() + "' does not exist");
  Run run;
  run.dir = dir;
  run.case_doc = read_object(dir / "case.json");
  run.summary = read_object(dir / "summary.json");
  run.score = read_object(dir / "score.json");
  run.manifest = read_object(dir / "manifest.json");
  const json& manifest = run.manifest;
  run.status = io::RunDirectory::run_status(dir);
  if (run.status == "missing") run.status = "incomplete";  // a directory without manifest: never finished
  for (const json* id : {&member(run.case_doc, "id"), &member(manifest, "case_id")})
    if (run.case_id.empty() && id->is_string()) run.case_id = id->get<std::string>();
  if (run.case_id.empty()) {  // results/<fidelity>/<id with "/" as "__"> (scripts/reproduce)
    const std::string name = dir.filename().string();
    for (std::size_t i = 0; i < name.size(); ++i) {
      const bool separator = name.compare(i, 2, "__") == 0;
      run.case_id += separator ? '/' : name[i];
      if (separator) ++i;
    }
  }
  for (const json* f : {&member(manifest, "fidelity"), &member(run.case_doc, "fidelity_applied"),
                        &member(run.summary, "fidelity")})
    if (run.fidelity.empty() && f->is_string()) run.fidelity = f->get<std::string>();
  if (run.fidelity.empty())
    run.fidelity = dir.parent_path().filename().string();  // results/<fidelity>/<case>
  run.params = parameters(run.case_doc);
  const json spacing = number_or(member(member(run.case_doc, "numerics"), "grid"), "fine_spacing", nullptr);
  run.fine_spacing = finite(spacing) && spacing.get<double>() > 0 ? spacing : json(nullptr);
  return run;
}

bool is_capsule(const Run& run) {
  return !capsule_body(run.case_doc).is_null() ||
         !summary_value(run.summary, "taylor_deformation_final").is_null();
}

/// The series.h5 column of `metric` (a capsule column, also as "<body>.<metric>"), if any.
const std::vector<double>* series_column(Run& run, const std::string& metric) {
  if (!run.series) {
    run.series.emplace();
    const fs::path file = run.dir / "series.h5";
    std::error_code ec;
    try {
      if (fs::is_regular_file(file, ec)) {
        auto data = io::read_series(file);
        if (data.count("t")) run.series->emplace("t", data["t"]);
        for (const auto& c : io::read_series_columns(file))
          for (const char* name : kSeries)
            if (c.name == name ||
                (c.name.size() > std::string(name).size() + 1 && c.name.ends_with(std::string(".") + name)))
              run.series->emplace(name, data[c.name]);  // the first matching column wins
      }
    } catch (const std::exception&) {
      // An unreadable series.h5 leaves the statistic unavailable, like a missing one.
    }
  }
  const auto it = run.series->find(metric);
  return it == run.series->end() ? nullptr : &it->second;
}

/// The number a trend or bound claim is about for one run: the "statistic" ("max"/"min") of
/// its series.h5 column, or its summary metric.
std::optional<double> statistic(Run& run, const json& claim) {
  const json& metric = member(claim, "metric");
  if (!metric.is_string() || metric.get_ref<const std::string&>().empty()) return std::nullopt;
  const json& stat = member(claim, "statistic");
  if (stat == "max" || stat == "min") {
    const auto* values = series_column(run, metric.get<std::string>());
    std::optional<double> out;
    if (values)
      for (double v : *values)
        if (std::isfinite(v)) out = !out ? v : (stat == "max" ? std::max(*out, v) : std::min(*out, v));
    return out;
  }
  const json v = summary_value(run.summary, metric.get<std::string>());
  return finite(v) ? std::optional<double>(v.get<double>()) : std::nullopt;
}

// ---- which runs a claim is about ----------------------------------------------------------------

bool matches(const json& value, const json& wanted) {
  if (wanted.is_null()) return true;
  if (wanted.is_array())
    return std::any_of(wanted.begin(), wanted.end(), [&](const json& w) { return matches(value, w); });
  if (wanted.is_object()) {
    const json &lo = member(wanted, "from"), &hi = member(wanted, "to");
    if (!finite(value) || !finite(lo) || !finite(hi)) return false;
    const double v = value.get<double>();
    return lo.get<double>() - 1e-12 <= v && v <= hi.get<double>() + 1e-12;
  }
  if (wanted.is_string()) return value == wanted;
  if (!finite(wanted) || !finite(value)) return false;
  const double a = value.get<double>(), b = wanted.get<double>();  // math.isclose(rel 1e-6, abs 1e-12)
  return std::abs(a - b) <= std::max(1e-6 * std::max(std::abs(a), std::abs(b)), 1e-12);
}

std::string symbol(const std::string& key) {
  static const std::map<std::string, std::string> symbols{{"aspect_ratio", "r"},         {"alpha", "α"},
                                                          {"reference_curvature", "κ0"}, {"capillary", "G"},
                                                          {"bending_ratio", "E_b"},      {"reynolds", "Re"},
                                                          {"area_dilation", "C"}};
  const auto it = symbols.find(key);
  return it == symbols.end() ? key : it->second;
}

/// The parameters of `claim` that `params` does not satisfy (empty when the claim is about the run).
std::vector<std::string> mismatches(const json& claim, const json& params) {
  std::vector<std::string> wrong;
  const json& wanted = member(claim, "parameters");
  if (!wanted.is_object()) return wrong;
  for (const auto& [key, w] : wanted.items()) {
    if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end() &&
        std::find(kMatchOnlyKeys.begin(), kMatchOnlyKeys.end(), key) == kMatchOnlyKeys.end())
      continue;
    if (key == "reference_curvature" && params["bending_ratio"] == 0.0) continue;  // no bending: no role
    if (!matches(params[key], w))
      wrong.push_back(fmt::format("{} = {} (claim: {})", symbol(key), params[key].dump(), w.dump()));
  }
  return wrong;
}


/// The acceptance entry of the run's case that names the claim ("...json#<id>"), or null.
const json* naming_entry(const Run& run, const std::string& id) {
  const json& acceptance = member(run.case_doc, "acceptance");
  if (!acceptance.is_array()) return nullptr;
  for (const auto& a : acceptance) {
    const json& ref = member(a, "reference");
    if (!ref.is_string()) continue;
    const std::string& r = ref.get_ref<const std::string&>();
    if (r.find(".json#") != std::string::npos && r.substr(r.rfind('#') + 1) == id) return &a;
  }
  return nullptr;
}

/// The score.json verdict of the accuracy entry for `entry`'s metric, or "not scored".
std::string scored_verdict(const Run& run, const json& entry) {
  const json& entries = member(member(run.score, "accuracy"), "entries");
  if (entries.is_array())
    for (const auto& e : entries)
      if (e.is_object() && member(e, "metric") == member(entry, "metric")) {
        const json& v = member(e, "verdict");
        return v.is_string() ? v.get<std::string>() : "";
      }
  return "not scored";
}

// ---- one claim -------------------------------------------------------------------------------

/// A run a claim is about, with its row in the claim's "runs".
struct Chosen {
  Run* run;
  std::vector<std::string> wrong;  // parameters that do not match (a run naming the claim)
  std::size_t row;
};

/// What a kind's check concluded; the claim's verdict follows from it (claims.hpp).
enum class Outcome { nothing, consistent, inconsistent, undecided, not_checkable };
struct KindResult {
  Outcome outcome = Outcome::nothing;
  std::string message;
};

json verdict_json(const std::optional<bool>& v) { return v ? json(*v ? "pass" : "fail") : json(nullptr); }

/// Outcome of the judged rows of a mode or bound check.
KindResult from_rows(const json& rows, const std::vector<Chosen>& ok, std::vector<std::string> failures) {
  const bool judged =
      std::any_of(ok.begin(), ok.end(), [&](const Chosen& c) { return !rows[c.row]["verdict"].is_null(); });
  if (!failures.empty()) return {Outcome::inconsistent, join(failures, "; ")};
  return {judged ? Outcome::consistent : Outcome::nothing, ""};
}

KindResult check_mode(const json& claim, const std::vector<Chosen>& ok, json& rows) {
  std::vector<std::string> modes;
  const json& m = claim.contains("modes") ? claim["modes"] : member(claim, "mode");
  if (m.is_string()) modes.push_back(m.get<std::string>());
  if (m.is_array())
    for (const auto& x : m)
      if (x.is_string()) modes.push_back(x.get<std::string>());
  std::vector<std::string> failures;
  for (const auto& c : ok) {
    json& row = rows[c.row];
    const std::string mode = mode_of(*c.run);
    const Comparison cmp = compare_mode(mode, modes);
    row["value"] = string_or_null(mode);
    row["verdict"] = verdict_json(cmp.pass && c.wrong.empty());
    if (!cmp.pass) row["note"] = mode.empty() ? "no mode in summary.json" : cmp.message;
    if (cmp.pass && !c.wrong.empty()) row["note"] = "not about this claim: " + join(c.wrong, "; ");
    if (row["verdict"] == "fail") failures.push_back(c.run->label() + ": " + row["note"].get<std::string>());
  }
  return from_rows(rows, ok, failures);
}

/// Reversals of the inclination in the last stage of a time sequence: two whole swings.
constexpr int kSequenceReversals = 4;

/// A sequence of regimes within each run (claims.hpp, "sequence"); judged for tumbling, then
/// swinging, from the series inclination (continuous, rad): the last stage follows the end of
/// the last turn through pi.
KindResult check_time_sequence(const json& claim, const std::vector<Chosen>& ok, json& rows) {
  const json& sequence = member(claim, "sequence");
  if (sequence != json{"tumbling", "oscillating_tank_treading"})
    return {Outcome::not_checkable,
            "of the time sequences only [\"tumbling\", \"oscillating_tank_treading\"] is judged"};
  std::vector<std::string> failures;
  for (const auto& c : ok) {
    json& row = rows[c.row];
    const std::vector<double>* t = series_column(*c.run, "t");
    const std::vector<double>* theta = series_column(*c.run, "inclination");
    if (!t || !theta || t->size() != theta->size() ||
        !std::all_of(theta->begin(), theta->end(), [](double v) { return std::isfinite(v); })) {
      row["note"] = "no finite series inclination (with t) in series.h5";
      continue;
    }
    // The longest end of the run over which the inclination spans less than pi.
    const std::size_t n = theta->size();
    std::size_t start = n;  // its first sample
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    while (start > 0) {
      lo = std::min(lo, (*theta)[start - 1]);
      hi = std::max(hi, (*theta)[start - 1]);
      if (hi - lo >= std::numbers::pi) break;
      --start;
    }
    const json& threshold = member(member(c.run->case_doc, "outputs"), "oscillation_threshold");
    const double threshold_rad = finite(threshold) ? threshold.get<double>() * std::numbers::pi / 180
                                                   : diagnostics::default_oscillation_threshold;
    // That suffix still holds the end of the last turn: the last stage starts at the turn's
    // extreme, the first turning point in it (a swing's first reversal); without one it is the
    // whole suffix.
    if (start > 0)
      for (const std::size_t k : diagnostics::turning_points(*theta, 2 * threshold_rad))
        if (k >= start) {
          start = k;
          break;
        }
    if (start == 0 || n - start < 3) {
      row["verdict"] = "fail";
      row["note"] = start == 0 ? "no initial tumbling: the inclination spans less than pi over the whole run"
                               : "too few samples after the inclination's last turn through pi";
      failures.push_back(c.run->label() + ": " + row["note"].get<std::string>());
      continue;
    }
    const auto [first_lo, first_hi] = std::minmax_element(theta->begin(), theta->begin() + start + 1);
    const diagnostics::CapsuleMotion last =
        diagnostics::classify_capsule_motion(*t, *theta, (*t)[start], threshold_rad);
    const bool swings =
        last.mode == "oscillating_tank_treading" && last.inclination_reversals >= kSequenceReversals;
    row["parameter"] = (*t)[start];
    row["value"] = fmt::format(
        "turned {:.3g} rad up to t = {:.4g}, then {} ({} reversals, half range {:.3g} degrees) to t = {:.4g}",
        *first_hi - *first_lo, (*t)[start], last.mode, last.inclination_reversals,
        last.inclination_amplitude * 180 / std::numbers::pi, t->back());
    row["verdict"] = verdict_json(swings && c.wrong.empty());
    if (!swings)
      row["note"] = fmt::format(
          "the last stage (from t = {:.4g}) is {}, not swinging ({} reversals of more than {:.3g} degrees; {} "
          "needed)",
          (*t)[start], last.mode, last.inclination_reversals, 2 * threshold_rad * 180 / std::numbers::pi,
          kSequenceReversals);
    if (swings && !c.wrong.empty()) row["note"] = "not about this claim: " + join(c.wrong, "; ");
    if (row["verdict"] == "fail") failures.push_back(c.run->label() + ": " + row["note"].get<std::string>());
  }
  return from_rows(rows, ok, failures);
}

/// The modes a side of a bracket accepts: the regime of `side` (claims.hpp).
std::vector<std::string> regime(const std::string& side) {
  const bool tank_treading =
      std::find(kTankTreading.begin(), kTankTreading.end(), side) != kTankTreading.end();
  return tank_treading ? kTankTreading : std::vector<std::string>{"tumbling"};
}

KindResult check_bracket(const json& claim, const std::vector<Chosen>& ok, json& rows) {
  const json &varying = member(claim, "varying"), &between = member(claim, "between");
  const json &below = member(claim, "below"), &above = member(claim, "above");
  if (!varying.is_string() || !between.is_array() || between.size() != 2 || !finite(between[0]) ||
      !finite(between[1]) || !below.is_string() || !above.is_string())
    return {
        Outcome::not_checkable,
        "a bracket needs \"varying\" (a parameter), \"between\": [lo, hi], \"below\" and \"above\" (modes)"};
  const double lo = between[0].get<double>(), hi = between[1].get<double>();
  std::vector<std::pair<double, std::string>> points;
  std::vector<std::string> labels;
  std::vector<std::size_t> at;
  for (const auto& c : ok) {
    json& row = rows[c.row];
    const json x = c.run->params.value(varying.get<std::string>(), json(nullptr));
    const std::string mode = mode_of(*c.run);
    row["parameter"] = x;
    row["value"] = string_or_null(mode);
    if (!finite(x)) {
      row["note"] = "no value of " + varying.get<std::string>();
      continue;
    }
    const double v = x.get<double>();
    row["note"] = v <= lo ? "below the bracket" : v >= hi ? "above the bracket" : "inside the bracket";
    points.emplace_back(v, mode);
    labels.push_back(c.run->label());
    at.push_back(c.row);
  }
  if (ok.empty()) return {};
  PointVerdicts verdicts;
  const Comparison cmp = compare_mode_bracket(points, lo, hi, regime(below.get<std::string>()),
                                              regime(above.get<std::string>()), labels, &verdicts);
  for (std::size_t k = 0; k < verdicts.size(); ++k) rows[at[k]]["verdict"] = verdict_json(verdicts[k]);
  if (!cmp.decided) return {Outcome::undecided, cmp.message};
  return {cmp.pass ? Outcome::consistent : Outcome::inconsistent, cmp.message};
}

/// A swing amplitude (half the range of an inclination over the window), which a tumbling run does
/// not have.
bool swing_metric(const std::string& metric) {
  return metric == "inclination_amplitude" || metric == "section_inclination_amplitude";
}

KindResult check_trend(const json& claim, const std::vector<Chosen>& ok, json& rows, json& series_out) {
  const json& varying_json = member(claim, "varying");
  if (!varying_json.is_string())
    return {Outcome::not_checkable,
            "several varying parameters (" + varying_json.dump() + "): not checkable"};
  const std::string varying = varying_json.get<std::string>(),
                    metric = member(claim, "metric").get<std::string>();
  const bool mode_metric = metric == "mode";
  const std::string direction =
      member(claim, "direction").is_string() ? claim["direction"].get<std::string>() : "";
  const json& limit = member(claim, "limit");
  std::optional<Direction> dir;
  std::string prefix;
  if (direction == "increasing") dir = mode_metric ? Direction::non_decreasing : Direction::increasing;
  if (direction == "decreasing") dir = mode_metric ? Direction::non_increasing : Direction::decreasing;
  if (direction == "sequence") dir = Direction::non_decreasing;
  if (direction == "approaches" && finite(limit)) {
    dir = Direction::decreasing;
    prefix = fmt::format("distance to the limit {:g}: ", limit.get<double>());
  }
  if (!dir)
    return {Outcome::not_checkable, "direction " + member(claim, "direction").dump() + " is not checkable"};
  if (mode_metric) prefix = "regime order (steady 0, oscillating 1, tumbling 2): ";

  struct Series {
    json fixed;
    std::vector<std::pair<double, double>> points;
    std::vector<std::string> labels;
    std::vector<std::size_t> rows;
  };
  std::vector<Series> series;
  std::map<std::string, std::size_t> index;
  for (const auto& c : ok) {
    json& row = rows[c.row];
    const json x = c.run->params.value(varying, json(nullptr));
    row["parameter"] = x;
    std::optional<double> y;
    if (mode_metric) {
      const std::string mode = mode_of(*c.run);
      row["value"] = string_or_null(mode);
      if (kModeOrder.count(mode)) y = kModeOrder.at(mode);
    } else if (swing_metric(metric) && mode_of(*c.run) == "tumbling") {
      // A tumbling capsule has no swing: its half range grows with the window (the thesis calls its
      // amplitude pi). Amplitude statements hold in the swinging region (claims.hpp).
      row["note"] = "tumbling: no swing amplitude";
      continue;
    } else {
      y = statistic(*c.run, claim);
      row["value"] = y ? json(*y) : json(nullptr);
    }
    if (!y || !finite(x)) {
      row["note"] = !y ? "no " + metric : "no value of " + varying;
      continue;
    }
    if (direction == "approaches") *y = std::abs(*y - limit.get<double>());
    json fixed = json::object();
    for (const char* k : kKeys)
      if (varying != k) fixed[k] = c.run->params[k];
    // Runs of one study: a trend is read along one chapter's sweep at one grid (a chapter 2
    // grid-study member, which at quick stops at k t = 4, is no point of chapter 3's sweep of
    // steady capsules, although its capsule parameters match). Not the averaging window: the
    // members of a sweep choose theirs by when they settle.
    fixed["fidelity"] = c.run->fidelity;
    fixed["fine_spacing"] = c.run->fine_spacing;
    const std::size_t slash = c.run->case_id.rfind('/');  // a user's own case may have no folder
    fixed["chapter"] = slash == std::string::npos ? std::string() : c.run->case_id.substr(0, slash);
    const auto [it, added] = index.emplace(fixed.dump(), series.size());
    if (added) series.push_back({std::move(fixed), {}, {}, {}});
    Series& s = series[it->second];
    s.points.emplace_back(x.get<double>(), *y);
    s.labels.push_back(c.run->label());
    s.rows.push_back(c.row);
    row["series"] = it->second;
  }
  std::vector<std::string> failures;
  bool passed = false;
  for (std::size_t i = 0; i < series.size(); ++i) {
    PointVerdicts verdicts;
    const Comparison cmp = compare_trend(series[i].points, *dir, 0.0, series[i].labels, &verdicts);
    for (std::size_t k = 0; k < verdicts.size(); ++k)
      rows[series[i].rows[k]]["verdict"] = verdict_json(verdicts[k]);
    const std::string message = cmp.message.empty() ? "" : prefix + cmp.message;
    const char* verdict = !cmp.decided ? "not enough runs" : cmp.pass ? "consistent" : "inconsistent";
    series_out.push_back({{"fixed", series[i].fixed},
                          {"verdict", verdict},
                          {"error", std::isfinite(cmp.error) ? json(cmp.error) : json(nullptr)},
                          {"message", message}});
    if (cmp.decided && !cmp.pass) failures.push_back(fmt::format("series {}: {}", i, message));
    passed = passed || (cmp.decided && cmp.pass);
  }
  if (!failures.empty()) return {Outcome::inconsistent, join(failures, "; ")};
  if (passed) return {Outcome::consistent, ""};
  if (ok.empty()) return {};
  return {Outcome::undecided,
          fmt::format("no series of runs with two values of {} (same other parameters, chapter, fidelity and grid)",
                      varying)};
}

KindResult check_bound(const json& claim, const std::vector<Chosen>& ok, json& rows) {
  const json &lower = member(claim, "lower"), &upper = member(claim, "upper");
  if ((!lower.is_null() && !finite(lower)) || (!upper.is_null() && !finite(upper)))
    return {Outcome::not_checkable, "\"lower\" and \"upper\" must be numbers"};
  if (lower.is_null() && upper.is_null()) return {Outcome::not_checkable, "the bound states no number"};
  const bool strict = member(claim, "strict") == true;
  const std::string metric = claim["metric"].get<std::string>();
  std::vector<std::string> failures;
  bool any_pass = false;
  for (const auto& c : ok) {
    json& row = rows[c.row];
    const auto v = statistic(*c.run, claim);
    row["value"] = v ? json(*v) : json(nullptr);
    if (!v) {
      row["note"] = "no " + metric;
      continue;
    }
    std::vector<std::string> outside;
    if (!lower.is_null() && !(strict ? *v > lower.get<double>() : *v >= lower.get<double>()))
      outside.push_back(fmt::format("{:.6g} is not {} {:.6g}", *v, strict ? ">" : ">=", lower.get<double>()));
    if (!upper.is_null() && !(strict ? *v < upper.get<double>() : *v <= upper.get<double>()))
      outside.push_back(fmt::format("{:.6g} is not {} {:.6g}", *v, strict ? "<" : "<=", upper.get<double>()));
    row["verdict"] = verdict_json(outside.empty());
    if (!outside.empty()) row["note"] = join(outside, ", ");
    any_pass = any_pass || outside.empty();
  }
  const bool some = member(claim, "quantifier") == "some";
  for (const auto& c : ok) {
    json& row = rows[c.row];
    if (row["verdict"] != "fail") continue;
    if (some && any_pass) {
      row["verdict"] = nullptr;  // one run inside suffices; the others are shown
    } else {
      failures.push_back(c.run->label() + ": " + row["note"].get<std::string>());
    }
  }
  return from_rows(rows, ok, failures);
}

void list_values(const json& claim, const std::vector<Chosen>& ok, json& rows) {
  const json &metric = member(claim, "metric"), &ref = member(claim, "value");
  if (!metric.is_string() || !finite(ref)) return;
  for (const auto& c : ok) {
    const json v = summary_value(c.run->summary, metric.get<std::string>());
    rows[c.row]["value"] = finite(v) ? v : json(nullptr);
    if (!finite(v))
      rows[c.row]["note"] = "no " + metric.get<std::string>();
    else if (ref.get<double>() != 0)
      rows[c.row]["note"] =
          fmt::format("{:+.1f} % from {:.4g}",
                      100 * (v.get<double>() - ref.get<double>()) / ref.get<double>(), ref.get<double>());
  }
}

json evaluate_claim(const json& claim, std::vector<Run>& runs) {
  const std::string id = claim["id"].get<std::string>();
  const json& kind_json = member(claim, "kind");
  const std::string kind = kind_json.is_string() ? kind_json.get<std::string>() : "";
  const json& metric = member(claim, "metric");
  const bool has_metric = metric.is_string() && !metric.get_ref<const std::string&>().empty();
  json out = {{"id", id},
              {"kind", kind_json},
              {"verdict", ""},
              {"message", ""},
              {"varying", member(claim, "varying")},
              {"metric", metric},
              {"direction", member(claim, "direction")},
              {"problems", json::array()},
              {"runs", json::array()}};
  json& rows = out["runs"];
  std::vector<Chosen> ok;
  std::vector<std::string> problems;
  for (auto& run : runs) {
    std::vector<std::string> wrong = mismatches(claim, run.params);
    const json* named = naming_entry(run, id);
    if (named && !wrong.empty())
      problems.push_back(run.case_id + " names this claim in its acceptance, but " + join(wrong, "; "));
    if (!wrong.empty() && !named) continue;
    json row = {{"run", run.case_id},   {"fidelity", run.fidelity}, {"directory", run.dir.string()},
                {"status", run.status}, {"parameter", nullptr},     {"value", nullptr},
                {"verdict", nullptr}};
    if (named) row["scored"] = scored_verdict(run, *named);
    if (run.status != "ok") row["note"] = "run " + run.status;
    rows.push_back(std::move(row));
    if (run.status == "ok") ok.push_back({&run, std::move(wrong), rows.size() - 1});
  }

  // Not checkable whatever the runs say (a run naming such a claim is not judged either).
  std::string immune;
  const bool time_sequence =
      kind == "trend" && member(claim, "varying") == "time" && member(claim, "sequence").is_array();
  if (kind == "value") immune = "a value statement: the runs' values are listed, not judged";
  if ((kind == "trend" || kind == "bound") && !has_metric && !time_sequence)
    immune = "no \"metric\": not in summary.json";

  KindResult result;
  if (kind == "mode") result = check_mode(claim, ok, rows);
  if (kind == "bracket") result = check_bracket(claim, ok, rows);
  if (time_sequence) {
    result = check_time_sequence(claim, ok, rows);
  } else if (kind == "trend" && has_metric) {
    out["series"] = json::array();
    result = check_trend(claim, ok, rows, out["series"]);
  }
  if (kind == "bound" && has_metric) result = check_bound(claim, ok, rows);
  if (kind == "value") list_values(claim, ok, rows);

  for (const auto& p : problems) out["problems"].push_back(p);
  std::string verdict, message = result.message;
  if (!immune.empty()) {
    verdict = "not checked";
    message = immune;
  } else if (!problems.empty() || result.outcome == Outcome::inconsistent) {
    verdict = "inconsistent";
    message = join(problems, "; ") + (problems.empty() || message.empty() ? "" : "; ") + message;
  } else if (result.outcome == Outcome::consistent) {
    verdict = "consistent";
  } else if (result.outcome == Outcome::not_checkable) {
    verdict = "not checked";
  } else if (ok.empty()) {
    verdict = "no run";
    message = rows.empty() ? "no capsule run is about this claim" : "no run about this claim finished \"ok\"";
  } else if (result.outcome == Outcome::undecided) {
    verdict = "not enough runs";
  } else {
    verdict = "not checked";
  }
  out["verdict"] = verdict;
  out["message"] = message;
  return out;
}

/// A claim with a "check" object (motion_claims.hpp): runs chosen by case id, not by parameters.
json evaluate_check_claim(const json& claim, std::vector<ClaimRun>& runs, const json& consistency) {
  CheckOutcome outcome = check_motion_claim(claim, runs, consistency);
  return {{"id", claim["id"]},
          {"kind", member(claim, "kind")},
          {"check", member(member(claim, "check"), "type")},
          {"verdict", outcome.verdict},
          {"message", outcome.message},
          {"varying", member(claim, "varying")},
          {"metric", member(claim, "metric")},
          {"direction", member(claim, "direction")},
          {"problems", json::array()},
          {"runs", std::move(outcome.rows)}};
}

}  // namespace

json evaluate_claims(const json& claims, const std::vector<fs::path>& run_dirs,
                     const ClaimsOptions& options) {
  if (!claims.is_object() || !claims.contains("claims") || !claims["claims"].is_array())
    throw core::InputError(
        "a claims file is {\"claims\": [...]} (references/capsule2d/claims.json); this one has no "
        "\"claims\" array");
  json result = {{"claims_file", nullptr},   {"runs", json::array()},     {"moving_runs", json::array()},
                 {"ignored", json::array()}, {"problems", json::array()}, {"claims", json::array()},
                 {"counts", json::object()}};
  std::vector<Run> runs;
  std::vector<ClaimRun> check_runs;  // every run: the claims with a "check" choose by case id
  for (const auto& dir : run_dirs) {
    Run run = load_run(dir);
    ClaimRun& check_run = check_runs.emplace_back();
    check_run.dir = run.dir;
    check_run.case_id = run.case_id;
    check_run.fidelity = run.fidelity;
    check_run.status = run.status;
    check_run.case_doc = run.case_doc;
    check_run.manifest = run.manifest;
    check_run.score = run.score;
    if (!is_capsule(run)) {
      const bool moving = is_moving(run.case_doc);
      if (moving)
        result["moving_runs"].push_back({{"run", run.case_id},
                                         {"fidelity", run.fidelity},
                                         {"directory", dir.string()},
                                         {"status", run.status}});
      else
        result["ignored"].push_back(
            {{"directory", dir.string()},
             {"reason",
              "not a capsule run (no membrane body in case.json, no "
              "taylor_deformation_final) nor a moving one: read only by claims with a "
              "\"check\" that name its case"}});
      continue;
    }
    result["runs"].push_back({{"run", run.case_id},
                              {"fidelity", run.fidelity},
                              {"directory", dir.string()},
                              {"status", run.status},
                              {"parameters", run.params}});
    runs.push_back(std::move(run));
  }
  std::set<std::string> seen;
  const json& list = claims["claims"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& id = member(list[i], "id");
    if (!id.is_string() || id.get_ref<const std::string&>().empty()) {
      result["problems"].push_back(fmt::format("claims/{}: a claim without an id (skipped)", i));
      continue;
    }
    if (!seen.insert(id.get<std::string>()).second) {
      result["problems"].push_back(
          fmt::format("claims/{}: claim id {} appears twice (skipped)", i, id.dump()));
      continue;
    }
    if (!id.get_ref<const std::string&>().starts_with(options.id_prefix)) continue;
    json verdict = member(list[i], "check").is_object()
                       ? evaluate_check_claim(list[i], check_runs, options.consistency)
                       : evaluate_claim(list[i], runs);
    auto& count = result["counts"][verdict["verdict"].get<std::string>()];
    count = count.is_null() ? 1 : count.get<int>() + 1;
    result["claims"].push_back(std::move(verdict));
  }
  return result;
}

json evaluate_claims(const fs::path& claims_file, const std::vector<fs::path>& run_dirs,
                     const ClaimsOptions& options) {
  std::ifstream in(claims_file);
  if (!in) throw core::InputError("cannot read the claims file '" + claims_file.string() + "'");
  const json doc = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded())
    throw core::InputError("the claims file '" + claims_file.string() + "' is not valid JSON");
  ClaimsOptions with_consistency = options;
  if (with_consistency.consistency.is_null()) {  // the start left out etc., beside the claims file
    const json provenance = read_object(claims_file.parent_path() / "provenance.json");
    with_consistency.consistency = member(provenance, "consistency");
  }
  json result = evaluate_claims(doc, run_dirs, with_consistency);
  result["claims_file"] = claims_file.string();
  return result;
}

std::string format_claims(const json& result) {
  const auto text = [](const json& v) { return v.is_string() ? v.get<std::string>() : std::string("-"); };
  const auto size = [](const json& v) { return v.is_array() ? v.size() : std::size_t{0}; };
  std::string out = fmt::format("claims of {}: {} capsule run(s), {} moving-body run(s), {} other run(s)\n",
                                text(member(result, "claims_file")), size(member(result, "runs")),
                                size(member(result, "moving_runs")), size(member(result, "ignored")));
  out += fmt::format("{:<44} {:<8} {:<16} {}\n", "claim", "kind", "verdict", "runs judged/about");
  std::string notes;
  for (const auto& c : array_or_empty(member(result, "claims"))) {
    const json& runs = member(c, "runs");
    std::size_t judged = 0;
    for (const auto& r : array_or_empty(runs)) judged += member(r, "verdict").is_null() ? 0 : 1;
    const std::string verdict = text(member(c, "verdict")), message = text(member(c, "message"));
    out += fmt::format("{:<44} {:<8} {:<16} {}/{}\n", text(member(c, "id")), text(member(c, "kind")), verdict,
                       judged, size(runs));
    if ((verdict == "inconsistent" || verdict == "not enough runs") && message != "-")
      notes += fmt::format("  {} ({}): {}\n", text(member(c, "id")), verdict, message);
  }
  if (!notes.empty()) out += "\n" + notes;
  std::string counts;
  const json& count = member(result, "counts");
  if (count.is_object())
    for (const auto& [verdict, n] : count.items())
      counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n.dump(), verdict);
  out += "\n" + (counts.empty() ? std::string("no claims") : counts) + "\n";
  for (const auto& p : array_or_empty(member(result, "problems"))) out += "problem: " + text(p) + "\n";
  return out;
}

int claims_exit_code(const json& result, bool strict) {
  if (!strict) return 0;
  if (!result.is_object() || !result.contains("claims") || !result["claims"].is_array()) return 1;
  for (const auto& c : result["claims"])
    if (!c.is_object() || c.value("verdict", json("inconsistent")) == "inconsistent") return 1;
  return 0;
}

}  // namespace caplab::score
