// Shape of a 2D capsule from its membrane nodes: area, centroid, second moments of area and
// the equivalent ellipse (Taylor deformation parameter and inclination).
//
// The membrane is the closed polygon X_0 .. X_{N-1} (counter-clockwise; the last node joins
// the first), or any region given by its oriented boundary edges (RegionMoments, a capsule's
// section). All integrals are exact for the polygon (Green's theorem on each edge):
//   area      A   = 1/2 sum c_i,                     c_i = x_i y_{i+1} - x_{i+1} y_i (shoelace)
//   centroid  C   = 1/(6A) sum (X_i + X_{i+1}) c_i
//   moments   Jxx = int x^2 dA = 1/12 sum c_i (x_i^2 + x_i x_{i+1} + x_{i+1}^2), Jyy likewise,
//             Jxy = int x y dA = 1/24 sum c_i (2 x_i y_i + x_i y_{i+1} + x_{i+1} y_i + 2 x_{i+1} y_{i+1}),
//             evaluated about the vertex mean (against cancellation) and moved to the centroid
//             by the parallel-axis theorem.
// Equivalent ellipse (Breyiannis & Pozrikidis 2000, thesis section 2.6.3): the ellipse whose
// second-moment tensor about its centre equals J. An ellipse with semi-axes L >= B has
// principal moments pi L^3 B / 4 and pi L B^3 / 4, so with the eigenvalues lambda1 >= lambda2
// of J:  L = (4/pi)^(1/4) lambda1^(3/8) lambda2^(-1/8),  B = (4/pi)^(1/4) lambda2^(3/8) lambda1^(-1/8),
// Taylor parameter D = (L - B)/(L + B) (thesis eq. 2.33) = (sqrt lambda1 - sqrt lambda2) /
// (sqrt lambda1 + sqrt lambda2), inclination = angle of the eigenvector of lambda1 from the x
// axis, in (-pi/2, pi/2]. The equivalent ellipse's area pi L B differs from A for non-elliptic
// shapes; `area` below is always the polygon's A.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>

#include "core/vec.hpp"

namespace caplab::diagnostics {

/// The polygon's area and centroid and its equivalent ellipse.
struct EquivalentEllipse {
  double area = 0;         ///< enclosed polygon area A
  double length = 0;       ///< semi-major axis L of the equivalent ellipse
  double width = 0;        ///< semi-minor axis B of the equivalent ellipse
  double taylor = 0;       ///< Taylor deformation parameter D = (L - B)/(L + B), eq. 2.33
  double inclination = 0;  ///< angle of the major axis from x, radians, in (-pi/2, pi/2]
  Vec<2> centroid = Vec<2>::Zero();
};

/// Perimeter of the closed polygon X (including the edge from the last node to the first).
double polygon_perimeter(std::span<const Vec<2>> X);

/// Largest local stretch of the closed polygon X against its rest edge lengths:
/// max over edges i -> i+1 (the last joins the first) of |l_i / rest_i - 1| (the 2D membrane's
/// "area change", thesis 3.2.3: its length changes locally). Throws core::Error when the sizes differ.
double max_length_change(std::span<const Vec<2>> X, std::span<const double> rest_lengths);

/// Centroid of the area enclosed by X. Throws core::Error when the signed area is not positive.
Vec<2> polygon_centroid(std::span<const Vec<2>> X);

/// Second-moment tensor of the enclosed area about its centroid, J = int (x - C)(x - C)^T dA
/// (not the polar "inertia" form int (|r|^2 I - r r^T) dA; both share principal axes, J's
/// largest eigenvalue belongs to the major axis). Throws core::Error when the signed area
/// is not positive (clockwise or degenerate polygon).
Eigen::Matrix2d area_second_moment(std::span<const Vec<2>> X);

/// Area, centroid and equivalent ellipse of the counter-clockwise polygon X. Throws
/// core::Error when the signed area is not positive (clockwise or degenerate polygon).
EquivalentEllipse equivalent_ellipse(std::span<const Vec<2>> X);

/// The area integrals above accumulated one boundary edge at a time, for a region whose edges
/// are produced one by one and never stored (a capsule's section, shape3d.hpp): edges in any
/// order and any number of contours, each with the region on its left. The sums are taken
/// relative to `reference`, a point near the region (against cancellation).
class RegionMoments {
 public:
  explicit RegionMoments(const Vec<2>& reference) : reference_(reference) {}

  /// Adds the edge from `a` to `b`.
  void add_edge(const Vec<2>& a, const Vec<2>& b);

  /// Area, centroid and equivalent ellipse of the region. Throws core::Error naming `what`
  /// when the signed area is not positive or there are fewer than 3 edges.
  EquivalentEllipse ellipse(const char* what = "region bounded by edges") const;

 private:
  friend struct RegionMomentsAccess;
  Vec<2> reference_;
  std::size_t edges_ = 0;
  double area_ = 0;                                      // 2 A
  Vec<2> first_ = Vec<2>::Zero();                        // 6 int r dA
  Eigen::Matrix2d second_ = Eigen::Matrix2d::Zero();     // 12 int x^2, 12 int y^2, 24 int x y
};

}  // namespace caplab::diagnostics
