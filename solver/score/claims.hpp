// Cross-run check of thesis statements (references/*/claims.json, format in
// references/capsule2d/provenance.json): do the capsule runs together agree with "D grows with
// G", "tumbling above E_b = 0.06", ...? score.json stays the per-run verdict; this is the
// verdict of a set of runs on one statement. Used by `caplab claims` and the reports.
//
// Two shapes of claim. A claim with a "check" object (references/moving/claims.json: moving
// rigid bodies and the multi-block grid) names its runs by case id ("cases") and is judged by
// that check: proximity_means, twin, refinement, fine_fraction, all of them in
// motion_claims.hpp, which also gives the fields its run rows add ("details", "part",
// "against"). Every other claim chooses capsule runs by parameters, as follows.
//
// Runs. A run directory is read for case.json, summary.json, manifest.json ("status",
// "fidelity", "case_id") and, when a claim needs it, score.json and series.h5. The claims with
// a "check" see every run directory given (selection by case id; partners such as the uniform
// twin by pairing). The others consider only capsule runs: a body with a "membrane" object, or
// a summary metric taylor_deformation_final. Its fidelity is the manifest's (else case.json "fidelity_applied",
// summary.json "fidelity", the name of the parent directory, results/<fidelity>/<case>); a
// directory without manifest.json is "incomplete". A run's parameters in the keys of the claims are read from its
// first membrane body, with the case-file defaults where a key is absent:
//   shape (shape.type), capillary, bending_ratio (0), reference_curvature ("initial"; a circle
//   with "circle" counts as "initial"), reynolds (physics.reynolds), angle (0),
//   aspect_ratio (2 for ellipses; oblate spheroids: as given), alpha (1.39, biconcave shapes
//   only), law (membrane.law), area_dilation (membrane.area_dilation, Skalak only).
//
// Which runs a claim is about. Every key of the claim's "parameters" among shape,
// aspect_ratio, alpha, reference_curvature, capillary, bending_ratio, reynolds, law,
// area_dilation must match
// (other keys are ignored; reference_curvature is ignored for a run with bending_ratio 0): a
// number within rel 1e-6 / abs 1e-12, a string exactly, {"from", "to"} inclusive (±1e-12),
// an array as any of its elements. A key the claim does not give is free (the parameter a
// trend varies). A run whose acceptance names the claim ("...json#<id>") is used even when it
// does not match, and that mismatch alone makes the claim "inconsistent". Runs whose status is
// not "ok" are listed and never judged.
//
// Kinds (each run's value is a summary.json metric; for a "statistic" of "max"/"min" the
// extreme of the series.h5 column named by "metric", one of taylor_deformation, inclination,
// area_change, tank_treading_phase, also as "<body>.<name>"):
//   mode     each run's summary "mode" is one of the claim's "modes" (or "mode");
//   bracket  compare_mode_bracket over ("varying" value, mode) with "between": [lo, hi],
//            "below" and "above" read as regimes: a tank-treading side (steady_ or
//            oscillating_tank_treading) accepts either tank-treading mode, any other side
//            accepts "tumbling";
//   trend    compare_trend, tolerance 0, in each series of runs that share every parameter
//            above except "varying" and area_dilation, the fidelity,
//            numerics.grid.fine_spacing and the chapter (the case id's folder, "ch3" of
//            "ch3/circle_G0.04_Eb0"; none for an id without one): one chapter's sweep.
//            A swing amplitude ("inclination_amplitude", "section_inclination_amplitude") is
//            taken from swinging runs only (a tumbling run has none; its row says so).
//            "direction": increasing / decreasing (strict; for "metric": "mode", the regimes
//            ordered steady_tank_treading < oscillating_tank_treading < tumbling, non-strict),
//            "sequence" (non-decreasing), "approaches" with a numeric "limit" (|v − limit|
//            decreasing). Consistent when no decided series fails and one passes.
//            With "varying": "time" and "sequence": ["tumbling", "oscillating_tank_treading"]
//            (no "metric" needed) a sequence of regimes within each run, judged per run on the
//            series inclination (continuous, with t): the last stage starts where the last turn
//            through pi ends ("parameter": that time), i.e. in the longest end of the run over
//            which the inclination spans less than pi, at the extreme of the turn's direction
//            from which it first comes back by more than twice the case's threshold (the whole
//            end when it never does); the run passes when it turned through pi before (an initial tumbling) and
//            the last stage swings (diagnostics::classify_capsule_motion from there, with the
//            case's outputs.oscillation_threshold: oscillating_tank_treading with at least 4
//            reversals, two whole swings); "value" says what was found. Other sequences are not
//            checked;
//   bound    "lower" / "upper" (exclusive when "strict"), each run; "quantifier": "some"
//            needs one run inside, the others are listed unjudged; a bound without a number
//            is not checked;
//   value    the runs' metric is listed, never judged.
// A trend (but a time sequence) or bound without "metric", a trend with several "varying"
// parameters or another "direction", and every value claim are "not checked".
//
// Verdict of a claim, in this order: "not checked" for a value claim or a trend or bound
// without "metric"; "inconsistent" when a named run is not about the claim or the check fails
// (a decided comparison, a judged run); "consistent"; "not checked" for the other claims that
// cannot be checked (above); "no run" when no run of the claim finished "ok"; "not enough
// runs" for a trend or bracket that is undecided (no series with two parameter values, no run
// on one side of the bracket); else "not checked" (runs, but nothing to judge, e.g. no
// metric). Only "consistent" and "inconsistent" are decided.
//
// Layout of the result:
//   {"claims_file": path | null,
//    "runs": [{"run", "fidelity", "directory", "status", "parameters": {...}}],  // capsule runs
//    "moving_runs": [{"run", "fidelity", "directory", "status"}],  // a prescribed-motion body
//    "ignored": [{"directory", "reason"}],  // neither (still read by claims whose "cases" name them)
//    "problems": [...],                     // claims without id, duplicates
//    "claims": [{"id", "kind", "check"?, "verdict", "message", "varying", "metric", "direction",
//                "problems": [...],
//                "runs": [{"run", "fidelity", "directory", "status", "parameter", "value",
//                          "verdict": pass | fail | null, "note"?, "series"?, "scored"?,
//                          "details"?, "part"?, "against"?}],
//                "series"?: [{"fixed": {...}, "verdict", "error", "message"}]}],   // trends
//    "counts": {verdict: number of claims}}
// "parameter" is the run's value of "varying" (null when the claim varies none), "value" its
// metric (a number, the mode string, or null), "series" the index of its trend series,
// "scored" the score.json verdict of the acceptance entry naming the claim (when one does).
// For a claim with a "check": "check" is its type, "value" and "note" of a row are texts and
// "details" lists the lines behind them (motion_claims.hpp); a run may have several rows (one
// per "part" of a fine_fraction check).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace caplab::score {

