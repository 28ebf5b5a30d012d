// Motion modes of a capsule in shear flow from its tracked inclination (thesis ch. 3: steady
// tank-treading, tank-treading with oscillation, tumbling).
//
// Input is the continuous (unwrapped) inclination theta(t) of the major axis of the
// equivalent ellipse (defined modulo pi, unwrapped by AngleUnwrapper(pi)). The tank-treading
// frequency is not measured here but from the tangential membrane velocity
// (Scene::tank_treading_period): a tracked node's phase turns unevenly around a deformed
// contour, so its mean rate over a window shorter than a revolution is biased.
//
// Classification (times in 1/k):
//   tumbling                   the inclination turns through more than pi in t >= t_from (the
//                              thesis: "the oscillation amplitude is larger than pi", ch. 3.2.2),
//                              or over the run while it still turns one way in the window (no
//                              reversal: a window shorter than a half-turn); a capsule that
//                              tumbled at first and swings in the window (the intermittent start
//                              near the transition, thesis figs. 6.10, 6.16) is not tumbling;
//   oscillating_tank_treading  otherwise, when theta reverses its direction in t >= t_from by
//                              more than twice `oscillation_threshold` (default 1 degree, so a
//                              swing of 2 degrees peak to peak): a monotone approach to the
//                              steady inclination, however fast, is not an oscillation;
//   steady_tank_treading       otherwise.
// For a tumbling capsule, over the window t >= t_from, the period of a half-turn of theta: (t_N - from) / N,
// t_n the time theta first reaches theta(from) -/+ n pi (exact for a periodic orbit whatever its phase at
// `from`), or pi (end - from) / |theta(end) - theta(from)| when the window holds no whole half-turn (Jeffery
// 1922: pi (1 + r^2)/r for a rigid ellipse of aspect ratio r, thesis eq. 3.11).
#pragma once

#include <numbers>
#include <optional>
#include <span>
#include <string>

namespace caplab::diagnostics {

/// Turns a sequence of angles known modulo `period` into a continuous one: each value is the
/// representative nearest to the previous one (the angle plus whole periods, so a value does not
/// depend on the samples between: following every step or every tenth gives the same doubles).
/// Valid while consecutive samples move by less than period / 2.
class AngleUnwrapper {
 public:
  explicit AngleUnwrapper(double period) : period_(period) {}
  double operator()(double angle);
  /// Forgets the history: the next value is taken as it is (e.g. while a shape is too round
  /// for its axis to mean anything).
  void reset() { started_ = false; }
  /// The history (io/checkpoint.hpp archive).
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    ar(prefix + "last", last_);
    ar(prefix + "started", started_);
  }

 private:
  double period_;
  double last_ = 0.0;
  bool started_ = false;
};

struct CapsuleMotion {
  std::string mode;                       ///< steady_tank_treading | oscillating_tank_treading | tumbling
  double inclination_turn = 0;            ///< max - min of theta over the whole run (rad)
  double inclination_amplitude = 0;       ///< (max - min)/2 of theta over the window (rad)
  int inclination_reversals = 0;          ///< turns of theta by more than 2 x threshold in the window
  std::optional<double> tumbling_period;  ///< time of a half-turn of theta (1/k), when tumbling
};

inline constexpr double default_oscillation_threshold = std::numbers::pi / 180;

/// Classifies the motion from theta(t), phi(t) sampled at t (strictly increasing). Throws
/// core::Error when fewer than 3 samples lie in t >= t_from or the lengths differ.
CapsuleMotion classify_capsule_motion(std::span<const double> t, std::span<const double> inclination,
                                      double t_from,
                                      double oscillation_threshold = default_oscillation_threshold);

/// Mean turning rate (rad per unit time, positive) of a continuous phase over its whole
/// revolutions in t >= t_from: 2 pi N / (t_N - t_from), t_N the time the phase first differs
/// from its value at t_from by N whole turns; nullopt when it does not complete one. Throws
/// core::Error when fewer than 3 samples lie in the window or the lengths differ.
std::optional<double> revolution_rate(std::span<const double> t, std::span<const double> phase, double t_from);

/// The tank-treading frequency of thesis 6.3.1 from a tracked membrane node's phase, with t in
/// 1/k: f / k = 2 pi / (k T), T the time of one whole revolution (the revolution_rate itself,
/// not revolutions per unit time; Tran-Son-Tay et al. 1984 give 0.22 for young red cells, T = 28.6/k).
inline std::optional<double> tank_treading_frequency_per_k(std::span<const double> t, std::span<const double> phase,
                                                           double t_from) {
  return revolution_rate(t, phase, t_from);
}

}  // namespace caplab::diagnostics
