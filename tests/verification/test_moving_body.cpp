// Verification of the hydrodynamic force on a moving rigid body, and of its internal-mass
// correction (ibm/internal_mass.hpp, rigid form, as sim/scene.hpp applies it to bodies with a
// prescribed motion): the added mass of a circular cylinder oscillating in fluid at rest.
//
// Set-up (built here as a case document and run through the public API, cases::parse_case and
// sim::run_case): a cylinder of diameter D = 2a oscillates along x, x_c = X0 + A sin(omega t),
// at the centre of a closed square box of side W = 6 D (far-field faces with the rest state,
// i.e. walls at the faces, Guo's non-equilibrium extrapolation). Unit of velocity U = A omega
// (the velocity amplitude), so the period is T = KC D/U. Physical parameters:
//   Keulegan-Carpenter number KC = U T / D = 2 pi A / D = 0.5       (small: linear, no separation)
//   Stokes number        beta = D^2 / (nu T) = 400                  (Re = U D / nu = beta KC = 200)
//   Mach number          Ma = sqrt(3) U_lu = 0.0043                 (U_lu = 0.0025 on every grid)
//   Period               N_T = 200 D/h steps = 9.6 periods of the box's lowest acoustic mode
//                        (2 W / c_s), the same on every grid (acoustic scaling). Compressibility
//                        is then a small offset that extrapolation does not remove: halving N_T
//                        moves C_a by 0.012 at D/h = 16, doubling it by 0.002.
// The amplitude is ramped in over the first period, x_c = X0 + A s(t) sin(omega t) with
// s = t/T - sin(2 pi t/T)/(2 pi) (C^2 at t = 0 and t = T: no impulse that would ring in the
// closed box, where sound is hardly damped at tau ~ 1/2); the next two periods are measured.
//
// Measurement: the series column drag_coefficient is F_body,x / (0.5 rho U^2 D) with
// F_body = -F_on_fluid + rho V a_c (V = pi a^2, a_c the exact centre acceleration). Least
// squares over two whole periods on the exact kinematics (a_c and u_c from the formula above,
// independent of the solver's expression parser) of
//   F_body / (rho V) = -C_a a_c - C_q omega u_c,
// C_a the added-mass coefficient, C_q the in-quadrature (damping) coefficient. Without the
// internal-mass term (-F_on_fluid alone) the same fit gives C_a + 1: the inertia of the fluid
// inside the cylinder, which the direct forcing accelerates with the body.
//
// Reference: potential flow plus the Stokes-layer correction.
//  * A circle of radius a at the centre of a square of half-side R, by images (a lattice of
//    dipoles at (2mR, 2nR) with sign (-1)^m; their uniform flow at the centre changes the
//    dipole strength): C_a,pot = (1 + k e)/(1 - k e), e = a^2/R^2,
//    k = pi^2/24 + (pi^2/2) sum_{n>=1} cosh(pi n)/sinh^2(pi n) = 0.85940, exact up to
//    O(e^3) (the non-uniform part of the image flow); for R/a = 6 this is 1.04891, which a
//    least-squares multipole solution of the same Neumann problem reproduces to 1e-6. The
//    concentric circular wall of radius R, C_a = (R^2 + a^2)/(R^2 - a^2) (k = 1, 1.05714 here),
//    bounds it from above, the circumscribed one (radius sqrt(2) R, k = 1/2) from below.
//  * Viscous correction for beta >> 1, KC << 1 (Stokes 1851; Wang 1968, J. Fluid Mech. 32):
//    C_a = C_a,pot + 4 (pi beta)^(-1/2) + O((pi beta)^(-3/2)), and
//    C_q = 4 (pi beta)^(-1/2) + 4 (pi beta)^(-1); here 0.1128 and 0.1160.
//  Together C_a = 1.1617 (the box contributes 0.049, the Stokes layer 0.113).
//
// Tolerance. The diffuse interface (cosine kernel, 4 h wide) makes the cylinder act roughly
// like one of radius a + h: C_a exceeds the reference by 0.78, 0.46, 0.27 at D/h = 12, 18, 27,
// far more than any tolerance worth having. The comparison is therefore made on the
// Richardson extrapolation of the three grids (ratio 1.5) with the observed order. Measured
// in the preparation of this test (same set-up): the error falls with an order of 1.27 to 1.32
// from D/h = 8 to 48 (errors 1.316, 0.775, 0.533, 0.459, 0.315, 0.218, 0.131 at D/h = 8, 12,
// 16, 18, 24, 32, 48); extrapolations from the triplets (8, 12, 18), (8, 16, 32), (12, 18, 27)
// and (12, 24, 48) give 1.173, 1.168, 1.155 and 1.170, i.e. within 0.012 of the reference;
// the same design at beta = 100 and 1000 extrapolates to within 0.021 and 0.017 of its own
// reference (that also checks the 4 (pi beta)^(-1/2) trend). The tolerance 0.05 is 2.5 times
// the largest of these deviations and one twentieth of the quantity under test (the inner
// mass, 1). The damping is checked for sign and magnitude only: the Stokes layer,
// delta = sqrt(2 nu / omega) = 0.34 - 0.76 h on these grids, is not resolved (C_q measured
// 0.127 - 0.135, 10 - 16 % above Wang's value).
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "case/load_case.hpp"
#include "io/series_writer.hpp"
#include "sim/run_case.hpp"

