// Scoring of a run directory (DESIGN.md sections 6 and 7): the one place where results are
// compared with references. Used at the end of `caplab run`, by `caplab score RUN_DIR
// [--strict]`, and read back (score.json) by the reports.
//
// Three separate verdicts:
//  - sanity: did it run correctly — manifest status "ok", every metric of summary.json a
//    finite number or a non-empty string (a classification such as "mode"), every boolean of
//    summary.json "sanity" true, |mass_drift| < 1e-3 when present;
//  - accuracy: each acceptance entry of case.json compared with its reference at the run's
//    fidelity level (comparators.hpp); "none" (with a reason) for a run that is not "ok" or a
//    case without acceptance entries;
//  - performance: wall time, MLUPS, steps and threads from the manifest, judged against the
//    case's "performance" "wall_time_budget_s" at the run's level: pass within it, fail over it,
//    "not judged" without a budget at that level or for a run that did not finish.
// The overall verdict fails when sanity or accuracy fails; performance never enters it (nor the
// exit code of --strict): wall time depends on the machine, its load and the thread count.
//
// Acceptance entries read from case.json (light validation here; a malformed entry fails with
// a message naming its JSON path, it never aborts scoring):
//   common:       "metric", "comparison", "tolerance" {level: number}, "reference", "justification"
//   relative, absolute: "reference_value" (number); "metric" is a key of summary.json "metrics"
//   bracket:      "bracket": [lo, hi]; "tolerance" optional: a margin allowed outside [lo, hi]
//                 (0 when the entry has no "tolerance" object)
//   time_series:  "metric" is a column of series.h5 (abscissa "t"); the reference series is
//                 "reference_series": {"t": [...], "value": [...]} or the CSV named by
//                 "reference" ("file.csv#t_column:value_column", see reference_series.hpp);
//                 optional "window": [from, to] (e.g. after the transient)
//   mode:         "reference_mode": a mode name or an array of allowed names (e.g. "tumbling",
//                 ["steady_tank_treading", "oscillating_tank_treading"]); "metric" is a key of
//                 summary.json "metrics" whose value is a string; no "tolerance" (exact match);
//                 "reference" names the statement, e.g. "references/capsule2d/claims.json#<id>"
//
// score.json layout:
//   {"case_id", "fidelity",
//    "sanity": {"verdict": pass|fail, "checks": [{"name","value","limit","verdict","message"}]},
//    "accuracy": {"verdict": pass|fail|none, "reason"?: "...", "entries": [{"metric","value",
//                 "unit","reference_value","reference","comparison","error","tolerance",
//                 "justification","verdict","message"?, "compared"?: {"from","to","points"}}]},
//    "performance": {"wall_time_s","mlups","steps","threads","budget_s","justification"?,
//                    "verdict": pass|fail|not judged, "reason"}, "verdict": pass|fail}
// A number that is not finite is written as null. For bracket entries "reference_value" is
// [lo, hi]; for time_series entries "value" and "reference_value" are null; for mode entries
// "value" is the metric's string, "reference_value" is "reference_mode" as written (a string or
// an array of strings), "error" is 0 (one of the reference modes) or 1, "tolerance" is null.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace caplab::score {

/// Limit on |mass_drift| of summary.json "sanity".
inline constexpr double kMassDriftLimit = 1e-3;

struct ScoreOptions {
  /// Directory against which relative reference paths ("references/...") are resolved. Empty:
  /// the ancestors of the run directory (nearest first), then the current directory.
  std::filesystem::path reference_root;
};

/// Scores the run in `run_dir` without writing anything (layout in the file header).
/// Throws core::InputError when `run_dir` is not a run directory (no manifest.json).
nlohmann::json evaluate_run(const std::filesystem::path& run_dir, const ScoreOptions& options = {});

/// evaluate_run, then writes the result to `run_dir`/score.json atomically; returns it.
nlohmann::json score_run(const std::filesystem::path& run_dir, const ScoreOptions& options = {});

/// Exit status of `caplab score`: 0 when not `strict`; when `strict`, 1 if the sanity or
/// accuracy verdict is "fail" (or missing), else 0.
int exit_code(const nlohmann::json& score, bool strict);

}  // namespace caplab::score
