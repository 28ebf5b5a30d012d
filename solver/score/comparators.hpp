// Comparators of the scoring module (DESIGN.md section 7): how one result is compared with
// its reference. Each is a pure function returning the error and the verdict; none throws.
//
//   relative     error = |v − r| / |r|                passes when error ≤ tol  (r ≠ 0)
//   absolute     error = |v − r|                      passes when error ≤ tol
//   bracket      error = distance from v to [lo, hi]  passes when error ≤ margin (0 in the bracket)
//   time_series  error = RMS over the reference abscissae t_i in the overlap of the two series
//                (and the optional window) of run(t_i) − ref(t_i), the run's series linearly
//                interpolated onto t_i; passes when error ≤ tol.
//   mode         a classification (e.g. the flow regime "tumbling"): error = 0 when the value
//                is one of the allowed reference modes, 1 otherwise; passes when error is 0.
//                A classification has no distance, so there is no tolerance.
//
// Sweep comparators: one verdict over the points (p, v) of several runs that differ in one
// parameter p (a thesis statement such as "D grows with G", references/*/claims.json).
//   trend        sorted by p, every point must move in the direction from every point at the
//                next lower value of p: increasing v > v' − tol, non_decreasing v ≥ v' − tol
//                (decreasing, non_increasing mirrored), so a tie fails a strict direction at
//                tol = 0. Points at the same p are not compared with each other (they show
//                no trend). error = the largest step against the direction, max s (v' − v)
//                with s = +1 (increasing) or −1 (decreasing): negative when every step goes
//                the right way. Undecided with fewer than two distinct values of p.
//   mode_bracket a regime transition lies between lo and hi: every point (p, mode) with
//                p ≤ lo has one of the `below` modes, every point with p ≥ hi one of the
//                `above` modes; points inside (lo, hi) are not judged. error = the number of
//                points on the wrong side. Undecided when no point is wrong and one side has
//                no point (a one-sided sweep does not locate a transition).
// An undecided comparison (decided = false) is neither a pass nor a failure: pass is false,
// error is NaN and the message says what is missing.
//
// Invariants: a non-finite value, reference, tolerance or error never passes; an empty mode
// name or an empty list of allowed modes never passes; a failing or undecided comparison
// always carries a message saying why.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace caplab::score {

/// Outcome of one comparison. `error` is NaN where it could not be computed.
struct Comparison {
  double error = 0.0;
  bool pass = false;
  std::string message;  ///< empty on a pass; why it failed (or could not decide) otherwise
  bool decided = true;  ///< false: the inputs cannot decide (sweep comparators); pass is false
};

/// |value − reference| / |reference| ≤ tolerance. Fails for reference 0 (use absolute).
Comparison compare_relative(double value, double reference, double tolerance);

/// |value − reference| ≤ tolerance.
Comparison compare_absolute(double value, double reference, double tolerance);

/// value in [lo − margin, hi + margin]; error is the distance from value to [lo, hi].
/// Fails when lo > hi.
Comparison compare_bracket(double value, double lo, double hi, double margin = 0.0);

/// A sampled series: abscissae `t` (strictly increasing) and values `y` of the same length.
struct Series {
  std::vector<double> t;
  std::vector<double> y;
};

/// Interval [from, to] to which a time-series comparison is restricted (e.g. after the transient).
struct Window {
  double from = 0.0;
  double to = 0.0;
};

/// Result of rms_distance: the distance and the abscissa range and count actually compared.
struct SeriesDistance {
  double rms = 0.0;
  double from = 0.0;
  double to = 0.0;
  std::size_t points = 0;
};

/// RMS distance between `run` and `reference`: `run` linearly interpolated onto the abscissae
/// of `reference` that lie in the overlap of both ranges (intersected with `window`, if given).
/// Throws core::Error naming both ranges when they do not overlap or no reference abscissa lies
/// in the overlap, and when a series is empty, has mismatched lengths, non-finite entries or
/// abscissae that are not strictly increasing.
SeriesDistance rms_distance(const Series& run, const Series& reference,
                            const std::optional<Window>& window = std::nullopt);

/// rms_distance(run, reference, window) ≤ tolerance; any error of rms_distance becomes a
/// failing Comparison with its message. When `detail` is given it receives the range and
/// point count compared (left untouched when rms_distance failed).
Comparison compare_time_series(const Series& run, const Series& reference, double tolerance,
                               const std::optional<Window>& window = std::nullopt,
                               SeriesDistance* detail = nullptr);

/// `value` is one of `allowed` (exact, case-sensitive string match). Fails when `allowed` is
/// empty or when `value` or one of `allowed` is an empty string.
Comparison compare_mode(std::string_view value, const std::vector<std::string>& allowed);

/// How the value of a trend moves as the parameter grows. The strict directions fail on a tie
/// (at tolerance 0); the non-strict ones accept it (e.g. a regime that persists over several
/// parameter values).
enum class Direction { increasing, decreasing, non_decreasing, non_increasing };

/// Per-point outcome of a sweep comparison, in the order of the input points: true or false
/// where the point was judged, nullopt where it was not (the points at the lowest parameter
/// value of a trend, the points inside a mode bracket). Left empty when the inputs are invalid.
using PointVerdicts = std::vector<std::optional<bool>>;

/// `points` (parameter, value) follow `direction` within `tolerance` (definition in the file
/// header). `labels`, when given (one per point, e.g. the run ids), name the points in the
/// message; otherwise they are named by position. Fails on a non-finite parameter or value, a
/// negative or non-finite tolerance, or labels of the wrong count; undecided with fewer than
/// two distinct parameter values. A failure message names every step against the direction.
Comparison compare_trend(std::vector<std::pair<double, double>> points, Direction direction,
                         double tolerance = 0.0, const std::vector<std::string>& labels = {},
                         PointVerdicts* verdicts = nullptr);

/// The points (parameter, mode) place a regime transition between `lo` and `hi` (definition in
/// the file header): one of `below` at parameter ≤ lo, one of `above` at parameter ≥ hi.
/// `labels` as for compare_trend. Fails when lo > hi or either is not finite, a parameter is
/// not finite, `below` or `above` is empty or holds an empty name; a point with an empty mode
/// (none reported) on a side is on the wrong side.
Comparison compare_mode_bracket(std::vector<std::pair<double, std::string>> points, double lo, double hi,
                                const std::vector<std::string>& below, const std::vector<std::string>& above,
                                const std::vector<std::string>& labels = {},
                                PointVerdicts* verdicts = nullptr);

}  // namespace caplab::score
