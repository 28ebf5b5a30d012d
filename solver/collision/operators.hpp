// Collision operators as policies: BGK (thesis eq. 2.1) and TRT (Ginzburg et al. 2008).
//
// Each operator relaxes the non-equilibrium part and adds the Guo source with the
// operator's own weighting. TRT relaxes the even part with ω+ = 1/τ (viscosity
// ν = (τ − ½) cs²) and the odd part with ω− from the magic parameter
// Λ = (τ+ − ½)(τ− − ½); Λ = 1/4 makes bounce-back walls viscosity-independent and keeps
// the scheme stable at large τ. TrtBulk adds a relaxation time of its own for the bulk mode
// (the trace of the second-order moment), which sets the bulk viscosity and so the damping of
// sound. All work on shifted populations (see field/populations.hpp).
#pragma once

#include <cmath>
#include <type_traits>

#include "collision/equilibrium.hpp"
#include "core/error.hpp"

namespace caplab::collision {

/// Single-relaxation-time (BGK) collision with relaxation time τ.
struct Bgk {
  double tau = 1.0;
  static constexpr const char* name = "bgk";
  /// Relaxation time of the odd (antisymmetric) non-equilibrium part; BGK relaxes both alike.
  double tau_minus() const { return tau; }
  /// Relaxation time of the bulk mode (TrtBulk): here the even part's.
  double tau_bulk(int /*dims*/) const { return tau; }

  /// Post-collision values from pre-collision f and equilibrium feq.
  template <class L, class T>
  inline void collide(const T (&f)[L::q], const T (&feq)[L::q], T (&out)[L::q]) const {
    const T omega = T(1.0 / tau);
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) out[i] = f[i] - omega * (f[i] - feq[i]);
  }
  /// The same with the Guo source s, weighted (1 − ω/2).
  template <class L, class T>
  inline void collide(const T (&f)[L::q], const T (&feq)[L::q], const T (&s)[L::q], T (&out)[L::q]) const {
    const T omega = T(1.0 / tau);
    const T source_factor = T(1) - T(0.5) * omega;
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) out[i] = f[i] - omega * (f[i] - feq[i]) + source_factor * s[i];
  }
};

/// Two-relaxation-time collision: τ+ = τ sets the viscosity, τ− follows from Λ.
struct Trt {
  double tau = 1.0;
  double magic = 0.25;
  static constexpr const char* name = "trt";

  double tau_minus() const { return 0.5 + magic / (tau - 0.5); }
  double tau_bulk(int /*dims*/) const { return tau; }

  template <class L, class T>
  inline void collide(const T (&f)[L::q], const T (&feq)[L::q], T (&out)[L::q]) const {
    const T wp = T(1.0 / tau), wm = T(1.0 / tau_minus());
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) {
      const int o = L::opposite[i];
      const T np = T(0.5) * ((f[i] - feq[i]) + (f[o] - feq[o]));
      const T nm = T(0.5) * ((f[i] - feq[i]) - (f[o] - feq[o]));
      out[i] = f[i] - wp * np - wm * nm;
    }
  }
  /// The same with the Guo source s: even part weighted (1 − ω+/2), odd part (1 − ω−/2).
  template <class L, class T>
  inline void collide(const T (&f)[L::q], const T (&feq)[L::q], const T (&s)[L::q], T (&out)[L::q]) const {
    const T wp = T(1.0 / tau), wm = T(1.0 / tau_minus());
    const T sp = T(1) - T(0.5) * wp, sm = T(1) - T(0.5) * wm;
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) {
      const int o = L::opposite[i];
      const T np = T(0.5) * ((f[i] - feq[i]) + (f[o] - feq[o]));
      const T nm = T(0.5) * ((f[i] - feq[i]) - (f[o] - feq[o]));
      out[i] = f[i] - wp * np - wm * nm + sp * T(0.5) * (s[i] + s[o]) + sm * T(0.5) * (s[i] - s[o]);
    }
  }
};

/// |c_i|².
template <class L>
constexpr int c_squared(int i) {
  int c2 = 0;
  for (int a = 0; a < L::d; ++a) c2 += L::c[i][a] * L::c[i][a];
  return c2;
}

/// The bulk mode's shape on the populations: β_i = w_i (|c_i|² − D cs²)/(2 D cs⁴), so that
/// B_i = β_i Π, Π = Σ_j |c_j|² g_j the trace of the second moment of g, is the trace part of g's
/// second-order Hermite term: Σ B = 0, Σ c B = 0, Σ c_a c_b B = Π δ_ab / D (fourth-order
/// isotropy of the lattice; tests/unit/collision). A function of i, not a table: inside the
/// kernel's vector loop GCC 12 folds the call for each unrolled i, while a local constexpr
/// array is read from memory and stops the loop from vectorizing (measured: 7 times slower).
template <class L>
constexpr double bulk_shape(int i) {
  return L::w[i] * (c_squared<L>(i) - L::d * L::cs2) / (2.0 * L::d * L::cs2 * L::cs2);
}

