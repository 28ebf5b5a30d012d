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
// Invariants: a non-finite value, reference, tolerance or error never passes; an empty mode
// name or an empty list of allowed modes never passes; a failing comparison always carries a
// message saying why.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace caplab::score {

/// Outcome of one comparison. `error` is NaN where it could not be computed.
struct Comparison {
  double error = 0.0;
  bool pass = false;
  std::string message;  ///< empty on a pass; why it failed otherwise
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

}  // namespace caplab::score
