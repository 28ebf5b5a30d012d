// Closed triangulated surfaces of 3D capsule membranes (thesis section 5.1.2).
//
// A TriangleMesh is a list of nodes and of triangles {a, b, c} ordered counter-clockwise seen
// from outside (outward normal (b − a) × (c − a)). Lengths in any unit (the case's L = a).
//
// Rest shapes (z is the symmetry axis of the non-spherical ones):
//   octahedron_sphere  each face of the regular octahedron |x| + |y| + |z| = 1 cut into 4^n
//                      triangles (N = 2^n segments per edge), shared nodes stored once, the
//                      nodes projected radially onto the sphere: 8·4^n triangles, 4·4^n + 2 nodes
//                      (n = 5: 8192 / 4098, n = 6: 32768 / 16386). The nodes lie on the sphere;
//                      the polyhedron's volume is 4/3·π·r³ (1 − O(4^-n)).
//   oblate_spheroid    thesis eq. 5.4 on the unit-sphere nodes: (R x, R y, (b/a) R z).
//   biconcave_discoid  thesis eq. 5.5 on the unit-sphere nodes, with r² = x² + y² (the thesis's
//                      r² = x² + z² is a typo, DESIGN.md section 3):
//                        (R x, R y, sign(z)·0.5 R sqrt(1 − r²)(0.207 + 2.003 r² − 1.123 r⁴)).
//                      On the unit sphere sign(z)·sqrt(1 − r²) = z, so z' = 0.5 R z P(r²) is
//                      used: no square root of a round-off-negative 1 − r² at the equator. The
//                      map (x, y, z) → (x, y, z·P(x² + y²)/2) has Jacobian determinant
//                      P/2 ≥ 0.1035 > 0, so it keeps the outward orientation.
//   For both, R is chosen so that the POLYHEDRON encloses exactly 4/3·π·r_eq³ (the volume of a
//   linear or node-wise-scaled mesh is R³ times that of the R = 1 mesh: closed form).
//
// Geometry of a current configuration X (positions change in time, the connectivity does not):
// volume, centroid (divergence theorem, exact for the polyhedron), areas. Quality of a mesh:
// angles, edge and area ratios, closedness and orientation (every edge in exactly two
// triangles, traversed in opposite directions), Euler characteristic V − E + F (2 for a sphere).
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "core/vec.hpp"

namespace caplab::geometry {

struct TriangleMesh {
  std::vector<Vec<3>> nodes;
  std::vector<std::array<int, 3>> triangles;  ///< outward orientation
};

/// Sphere of `radius` from the octahedron, each face subdivided into 4^subdivisions triangles,
/// nodes projected onto the sphere. Throws core::Error unless 0 <= subdivisions <= 8 and the
/// radius is positive and finite.
TriangleMesh octahedron_sphere(int subdivisions, double radius);

/// Oblate spheroid of eq. 5.4 with semi-axis ratio b/a = short_over_long in (0, 1] along z,
/// scaled so the mesh encloses 4/3·π·equivalent_radius³. short_over_long = 1 is the
/// octahedron sphere scaled by (4/3·π r³ / V_mesh)^(1/3) (nodes slightly outside r). Throws
/// core::Error on an argument out of range.
TriangleMesh oblate_spheroid(int subdivisions, double short_over_long, double equivalent_radius);

/// Biconcave discoid (red blood cell) of eq. 5.5 with z the symmetry axis, scaled so the mesh
/// encloses 4/3·π·equivalent_radius³. Throws core::Error on an argument out of range.
TriangleMesh biconcave_discoid(int subdivisions, double equivalent_radius);

/// Outward area vector of triangle t in configuration X: ½ (b − a) × (c − a) (|·| = area).
Vec<3> area_vector(std::span<const Vec<3>> X, const std::array<int, 3>& t);

/// Area of triangle t in configuration X.
double triangle_area(std::span<const Vec<3>> X, const std::array<int, 3>& t);

/// Volume enclosed by the closed surface (positive for outward orientation): the sum of the
/// signed tetrahedra from the vertex mean to each triangle, exact for the polyhedron.
double enclosed_volume(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles);

/// Total area of the triangles.
double surface_area(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles);

/// The area of each triangle into `out`. Throws core::Error when out.size() != triangles.size().
void triangle_areas(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles,
                    std::span<double> out);

/// Centroid of the enclosed volume (exact for the polyhedron). Throws core::Error when the
/// enclosed volume is not positive.
Vec<3> volume_centroid(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles);

/// Shape-quality figures of a mesh. Angles in degrees; ratios >= 1.
struct MeshQuality {
  double min_angle_deg = 0, max_angle_deg = 0;  ///< smallest and largest interior angle
  double edge_ratio = 0;                        ///< longest / shortest edge
  double area_ratio = 0;                        ///< largest / smallest triangle
  bool closed_and_oriented = false;  ///< every edge in exactly two triangles, in opposite directions
  int euler_characteristic = 0;      ///< V − E + F (2 for a closed surface of genus 0)
  double volume = 0;                 ///< enclosed_volume (positive when outward)
};

/// Quality figures of `mesh`. Throws core::Error on a node index out of range.
MeshQuality mesh_quality(const TriangleMesh& mesh);

/// Throws core::Error naming `what`, the failing property and its value when the mesh is not
/// closed, not consistently oriented, not of Euler characteristic 2, encloses a non-positive
/// volume (inward orientation) or has a degenerate triangle (an angle below 1 degree).
void check_mesh(const TriangleMesh& mesh, const std::string& what);

}  // namespace caplab::geometry
