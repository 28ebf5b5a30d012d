// Thesis statements about moving rigid bodies and the multi-block grid (thesis sections
// 2.2.2-2.2.3, references/moving/claims.json): the claims with a "check" object. Unlike the
// capsule claims, whose runs are chosen by parameters, these name the case ids they are about
// ("cases") and are judged either on the flow of each run (proximity_means) or by comparing caplab
// runs with each other (twin, refinement, fine_fraction: consistency, caplab against caplab).
// Conventions (time scale, sign of the drag, relative RMS, fine fraction, cost) are those of
// references/moving/provenance.json; the numbers of each check are read from the claim and from
// provenance.json "consistency" (the start left out of run-to-run differences), never written here.
//
// Runs. Every run directory given to `caplab claims` is a ClaimRun; a claim takes those whose
// case id is in its "cases" (sorted by case id, then fidelity), and finds partners (the uniform
// twin, a finer grid, the pair of "compare_with") among all of them. series.h5 is read on first
// use; only columns as long as "t" are kept. A run whose status is not "ok" is listed, never judged.
//
// Checks ("check.type"):
//   proximity_means  per run: dx = x_<body> − x_<other> (series "<body>.x", "<other>.x");
//                    "approaching" is t < t_e, "separating" t > t_e, with t_e the first sign
//                    change of dx (linear interpolation; none: the run is not judged). Each
//                    window is an interval of dx ("(0, 3]", "[-3, 0)": round bracket open,
//                    square closed) and a phase. The drag opposing the motion is
//                    −sign(ū)·<body>.<column> ("column", default drag_coefficient), ū the mean of
//                    u_x = d x_<body>/dt (second-order differences, first order at the ends) over
//                    the samples of all windows; |ū| ≤ 1e-9: not judged. A window's mean needs
//                    kMinSamples finite samples; without the baseline's the run is not judged.
//                    Each window passes when its mean is "expect": above (>) or below (<) the
//                    baseline mean; the run passes when every window passes, and fails when
//                    one fails (even if another window has too few samples to be judged).
//   twin             per run: the relative RMS (below) of each of "columns" against the uniform
//                    twin, at most the claim's "upper". The twin of a run with
//                    numerics.grid.refinement "two_level": another run with refinement "uniform",
//                    the same fidelity, equal "physics" and fine spacing (rel 1e-9); finished runs
//                    first, then the one named "<case id>_uniform", then by case id.
//   refinement       per fidelity: the claim's "cases" are one grid study (a case and its
//                    members on finer grids, equal apart from numerics.grid), and a level's runs
//                    differ in the grid alone. Each two-level run whose fine spacing is coarser (by
//                    more than rel 1e-9) than the finest finished two-level run at its fidelity is
//                    compared with that run (the self-reference), as for twin. "check.fine_spacing"
//                    (optional): the grid the statement is about ("further refinement of this grid
//                    gives nearly the same results"); runs coarser than it are listed, not judged.
//   fine_fraction    per run, up to three rows ("part"): "fine fraction" = area of
//                    numerics.grid.fine_region over that of physics.domain.size, within
//                    check.tolerance of the claim's "value" ("as built", the fine block's node
//                    extent over the coarse block's from manifest lattice.blocks, is shown);
//                    "effort saved" = node updates (manifest lattice.node_updates) of the twin
//                    over the run's, above 1 (wall times, manifest or score.json performance
//                    wall_time_s, are shown, not judged); "saving less than <compare_with>" =
//                    the saving 1 − 1/ratio below that of the run of check.compare_with at the
//                    same fidelity and its twin.
// Relative RMS of a column between a run and a reference run: over t ≥ t_from (provenance.json
// consistency.twin_difference.from, else 0), each series linearly interpolated onto the other's
// abscissae in the overlap (score::rms_distance both ways), the larger RMS, over the peak |y| of
// the reference for t ≥ t_from. A non-finite sample from t_from on makes it NaN: never a pass.
//
// Result (the layout of a claim in claims.hpp; each row has "run", "fidelity", "directory",
// "status", "parameter" (null), "value", "verdict", "note", "details"):
//   "value"    the row's numbers in one line (a text), null when nothing could be computed;
//   "note"     why the row failed or was not judged ("" for a pass);
//   "details"  the lines behind the numbers (window means and spans, peaks, RMS over peak per
//              column, numerics in which the compared runs differ, node updates, ...);
//   "part"     (fine_fraction) which of the three statements the row is about;
//   "against"  (twin, refinement) "<case id> (<fidelity>)" of the reference run.
// Verdict: "inconsistent" when a row fails; "consistent" when one passes (the message names the
// rows not judged); else "no run" when no run of "cases" finished "ok", "not enough runs" when a
// row waits for a partner run (no twin, no finer grid, no compare_with pair), "not checked"
// otherwise (columns missing, no encounter, a malformed check or an unknown type).
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace caplab::score {

/// Fewer finite samples in a window than this and its mean is not taken.
inline constexpr std::size_t kMinSamples = 3;

/// A run directory as the claims with a "check" read it.
struct ClaimRun {
  std::filesystem::path dir;
  std::string case_id, fidelity, status;
  nlohmann::json case_doc, manifest, score;
  /// series.h5 columns (only those as long as "t"), read on first use; empty with `series_problem`.
  std::optional<std::map<std::string, std::vector<double>>> series;
  std::string series_problem;

  std::string label() const { return case_id + " (" + fidelity + ")"; }
};

/// A case with a body that moves on a prescribed path and has no membrane (catalogue/schema.json).
bool is_moving(const nlohmann::json& case_doc);

/// Verdict, message and run rows of one claim with a "check" (file header).
struct CheckOutcome {
  std::string verdict;  ///< consistent | inconsistent | no run | not enough runs | not checked
  std::string message;
  nlohmann::json rows = nlohmann::json::array();
};

/// Evaluates `claim` (one with a "check" object) against `runs`; `consistency` is the
/// "consistency" object of references/moving/provenance.json (null: nothing left out at the
/// start). Never throws for a malformed claim: it is "not checked" with a message.
CheckOutcome check_motion_claim(const nlohmann::json& claim, std::vector<ClaimRun>& runs,
                                const nlohmann::json& consistency);

/// t before which run-to-run differences are not taken: consistency.twin_difference.from, else 0.
double start_left_out(const nlohmann::json& consistency);

}  // namespace caplab::score
