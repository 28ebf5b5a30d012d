// Lagrangian marker sets: points on a curve (2D) or surface (3D) with their measure.
//
// A MarkerSet is what the immersed-boundary transfer consumes: marker positions X_m and
// the measure w_m each marker stands for (arc length in 2D, area in 3D), so that
// sum_m w_m equals the perimeter or the surface area of the shape (thesis eq. 2.16/5.8
// discretised as f(x) = sum_m F_m delta(x - X_m) w_m). Everything here is in physical
// units; the IB module converts to lattice units (w_lu = w / dx^(D-1)).
//
// Shapes:
//   circle_markers   N = ceil(pi d / spacing) equally spaced points, w = pi d / N.
//   ellipse_markers  equally spaced in arc length (arc length integrated numerically by
//                    Gauss-Legendre quadrature, inverted by Newton), w = P / N.
//   sphere_markers   golden-spiral (Fibonacci) points, equal area weights pi d^2 / N,
//                    N chosen so that the hexagonal-packing spacing matches the target.
//
// Invariants: every point lies on the shape to round-off; weights are positive and sum to
// the perimeter/area to round-off (ellipse: to the quadrature accuracy, ~1e-13 relative).
#pragma once

#include <cstddef>
#include <vector>

#include "core/vec.hpp"

namespace caplab::geometry {

/// Marker positions and the measure each marker represents (physical units).
template <int D>
struct MarkerSet {
  std::vector<Vec<D>> X;       ///< marker positions
  std::vector<double> weight;  ///< arc length (2D) or area (3D) of each marker

  std::size_t size() const { return X.size(); }
  /// Perimeter (2D) or surface area (3D) represented by the set.
  double total_weight() const {
    double s = 0.0;
    for (double w : weight) s += w;
    return s;
  }
};

/// Circle of the given diameter: N = ceil(pi d / target_spacing) equally spaced markers
/// starting at angle 0, counter-clockwise; each weight is pi d / N.
MarkerSet<2> circle_markers(const Vec<2>& center, double diameter, double target_spacing);

/// Ellipse with semi-axes a (along the body x axis) and b (body y axis), the body axes
/// rotated by `angle` (radians, counter-clockwise). N = ceil(P / target_spacing) markers
/// equally spaced in arc length starting at the end of the a axis, counter-clockwise;
/// each weight is the arc length between the mid-arcs to its neighbours (= P / N).
MarkerSet<2> ellipse_markers(const Vec<2>& center, double a, double b, double angle, double target_spacing);

/// Perimeter of an ellipse with semi-axes a, b (Gauss-Legendre quadrature, ~1e-14 relative).
double ellipse_perimeter(double a, double b);

/// Sphere of the given diameter: golden-spiral points z_k = 1 - (2k+1)/N, azimuth
/// k * pi (3 - sqrt 5), with N = ceil(pi d^2 / (target_spacing^2 sqrt(3)/2)), the density of a
/// hexagonal packing of the target spacing. The spiral is not hexagonal: the mean distance
/// to the six nearest neighbours is ~1.03 x target, the nearest-neighbour distance
/// 0.81..0.93 x target. Equal area weights pi d^2 / N.
MarkerSet<3> sphere_markers(const Vec<3>& center, double diameter, double target_spacing);

}  // namespace caplab::geometry
