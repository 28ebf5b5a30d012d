// Comparators of the scoring module; see comparators.hpp for the definitions and invariants.
#include "score/comparators.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace caplab::score {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Checks shared by every comparator; returns a failing Comparison when an input is unusable.
std::optional<Comparison> reject_inputs(double value, double tolerance, const char* tolerance_name) {
  if (!std::isfinite(value)) return Comparison{kNaN, false, fmt::format("value is not finite ({})", value)};
  if (!std::isfinite(tolerance) || tolerance < 0)
    return Comparison{kNaN, false,
                      fmt::format("{} must be finite and >= 0 (got {})", tolerance_name, tolerance)};
  return std::nullopt;
}

Comparison judge(double error, double tolerance, const std::string& what) {
  if (error <= tolerance) return {error, true, ""};
  return {error, false, fmt::format("{} {:.4g} exceeds tolerance {:.4g}", what, error, tolerance)};
}

void check_series(const Series& s, const char* name) {
  if (s.t.empty()) throw core::Error(fmt::format("time_series: the {} series is empty", name));
  if (s.t.size() != s.y.size())
    throw core::Error(fmt::format("time_series: the {} series has {} abscissae but {} values", name,
                                  s.t.size(), s.y.size()));
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    if (!std::isfinite(s.t[i]) || !std::isfinite(s.y[i]))
      throw core::Error(
          fmt::format("time_series: the {} series has a non-finite entry at index {} "
                      "(t = {}, value = {})",
                      name, i, s.t[i], s.y[i]));
    if (i > 0 && !(s.t[i] > s.t[i - 1]))
      throw core::Error(
          fmt::format("time_series: the {} series abscissae are not strictly increasing at "
                      "index {} ({} after {})",
                      name, i, s.t[i], s.t[i - 1]));
  }
}

/// Linear interpolation of `s` at `t`, for t in [s.t.front(), s.t.back()].
double interpolate(const Series& s, double t) {
  const auto upper = std::upper_bound(s.t.begin(), s.t.end(), t);
  if (upper == s.t.begin()) return s.y.front();
  if (upper == s.t.end()) return s.y.back();
  const auto i = static_cast<std::size_t>(upper - s.t.begin());
  const double w = (t - s.t[i - 1]) / (s.t[i] - s.t[i - 1]);
  return (1.0 - w) * s.y[i - 1] + w * s.y[i];
}

}  // namespace

Comparison compare_relative(double value, double reference, double tolerance) {
  if (auto bad = reject_inputs(value, tolerance, "tolerance")) return *bad;
  if (!std::isfinite(reference) || reference == 0.0)
    return {
        kNaN, false,
        fmt::format("relative error is undefined for reference {} (use an absolute comparison)", reference)};
  return judge(std::abs(value - reference) / std::abs(reference), tolerance, "relative error");
}

Comparison compare_absolute(double value, double reference, double tolerance) {
  if (auto bad = reject_inputs(value, tolerance, "tolerance")) return *bad;
  if (!std::isfinite(reference)) return {kNaN, false, fmt::format("reference is not finite ({})", reference)};
  return judge(std::abs(value - reference), tolerance, "absolute error");
}

Comparison compare_bracket(double value, double lo, double hi, double margin) {
  if (auto bad = reject_inputs(value, margin, "bracket margin")) return *bad;
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
    return {kNaN, false, fmt::format("bracket [{}, {}] is not a finite interval with lo <= hi", lo, hi)};
  const double error = value < lo ? lo - value : (value > hi ? value - hi : 0.0);
  if (error <= margin) return {error, true, ""};
  return {error, false,
          fmt::format("value {:.6g} lies outside [{:.6g}, {:.6g}] by {:.4g} (margin {:.4g})", value, lo, hi,
                      error, margin)};
}

SeriesDistance rms_distance(const Series& run, const Series& reference, const std::optional<Window>& window) {
  check_series(run, "run");
  check_series(reference, "reference");
  double from = std::max(run.t.front(), reference.t.front());
  double to = std::min(run.t.back(), reference.t.back());
  std::string range = fmt::format("run covers t in [{:.6g}, {:.6g}], reference covers [{:.6g}, {:.6g}]",
                                  run.t.front(), run.t.back(), reference.t.front(), reference.t.back());
  if (window) {
    if (!(window->from <= window->to))
      throw core::Error(fmt::format("time_series: window [{}, {}] is empty", window->from, window->to));
    from = std::max(from, window->from);
    to = std::min(to, window->to);
    range += fmt::format(", window [{:.6g}, {:.6g}]", window->from, window->to);
  }
  if (from > to) throw core::Error("time_series: the series do not overlap (" + range + ")");
  SeriesDistance d;
  d.from = from;
  d.to = to;
  double sum = 0.0;
  for (std::size_t i = 0; i < reference.t.size(); ++i) {
    const double t = reference.t[i];
    if (t < from || t > to) continue;
    const double diff = interpolate(run, t) - reference.y[i];
    sum += diff * diff;
    ++d.points;
  }
  if (d.points == 0)
    throw core::Error("time_series: no reference abscissa lies in the overlap of the series (" + range + ")");
  d.rms = std::sqrt(sum / static_cast<double>(d.points));
  return d;
}

Comparison compare_time_series(const Series& run, const Series& reference, double tolerance,
                               const std::optional<Window>& window, SeriesDistance* detail) {
  if (!std::isfinite(tolerance) || tolerance < 0)
    return {kNaN, false, fmt::format("tolerance must be finite and >= 0 (got {})", tolerance)};
  try {
    const SeriesDistance d = rms_distance(run, reference, window);
    if (detail) *detail = d;
    return judge(d.rms, tolerance, "RMS distance");
  } catch (const core::Error& e) {
    return {kNaN, false, e.what()};
  }
}

Comparison compare_mode(std::string_view value, const std::vector<std::string>& allowed) {
  if (allowed.empty()) return {kNaN, false, "no reference mode given"};
  std::string listed;
  for (const auto& mode : allowed) {
    if (mode.empty()) return {kNaN, false, "a reference mode is an empty string"};
    listed += (listed.empty() ? "\"" : " or \"") + mode + "\"";
  }
  if (value.empty()) return {kNaN, false, "the mode is an empty string; expected " + listed};
  if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return {0.0, true, ""};
  return {1.0, false, fmt::format("mode \"{}\" is not the reference {}", value, listed)};
}

}  // namespace caplab::score