namespace caplab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using std::numbers::pi;

constexpr double keulegan_carpenter = 0.5;  // U T / D; with U = A omega and D = 1, T = KC
constexpr double stokes = 400.0;            // D^2 / (nu T)
constexpr double box = 6.0;                 // side W of the square box, in D
constexpr int steps_per_cell = 200;         // steps per period over cells per diameter (fixed Mach)
constexpr int measured_periods = 2;         // after one period of ramp
constexpr int samples_per_period = 100;     // a whole number of steps apart on every grid below
constexpr double period = keulegan_carpenter;
constexpr double amplitude = keulegan_carpenter / (2 * pi);  // A, in D
constexpr double omega = 2 * pi / period;

/// Added-mass coefficient of a circle of radius a at the centre of a square box of half-side R,
/// in potential flow, by images (see the file header); radius_ratio = a / R.
double square_box_added_mass(double radius_ratio) {
  double sum = 0;
  for (int n = 1; n <= 20; ++n) sum += std::cosh(pi * n) / (std::sinh(pi * n) * std::sinh(pi * n));
  const double kappa = pi * pi / 24 + pi * pi / 2 * sum;
  const double e = kappa * radius_ratio * radius_ratio;
  return (1 + e) / (1 - e);
}

/// Potential-flow added mass inside a concentric circular wall, radius_ratio = a / R.
double circular_box_added_mass(double radius_ratio) {
  const double e = radius_ratio * radius_ratio;
  return (1 + e) / (1 - e);
}

/// Stokes-layer correction of the added mass (and leading part of C_q), Wang 1968.
double stokes_layer_correction() { return 4 / std::sqrt(pi * stokes); }

/// The reference C_a of the header: square box plus the Stokes layer.
double reference_added_mass() { return square_box_added_mass(0.5 / (0.5 * box)) + stokes_layer_correction(); }

/// The case: uniform grid of `cells_per_diameter` cells per D.
json oscillating_cylinder_case(int cells_per_diameter) {
  const double h = 1.0 / cells_per_diameter;
  const double c = 0.5 * box;
  const std::string ramp = "(t/T - sin(2*pi*t/T)/(2*pi))";
  json motion = {{"type", "prescribed"},
                 {"parameters", {{"x0", c}, {"y0", c}, {"A", amplitude}, {"T", period}}},
                 {"segments",
                  {{{"until", period}, {"position", {"x0 + A*" + ramp + "*sin(2*pi*t/T)", "y0"}}},
                   {{"position", {"x0 + A*sin(2*pi*t/T)", "y0"}}}}}};
  return {
      {"id", "verification/oscillating_cylinder"},
      {"title", "Circular cylinder oscillating in a closed box of fluid at rest (added mass)"},
      {"description",
       "A cylinder of diameter D = 1 oscillates along x, x = X0 + A sin(2 pi t / T), ramped in over the "
       "first period, at the centre of a 6 D square box with rest walls; KC = 2 pi A / D = 0.5, Stokes "
       "number D^2/(nu T) = 400, U = A omega. The body force includes the inertia of the fluid inside the "
       "cylinder."},
      {"physics",
       {{"dimension", 2},
        {"flow", {{"type", "rest"}}},
        {"reynolds", stokes * keulegan_carpenter},
        {"domain", {{"size", {box, box}}, {"boundaries", {"far_field", "far_field"}}}},
        {"bodies",
         {{{"name", "cylinder"},
           {"shape", {{"type", "circle"}, {"center", {c, c}}, {"diameter", 1.0}}},
           {"motion", motion}}}}}},
      {"numerics",
       {{"grid", {{"refinement", "uniform"}, {"fine_spacing", h}}},
        {"collision", {{"operator", "trt"}}},
        {"precision", "double"},
        {"ib", {{"kernel", "cosine4"}, {"marker_spacing", 0.79}, {"forcing_iterations", 1}}},
        {"lattice_velocity", period / (steps_per_cell * cells_per_diameter * h)},
        {"end_time", period * (1 + measured_periods)}}},
      {"fidelity", {{"standard", json::object()}}},
      {"outputs",
       {{"series", {{"interval", period / samples_per_period}, {"quantities", {"drag_coefficient"}}}}}}};
}

