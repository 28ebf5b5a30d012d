#include "geometry/triangle_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "core/error.hpp"

namespace caplab::geometry {
namespace {

constexpr int max_subdivisions = 8;  // 8·4^8 = 524288 triangles; more is never a membrane

void check_subdivisions(int subdivisions) {
  CAPLAB_CHECK(subdivisions >= 0 && subdivisions <= max_subdivisions,
               "triangle mesh: subdivisions is " + std::to_string(subdivisions) + ", expected 0 to " +
                   std::to_string(max_subdivisions));
}

void check_positive(const char* what, double value) {
  std::ostringstream msg;
  msg << "triangle mesh: " << what << " is " << value << ", expected positive and finite";
  CAPLAB_CHECK(std::isfinite(value) && value > 0.0, msg.str());
}

// The nodes of the subdivided octahedron are the integer points p with |px| + |py| + |pz| = N.
// Such a point is fixed by (px, py) and the sign of pz (pz = 0 only where |px| + |py| = N), which
// addresses one slot of a dense table: shared edge and corner nodes get one index.
class OctahedronNodes {
 public:
  explicit OctahedronNodes(int N) : N_(N), slot_(2 * (2 * N + 1) * (2 * N + 1), -1) {}

  int index(const Index<3>& p, std::vector<Vec<3>>& nodes) {
    int& s = slot_[2 * ((p[0] + N_) * (2 * N_ + 1) + p[1] + N_) + (p[2] > 0 ? 1 : 0)];
    if (s < 0) {
      s = static_cast<int>(nodes.size());
      nodes.push_back(Vec<3>(p[0], p[1], p[2]).normalized());  // radial projection to the unit sphere
    }
    return s;
  }

 private:
  int N_;
  std::vector<int> slot_;
};

// Face (A, B, C) of the octahedron, counter-clockwise from outside, cut into N² triangles: the
// grid points P(i, j) = (N − i − j) A + i B + j C, an "up" triangle at every (i, j) with
// i + j < N and a "down" one at every i + j < N − 1, both with the orientation of (A, B, C).
void subdivide_face(const Index<3>& A, const Index<3>& B, const Index<3>& C, int N, OctahedronNodes& index,
                    TriangleMesh& mesh) {
  auto P = [&](int i, int j) {
    Index<3> p;
    for (int d = 0; d < 3; ++d) p[d] = (N - i - j) * A[d] + i * B[d] + j * C[d];
    return index.index(p, mesh.nodes);
  };
  for (int i = 0; i < N; ++i)
    for (int j = 0; i + j < N; ++j) {
      mesh.triangles.push_back({P(i, j), P(i + 1, j), P(i, j + 1)});
      if (i + j < N - 1) mesh.triangles.push_back({P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)});
    }
}

// The subdivided octahedron projected onto the unit sphere.
TriangleMesh unit_sphere(int subdivisions) {
  const int N = 1 << subdivisions;
  TriangleMesh mesh;
  mesh.nodes.reserve(4 * N * N + 2);
  mesh.triangles.reserve(8 * N * N);
  OctahedronNodes index(N);
  for (int sx : {1, -1})
    for (int sy : {1, -1})
      for (int sz : {1, -1}) {
        const Index<3> A{sx, 0, 0};
        Index<3> B{0, sy, 0}, C{0, 0, sz};
        // (e_x, e_y, e_z) is counter-clockwise from outside; each sign flip mirrors the face.
        if (sx * sy * sz < 0) std::swap(B, C);
        subdivide_face(A, B, C, N, index, mesh);
      }
  return mesh;
}

// Scales the nodes about the origin so that the mesh encloses 4/3·π·r_eq³ (volume ∝ scale³).
void scale_to_volume(TriangleMesh& mesh, double equivalent_radius) {
  const double target = 4.0 / 3.0 * std::numbers::pi * std::pow(equivalent_radius, 3);
  const double scale = std::cbrt(target / enclosed_volume(mesh.nodes, mesh.triangles));
  for (Vec<3>& x : mesh.nodes) x *= scale;
}

Vec<3> vertex_mean(std::span<const Vec<3>> X) {
  Vec<3> s = Vec<3>::Zero();
  for (const Vec<3>& x : X) s += x;
  return X.empty() ? s : Vec<3>(s / static_cast<double>(X.size()));
}

// How the triangles share their edges.
struct EdgeCount {
  int edges = 0;           // distinct undirected edges
  int boundary = 0;        // in one triangle only (a hole)
  int non_manifold = 0;    // in more than two triangles
  int same_direction = 0;  // in two triangles that traverse it the same way (a flipped triangle)
  bool closed_and_oriented() const { return boundary == 0 && non_manifold == 0 && same_direction == 0; }
};

EdgeCount count_edges(std::span<const std::array<int, 3>> triangles) {
  std::vector<std::array<int, 3>> e;  // (lower node, higher node, +1 when traversed lower → higher)
  e.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      e.push_back(a < b ? std::array<int, 3>{a, b, 1} : std::array<int, 3>{b, a, -1});
    }
  std::sort(e.begin(), e.end());
  EdgeCount c;
  for (std::size_t i = 0; i < e.size();) {
    std::size_t j = i;
    while (j < e.size() && e[j][0] == e[i][0] && e[j][1] == e[i][1]) ++j;
    ++c.edges;
    if (j - i == 1) ++c.boundary;
    if (j - i > 2) ++c.non_manifold;
    if (j - i == 2 && e[i][2] == e[i + 1][2]) ++c.same_direction;
    i = j;
  }
  return c;
}

