// Shape of a 3D capsule from its membrane triangles: the equivalent ellipsoid of the enclosed
// volume (semi-axes, Taylor parameter D_xz in the shear plane, inclination), the contour of the
// section with a plane y = y0 and its equivalent ellipse, and the largest local area change of
// the membrane.
//
// The membrane is a closed, outward-oriented triangulation (geometry/triangle_mesh.hpp) in its
// current configuration X. The integrals are exact for the polyhedron: the enclosed volume is
// the signed sum of the tetrahedra (p, a, b, c) from the vertex mean p to each triangle. With the
// corners relative to p (0, a, b, c), V_t = a·(b × c)/6 and s = a + b + c,
//   ∫ x dV = V_t s / 4,   ∫ x_i x_j dV = V_t/20 (a_i a_j + b_i b_j + c_i c_j + s_i s_j),
// and the parallel-axis theorem moves the second moments to the volume centroid C:
//   M = ∫ (x − C)(x − C)ᵀ dV.
// Equivalent ellipsoid (Ramanujan & Pozrikidis 1998; Lac et al. 2004): the solid ellipsoid with
// the same M. A solid ellipsoid has ∫ x_k² dV = V a_k²/5 along its axes, so with the eigenvalues
// λ_k of M, a_k = sqrt(5 λ_k / V). For an ellipsoid it is the ellipsoid itself; for other shapes
// its volume 4/3·π·a1·a2·a3 differs from V, and `volume` is always the polyhedron's V.
//
// Shear plane: the flow is u = (k z, 0, 0), so x–z is the plane of shear and y the vorticity
// axis. D_xz = (L − B)/(L + B) (thesis section 5.3.1.1) with L >= B the semi-axes "in the plane of
// shear": of the three eigenvectors, the one with the largest |y| component is taken as the
// vorticity-aligned axis and left out, the other two lie (most nearly) in the x–z plane. A sphere
// gives D_xz = 0 and arbitrary axes (its inclination means nothing). Where two semi-axes tie,
// their eigenvectors are arbitrary within their plane, but D_xz is not affected: the tied axes
// have the same length. The inclination is the angle of the L axis from +x toward +z,
// atan2(e_z, e_x) of its unit vector e, folded into (−π/2, π/2] (an axis has no direction). A
// capsule in u = (k z, 0, 0) leans at about +π/4 at small deformation.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "core/vec.hpp"
#include "diagnostics/shape2d.hpp"

namespace caplab::diagnostics {

/// The enclosed volume of a closed triangulated surface and its equivalent ellipsoid.
struct EquivalentEllipsoid {
  Vec<3> center = Vec<3>::Zero();     ///< centroid C of the enclosed volume
  double volume = 0;                  ///< enclosed volume V of the polyhedron
  std::array<double, 3> semi_axes{};  ///< a_k = sqrt(5 λ_k / V), L1 >= L2 >= L3
  /// Unit eigenvectors of M in the order of semi_axes, each with its largest component positive.
  std::array<Vec<3>, 3> axes{Vec<3>::UnitX(), Vec<3>::UnitY(), Vec<3>::UnitZ()};
  double taylor_xz = 0;    ///< D_xz = (L − B)/(L + B) of the two axes nearest the shear plane x–z
  double inclination = 0;  ///< angle of the L axis from +x toward +z, radians, in (−π/2, π/2]
};

/// Equivalent ellipsoid of the volume enclosed by the outward-oriented triangles over X. Throws
/// core::Error when the enclosed volume is not positive (open, inward or degenerate surface).
EquivalentEllipsoid equivalent_ellipsoid(std::span<const Vec<3>> X,
                                         std::span<const std::array<int, 3>> triangles);

/// Segments {p, q} where the surface crosses the plane y = y0 (for cross-section contours), one
/// per crossed triangle, oriented counter-clockwise in the (x, z) coordinates (from +x toward +z,
/// the section on the left). Nodes exactly on the plane count as above it (y >= y0), so a mesh
/// edge lying in the plane is returned once (by the triangle below it) and zero-length segments
/// are dropped: the segments join into closed contours.
std::vector<std::array<Vec<3>, 2>> shear_plane_section(std::span<const Vec<3>> X,
                                                       std::span<const std::array<int, 3>> triangles,
                                                       double y0);

/// The equivalent ellipse (shape2d.hpp) of the section with the plane y = y0, in the shear-plane
/// coordinates (x, z): its inclination is the angle of the section's major axis from x toward z,
/// in (−π/2, π/2], like the ellipsoid's, and its centroid is (x, z). Through the volume centroid
/// (y0 = center[1]) it is the thesis's "middle cross section in the plane of shear" (6.3, fig.
/// 6.14 and 6.16). Throws core::Error when the plane misses the surface or the section encloses
/// no area.
EquivalentEllipse shear_plane_section_ellipse(std::span<const Vec<3>> X,
                                              std::span<const std::array<int, 3>> triangles, double y0);

/// Largest local area change max_e |A_e / A0_e − 1| over the triangles (A0: reference_areas, one
/// per triangle). Throws core::Error when the sizes differ.
double max_area_change(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles,
                       std::span<const double> reference_areas);

}  // namespace caplab::diagnostics
