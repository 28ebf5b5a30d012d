#include "diagnostics/signal.hpp"

#include <algorithm>
#include <vector>

#include "core/error.hpp"

namespace caplab::diagnostics {

SignalStats analyse_signal(std::span<const double> t, std::span<const double> v, double t_from) {
  CAPLAB_CHECK(t.size() == v.size(), "signal: t and v differ in length");
  const auto first = std::lower_bound(t.begin(), t.end(), t_from) - t.begin();
  const std::size_t n = t.size() - first;
  CAPLAB_CHECK(n >= 3, "signal: fewer than three samples after the start of the averaging window");
  SignalStats s;
  double sum = 0;
  s.min = s.max = v[first];
  for (std::size_t k = first; k < t.size(); ++k) {
    sum += v[k];
    s.min = std::min(s.min, v[k]);
    s.max = std::max(s.max, v[k]);
  }
  s.mean = sum / static_cast<double>(n);
  s.amplitude = 0.5 * (s.max - s.min);
  std::vector<double> up;
  for (std::size_t k = first + 1; k < t.size(); ++k) {
    const double a = v[k - 1] - s.mean, b = v[k] - s.mean;
    if (a < 0 && b >= 0) up.push_back(t[k - 1] + (t[k] - t[k - 1]) * (-a) / (b - a));
  }
  if (up.size() >= 3) {
    s.periods = static_cast<int>(up.size()) - 1;
    s.frequency = s.periods / (up.back() - up.front());
  }
  return s;
}

}  // namespace caplab::diagnostics