void check_indices(const TriangleMesh& mesh) {
  const int n = static_cast<int>(mesh.nodes.size());
  for (std::size_t e = 0; e < mesh.triangles.size(); ++e)
    for (const int a : mesh.triangles[e])
      CAPLAB_CHECK(a >= 0 && a < n, "triangle mesh: triangle " + std::to_string(e) + " refers to node " +
                                        std::to_string(a) + " of " + std::to_string(n));
}

MeshQuality quality(const TriangleMesh& mesh, const EdgeCount& edges) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  constexpr double deg = 180.0 / std::numbers::pi;
  MeshQuality q;
  double min_angle = inf, max_angle = 0, min_edge = inf, max_edge = 0, min_area = inf, max_area = 0;
  const std::span<const Vec<3>> X = mesh.nodes;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Vec<3> u = X[t[(k + 1) % 3]] - X[t[k]], v = X[t[(k + 2) % 3]] - X[t[k]];
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v));  // accurate at small and large angles
      min_angle = std::min(min_angle, angle), max_angle = std::max(max_angle, angle);
      min_edge = std::min(min_edge, u.norm()), max_edge = std::max(max_edge, u.norm());
    }
    const double area = triangle_area(X, t);
    min_area = std::min(min_area, area), max_area = std::max(max_area, area);
  }
  q.min_angle_deg = min_angle * deg;
  q.max_angle_deg = max_angle * deg;
  q.edge_ratio = max_edge / min_edge;
  q.area_ratio = max_area / min_area;
  q.closed_and_oriented = edges.closed_and_oriented();
  q.euler_characteristic =
      static_cast<int>(mesh.nodes.size()) - edges.edges + static_cast<int>(mesh.triangles.size());
  q.volume = enclosed_volume(X, mesh.triangles);
  return q;
}

[[noreturn]] void mesh_failed(const std::string& what, const std::string& problem) {
  throw core::Error("triangle mesh \"" + what + "\": " + problem);
}

}  // namespace

TriangleMesh octahedron_sphere(int subdivisions, double radius) {
  check_subdivisions(subdivisions);
  check_positive("the sphere radius", radius);
  TriangleMesh mesh = unit_sphere(subdivisions);
  for (Vec<3>& x : mesh.nodes) x *= radius;
  return mesh;
}

TriangleMesh oblate_spheroid(int subdivisions, double short_over_long, double equivalent_radius) {
  check_subdivisions(subdivisions);
  check_positive("the equivalent radius", equivalent_radius);
  std::ostringstream msg;
  msg << "triangle mesh: the oblate spheroid's short_over_long (b/a) is " << short_over_long
      << ", expected in (0, 1]";
  CAPLAB_CHECK(short_over_long > 0.0 && short_over_long <= 1.0, msg.str());
  TriangleMesh mesh = unit_sphere(subdivisions);
  for (Vec<3>& x : mesh.nodes) x[2] *= short_over_long;  // eq. 5.4 with R = 1
  scale_to_volume(mesh, equivalent_radius);
  return mesh;
}

