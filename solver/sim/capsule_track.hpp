// What a scene measures on a capsule as it moves: the series quantities of one capsule, per
// dimension, with their units and definitions, and the mesh it adds to a snapshot.
//
// 2D (thesis ch. 2-4): the equivalent ellipse of the enclosed area (diagnostics/shape2d.hpp):
// D_xy and inclination, the enclosed-area change, the membrane's length change (total and the
// largest local stretch), a tracked node's phase and the tank-treading
// period from the tangential membrane velocity.
// 3D (thesis ch. 5-6): the equivalent ellipsoid of the enclosed volume (diagnostics/shape3d.hpp)
// in the shear plane x-z of u = (k z, 0, 0): D_xz, inclination, the semi-axes (length and
// thickness in the shear plane, width along the vorticity axis y), the volume change, the
// membrane area change (total and the largest local one), the phase of the node that starts
// at the largest x (on the shear plane through the centre), and, when asked for, the
// inclination of the middle cross section in the shear plane (the thesis's angle of 6.3).
//
// update() runs once per coarse step, so the unwrapped angles follow tumbling and tank-treading
// at any sampling interval. Angles are counter-clockwise from x in the shear plane (3D: from x
// toward z); tank-treading turns the phase negative in both dimensions.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "diagnostics/capsule_motion.hpp"
#include "diagnostics/shape2d.hpp"
#include "diagnostics/shape3d.hpp"
#include "geometry/triangle_mesh.hpp"
#include "io/snapshot_writer.hpp"
#include "membrane/fem_membrane.hpp"
#include "membrane/ring_membrane.hpp"
#include "sim/capsule.hpp"

namespace caplab::sim {

/// One column a capsule can contribute to the series.
struct CapsuleQuantity {
  std::string_view name, unit, definition;
};

template <int D>
class CapsuleTrack;

/// Longest time (L/U: 1/k in shear flow) between two shape updates of a capsule track. Its
/// angles must move by less than half their period (pi/2 for the axis, pi for the tracked node)
/// between updates; a capsule turns at about the shear rate, so they move by about 0.01 rad
/// (a node near the tip of an elongated capsule a few times that). Updating every step cost up to
/// a tenth of a 3D capsule's step (32768 triangles scanned twice per step: the equivalent
/// ellipsoid and the middle section); the values at the steps that read them are the same
/// (diagnostics::AngleUnwrapper depends on the angle alone, not on the samples between). Not the
/// same only for a shape that becomes round (Taylor parameter below round_capsule_taylor) for
/// less than this interval, whose axis then keeps its branch instead of starting afresh.
inline constexpr double capsule_track_interval = 0.01;

/// Below this Taylor parameter an initially round capsule has no axis worth following.
inline constexpr double round_capsule_taylor = 1e-4;

/// The continuous inclination of a capsule's axis, the angle in (-pi/2, pi/2] as measured. An
/// initially round capsule starts at D = 0, where the axis is noise: while it is that round the
/// history is forgotten and the raw angle reported, so the first meaningful axis starts it (a
/// round first reading fed to the unwrapper put a later 45 degrees on the branch 45 - 180).
inline double follow_axis(diagnostics::AngleUnwrapper& unwrap, double taylor, double angle) {
  if (taylor >= round_capsule_taylor) return unwrap(angle);
  unwrap.reset();
  return angle;
}

/// The inclination and the tracked node's phase, kept continuous in time; their history is the
/// only state of a track that a restart must restore (the shape is recomputed by the next update,
/// before anything reads it).
struct TrackAngles {
  diagnostics::AngleUnwrapper inclination{std::numbers::pi}, phase{2 * std::numbers::pi};
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    inclination.checkpoint(ar, prefix + "inclination/");
    phase.checkpoint(ar, prefix + "phase/");
  }
};

template <>
class CapsuleTrack<2> {
 public:
  static constexpr std::array<CapsuleQuantity, 7> quantities{{
      {"taylor_deformation", "1",
       "D_xy = (L - B)/(L + B), L, B semi-axes of the ellipse with the inertia tensor of the enclosed area "
       "(thesis eq. 2.33)"},
      {"inclination", "rad",
       "angle of the major axis of that ellipse from the x axis, continuous in time (tumbling keeps "
       "decreasing); counter-clockwise positive"},
      {"area_change", "1", "enclosed area over its initial value, minus 1"},
      {"length_change", "1", "membrane contour length over its rest length (the initial one), minus 1"},
      {"max_length_change", "1",
       "largest |l_i/l_i0 - 1| over the membrane's segments, l_i0 the rest length (local stretch)"},
      {"tank_treading_phase", "rad",
       "angle of membrane node 0 about the centroid, continuous in time (tank-treading: decreasing)"},
      {"tank_treading_period", "1/k",
       "T = sum over segments of length / |tangential membrane velocity|: the time a node takes to go once "
       "around the current contour (exact for a steady tank-treading shape)"},
  }};

