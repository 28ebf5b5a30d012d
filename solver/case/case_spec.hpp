// The typed, validated form of a case file (DESIGN.md section 5).
//
// A case file is JSON; `case::load_case` parses it, applies the chosen fidelity level and
// the `--set` overrides, validates every value, and returns a CaseSpec. Nothing downstream
// reads JSON: model code sees only these types. Units: every length is in units of the
// reference length L (D for a cylinder, a for a capsule), every velocity in units of the
// reference velocity U (U∞, or k·a for shear flow), time in L/U (t·U∞/D, or k·t).
#pragma once

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "expr/rigid_kinematics.hpp"

namespace caplab::cases {

/// Imposed (unperturbed) flow: initial condition and far-field / wall velocity.
struct FlowSpec {
  enum class Type {
    rest,         ///< u = 0
    uniform,      ///< u = U · direction (flow past a body)
    shear,        ///< u_x = k (x_g − centre_g), g = y in 2D, z in 3D (thesis section 4 conventions)
    body_force,   ///< u = 0 initially, driven by a constant body force along x (Poiseuille)
    taylor_green  ///< decaying Taylor–Green vortex (verification)
  };
  Type type = Type::rest;
  std::vector<double> direction;  ///< uniform: unit vector (default +x)
  double body_force = 0.0;        ///< body_force: force density along x, in ρU²/L
  /// uniform: amplitude (in U) of a transverse velocity blob in the initial condition,
  /// 1.5 D downstream of each body with width D/2, that breaks the wake's symmetry so that
  /// shedding starts early instead of waiting for round-off to grow (0: none).
  double perturbation = 0.0;
};

/// What happens on the two faces normal to one axis.
enum class BoundaryType {
  periodic,   ///< periodic along this axis
  far_field,  ///< unperturbed flow imposed by Guo's non-equilibrium extrapolation
  wall        ///< half-way bounce-back wall moving with the imposed flow's velocity there
};

/// How a rigid body moves. `prescribed`: time segments, each with the centre per axis and
/// (2D) the orientation as expressions of t in L/U (expr/expression.hpp), e.g. thesis eq. 2.28
/// as two segments split at t = 16. The centre at t = 0 is shape.center and the orientation
/// shape.angle (checked); velocities and accelerations are the exact derivatives.
struct RigidMotionSpec {
  enum class Type { fixed, prescribed };
  Type type = Type::fixed;
  /// Built by the loader for every rigid body: fixed, constant at shape.center / shape.angle;
  /// prescribed, the parsed segments.
  std::optional<expr::RigidKinematics> kinematics;
};

struct ShapeSpec {
  /// 2D: circle, ellipse, biconcave (eq. 3.12). 3D: sphere, oblate_spheroid (eq. 5.4) and
  /// biconcave_discoid (eq. 5.5), both with their symmetry axis along z.
  enum class Type { circle, ellipse, biconcave, sphere, oblate_spheroid, biconcave_discoid };
  Type type = Type::circle;
  std::vector<double> center;  ///< in L
  /// In L: the diameter of a circle or sphere; for the other shapes the equivalent diameter,
  /// twice the equivalent radius: 2D 2 (area/pi)^(1/2) (thesis eq. 3.9), 3D 2 (3V/(4pi))^(1/3).
  double diameter = 1.0;
  /// ellipse: semi-major over semi-minor axis (thesis ch. 3: 2); oblate_spheroid: equatorial
  /// over polar semi-axis (thesis "10:9", "3:2", "2:1").
  double aspect_ratio = 2.0;
  double alpha = 1.39;        ///< biconcave: cell radius ratio of thesis eq. 3.12 (red cell 1.39)
  double angle = 0.0;         ///< 2D shapes: rotation of the long axis from x, radians (counter-clockwise)

