// Comparators of the scoring module; see comparators.hpp for the definitions and invariants.
#include "score/comparators.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

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

/// "\"a\" or \"b\"": the modes of a list as they appear in messages.
std::string quoted_list(const std::vector<std::string>& modes) {
  std::string listed;
  for (const auto& mode : modes) listed += (listed.empty() ? "\"" : " or \"") + mode + "\"";
  return listed;
}

/// Why a list of allowed modes cannot be used (empty when it can); `what` names the list.
std::string bad_modes(const std::vector<std::string>& modes, const std::string& what) {
  if (modes.empty()) return "no " + what + " mode given";
  if (std::find(modes.begin(), modes.end(), "") != modes.end())
    return "a " + what + " mode is an empty string";
  return "";
}

std::string join(const std::vector<std::string>& parts, const char* separator) {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

/// How point `i` of a sweep is named in messages: its label, or its position.
std::string point_name(const std::vector<std::string>& labels, std::size_t i) {
  return labels.empty() ? fmt::format("point {}", i + 1) : labels[i];
}

std::optional<Comparison> reject_labels(const std::vector<std::string>& labels, std::size_t points) {
  if (labels.empty() || labels.size() == points) return std::nullopt;
  return Comparison{kNaN, false, fmt::format("{} labels given for {} points", labels.size(), points)};
}

const char* direction_name(Direction d) {
  switch (d) {
    case Direction::increasing:
      return "increasing";
    case Direction::decreasing:
      return "decreasing";
    case Direction::non_decreasing:
      return "non-decreasing";
    case Direction::non_increasing:
      return "non-increasing";
  }
  return "?";
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
  if (const std::string bad = bad_modes(allowed, "reference"); !bad.empty()) return {kNaN, false, bad};
  const std::string listed = quoted_list(allowed);
  if (value.empty()) return {kNaN, false, "the mode is an empty string; expected " + listed};
  if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return {0.0, true, ""};
  return {1.0, false, fmt::format("mode \"{}\" is not the reference {}", value, listed)};
}

Comparison compare_trend(std::vector<std::pair<double, double>> points, Direction direction, double tolerance,
                         const std::vector<std::string>& labels, PointVerdicts* verdicts) {
  if (verdicts) verdicts->clear();
  if (!std::isfinite(tolerance) || tolerance < 0)
    return {kNaN, false, fmt::format("tolerance must be finite and >= 0 (got {})", tolerance)};
  if (auto bad = reject_labels(labels, points.size())) return *bad;
  const std::size_t n = points.size();
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(points[i].first) || !std::isfinite(points[i].second))
      return {kNaN, false,
              fmt::format("{} is not finite (parameter {}, value {})", point_name(labels, i), points[i].first,
                          points[i].second)};

  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return points[a].first < points[b].first; });
  const bool up = direction == Direction::increasing || direction == Direction::non_decreasing;
  const bool strict = direction == Direction::increasing || direction == Direction::decreasing;
  const double sign = up ? 1.0 : -1.0;
  auto describe = [&](std::size_t i) {
    return fmt::format("{:.6g} at {:.6g} ({})", points[i].second, points[i].first, point_name(labels, i));
  };

  PointVerdicts judged(n);
  double error = -std::numeric_limits<double>::infinity();
  std::size_t steps = 0, levels = 0;
  std::vector<std::string> against;
  // [lower, begin): the points at the previous distinct parameter value; [begin, end): this one.
  for (std::size_t lower = 0, begin = 0; begin < n; ++levels) {
    std::size_t end = begin;
    while (end < n && points[order[end]].first == points[order[begin]].first) ++end;
    for (std::size_t a = begin; levels > 0 && a < end; ++a) {
      bool ok = true;
      for (std::size_t b = lower; b < begin; ++b) {
        const std::size_t i = order[a], j = order[b];
        const double step = sign * (points[j].second - points[i].second);  // > 0: against the direction
        error = std::max(error, step);
        ++steps;
        if (strict ? step < tolerance : step <= tolerance) continue;
        ok = false;
        against.push_back(describe(j) + " -> " + describe(i));
      }
      judged[order[a]] = ok;
    }
    lower = begin;
    begin = end;
  }
  if (verdicts) *verdicts = judged;
  if (steps == 0)
    return {kNaN, false,
            fmt::format("{} point(s) at {} distinct parameter value(s): a trend needs two values", n, levels),
            false};
  if (against.empty()) return {error, true, ""};
  return {error, false,
          fmt::format("not {}{}: {} of {} steps go against it: {}", direction_name(direction),
                      tolerance > 0 ? fmt::format(" within {:.4g}", tolerance) : "", against.size(), steps,
                      join(against, "; "))};
}

Comparison compare_mode_bracket(std::vector<std::pair<double, std::string>> points, double lo, double hi,
                                const std::vector<std::string>& below, const std::vector<std::string>& above,
                                const std::vector<std::string>& labels, PointVerdicts* verdicts) {
  if (verdicts) verdicts->clear();
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
    return {kNaN, false, fmt::format("bracket [{}, {}] is not a finite interval with lo <= hi", lo, hi)};
  for (const auto& [modes, what] : {std::pair{&below, "below"}, std::pair{&above, "above"}})
    if (const std::string bad = bad_modes(*modes, what); !bad.empty()) return {kNaN, false, bad};
  if (auto bad = reject_labels(labels, points.size())) return *bad;

  PointVerdicts judged(points.size());
  std::size_t n_below = 0, n_above = 0;
  std::vector<std::string> wrong;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& [x, mode] = points[i];
    if (!std::isfinite(x))
      return {kNaN, false, fmt::format("the parameter of {} is not finite ({})", point_name(labels, i), x)};
    const bool is_below = x <= lo;
    if (!is_below && x < hi) continue;  // inside the bracket: either regime
    const std::vector<std::string>& expected = is_below ? below : above;
    ++(is_below ? n_below : n_above);
    judged[i] = std::find(expected.begin(), expected.end(), mode) != expected.end();
    if (!*judged[i])
      wrong.push_back(fmt::format("{} at {:.6g} ({} the bracket) is {}, expected {}", point_name(labels, i),
                                  x, is_below ? "below" : "above",
                                  mode.empty() ? "without a mode" : "\"" + mode + "\"",
                                  quoted_list(expected)));
  }
  if (verdicts) *verdicts = judged;
  if (!wrong.empty())
    return {static_cast<double>(wrong.size()), false,
            fmt::format("{} of {} points on the wrong side of [{:.6g}, {:.6g}]: {}", wrong.size(),
                        n_below + n_above, lo, hi, join(wrong, "; "))};
  if (n_below == 0 || n_above == 0)
    return {kNaN, false,
            fmt::format(
                "{} point(s) at or below {:.6g} and {} at or above {:.6g}: the transition needs a point on "
                "each side",
                n_below, lo, n_above, hi),
            false};
  return {0.0, true, ""};
}

}  // namespace caplab::score
