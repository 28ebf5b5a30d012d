// Rest shapes of 2D capsules: closed rings of N nodes equally spaced in arc length.
//
// A ring is what a 2D membrane (membrane::RingMembrane) is built from: N node positions,
// counter-clockwise, node 0 at the end of the body x axis (the rightmost point before
// rotation), equally spaced in the arc length of the smooth parametric curve.
//
// Shapes (body axes, before scaling, rotation and translation):
//   circle     (cos u, sin u)
//   ellipse    (r cos u, sin u), r = aspect ratio (thesis 3.2.2: 2:1, long axis along x)
//   biconcave  thesis eq. 3.12 (Pozrikidis 2003b) with a = 1:
//                x = alpha sin chi,  y = (alpha/2)(0.207 + 2.003 sin^2 chi - 1.123 sin^4 chi) cos chi,
//              chi in [-pi/2, 3pi/2]. That parametrisation runs clockwise; it is used reversed,
//              chi = pi/2 - u, so that u runs counter-clockwise from the rightmost point.
//
// Method: the arc length of the curve is tabulated on 1024 equal panels of the parameter
// (5-point Gauss-Legendre per panel, smooth periodic integrands, ~1e-15 relative), and each
// target arc length k P / N is hit by safeguarded Newton (bisection fallback) inside its
// panel. The ring is then scaled about the curve's origin so that the POLYGON of the N nodes
// (the shape the membrane and the shape diagnostics see) encloses exactly pi a_eq^2 (thesis
// eq. 3.9: a = (area / pi)^0.5); the smooth curve through the nodes encloses pi a_eq^2
// (1 + O(N^-2)). Scaling preserves equal arc spacing. Finally the ring is rotated by `angle`
// (radians, counter-clockwise) and translated to `center`.
//
// Invariants: nodes are counter-clockwise (positive shoelace area), equally spaced in arc
// length to ~1e-13 relative, the polygon area is pi a_eq^2 to round-off.
#pragma once

#include <span>
#include <vector>

#include "core/vec.hpp"

namespace caplab::geometry {

/// Which rest shape a ring has, with its shape parameters.
struct RingShape {
  enum class Type { circle, ellipse, biconcave };
  Type type = Type::circle;
  double aspect_ratio = 2.0;  ///< ellipse: semi-axis along body x / semi-axis along body y (> 0)
  double alpha = 1.39;        ///< biconcave: cell radius ratio of eq. 3.12 (1.39 for a red blood cell)
};

/// `nodes` (>= 3) ring nodes of `shape`, counter-clockwise and equally spaced in arc length,
/// node 0 at the end of the body x axis; scaled so that the polygon encloses
/// pi equivalent_radius^2, rotated by `angle` (radians, CCW) and centred at `center` (the
/// symmetry centre of the shape). Throws core::Error on non-positive or non-finite arguments.
std::vector<Vec<2>> ring_nodes(const RingShape& shape, const Vec<2>& center, double equivalent_radius,
                               double angle, int nodes);

/// Equivalent radius (area / pi)^0.5 of the smooth eq. 3.12 biconcave curve with a = 1.
/// For alpha = 1.39 it is 0.740346 (the thesis quotes 0.74). Throws core::Error when
/// alpha is not positive and finite.
double biconcave_equivalent_radius(double alpha = 1.39);

/// Signed area enclosed by the closed polygon X (positive when counter-clockwise; 0 for < 3 nodes).
double polygon_area(std::span<const Vec<2>> X);

}  // namespace caplab::geometry
