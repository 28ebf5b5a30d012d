// Regularised delta functions of the immersed-boundary method (1D factors).
//
// Each kernel is a policy: `support` is the number of grid nodes per axis that it touches,
// `phi(r)` the 1D weight at the distance r (in grid spacings) between a node and a marker,
// and `weights(d, w)` the support weights w[s] = phi(d - s) of the stencil whose first node
// lies d behind the marker (what the transfer computes per marker and axis; the cosine
// kernel gets all four from one polynomial sine and cosine). The D-dimensional kernel is
// the tensor product phi(x) phi(y) [phi(z)] (thesis eq. 2.18 / 5.9). Kernels are even,
// vanish for |r| >= support / 2 and have unit integral.
//
// Discrete moment properties, for every marker position x (sums over the nodes i):
//   kernel    sum phi(x-i)   sum (x-i) phi(x-i)             sum phi(x-i)^2
//   Cosine4   1 (exact)      x-1/2+(cos(pi x/2)-sin(pi x/2))/2, 3/8 (exact)
//                            |.| <= 0.02115, for x in [0,1)
//   Roma3     1 (exact)      0 (exact)                       1/2 (exact)
//   Linear2   1 (exact)      0 (exact)                       not constant
// Exact zeroth moment gives conservation of momentum between markers and grid; an exact
// first moment also conserves angular momentum (the cosine kernel does not, to ~2% of the
// marker force times one grid spacing).
//
// References:
//   Cosine4: Peskin 2002, Acta Numerica 11, 479-517; thesis eq. 2.17 / 5.10.
//   Roma3:   Roma, Pope & Kendall 1999, J. Comput. Phys. 153, 509-534.
//   Linear2: the hat function (bilinear / trilinear interpolation).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

namespace caplab::ibm {

/// Peskin's 4-point cosine kernel, thesis eq. 2.17 / 5.10:
/// phi(r) = (1 + cos(pi r / 2)) / 4 for |r| <= 2, else 0.
struct Cosine4 {
  static constexpr int support = 4;
  static constexpr const char* name = "cosine4";
  static double phi(double r) {
    const double a = std::abs(r);
    return a < 2.0 ? 0.25 * (1.0 + std::cos(0.5 * std::numbers::pi * a)) : 0.0;
  }
  /// d in [1, 2) (the transfer's first node lies d behind the marker): cos(pi (d - k) / 2)
  /// for k = 0..3 is c, s, -c, -s with c = cos(theta), s = sin(theta), theta = pi d / 2. With
  /// theta = 3 pi / 4 + p, |p| <= pi / 4, both follow from cos p and sin p, here their Taylor
  /// series to p^16 and p^17 (truncation below 1e-17, so the weights agree with phi() to
  /// round-off): no libm call, which was 7 % of a chapter 6 biconcave step (three sincos per
  /// marker and step; solver/bench/NOTES.md).
  static void weights(double d, double (&w)[support]) {
    // Taylor coefficients of sin(p) / p and cos(p) in q = p^2, highest power first.
    static constexpr double sin_c[] = {1.0 / 355687428096000, -1.0 / 1307674368000, 1.0 / 6227020800,
                                       -1.0 / 39916800,       1.0 / 362880,          -1.0 / 5040,
                                       1.0 / 120,             -1.0 / 6,              1.0};
    static constexpr double cos_c[] = {1.0 / 20922789888000, -1.0 / 87178291200, 1.0 / 479001600,
                                       -1.0 / 3628800,       1.0 / 40320,         -1.0 / 720,
                                       1.0 / 24,             -1.0 / 2,            1.0};
    const double p = 0.5 * std::numbers::pi * (d - 1.5);
    const double q = p * p;
    double sin_p = 0.0, cos_p = 0.0;
    for (int k = 0; k < 9; ++k) {
      sin_p = sin_p * q + sin_c[k];
      cos_p = cos_p * q + cos_c[k];
    }
    sin_p *= p;
    const double h = 0.5 * std::numbers::sqrt2;  // cos(3 pi/4) = -h, sin(3 pi/4) = h
    const double c = -h * (cos_p + sin_p), s = h * (cos_p - sin_p);
    w[0] = 0.25 * (1.0 + c);
    w[1] = 0.25 * (1.0 + s);
    w[2] = 0.25 * (1.0 - c);
    w[3] = 0.25 * (1.0 - s);
  }
};

/// weights() of a kernel from its phi(): w[s] = phi(d - s).
template <class Kernel>
void weights_from_phi(double d, double (&w)[Kernel::support]) {
  for (int s = 0; s < Kernel::support; ++s) w[s] = Kernel::phi(d - s);
}

/// Three-point kernel of Roma, Pope & Kendall 1999:
/// phi(r) = (1 + sqrt(1 - 3 r^2)) / 3                       for |r| <= 1/2,
///          (5 - 3|r| - sqrt(1 - 3 (1 - |r|)^2)) / 6        for 1/2 <= |r| <= 3/2, else 0.
struct Roma3 {
  static constexpr int support = 3;
  static constexpr const char* name = "roma3";
  static double phi(double r) {
    const double a = std::abs(r);
    if (a <= 0.5) return (1.0 + std::sqrt(1.0 - 3.0 * a * a)) / 3.0;
    if (a < 1.5) {
      const double b = 1.0 - a;
      return (5.0 - 3.0 * a - std::sqrt(std::max(0.0, 1.0 - 3.0 * b * b))) / 6.0;
    }
    return 0.0;
  }
  static void weights(double d, double (&w)[support]) { weights_from_phi<Roma3>(d, w); }
};

/// Two-point hat kernel phi(r) = 1 - |r| for |r| <= 1, else 0 (multi-linear interpolation).
struct Linear2 {
  static constexpr int support = 2;
  static constexpr const char* name = "linear2";
  static double phi(double r) {
    const double a = std::abs(r);
    return a < 1.0 ? 1.0 - a : 0.0;
  }
  static void weights(double d, double (&w)[support]) { weights_from_phi<Linear2>(d, w); }
};

}  // namespace caplab::ibm