  /// ellipse: the semi-axes along the long and the short body axis, in L (same area as the
  /// equivalent circle: a b = (diameter/2)^2).
  double semi_major() const { return 0.5 * diameter * std::sqrt(aspect_ratio); }
  double semi_minor() const { return 0.5 * diameter / std::sqrt(aspect_ratio); }
};

/// Elastic membrane of a capsule: 2D rings with Hooke tension and bending (thesis ch. 3,
/// eq. 3.1-3.10); 3D triangulated surfaces with finite-element forces from the strain energy
/// (ch. 5, eq. 5.1-5.3). Moduli as dimensionless groups.
struct MembraneSpec {
  enum class Law { hooke, neo_hookean, zero_thickness, skalak };
  enum class ReferenceCurvature { initial, circle, flat };
  Law law = Law::hooke;
  double capillary = 0.04;    ///< G = mu k a / E (eq. 3.9; 3D: E the modulus of eq. 5.1-5.3)
  double bending_ratio = 0.0; ///< 2D: E_b = E_B / (a^2 E) (eq. 3.10)
  ReferenceCurvature reference_curvature = ReferenceCurvature::initial;  ///< 2D: kappa_0 of eq. 3.8
  double area_dilation = 1.0; ///< skalak: C of eq. 5.3 (area-dilation over shear modulus)
  int nodes = 0;              ///< 2D: Lagrangian nodes, equally spaced in arc length (0 in 3D)
  int subdivisions = 0;       ///< 3D: each octahedron face cut into 4^n triangles (5: 4098 nodes; 0 in 2D)
};

/// A rigid body (with `motion`) or, when `membrane` is set, a liquid-filled capsule whose
/// membrane moves with the fluid (thesis eq. 2.15).
struct BodySpec {
  std::string name;
  ShapeSpec shape;
  std::optional<RigidMotionSpec> motion;   ///< rigid bodies
  bool is_moving() const { return motion && motion->type == RigidMotionSpec::Type::prescribed; }
  std::optional<MembraneSpec> membrane;   ///< capsules
  bool is_capsule() const { return membrane.has_value(); }
};

struct PhysicsSpec {
  int dimension = 2;
  FlowSpec flow;
  double reynolds = 1.0;             ///< with the convention of the flow type (see units)
  std::vector<double> domain_size;   ///< in L, one per axis
  std::vector<BoundaryType> boundaries;  ///< one per axis
  std::vector<BodySpec> bodies;
};

struct GridSpec {
  enum class Refinement { uniform, two_level };
  Refinement refinement = Refinement::uniform;
  double fine_spacing = 0.02;        ///< Δx of the finest block, in L (coarse = 2·fine)
  std::vector<double> fine_min, fine_max;  ///< fine block extent in L (two_level only)
};

struct CollisionSpec {
  enum class Operator { bgk, trt };
  Operator op = Operator::bgk;
  double magic = 0.25;  ///< TRT magic parameter Λ = (τ+ − ½)(τ− − ½)
  /// ζ/μ, the bulk to the shear viscosity, when the bulk mode relaxes with its own time
  /// (collision::TrtBulk); absent: the operator's own 2/D.
  std::optional<double> bulk_viscosity_ratio;
};

struct IbSpec {
  enum class Kernel { cosine4, roma3, linear2 };
  Kernel kernel = Kernel::cosine4;
  double marker_spacing = 0.79;  ///< Lagrangian marker spacing in fine-grid spacings
  int forcing_iterations = 1;    ///< multi-direct-forcing iterations (1 = plain direct forcing)
};

enum class Precision { double_, single };

/// How the far-field faces impose the unperturbed flow (boundary/boundary_set.hpp).
enum class FarFieldScheme { extrapolation, equilibrium };

/// The checks every run makes while it goes (sim/scene.hpp check_guards): a run that leaves
/// these bounds stops with exit code 3 instead of writing garbage.
struct GuardSpec {
  int every = 100;                      ///< coarse steps between checks
  double max_mach = 0.5;                ///< local |u| sqrt(3) in lattice units, any block
  double max_density_deviation = 0.2;   ///< |rho - 1|
  double max_volume_change = 0.1;       ///< |V/V0 - 1| of a capsule (2D: enclosed area)
  double min_area_ratio = 0.05;         ///< smallest element area (2D: segment length) over its rest value
};

struct NumericsSpec {
  GridSpec grid;
  CollisionSpec collision;
  Precision precision = Precision::double_;
  IbSpec ib;
  FarFieldScheme far_field = FarFieldScheme::extrapolation;
  double lattice_velocity = 0.1;  ///< U in lattice units (same on every block: acoustic scaling)
  double end_time = 1.0;          ///< in L/U
  int threads = 0;                ///< 0: OMP_NUM_THREADS, else the usable processors (CPU quota respected)
  GuardSpec guards;
};

struct SeriesSpec {
  double interval = 0.1;             ///< sampling interval of the time series, in L/U
  std::vector<std::string> quantities;  ///< e.g. "drag", "lift", "kinetic_energy", "mass"
};

struct SnapshotSpec {
  std::vector<double> times;          ///< in L/U
  std::vector<std::string> fields;    ///< "vorticity", "velocity", "density"
};

/// When a run writes checkpoint.h5 (for `caplab run --resume`): every `interval` L/U of
/// simulated time and every `wall_seconds` of wall time, whichever comes first (0: off).
struct CheckpointSpec {
  double interval = 0.0;
  double wall_seconds = 600.0;
};

struct OutputSpec {
  SeriesSpec series;
  SnapshotSpec snapshots;
  double average_from = 0.0;  ///< start of the window for means, amplitudes and frequencies (L/U)
  /// Smallest reversal of a capsule's inclination, in degrees, that counts as swinging: twice this,
  /// peak to peak, in the window (diagnostics::classify_capsule_motion).
  double oscillation_threshold_deg = 1.0;
  CheckpointSpec checkpoint;
};

/// One scored metric (issue "catalogue scoring"); kept typed so scoring and reports share it.
struct AcceptanceSpec {
  std::string metric;         ///< a key of summary.json
  std::string reference;      ///< path of a references/ dataset (with #key) or "value"
  double reference_value = 0.0;
  std::string comparison;     ///< "relative" | "absolute" | "time_series" | "mode"
  std::map<std::string, double> tolerance;  ///< per fidelity level (numeric comparisons)
  std::vector<std::string> reference_modes;   ///< comparison "mode": the allowed modes
  std::vector<double> window;                 ///< comparison "time_series": [from, to] in L/U, or empty
  std::string justification;
};

/// The run's wall-time budget per fidelity level (levels without one are not judged), with the
/// reason for it; judged by the scorer as the performance verdict, never as the run's verdict.
struct PerformanceSpec {
  std::map<std::string, double> wall_time_budget_s;
  std::string justification;
};

struct CaseSpec {
  std::string source_file;  ///< where it was loaded from (for messages)
  std::string id, title, description;
  std::string fidelity;     ///< the level that was applied
  PhysicsSpec physics;
  NumericsSpec numerics;
  OutputSpec outputs;
  std::vector<AcceptanceSpec> acceptance;
  std::optional<PerformanceSpec> performance;
  nlohmann::json resolved;  ///< the fully resolved JSON (fidelity and overrides applied)
  nlohmann::json document;  ///< the case as read, before the level and the overrides (a resumed run reloads it)
  std::vector<std::string> overrides;  ///< the --set overrides, in order
};

}  // namespace caplab::cases