struct ClaimsOptions {
  /// Only the claims whose id starts with this (e.g. "ch3."); empty: every claim.
  std::string id_prefix;
  /// The "consistency" object of references/moving/provenance.json (the start left out of
  /// run-to-run differences) for the claims with a "check"; null: evaluate_claims on a file
  /// reads it from the provenance.json beside that file, the document overload leaves out none.
  nlohmann::json consistency = nullptr;
};

/// Evaluates every claim of `claims` (a document {"claims": [...]}) against the runs in
/// `run_dirs` (layout in the file header); reads, never writes. Throws core::InputError when
/// `claims` has no "claims" array or a run directory does not exist.
nlohmann::json evaluate_claims(const nlohmann::json& claims,
                               const std::vector<std::filesystem::path>& run_dirs,
                               const ClaimsOptions& options = {});

/// evaluate_claims on the file `claims_file`; throws core::InputError when it cannot be read.
nlohmann::json evaluate_claims(const std::filesystem::path& claims_file,
                               const std::vector<std::filesystem::path>& run_dirs,
                               const ClaimsOptions& options = {});

/// The result as a text table (one row per claim, then the message of each inconsistent or
/// undecided claim, then the counts).
std::string format_claims(const nlohmann::json& result);

/// Exit status of `caplab claims`: 0 when not `strict`; when `strict`, 1 if a claim is
/// "inconsistent" (or the result is malformed), else 0.
int claims_exit_code(const nlohmann::json& result, bool strict);

}  // namespace caplab::score
