// Statistics of a sampled time signal over a window: mean, amplitude, dominant frequency.
//
// The frequency comes from the up-crossings of the signal through its window mean, located
// by linear interpolation between samples: f = (number of full periods) / (time between the
// first and last up-crossing). For a shedding lift signal this gives the Strouhal number
// St = f D/U directly in case units. Needs at least two full periods in the window.
#pragma once

#include <optional>
#include <span>

namespace caplab::diagnostics {

struct SignalStats {
  double mean = 0;
  double amplitude = 0;  ///< (max − min)/2 over the window
  double min = 0, max = 0;
  std::optional<double> frequency;  ///< none when fewer than two periods
  int periods = 0;
};

/// Statistics of v(t) over t >= t_from. Throws core::Error when the window holds < 3 samples.
SignalStats analyse_signal(std::span<const double> t, std::span<const double> v, double t_from);

}  // namespace caplab::diagnostics