  /// `ring`: the capsule's membrane, whose rest lengths the local stretch is measured against.
  CapsuleTrack(const Capsule<2>& c, const membrane::RingMembrane& ring)
      : ring_(&ring),
        area0_(diagnostics::equivalent_ellipse(c.positions()).area),
        length0_(std::accumulate(ring.rest_lengths().begin(), ring.rest_lengths().end(), 0.0)) {
    update(c);
  }

  void update(const Capsule<2>& c) {
    const auto X = c.positions();
    shape_ = diagnostics::equivalent_ellipse(X);
    theta_ = follow_axis(angles_.inclination, shape_.taylor, shape_.inclination);
    const Vec<2> r = X[0] - shape_.centroid;
    phi_ = angles_.phase(std::atan2(r[1], r[0]));
  }

  /// `velocity_lu`: the reference velocity k a in lattice units (node velocities are lattice units).
  double value(std::string_view q, const Capsule<2>& c, double velocity_lu) const {
    if (q == "taylor_deformation") return shape_.taylor;
    if (q == "inclination") return theta_;
    if (q == "area_change") return volume_change();
    if (q == "length_change") return diagnostics::polygon_perimeter(c.positions()) / length0_ - 1.0;
    if (q == "max_length_change") return diagnostics::max_length_change(c.positions(), ring_->rest_lengths());
    if (q == "tank_treading_period") return tank_treading_period(c, velocity_lu);
    return phi_;
  }

  /// Enclosed area over its initial value, minus 1 (the 2D volume, for the guards).
  double volume_change() const { return shape_.area / area0_ - 1.0; }

  /// The unwrapping history (io/checkpoint.hpp archive); the shape is recomputed by the next update.
  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) { angles_.checkpoint(ar, prefix); }

  void add_to_snapshot(io::SnapshotWriter<2>& w, double t, const Capsule<2>& c) const {
    const auto segs = io::closed_ring_segments(static_cast<int>(c.positions().size()));
    w.add_mesh_step(t, c.name(), c.positions(), segs);
  }

 private:
  /// sum_i l_i / |v_t,i| over the segments of the contour, v_t the tangential component of the
  /// mean node velocity of the segment, in k a (so T is in 1/k).
  static double tank_treading_period(const Capsule<2>& c, double velocity_lu) {
    const auto X = c.positions();
    const auto U = c.velocities();
    double period = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      const std::size_t j = i + 1 == X.size() ? 0 : i + 1;
      const Vec<2> d = X[j] - X[i];
      const double l = d.norm();
      const double v_t = 0.5 * (U[i] + U[j]).dot(d) / l / velocity_lu;
      period += l / std::abs(v_t);
    }
    return period;
  }

  const membrane::RingMembrane* ring_;
  double area0_, length0_;
  diagnostics::EquivalentEllipse shape_;
  TrackAngles angles_;
  double theta_ = 0.0, phi_ = 0.0;
};

template <>
class CapsuleTrack<3> {
 public:
  static constexpr std::array<CapsuleQuantity, 10> quantities{{
      {"taylor_deformation", "1",
       "D_xz = (L - B)/(L + B), L, B the semi-axes in the shear plane x-z of the ellipsoid with the second "
       "moments of the enclosed volume (thesis section 5.3.1.1)"},
      {"inclination", "rad",
       "angle of the L axis of that ellipsoid from x toward z, continuous in time (tumbling keeps decreasing)"},
      {"length", "L", "semi-axis L of that ellipsoid: the longer one in the shear plane"},
      {"width", "L", "semi-axis of that ellipsoid along the vorticity axis y"},
      {"thickness", "L", "semi-axis B of that ellipsoid: the shorter one in the shear plane"},
      {"volume_change", "1", "enclosed volume over its initial value, minus 1"},
      {"surface_area_change", "1", "membrane area over its initial value, minus 1"},
      {"max_area_change", "1", "largest |A_e/A_e0 - 1| over the membrane's triangles (local area change)"},
      {"tank_treading_phase", "rad",
       "angle about the centroid, in the shear plane from x toward z, of the membrane node that starts at the "
       "largest x; continuous in time (tank-treading: decreasing)"},
      {"section_inclination", "rad",
       "angle from x toward z of the major axis of the ellipse with the second moments of the capsule's section "
       "by the plane y = y_c through its volume centroid (the 'middle cross section in the plane of shear' of "
       "thesis 6.3, fig. 6.14, 6.16), continuous in time"},
  }};