struct ForceFit {
  double added_mass = 0;  ///< C_a
  double damping = 0;     ///< C_q
  double residual = 0;    ///< rms misfit over rms force
};

/// Least squares of f = -C_a a_c - C_q omega u_c over the measured periods; `f` is the force
/// over rho V, `inner_mass` is added to it first (-1: the force without the correction).
ForceFit fit_force(const std::vector<double>& t, const std::vector<double>& drag_coefficient,
                   double inner_mass) {
  double s_aa = 0, s_av = 0, s_vv = 0, s_fa = 0, s_fv = 0;
  std::vector<std::array<double, 3>> rows;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] <= period * (1 + 1e-9)) continue;  // the ramp
    const double a_c = -amplitude * omega * omega * std::sin(omega * t[i]);
    const double u_c = amplitude * omega * std::cos(omega * t[i]);
    // F = 0.5 rho U^2 D C_d with rho = U = D = 1 and rho V = pi/4.
    const double f = 0.5 * drag_coefficient[i] / (pi / 4) + inner_mass * a_c;
    const double xa = -a_c, xv = -omega * u_c;
    s_aa += xa * xa, s_av += xa * xv, s_vv += xv * xv, s_fa += f * xa, s_fv += f * xv;
    rows.push_back({f, xa, xv});
  }
  const double det = s_aa * s_vv - s_av * s_av;
  ForceFit r;
  r.added_mass = (s_fa * s_vv - s_fv * s_av) / det;
  r.damping = (s_aa * s_fv - s_av * s_fa) / det;
  double misfit = 0, norm = 0;
  for (const auto& [f, xa, xv] : rows) {
    const double e = f - r.added_mass * xa - r.damping * xv;
    misfit += e * e, norm += f * f;
  }
  r.residual = std::sqrt(misfit / norm);
  return r;
}

struct GridResult {
  int cells_per_diameter = 0;
  std::size_t samples = 0;
  ForceFit corrected, uncorrected;
};

GridResult run_grid(int cells_per_diameter) {
  const auto spec =
      cases::parse_case(oscillating_cylinder_case(cells_per_diameter), "test_moving_body", "standard", {});
  const fs::path out = fs::temp_directory_path() / ("caplab_test_moving_body_" + std::to_string(::getpid()) +
                                                    "_" + std::to_string(cells_per_diameter));
  const auto start = std::chrono::steady_clock::now();
  sim::run_case(spec, out, {});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto series = io::read_series(out / "series.h5");
  fs::remove_all(out);
  GridResult g;
  g.cells_per_diameter = cells_per_diameter;
  const auto& t = series.at("t");
  const auto& cd = series.at("drag_coefficient");
  g.samples = t.size();
  g.corrected = fit_force(t, cd, 0.0);
  g.uncorrected = fit_force(t, cd, -1.0);
  std::printf("D/h = %2d: C_a = %.4f (without the inner mass %.4f), C_q = %.4f, misfit %.4f, %.1f s\n",
              cells_per_diameter, g.corrected.added_mass, g.uncorrected.added_mass, g.corrected.damping,
              g.corrected.residual, wall);
  return g;
}

struct Extrapolation {
  double order = 0;
  double value = 0;
};

/// Richardson extrapolation of values on grids refined by `ratio`, with the observed order.
Extrapolation richardson(double coarse, double medium, double fine, double ratio) {
  Extrapolation e;
  e.order = std::log((coarse - medium) / (medium - fine)) / std::log(ratio);
  e.value = fine - (medium - fine) / (std::pow(ratio, e.order) - 1);
  return e;
}

