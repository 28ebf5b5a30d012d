#include "diagnostics/capsule_motion.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "diagnostics/turning_points.hpp"

namespace caplab::diagnostics {

double AngleUnwrapper::operator()(double angle) {
  if (!started_) {
    started_ = true;
    return last_ = angle;
  }
  // The measured angle plus whole periods, not a running sum of increments: the value depends on
  // the angle and its branch alone, not on how often (or since when) the angle was sampled.
  return last_ = angle + period_ * std::round((last_ - angle) / period_);
}

namespace {

// Whole turns of v by `turn` from v[first], in the sense v ends up moving, and the time the
// last one completed (linear interpolation between samples).
struct Turns {
  int count = 0;
  double t_last = 0;
};
Turns whole_turns(std::span<const double> t, std::span<const double> v, std::size_t first, double turn) {
  const std::size_t last = t.size() - 1;
  const double sense = v[last] < v[first] ? -1.0 : 1.0;
  double level = v[first] + sense * turn;
  Turns r{0, t[first]};
  for (std::size_t k = first + 1; k <= last; ++k)
    while ((v[k] - level) * sense >= 0) {  // crossed: interpolate the time
      const double s = (level - v[k - 1]) / (v[k] - v[k - 1]);
      r.t_last = t[k - 1] + s * (t[k] - t[k - 1]);
      ++r.count, level += sense * turn;
    }
  return r;
}

std::size_t window_start(std::span<const double> t, std::span<const double> v, double t_from, const char* what) {
  CAPLAB_CHECK(t.size() == v.size(), std::string(what) + ": time and angle need the same number of samples");
  const std::size_t first = std::lower_bound(t.begin(), t.end(), t_from) - t.begin();
  CAPLAB_CHECK(t.size() >= first + 3, std::string(what) + ": fewer than 3 samples after the start of the window");
  return first;
}

}  // namespace

std::optional<double> revolution_rate(std::span<const double> t, std::span<const double> phase, double t_from) {
  const std::size_t first = window_start(t, phase, t_from, "revolution rate");
  const Turns r = whole_turns(t, phase, first, 2 * std::numbers::pi);
  if (r.count == 0) return std::nullopt;
  return 2 * std::numbers::pi * r.count / (r.t_last - t[first]);
}

CapsuleMotion classify_capsule_motion(std::span<const double> t, std::span<const double> inclination,
                                      double t_from, double oscillation_threshold) {
  const std::size_t first = window_start(t, inclination, t_from, "capsule motion");
  const std::size_t last = t.size() - 1;

  CapsuleMotion m;
  const auto [lo_all, hi_all] = std::minmax_element(inclination.begin(), inclination.end());
  m.inclination_turn = *hi_all - *lo_all;
  const auto [lo, hi] = std::minmax_element(inclination.begin() + first, inclination.end());
  m.inclination_amplitude = 0.5 * (*hi - *lo);
  m.inclination_reversals =
      static_cast<int>(turning_points(inclination.subspan(first), 2 * oscillation_threshold).size());
  const double span = t[last] - t[first];
  // Tumbling: the inclination turns through more than pi in the window, or it did over the run
  // and is still turning one way (a window shorter than a half-turn). A capsule that tumbled at
  // first and swings in the window (the intermittent start near the transition, thesis fig.
  // 6.10 and 6.16) is swinging.
  if (2 * m.inclination_amplitude > std::numbers::pi ||
      (m.inclination_turn > std::numbers::pi && m.inclination_reversals == 0)) {
    m.mode = "tumbling";
    const Turns turns = whole_turns(t, inclination, first, std::numbers::pi);
    const double turn = std::abs(inclination[last] - inclination[first]);
    if (turns.count > 0)
      m.tumbling_period = (turns.t_last - t[first]) / turns.count;
    else if (turn > 0)
      m.tumbling_period = std::numbers::pi * span / turn;
  } else {
    m.mode = m.inclination_reversals > 0 ? "oscillating_tank_treading" : "steady_tank_treading";
  }
  return m;
}

}  // namespace caplab::diagnostics
