// Equilibrium, moments and the Guo forcing term, in the shifted representation.
//
// Thesis eq. 2.4: f_eq_i = w_i ρ [1 + c_i·u/cs² + (c_i·u)²/(2cs⁴) − u²/(2cs²)].
// Shifted (f − w): f_eq_i − w_i = w_i [δρ + ρ(c_i·u/cs² + (c_i·u)²/(2cs⁴) − u²/(2cs²))].
// Guo et al. 2002 forcing, correct form (thesis eq. 5.22; eq. 2.26 has a typo):
//   S_i = w_i [(c_i − u)/cs² + (c_i·u) c_i/cs⁴] · F, applied with the factor (1 − ω/2)
//   by the collision operator, and ρu = Σ c_i f_i + F/2 for the equilibrium and the output.
#pragma once

#include <array>

namespace caplab::collision {

/// Density and velocity of one node from its shifted populations.
template <class L, class T>
struct Moments {
  T rho;
  std::array<T, L::d> u;
};

/// ρ = 1 + Σ f_i and u = (Σ c_i f_i + F/2)/ρ from shifted populations f (F may be zero).
template <class L, class T>
inline Moments<L, T> moments(const T (&f)[L::q], const T* force = nullptr) {
  Moments<L, T> m;
  T drho = 0;
  std::array<T, L::d> j{};
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    drho += f[i];
    for (int a = 0; a < L::d; ++a) j[a] += T(L::c[i][a]) * f[i];
  }
  m.rho = T(1) + drho;
  const T inv_rho = T(1) / m.rho;
  for (int a = 0; a < L::d; ++a) m.u[a] = (j[a] + (force ? T(0.5) * force[a] : T(0))) * inv_rho;
  return m;
}

/// Shifted equilibrium f_eq_i − w_i for all i.
template <class L, class T>
inline void equilibrium(T rho, const std::array<T, L::d>& u, T (&feq)[L::q]) {
  constexpr T inv_cs2 = T(3);
  T usq = 0;
  for (int a = 0; a < L::d; ++a) usq += u[a] * u[a];
  const T drho = rho - T(1);
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    T cu = 0;
    for (int a = 0; a < L::d; ++a) cu += T(L::c[i][a]) * u[a];
    feq[i] = T(L::w[i]) * (drho + rho * (inv_cs2 * cu + T(4.5) * cu * cu - T(1.5) * usq));
  }
}

/// Guo source S_i (without the (1 − ω/2) factor) for force density F and velocity u.
template <class L, class T>
inline void guo_source(const std::array<T, L::d>& u, const T* force, T (&s)[L::q]) {
  T uF = 0;
  for (int a = 0; a < L::d; ++a) uF += u[a] * force[a];
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    T cu = 0, cF = 0;
    for (int a = 0; a < L::d; ++a) {
      cu += T(L::c[i][a]) * u[a];
      cF += T(L::c[i][a]) * force[a];
    }
    s[i] = T(L::w[i]) * (T(3) * (cF - uF) + T(9) * cu * cF);
  }
}

}  // namespace caplab::collision