TEST(AddedMassReference, SquareBoxLiesBetweenInscribedAndCircumscribedCircles) {
  for (const double ratio : {0.5, 1.0 / 3.0, 1.0 / 6.0, 0.05}) {
    const double square = square_box_added_mass(ratio);
    EXPECT_LT(square, circular_box_added_mass(ratio)) << "a/R = " << ratio;
    EXPECT_GT(square, circular_box_added_mass(ratio / std::sqrt(2.0))) << "a/R = " << ratio;
  }
  EXPECT_NEAR(square_box_added_mass(1e-3), 1.0, 1e-5);            // unbounded fluid: C_a = 1
  EXPECT_NEAR(square_box_added_mass(1.0 / 6.0), 1.048912, 1e-6);  // the multipole solution
}

TEST(AddedMassReference, RichardsonRecoversAKnownLimit) {
  auto f = [](double h) { return 1.25 + 3.0 * std::pow(h, 1.3); };
  const auto e = richardson(f(1.0 / 12), f(1.0 / 18), f(1.0 / 27), 1.5);
  EXPECT_NEAR(e.order, 1.3, 1e-9);
  EXPECT_NEAR(e.value, 1.25, 1e-9);
}

// Three runs, D/h = 12, 18, 27 (73^2 to 163^2 nodes, 2400 to 5400 steps per period, three
// periods each): about 13 s single-threaded.
TEST(OscillatingCylinder, InternalMassCorrectionGivesThePotentialAddedMass) {
  const double reference = reference_added_mass();
  const int grids[] = {12, 18, 27};
  std::vector<GridResult> r;
  for (int n : grids) r.push_back(run_grid(n));

  // Sanity: a harmonic force at the forcing frequency, sampled over two whole periods, and
  // energy going from the body into the fluid.
  for (const auto& g : r) {
    EXPECT_EQ(g.samples, static_cast<std::size_t>((1 + measured_periods) * samples_per_period))
        << g.cells_per_diameter;
    EXPECT_LT(g.corrected.residual, 0.03)
        << "D/h = " << g.cells_per_diameter << ": not a harmonic force at omega";
    EXPECT_GT(g.corrected.damping, 0) << "D/h = " << g.cells_per_diameter;
  }
  // Sanity: the diffuse-interface error shrinks monotonically at the order the preparation
  // measured (1.2 - 1.4 over D/h = 8 - 48 and beta = 100 - 1000).
  for (std::size_t k = 1; k < r.size(); ++k)
    EXPECT_LT(std::abs(r[k].corrected.added_mass - reference),
              std::abs(r[k - 1].corrected.added_mass - reference))
        << "D/h = " << r[k].cells_per_diameter;
  const auto c =
      richardson(r[0].corrected.added_mass, r[1].corrected.added_mass, r[2].corrected.added_mass, 1.5);
  const auto u =
      richardson(r[0].uncorrected.added_mass, r[1].uncorrected.added_mass, r[2].uncorrected.added_mass, 1.5);
  std::printf(
      "extrapolated: C_a = %.4f at order %.2f (without the inner mass %.4f); reference %.4f = %.4f (square "
      "box, potential flow) + %.4f (Stokes layer)\n",
      c.value, c.order, u.value, reference, square_box_added_mass(0.5 / (0.5 * box)),
      stokes_layer_correction());
  EXPECT_GT(c.order, 1.0);
  EXPECT_LT(c.order, 1.7);

  // Closeness to the reference (tolerance: see the file header).
  const double tolerance = 0.05;
  EXPECT_NEAR(c.value, reference, tolerance) << "the added mass of the corrected body force";
  // The comparator must reject the force without the internal-mass term: it carries the inner
  // fluid's inertia, C_a + 1.
  EXPECT_GT(std::abs(u.value - reference), 10 * tolerance) << "the force without the inner mass passed";
  EXPECT_NEAR(u.value - c.value, 1.0, 1e-9) << "the correction is not rho V a";

  // Damping: sign and magnitude of the Stokes-layer value (under-resolved, see the header).
  const double wang = stokes_layer_correction() + 4 / (pi * stokes);
  EXPECT_NEAR(r.back().corrected.damping / wang, 1.0, 0.3) << "C_q = " << r.back().corrected.damping;
}

}  // namespace
}  // namespace caplab