TriangleMesh biconcave_discoid(int subdivisions, double equivalent_radius) {
  check_subdivisions(subdivisions);
  check_positive("the equivalent radius", equivalent_radius);
  TriangleMesh mesh = unit_sphere(subdivisions);
  for (Vec<3>& x : mesh.nodes) {
    const double r2 = x[0] * x[0] + x[1] * x[1];
    x[2] *= 0.5 * (0.207 + 2.003 * r2 - 1.123 * r2 * r2);  // eq. 5.5 with R = 1; sign(z)·sqrt(1 − r²) = z
  }
  scale_to_volume(mesh, equivalent_radius);
  return mesh;
}

Vec<3> area_vector(std::span<const Vec<3>> X, const std::array<int, 3>& t) {
  return 0.5 * (X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]);
}

double triangle_area(std::span<const Vec<3>> X, const std::array<int, 3>& t) {
  return area_vector(X, t).norm();
}

double enclosed_volume(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles) {
  const Vec<3> p = vertex_mean(X);  // reference point near the body: less cancellation than the origin
  double six_v = 0.0;
  for (const auto& t : triangles) six_v += (X[t[0]] - p).dot((X[t[1]] - p).cross(X[t[2]] - p));
  return six_v / 6.0;
}

double surface_area(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles) {
  double area = 0.0;
  for (const auto& t : triangles) area += triangle_area(X, t);
  return area;
}

void triangle_areas(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles,
                    std::span<double> out) {
  CAPLAB_CHECK(out.size() == triangles.size(), "triangle areas: " + std::to_string(out.size()) +
                                                   " outputs for " + std::to_string(triangles.size()) +
                                                   " triangles");
  for (std::size_t e = 0; e < triangles.size(); ++e) out[e] = triangle_area(X, triangles[e]);
}

Vec<3> volume_centroid(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles) {
  const Vec<3> p = vertex_mean(X);
  double six_v = 0.0;
  // 24 ∫ (x − p) dV: the tetrahedron (p, a, b, c), corners relative to p, adds 6V·(a + b + c).
  Vec<3> first = Vec<3>::Zero();
  for (const auto& t : triangles) {
    const Vec<3> a = X[t[0]] - p, b = X[t[1]] - p, c = X[t[2]] - p;
    const double w = a.dot(b.cross(c));
    six_v += w;
    first += w * (a + b + c);
  }
  std::ostringstream msg;
  msg << "volume centroid: the surface encloses volume " << six_v / 6.0
      << "; expected positive (closed, outward-oriented triangles)";
  CAPLAB_CHECK(six_v > 0.0, msg.str());
  return p + first / (4.0 * six_v);
}

MeshQuality mesh_quality(const TriangleMesh& mesh) {
  check_indices(mesh);
  return quality(mesh, count_edges(mesh.triangles));
}

void check_mesh(const TriangleMesh& mesh, const std::string& what) {
  check_indices(mesh);
  const EdgeCount edges = count_edges(mesh.triangles);
  if (edges.boundary > 0 || edges.non_manifold > 0)
    mesh_failed(what, "not closed: " + std::to_string(edges.boundary) +
                          " edges belong to one triangle only and " + std::to_string(edges.non_manifold) +
                          " to more than two (expected every edge in two)");
  if (edges.same_direction > 0)
    mesh_failed(what, "wrong orientation: " + std::to_string(edges.same_direction) +
                          " edges are traversed in the same direction by both their triangles (a flipped "
                          "triangle; expected counter-clockwise seen from outside)");
  const MeshQuality q = quality(mesh, edges);
  if (q.euler_characteristic != 2)
    mesh_failed(what, "Euler characteristic V - E + F is " + std::to_string(q.euler_characteristic) +
                          ", expected 2 (one closed surface without handles)");
  std::ostringstream msg;
  if (!(q.volume > 0.0)) {
    msg << "negative volume: the enclosed volume is " << q.volume
        << ", expected positive (triangles ordered inward, clockwise seen from outside?)";
    mesh_failed(what, msg.str());
  }
  if (!(q.min_angle_deg >= 1.0)) {
    msg << "degenerate triangle: the smallest angle is " << q.min_angle_deg
        << " degrees, expected at least 1";
    mesh_failed(what, msg.str());
  }
}

}  // namespace caplab::geometry
