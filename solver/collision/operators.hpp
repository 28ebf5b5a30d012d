// Collision operators as policies: BGK (thesis eq. 2.1) and TRT (Ginzburg et al. 2008).
//
// Each operator relaxes the non-equilibrium part and adds the Guo source with the
// operator's own weighting. TRT relaxes the even part with ω+ = 1/τ (viscosity
// ν = (τ − ½) cs²) and the odd part with ω− from the magic parameter
// Λ = (τ+ − ½)(τ− − ½); Λ = 1/4 makes bounce-back walls viscosity-independent and keeps
// the scheme stable at large τ. Both work on shifted populations (see field/populations.hpp).
#pragma once

#include <cmath>

#include "collision/equilibrium.hpp"
#include "core/error.hpp"

namespace caplab::collision {

/// Single-relaxation-time (BGK) collision with relaxation time τ.
struct Bgk {
  double tau = 1.0;
  static constexpr const char* name = "bgk";
  /// Relaxation time of the odd (antisymmetric) non-equilibrium part; BGK relaxes both alike.
  double tau_minus() const { return tau; }

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

}  // namespace caplab::collision
