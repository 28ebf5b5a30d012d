// Triangulated membranes (thesis section 5.1.2): node and triangle counts of the subdivided
// octahedron, closedness/orientation/Euler characteristic, second-order convergence of the
// sphere's volume and area, the volume normalisation and the eq. 5.5 profile of the mapped
// shapes, exact geometry of the octahedron, the quality of the n = 5 rest shapes, and
// rejection of broken meshes by check_mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "geometry/triangle_mesh.hpp"

namespace caplab::geometry {
namespace {

constexpr double pi = std::numbers::pi;

double sphere_volume(double r) { return 4.0 / 3.0 * pi * r * r * r; }

// Eq. 5.5 thickness polynomial P(r²) (z = ±0.5 R sqrt(1 − r²) P(r²)).
double rbc_p(double r2) { return 0.207 + 2.003 * r2 - 1.123 * r2 * r2; }

// Smallest cosine between the normals of two triangles sharing an edge: a folded (inverted)
// triangle inside a consistently numbered mesh shows up as a negative value.
double min_neighbour_normal_cosine(const TriangleMesh& m) {
  std::map<std::pair<int, int>, std::vector<int>> by_edge;
  for (int e = 0; e < static_cast<int>(m.triangles.size()); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles[e][k], b = m.triangles[e][(k + 1) % 3];
      by_edge[{std::min(a, b), std::max(a, b)}].push_back(e);
    }
  double worst = 1.0;
  for (const auto& [edge, tris] : by_edge) {
    const Vec<3> n0 = area_vector(m.nodes, m.triangles[tris[0]]).normalized();
    const Vec<3> n1 = area_vector(m.nodes, m.triangles[tris[1]]).normalized();
    worst = std::min(worst, n0.dot(n1));
  }
  return worst;
}

// z where the vertical line through (x, y) meets the surface (all crossings).
std::vector<double> vertical_crossings(const TriangleMesh& m, double x, double y) {
  std::vector<double> z;
  for (const auto& t : m.triangles) {
    const Vec<3>&a = m.nodes[t[0]], &b = m.nodes[t[1]], &c = m.nodes[t[2]];
    const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (det == 0.0) continue;
    const double l1 = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
    const double l2 = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
    if (l1 >= 0 && l2 >= 0 && l1 + l2 <= 1) z.push_back((1 - l1 - l2) * a[2] + l1 * b[2] + l2 * c[2]);
  }
  return z;
}

std::string thrown_message(const TriangleMesh& m) {
  try {
    check_mesh(m, "test capsule");
  } catch (const core::Error& e) {
    return e.what();
  }
  return "";
}

void report(const std::string& name, const MeshQuality& q) {
  std::cout << name << ": min angle " << q.min_angle_deg << " deg, max angle " << q.max_angle_deg
            << " deg, edge ratio " << q.edge_ratio << ", area ratio " << q.area_ratio
            << ", closed and oriented " << q.closed_and_oriented << ", Euler " << q.euler_characteristic
            << ", volume " << q.volume << "\n";
  ::testing::Test::RecordProperty(name + "_min_angle_deg", std::to_string(q.min_angle_deg));
  ::testing::Test::RecordProperty(name + "_max_angle_deg", std::to_string(q.max_angle_deg));
  ::testing::Test::RecordProperty(name + "_edge_ratio", std::to_string(q.edge_ratio));
  ::testing::Test::RecordProperty(name + "_area_ratio", std::to_string(q.area_ratio));
}

TEST(TriangleMesh, OctahedronCountsAndTopology) {
  for (int n = 0; n <= 6; ++n) {
    const TriangleMesh m = octahedron_sphere(n, 2.5);
    const std::size_t N2 = std::size_t{1} << (2 * n);  // 4^n
    EXPECT_EQ(m.triangles.size(), 8 * N2) << "n = " << n;
    EXPECT_EQ(m.nodes.size(), 4 * N2 + 2) << "n = " << n;
    const MeshQuality q = mesh_quality(m);
    EXPECT_TRUE(q.closed_and_oriented) << "n = " << n;
    EXPECT_EQ(q.euler_characteristic, 2) << "n = " << n;
    EXPECT_GT(q.volume, 0.0);
    double worst = 0;
    for (const Vec<3>& x : m.nodes) worst = std::max(worst, std::abs(x.norm() - 2.5));
    EXPECT_LT(worst, 1e-14) << "nodes projected onto the sphere, n = " << n;
    EXPECT_NO_THROW(check_mesh(m, "sphere"));
  }
  EXPECT_EQ(octahedron_sphere(5, 1).triangles.size(), 8192u);
  EXPECT_EQ(octahedron_sphere(5, 1).nodes.size(), 4098u);
  EXPECT_EQ(octahedron_sphere(6, 1).triangles.size(), 32768u);
  EXPECT_EQ(octahedron_sphere(6, 1).nodes.size(), 16386u);
  // n = 0 is the octahedron itself: the six points ±r e_i.
  const TriangleMesh o = octahedron_sphere(0, 2.0);
  for (const Vec<3>& x : o.nodes) EXPECT_DOUBLE_EQ(x.cwiseAbs().sum(), 2.0);
}

TEST(TriangleMesh, RejectsArgumentsOutOfRange) {
  EXPECT_THROW(octahedron_sphere(-1, 1.0), core::Error);
  EXPECT_THROW(octahedron_sphere(9, 1.0), core::Error);
  EXPECT_THROW(octahedron_sphere(2, 0.0), core::Error);
  EXPECT_THROW(octahedron_sphere(2, std::nan("")), core::Error);
  EXPECT_THROW(oblate_spheroid(2, 0.0, 1.0), core::Error);
  EXPECT_THROW(oblate_spheroid(2, 1.5, 1.0), core::Error);
  EXPECT_THROW(oblate_spheroid(-1, 0.5, 1.0), core::Error);
  EXPECT_THROW(biconcave_discoid(2, -1.0), core::Error);
  EXPECT_THROW(biconcave_discoid(9, 1.0), core::Error);
  EXPECT_NO_THROW(octahedron_sphere(8, 1.0));
}

TEST(TriangleMesh, OctahedronGeometryIsExact) {
  // |x| + |y| + |z| <= r: volume 4/3 r³, area 8 · (√3/4)(√2 r)² = 4√3 r², centroid at its centre.
  const double r = 1.7;
  TriangleMesh o = octahedron_sphere(0, r);
  const Vec<3> shift(10.0, -3.0, 0.25);
  for (Vec<3>& x : o.nodes) x += shift;
  EXPECT_NEAR(enclosed_volume(o.nodes, o.triangles), 4.0 / 3.0 * r * r * r, 1e-13);
  EXPECT_NEAR(surface_area(o.nodes, o.triangles), 4.0 * std::sqrt(3.0) * r * r, 1e-13);
  EXPECT_NEAR((volume_centroid(o.nodes, o.triangles) - shift).norm(), 0.0, 1e-14);
  std::vector<double> areas(o.triangles.size());
  triangle_areas(o.nodes, o.triangles, areas);
  for (double a : areas) EXPECT_NEAR(a, std::sqrt(3.0) / 2.0 * r * r, 1e-14);
  std::vector<double> too_few(3);
  EXPECT_THROW(triangle_areas(o.nodes, o.triangles, too_few), core::Error);
  // Inward triangles: the volume changes sign and the centroid is refused.
  for (auto& t : o.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(enclosed_volume(o.nodes, o.triangles), -4.0 / 3.0 * r * r * r, 1e-13);
  EXPECT_THROW(volume_centroid(o.nodes, o.triangles), core::Error);
}

TEST(TriangleMesh, SphereVolumeAndAreaConvergeAtSecondOrder) {
  const double r = 1.3;
  std::vector<double> dv, da;
  for (int n = 3; n <= 6; ++n) {
    const TriangleMesh m = octahedron_sphere(n, r);
    dv.push_back(std::abs(enclosed_volume(m.nodes, m.triangles) / sphere_volume(r) - 1.0));
    da.push_back(std::abs(surface_area(m.nodes, m.triangles) / (4.0 * pi * r * r) - 1.0));
  }
  for (std::size_t k = 1; k + 1 < dv.size(); ++k) {  // orders between n = 4, 5 and n = 5, 6
    const double pv = std::log2(dv[k] / dv[k + 1]), pa = std::log2(da[k] / da[k + 1]);
    std::cout << "sphere n = " << k + 3 << " -> " << k + 4 << ": volume error " << dv[k] << " -> "
              << dv[k + 1] << " (order " << pv << "), area error " << da[k] << " -> " << da[k + 1]
              << " (order " << pa << ")\n";
    RecordProperty("volume_order_n" + std::to_string(k + 3), std::to_string(pv));
    RecordProperty("area_order_n" + std::to_string(k + 3), std::to_string(pa));
    EXPECT_NEAR(pv, 2.0, 0.1);
    EXPECT_NEAR(pa, 2.0, 0.1);
  }
  EXPECT_LT(dv[2], 5e-3);  // n = 5, the thesis's membrane: within 0.5 % of the sphere
}

TEST(TriangleMesh, MappedShapesEncloseTheEquivalentVolume) {
  const double r_eq = 2.2;
  for (int n : {2, 5}) {
    for (double s : {0.5, 0.9, 1.0}) {
      const TriangleMesh m = oblate_spheroid(n, s, r_eq);
      EXPECT_NEAR(enclosed_volume(m.nodes, m.triangles) / sphere_volume(r_eq), 1.0, 1e-12) << "n " << n;
      // Eq. 5.4: the poles (0, 0, ±s R) and the equator radius R keep the ratio b/a exactly.
      double z_max = 0, rho_max = 0;
      for (const Vec<3>& x : m.nodes)
        z_max = std::max(z_max, x[2]), rho_max = std::max(rho_max, x.head<2>().norm());
      EXPECT_NEAR(z_max / rho_max, s, 1e-14);
      EXPECT_NO_THROW(check_mesh(m, "oblate"));
    }
    const TriangleMesh b = biconcave_discoid(n, r_eq);
    EXPECT_NEAR(enclosed_volume(b.nodes, b.triangles) / sphere_volume(r_eq), 1.0, 1e-12) << "n " << n;
    EXPECT_NO_THROW(check_mesh(b, "biconcave"));
  }
  // b/a = 1: the octahedron sphere scaled to the volume (slightly outside r_eq).
  const TriangleMesh s = octahedron_sphere(4, 1.0), o = oblate_spheroid(4, 1.0, 1.0);
  const double scale = o.nodes[0].norm();
  EXPECT_GT(scale, 1.0);
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    EXPECT_NEAR((o.nodes[i] - scale * s.nodes[i]).norm(), 0.0, 1e-14);
}

TEST(TriangleMesh, BiconcaveFollowsEquation55) {
  const double r_eq = 1.0;
  const TriangleMesh m = biconcave_discoid(6, r_eq);
  double R = 0;
  for (const Vec<3>& x : m.nodes) R = std::max(R, x.head<2>().norm());
  // Every node: z = ±0.5 R sqrt(1 − r²) P(r²), r = rho / R; the equator nodes are the rim z = 0.
  double worst = 0;
  for (const Vec<3>& x : m.nodes) {
    const double r2 = x.head<2>().squaredNorm() / (R * R);
    if (x[2] == 0.0) {
      EXPECT_NEAR(r2, 1.0, 1e-14);
      continue;
    }
    worst = std::max(worst, std::abs(std::abs(x[2]) - 0.5 * R * std::sqrt(1.0 - r2) * rbc_p(r2)));
  }
  EXPECT_LT(worst, 1e-12 * R);

  // The surface between the nodes: thickness 2 h(r) = R sqrt(1 − r²) P(r²) on vertical lines,
  // to the second-order error of flat triangles (largest error over 32 azimuths, so that the
  // lines sample every position inside the triangles); exact at the poles.
  const TriangleMesh coarse = biconcave_discoid(4, r_eq);
  double Rc = 0;
  for (const Vec<3>& x : coarse.nodes) Rc = std::max(Rc, x.head<2>().norm());
  auto thickness_error = [](const TriangleMesh& mesh, double radius, double r) {
    const double exact = std::sqrt(1.0 - r * r) * rbc_p(r * r);
    double largest = 0;
    for (int k = 0; k < 32; ++k) {
      const double phi = 2 * pi * (k + 0.37) / 32;
      const auto z = vertical_crossings(mesh, r * radius * std::cos(phi), r * radius * std::sin(phi));
      EXPECT_GE(z.size(), 2u);
      const double t =
          (*std::max_element(z.begin(), z.end()) - *std::min_element(z.begin(), z.end())) / radius;
      largest = std::max(largest, std::abs(t - exact));
    }
    return largest;
  };
  for (double r : {0.0, 0.3, 0.6, 0.85, 0.95}) {
    const double e6 = thickness_error(m, R, r), e4 = thickness_error(coarse, Rc, r);
    std::cout << "biconcave thickness / R at r = " << r << ": eq. 5.5 "
              << std::sqrt(1.0 - r * r) * rbc_p(r * r) << ", largest error n = 4 " << e4 << ", n = 6 " << e6
              << "\n";
    if (r == 0.0) {
      EXPECT_NEAR(e6, 0.0, 1e-14);
    } else {
      EXPECT_LT(e6, 1e-3);
      EXPECT_LT(e6, e4 / 8.0) << "second order: 16 times smaller from n = 4 to 6";
    }
  }

  // Max thickness / diameter: d/dw [sqrt(1 − w) P(w)] = 0 is 2 (1 − w) P'(w) = P(w), i.e.
  // 5.615 w² − 10.501 w + 3.799 = 0.
  const double w = (10.501 - std::sqrt(10.501 * 10.501 - 4 * 5.615 * 3.799)) / (2 * 5.615);
  const double ratio = std::sqrt(1.0 - w) * rbc_p(w) / 2.0;
  double z_max = 0;
  for (const Vec<3>& x : m.nodes) z_max = std::max(z_max, x[2]);
  std::cout << "biconcave max thickness / diameter: eq. 5.5 " << ratio << " (at r = " << std::sqrt(w)
            << "), mesh n = 6 " << z_max / R << "\n";
  EXPECT_NEAR(ratio, 0.32809, 1e-5);
  EXPECT_LE(z_max / R, ratio + 1e-14);  // nodes sample the smooth surface
  EXPECT_NEAR(z_max / R, ratio, 1e-4);
}

TEST(TriangleMesh, QualityOfTheRestShapes) {
  const MeshQuality sphere = mesh_quality(octahedron_sphere(5, 1.0));
  const MeshQuality oblate = mesh_quality(oblate_spheroid(5, 0.5, 1.0));
  const TriangleMesh rbc = biconcave_discoid(5, 1.0);
  const MeshQuality biconcave = mesh_quality(rbc);
  report("sphere_n5", sphere);
  report("oblate_2to1_n5", oblate);
  report("biconcave_n5", biconcave);
  for (const MeshQuality* q : {&sphere, &oblate, &biconcave}) {
    EXPECT_TRUE(q->closed_and_oriented);
    EXPECT_EQ(q->euler_characteristic, 2);
    EXPECT_GT(q->volume, 0.0);
    EXPECT_GT(q->min_angle_deg, 15.0);
    EXPECT_LT(q->max_angle_deg, 120.0);
  }
  // Projection from the octahedron enlarges the triangles at the face centres against those at
  // its vertices (area ratio 4.9 at n = 5); the 2:1 map stretches the equator further.
  EXPECT_GT(sphere.min_angle_deg, 40.0);
  EXPECT_LT(sphere.edge_ratio, 2.5);
  EXPECT_LT(sphere.area_ratio, 5.5);
  for (const MeshQuality* q : {&oblate, &biconcave}) {
    EXPECT_LT(q->edge_ratio, 5.0);
    EXPECT_LT(q->area_ratio, 8.0);
  }
  EXPECT_GT(min_neighbour_normal_cosine(rbc), 0.5) << "no folded triangle near the rim or the dimple";
}

TEST(TriangleMesh, CheckMeshRejectsBrokenMeshes) {
  const TriangleMesh good = octahedron_sphere(2, 1.0);
  EXPECT_EQ(thrown_message(good), "");

  TriangleMesh flipped = good;
  std::swap(flipped.triangles[7][1], flipped.triangles[7][2]);
  EXPECT_FALSE(mesh_quality(flipped).closed_and_oriented);
  EXPECT_NE(thrown_message(flipped).find("wrong orientation: 3 edges"), std::string::npos)
      << thrown_message(flipped);
  EXPECT_NE(thrown_message(flipped).find("test capsule"), std::string::npos);

  TriangleMesh holed = good;
  holed.triangles.erase(holed.triangles.begin() + 11);
  EXPECT_FALSE(mesh_quality(holed).closed_and_oriented);
  EXPECT_NE(thrown_message(holed).find("not closed: 3 edges"), std::string::npos) << thrown_message(holed);

  TriangleMesh inward = good;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  EXPECT_TRUE(mesh_quality(inward).closed_and_oriented);  // consistently oriented, but inward
  EXPECT_NE(thrown_message(inward).find("negative volume"), std::string::npos) << thrown_message(inward);

  TriangleMesh two = good;  // two disjoint spheres: V − E + F = 4
  const int offset = static_cast<int>(good.nodes.size());
  for (const Vec<3>& x : good.nodes) two.nodes.push_back(x + Vec<3>(5, 0, 0));
  for (const auto& t : good.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  EXPECT_EQ(mesh_quality(two).euler_characteristic, 4);
  EXPECT_NE(thrown_message(two).find("Euler characteristic V - E + F is 4"), std::string::npos)
      << thrown_message(two);

  // A face of the octahedron split into three about a node 0.1 % of the way off one edge: still
  // closed, oriented, of Euler characteristic 2 and positive volume, but with a sliver.
  TriangleMesh sliver = octahedron_sphere(0, 1.0);
  const auto [a, b, c] = sliver.triangles[0];
  const Vec<3> mid = 0.5 * (sliver.nodes[a] + sliver.nodes[b]);
  sliver.nodes.push_back(mid + 1e-3 * (sliver.nodes[c] - mid));
  const int s = static_cast<int>(sliver.nodes.size()) - 1;
  sliver.triangles[0] = {a, b, s};
  sliver.triangles.push_back({b, c, s});
  sliver.triangles.push_back({c, a, s});
  EXPECT_LT(mesh_quality(sliver).min_angle_deg, 1.0);
  EXPECT_NE(thrown_message(sliver).find("degenerate triangle"), std::string::npos) << thrown_message(sliver);

  TriangleMesh bad_index = good;
  bad_index.triangles[0][2] = 1000;
  EXPECT_THROW(mesh_quality(bad_index), core::Error);
  EXPECT_THROW(check_mesh(bad_index, "bad"), core::Error);
}

}  // namespace
}  // namespace caplab::geometry
