#include "diagnostics/capsule_motion.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace caplab::diagnostics {

double AngleUnwrapper::operator()(double angle) {
  if (!started_) {
    started_ = true;
    return last_ = angle;
  }
  const double d = angle - last_;
  return last_ += d - period_ * std::round(d / period_);
}

namespace {

// Turns of v by more than `swing` back from its extreme since the last turn (a zigzag
// filter): 0 for a monotone signal, however it curves.
int reversals(std::span<const double> v, double swing) {
  int dir = 0, turns = 0;
  double hi = v.front(), lo = v.front();
  for (const double x : v) {
    hi = std::max(hi, x);
    lo = std::min(lo, x);
    if (dir >= 0 && hi - x > swing) {  // fell from a maximum
      if (dir > 0) ++turns;
      dir = -1, hi = lo = x;
    } else if (dir <= 0 && x - lo > swing) {  // rose from a minimum
      if (dir < 0) ++turns;
      dir = 1, hi = lo = x;
    }
  }
  return turns;
}

}  // namespace

CapsuleMotion classify_capsule_motion(std::span<const double> t, std::span<const double> inclination,
                                      double t_from, double oscillation_threshold) {
  CAPLAB_CHECK(t.size() == inclination.size(),
               "capsule motion: time and inclination need the same number of samples");
  const std::size_t first = std::lower_bound(t.begin(), t.end(), t_from) - t.begin();
  CAPLAB_CHECK(t.size() >= first + 3, "capsule motion: fewer than 3 samples after the start of the window");
  const std::size_t last = t.size() - 1;

  CapsuleMotion m;
  const auto [lo_all, hi_all] = std::minmax_element(inclination.begin(), inclination.end());
  m.inclination_turn = *hi_all - *lo_all;
  const auto [lo, hi] = std::minmax_element(inclination.begin() + first, inclination.end());
  m.inclination_amplitude = 0.5 * (*hi - *lo);
  m.inclination_reversals = reversals(inclination.subspan(first), 2 * oscillation_threshold);
  const double span = t[last] - t[first];
  if (m.inclination_turn > std::numbers::pi) {
    m.mode = "tumbling";
    const double sense = inclination[last] < inclination[first] ? -1.0 : 1.0;
    double level = inclination[first] + sense * std::numbers::pi, t_last_turn = t[first];
    int turns = 0;
    for (std::size_t k = first + 1; k <= last; ++k)
      while ((inclination[k] - level) * sense >= 0) {  // crossed: interpolate the time
        const double s = (level - inclination[k - 1]) / (inclination[k] - inclination[k - 1]);
        t_last_turn = t[k - 1] + s * (t[k] - t[k - 1]);
        ++turns, level += sense * std::numbers::pi;
      }
    const double turn = std::abs(inclination[last] - inclination[first]);
    if (turns > 0)
      m.tumbling_period = (t_last_turn - t[first]) / turns;
    else if (turn > 0)
      m.tumbling_period = std::numbers::pi * span / turn;
  } else {
    m.mode = m.inclination_reversals > 0 ? "oscillating_tank_treading" : "steady_tank_treading";
  }
  return m;
}

}  // namespace caplab::diagnostics
