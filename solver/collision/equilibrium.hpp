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

/// c_i · v. Only the nonzero components of c_i take part: a product with the constant 0 is not
/// folded away in IEEE arithmetic (−0, NaN), and after unrolling the tests are on constants
/// and vanish. Σ_a c_ia v_a cost each D3Q19 node 27 multiplications by zero per sum.
template <class L, class T>
[[gnu::always_inline]] inline T c_dot(int i, const T (&v)[L::d]) {
  T s = 0;
  for (int a = 0; a < L::d; ++a) {
    if (L::c[i][a] > 0) s += v[a];
    if (L::c[i][a] < 0) s -= v[a];
  }
  return s;
}

/// δρ = Σ f_i and j = Σ c_i f_i from shifted populations f (ρ = 1 + δρ).
/// Scalars and references to C arrays only: this is what the vectorized kernel calls (an
/// aggregate or a pointer to a per-lane array inside an `omp simd` loop stops GCC 12 from
/// vectorizing it; checked with -fopt-info-vec).
template <class L, class T>
inline void shifted_density_momentum(const T (&f)[L::q], T& drho, T (&j)[L::d]) {
  drho = 0;
  for (int a = 0; a < L::d; ++a) j[a] = 0;
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    drho += f[i];
    for (int a = 0; a < L::d; ++a) {  // zero components skipped, as in c_dot
      if (L::c[i][a] > 0) j[a] += f[i];
      if (L::c[i][a] < 0) j[a] -= f[i];
    }
  }
}

/// ρ = 1 + Σ f_i and j = Σ c_i f_i of shifted populations.
template <class L, class T>
inline void density_momentum(const T (&f)[L::q], T& rho, T (&j)[L::d]) {
  T drho;
  shifted_density_momentum<L, T>(f, drho, j);
  rho = T(1) + drho;
}

/// ρ and u = Σ c_i f_i / ρ (no force).
template <class L, class T>
inline void moments(const T (&f)[L::q], T& rho, T (&u)[L::d]) {
  density_momentum<L, T>(f, rho, u);
  const T inv_rho = T(1) / rho;
  for (int a = 0; a < L::d; ++a) u[a] *= inv_rho;
}

/// ρ and u = (Σ c_i f_i + F/2)/ρ (Guo forcing, thesis eq. 2.25).
template <class L, class T>
inline void moments(const T (&f)[L::q], const T (&F)[L::d], T& rho, T (&u)[L::d]) {
  density_momentum<L, T>(f, rho, u);
  const T inv_rho = T(1) / rho;
  for (int a = 0; a < L::d; ++a) u[a] = (u[a] + T(0.5) * F[a]) * inv_rho;
}

/// Density and velocity of one node (for code outside the kernel).
template <class L, class T>
struct Moments {
  T rho;
  std::array<T, L::d> u;
};

template <class L, class T>
inline Moments<L, T> moments(const T (&f)[L::q], const T* force = nullptr) {
  Moments<L, T> m;
  T u[L::d];
  if (force) {
    T F[L::d];
    for (int a = 0; a < L::d; ++a) F[a] = force[a];
    moments<L, T>(f, F, m.rho, u);
  } else {
    moments<L, T>(f, m.rho, u);
  }
  for (int a = 0; a < L::d; ++a) m.u[a] = u[a];
  return m;
}

/// Shifted equilibrium f_eq_i − w_i for all i; u points to D components.
/// Evaluated per pair of opposite directions (c_o = −c_i): the part even in c·u is shared, the
/// odd part changes sign. With c_dot and the same skipping in density_momentum this took the
/// D3Q19 BGK kernel in cache from about 90-99 to 117-124 MLUPS (double, one thread;
/// solver/bench/NOTES.md, 2026-12-06).
template <class L, class T>
inline void equilibrium(T rho, const T (&u)[L::d], T (&feq)[L::q]) {
  T usq = 0;
  for (int a = 0; a < L::d; ++a) usq += u[a] * u[a];
  const T drho = rho - T(1);
  const T even0 = drho - T(1.5) * rho * usq, rho_45 = T(4.5) * rho, rho_3 = T(3) * rho;
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    const int o = L::opposite[i];
    if (o < i) continue;  // done with its pair
    const T cu = c_dot<L>(i, u);
    const T even = T(L::w[i]) * (even0 + rho_45 * cu * cu);
    const T odd = T(L::w[i]) * rho_3 * cu;
    feq[i] = even + odd;
    if (o != i) feq[o] = even - odd;
  }
}
template <class L, class T>
inline void equilibrium(T rho, const std::array<T, L::d>& u, T (&feq)[L::q]) {
  T v[L::d];
  for (int a = 0; a < L::d; ++a) v[a] = u[a];
  equilibrium<L, T>(rho, v, feq);
}

/// Guo source S_i (without the (1 − ω/2) factor) for force density F and velocity u.
template <class L, class T>
inline void guo_source(const T (&u)[L::d], const T (&force)[L::d], T (&s)[L::q]) {
  T uF = 0;
  for (int a = 0; a < L::d; ++a) uF += u[a] * force[a];
#pragma GCC unroll 19
  for (int i = 0; i < L::q; ++i) {
    const T cu = c_dot<L>(i, u), cF = c_dot<L>(i, force);
    s[i] = T(L::w[i]) * (T(3) * (cF - uF) + T(9) * cu * cF);
  }
}
template <class L, class T>
inline void guo_source(const std::array<T, L::d>& u, const T* force, T (&s)[L::q]) {
  T v[L::d], F[L::d];
  for (int a = 0; a < L::d; ++a) v[a] = u[a], F[a] = force[a];
  guo_source<L, T>(v, F, s);
}

}  // namespace caplab::collision
