#include "diagnostics/shape3d.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "geometry/triangle_mesh.hpp"

namespace caplab::diagnostics {
namespace {

constexpr double pi = std::numbers::pi;

// Volume integrals of the polyhedron relative to a reference point p: V, ∫ r dV, ∫ r rᵀ dV.
struct Moments {
  double volume = 0;
  Vec<3> first = Vec<3>::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
};

Moments moments_about(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles,
                      const Vec<3>& p) {
  Moments m;
  for (const auto& t : triangles) {
    const Vec<3> a = X[t[0]] - p, b = X[t[1]] - p, c = X[t[2]] - p, s = a + b + c;
    const double w = a.dot(b.cross(c));  // 6 V_t
    m.volume += w;
    m.first += w * s;
    m.second += w * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  m.volume /= 6.0;
  m.first /= 24.0;
  m.second /= 120.0;
  return m;
}

Vec<3> vertex_mean(std::span<const Vec<3>> X) {
  Vec<3> s = Vec<3>::Zero();
  for (const Vec<3>& x : X) s += x;
  return X.empty() ? s : Vec<3>(s / static_cast<double>(X.size()));
}

// Second moments about the volume centroid, with the volume and the centroid.
Eigen::Matrix3d central_second_moment(std::span<const Vec<3>> X,
                                      std::span<const std::array<int, 3>> triangles, double& volume,
                                      Vec<3>& center) {
  const Vec<3> p = vertex_mean(X);  // near the body: less cancellation than the origin
  const Moments m = moments_about(X, triangles, p);
  std::ostringstream msg;
  msg << "shape diagnostics: the surface of " << triangles.size() << " triangles encloses volume " << m.volume
      << "; expected positive (a closed surface, triangles counter-clockwise seen from outside)";
  CAPLAB_CHECK(m.volume > 0.0, msg.str());
  const Vec<3> d = m.first / m.volume;  // centroid relative to p
  volume = m.volume;
  center = p + d;
  const Eigen::Matrix3d M = m.second - m.volume * d * d.transpose();
  return 0.5 * (M + M.transpose());  // exactly symmetric for the eigensolver
}

// The sign that makes the largest component positive: reproducible axes from run to run.
Vec<3> canonical_sign(const Vec<3>& e) {
  Eigen::Index i;
  e.cwiseAbs().maxCoeff(&i);
  return e[i] < 0 ? Vec<3>(-e) : e;
}

// An axis angle folded into (−π/2, π/2].
double fold_half_turn(double theta) {
  if (theta > 0.5 * pi) return theta - pi;
  if (theta <= -0.5 * pi) return theta + pi;
  return theta;
}

// D_xz and inclination from the two axes nearest the shear plane (see the header).
void shear_plane_shape(EquivalentEllipsoid& e) {
  int vorticity = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(e.axes[k][1]) > std::abs(e.axes[vorticity][1])) vorticity = k;
  const int l = vorticity == 0 ? 1 : 0;  // semi_axes descend: the first remaining is L
  const int b = vorticity == 2 ? 1 : 2;  // and the second B
  const double L = e.semi_axes[l], B = e.semi_axes[b];
  e.taylor_xz = (L - B) / (L + B);
  e.inclination = fold_half_turn(std::atan2(e.axes[l][2], e.axes[l][0]));
}

// The point where edge (i, j) crosses y = y0, the same from both triangles of the edge (endpoints
// taken in index order) and exactly the node when the node lies on the plane.
Vec<3> edge_crossing(std::span<const Vec<3>> X, int i, int j, double y0) {
  const Vec<3>& lo = X[std::min(i, j)];
  const Vec<3>& hi = X[std::max(i, j)];
  const double t = (y0 - lo[1]) / (hi[1] - lo[1]);
  return (1.0 - t) * lo + t * hi;
}

}  // namespace

EquivalentEllipsoid equivalent_ellipsoid(std::span<const Vec<3>> X,
                                         std::span<const std::array<int, 3>> triangles) {
  EquivalentEllipsoid e;
  const Eigen::Matrix3d M = central_second_moment(X, triangles, e.volume, e.center);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(M);
  CAPLAB_CHECK(eigen.info() == Eigen::Success, "shape diagnostics: the second-moment eigensolver failed");
  std::ostringstream msg;
  msg << "shape diagnostics: the second-moment tensor has eigenvalues " << eigen.eigenvalues().transpose()
      << "; expected positive (a surface enclosing a solid)";
  CAPLAB_CHECK(eigen.eigenvalues()[0] > 0.0, msg.str());
  for (int k = 0; k < 3; ++k) {  // the eigenvalues ascend; the semi-axes descend
    e.semi_axes[k] = std::sqrt(5.0 * eigen.eigenvalues()[2 - k] / e.volume);
    e.axes[k] = canonical_sign(eigen.eigenvectors().col(2 - k));
  }
  shear_plane_shape(e);
  return e;
}

namespace {

// Calls segment(p, q) for each triangle the plane y = y0 crosses, p -> q counter-clockwise in
// (x, z) (see shear_plane_section).
template <class Segment>
void for_each_section_segment(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles, double y0,
                              Segment&& segment) {
  for (const auto& t : triangles) {
    std::array<bool, 3> above;
    for (int k = 0; k < 3; ++k) above[k] = X[t[k]][1] >= y0;
    if (above[0] == above[1] && above[1] == above[2]) continue;
    std::array<Vec<3>, 2> s;
    for (int k = 0, n = 0; k < 3; ++k)
      if (above[k] != above[(k + 1) % 3]) s[n++] = edge_crossing(X, t[k], t[(k + 1) % 3], y0);
    if (s[0] == s[1]) continue;  // touches the plane at one node only
    // Counter-clockwise in (x, z): along n × e_y = (−n_z, 0, n_x), n the outward normal.
    const Vec<3> n = geometry::area_vector(X, t);
    if ((s[1] - s[0]).dot(Vec<3>(-n[2], 0.0, n[0])) < 0.0) std::swap(s[0], s[1]);
    segment(s[0], s[1]);
  }
}

}  // namespace

std::vector<std::array<Vec<3>, 2>> shear_plane_section(std::span<const Vec<3>> X,
                                                       std::span<const std::array<int, 3>> triangles,
                                                       double y0) {
  std::vector<std::array<Vec<3>, 2>> segments;
  for_each_section_segment(X, triangles, y0, [&](const Vec<3>& p, const Vec<3>& q) { segments.push_back({p, q}); });
  return segments;
}

EquivalentEllipse shear_plane_section_ellipse(std::span<const Vec<3>> X,
                                              std::span<const std::array<int, 3>> triangles, double y0) {
  // Accumulated as the segments come (no buffer: the capsule track calls this every step),
  // relative to the first segment's start, which lies on the section.
  std::optional<RegionMoments> moments;
  for_each_section_segment(X, triangles, y0, [&](const Vec<3>& p, const Vec<3>& q) {
    const Vec<2> a(p[0], p[2]), b(q[0], q[2]);
    if (!moments) moments.emplace(a);
    moments->add_edge(a, b);
  });
  CAPLAB_CHECK(moments.has_value(), "shape diagnostics: the plane y = " + std::to_string(y0) + " misses the surface");
  return moments->ellipse("section");
}

double max_area_change(std::span<const Vec<3>> X, std::span<const std::array<int, 3>> triangles,
                       std::span<const double> reference_areas) {
  CAPLAB_CHECK(reference_areas.size() == triangles.size(),
               "max area change: " + std::to_string(reference_areas.size()) + " reference areas for " +
                   std::to_string(triangles.size()) + " triangles");
  double worst = 0.0;
  for (std::size_t e = 0; e < triangles.size(); ++e)
    worst = std::max(worst, std::abs(geometry::triangle_area(X, triangles[e]) / reference_areas[e] - 1.0));
  return worst;
}

}  // namespace caplab::diagnostics