  /// `section`: also follow the middle cross section (quantity section_inclination), a scan of
  /// all triangles per step that only the cases that ask for it pay.
  CapsuleTrack(const Capsule<3>& c, const membrane::FemMembrane& m, bool section) : fem_(&m), section_(section) {
    const auto X = c.positions();
    const auto& tris = m.triangles();
    volume0_ = geometry::enclosed_volume(X, tris);
    area0_ = geometry::surface_area(X, tris);
    tracked_ = static_cast<std::size_t>(
        std::max_element(X.begin(), X.end(), [](const Vec<3>& a, const Vec<3>& b) { return a[0] < b[0]; }) -
        X.begin());
    update(c);
  }

  void update(const Capsule<3>& c) {
    const auto X = c.positions();
    shape_ = diagnostics::equivalent_ellipsoid(X, fem_->triangles());
    theta_ = follow_axis(angles_.inclination, shape_.taylor_xz, shape_.inclination);
    const Vec<3> r = X[tracked_] - shape_.center;
    phi_ = angles_.phase(std::atan2(r[2], r[0]));
    if (section_) {
      const auto s = diagnostics::shear_plane_section_ellipse(X, fem_->triangles(), shape_.center[1]);
      section_theta_ = follow_axis(section_angle_, s.taylor, s.inclination);
    }
  }

  double value(std::string_view q, const Capsule<3>& c, double /*velocity_lu*/) const {
    if (q == "taylor_deformation") return shape_.taylor_xz;
    if (q == "inclination") return theta_;
    if (q == "section_inclination") return section_theta_;
    if (q == "length" || q == "width" || q == "thickness") return semi_axis(q);
    if (q == "volume_change") return volume_change();
    if (q == "surface_area_change") return geometry::surface_area(c.positions(), fem_->triangles()) / area0_ - 1.0;
    if (q == "max_area_change")
      return diagnostics::max_area_change(c.positions(), fem_->triangles(), fem_->reference_areas());
    return phi_;
  }

  /// The surface with, per node, the mean over its triangles of the largest principal stretch
  /// and of the local area ratio J = lambda1 lambda2 (ParaView colours the membrane by them).
  /// Enclosed volume over its initial value, minus 1.
  double volume_change() const { return shape_.volume / volume0_ - 1.0; }

  template <class Archive>
  void checkpoint(Archive& ar, const std::string& prefix) {
    angles_.checkpoint(ar, prefix);
    if (section_) section_angle_.checkpoint(ar, prefix + "section_inclination/");
  }

  void add_to_snapshot(io::SnapshotWriter<3>& w, double t, const Capsule<3>& c) const {
    const auto X = c.positions();
    const auto& tris = fem_->triangles();
    std::vector<membrane::ElementStrain> strain(tris.size());
    fem_->element_strains(X, strain);
    std::vector<double> stretch(X.size(), 0.0), ratio(X.size(), 0.0), count(X.size(), 0.0);
    for (std::size_t e = 0; e < tris.size(); ++e)
      for (const int n : tris[e]) {
        stretch[n] += strain[e].lambda1;
        ratio[n] += strain[e].lambda1 * strain[e].lambda2;
        count[n] += 1;
      }
    for (std::size_t n = 0; n < X.size(); ++n) stretch[n] /= count[n], ratio[n] /= count[n];
    w.add_mesh_step(t, c.name(), X, tris, {{"max_principal_stretch", stretch}, {"area_ratio", ratio}});
  }

 private:
  /// The ellipsoid's semi-axis along y (width), and the longer (length) and shorter (thickness)
  /// of the other two, which span the shear plane.
  double semi_axis(std::string_view q) const {
    int y_axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(shape_.axes[k][1]) > std::abs(shape_.axes[y_axis][1])) y_axis = k;
    if (q == "width") return shape_.semi_axes[y_axis];
    std::array<double, 2> in_plane{};
    for (int k = 0, j = 0; k < 3; ++k)
      if (k != y_axis) in_plane[j++] = shape_.semi_axes[k];
    return q == "length" ? std::max(in_plane[0], in_plane[1]) : std::min(in_plane[0], in_plane[1]);
  }

  const membrane::FemMembrane* fem_;
  bool section_;
  double volume0_ = 0, area0_ = 0;
  std::size_t tracked_ = 0;
  diagnostics::EquivalentEllipsoid shape_;
  TrackAngles angles_;
  diagnostics::AngleUnwrapper section_angle_{std::numbers::pi};
  double theta_ = 0.0, phi_ = 0.0, section_theta_ = 0.0;
};

/// The quantity named `q` of a D-dimensional capsule track, or nullptr.
template <int D>
const CapsuleQuantity* find_capsule_quantity(std::string_view q) {
  const auto& list = CapsuleTrack<D>::quantities;
  const auto it = std::find_if(list.begin(), list.end(), [&](const CapsuleQuantity& c) { return c.name == q; });
  return it == list.end() ? nullptr : &*it;
}

}  // namespace caplab::sim