/// Π = Σ |c_i|² g_i, the trace of the second moment of g.
template <class L, class T>
[[gnu::always_inline]] inline T second_moment_trace(const T (&g)[L::q]) {
  T pi = 0;
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i)
    if (c_squared<L>(i) != 0) pi += T(c_squared<L>(i)) * g[i];
  return pi;
}

/// TRT (or BGK, `bgk` true: τ− = τ) whose bulk mode relaxes with a time of its own, τ_b
/// (Dellar 2001, Phys. Rev. E 64, 031203): the trace Π of the second-order non-equilibrium
/// moment relaxes with ω_b = 1/τ_b, everything else as in the base operator:
///   out_i = base_i − (ω_b − ω+) β_i Π,   Π = Σ |c_j|² (f_j − feq_j)   (β: bulk_shape),
/// and with Guo's source S the bulk part of S is weighted (1 − ω_b/2) instead of (1 − ω+/2).
/// Chapman–Enskog gives the bulk viscosity ζ = (2/D) ρ cs² (τ_b − ½) beside μ = ρ cs² (τ − ½):
/// the base operator's ζ/μ is 2/D. `bulk_ratio` = ζ/μ sets τ_b − ½ = (D/2) ratio (τ − ½), which
/// scales across the refinement interface as τ − ½ does (one physical ζ on both blocks). Sound
/// of wavenumber k decays at the rate k²/2 [(2 − 2/D) ν + ζ/ρ]: a large ratio damps the sound
/// a weakly compressible run makes (an impulsive start in a closed box), which the
/// incompressible flow it stands for does not have, while the shear stress is the base's.
struct TrtBulk {
  double tau = 1.0;
  double magic = 0.25;
  double bulk_ratio = 1.0;  // ζ/μ
  bool bgk = false;         // odd part with τ, as BGK
  static constexpr const char* name = "trt_bulk";

  /// The base operator: TRT, or BGK as TRT with Λ = (τ − ½)² (τ− = τ). Both Λ computed, one
  /// chosen: a conditional division inside the kernel's vector loop (the operator is evaluated
  /// there, on the kernel's copy) stops GCC 12 from vectorizing it.
  Trt base() const {
    const double bgk_magic = (tau - 0.5) * (tau - 0.5);
    return {tau, bgk ? bgk_magic : magic};
  }
  double tau_minus() const { return base().tau_minus(); }
  double tau_bulk(int dims) const { return 0.5 + 0.5 * dims * bulk_ratio * (tau - 0.5); }

  template <class L, class T>
  [[gnu::always_inline]] inline void collide(const T (&f)[L::q], const T (&feq)[L::q], T (&out)[L::q]) const {
    T neq[L::q];
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) neq[i] = f[i] - feq[i];
    collide_with_trace<L, T>(f, feq, second_moment_trace<L, T>(neq), out);
  }
  /// The same with Π given (a refinement ghost, whose populations are not all at hand).
  template <class L, class T>
  [[gnu::always_inline]] inline void collide_with_trace(const T (&f)[L::q], const T (&feq)[L::q], T trace,
                                                        T (&out)[L::q]) const {
    base().template collide<L, T>(f, feq, out);
    subtract_bulk<L, T>(trace, out);
  }
  template <class L, class T>
  [[gnu::always_inline]] inline void collide(const T (&f)[L::q], const T (&feq)[L::q], const T (&s)[L::q],
                                             T (&out)[L::q]) const {
    T neq[L::q];
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) neq[i] = f[i] - feq[i];
    base().template collide<L, T>(f, feq, s, out);
    // −(ω_b − ω+) β Π(f_neq) and ((1 − ω_b/2) − (1 − ω+/2)) β Π(S) in one term.
    subtract_bulk<L, T>(second_moment_trace<L, T>(neq) + T(0.5) * second_moment_trace<L, T>(s), out);
  }

 private:
  /// out_i −= (ω_b − ω+) β_i Π.
  template <class L, class T>
  [[gnu::always_inline]] inline void subtract_bulk(T trace, T (&out)[L::q]) const {
    const T bulk = (T(1.0 / tau_bulk(L::d)) - T(1.0 / tau)) * trace;
#pragma GCC unroll 19
    for (int i = 0; i < L::q; ++i) out[i] -= T(bulk_shape<L>(i)) * bulk;
  }
};

/// Whether operator Op relaxes its bulk mode on its own (the refinement then rescales it apart).
template <class Op>
inline constexpr bool has_bulk_mode = std::is_same_v<Op, TrtBulk>;

}  // namespace caplab::collision
