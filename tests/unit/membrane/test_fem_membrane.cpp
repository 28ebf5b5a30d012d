// Finite-element membrane forces (thesis eq. 5.1-5.3, 5.6 as written in fem_membrane.hpp): zero
// force and energy at rest and after rigid motions, forces = -grad(energy), vanishing total force
// and torque, the three laws agree at small strain with the README unit conventions, uniaxial
// tension against the exact curves and the digitized points of Barthes-Biesel, Diaz & Dhenin 2002,
// principal stretches, thread-count independence; bad meshes and moduli rejected.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "geometry/triangle_mesh.hpp"
#include "membrane/fem_membrane.hpp"

namespace caplab::membrane {
namespace {

using geometry::TriangleMesh;

// Octahedron with each face split 4^levels times, projected on the unit sphere; outward
// orientation (levels = 2: 128 triangles, 66 nodes; 6: 32768 / 16386).
TriangleMesh octasphere(int levels) {
  TriangleMesh m;
  m.nodes = {Vec<3>(1, 0, 0),  Vec<3>(-1, 0, 0), Vec<3>(0, 1, 0),
             Vec<3>(0, -1, 0), Vec<3>(0, 0, 1),  Vec<3>(0, 0, -1)};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto [it, added] = mid.try_emplace(key, static_cast<int>(m.nodes.size()));
      if (added) m.nodes.push_back(0.5 * (m.nodes[a] + m.nodes[b]));
      return it->second;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& [a, b, c] : m.triangles) {
      const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      finer.insert(finer.end(), {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}});
    }
    m.triangles = std::move(finer);
  }
  for (auto& x : m.nodes) x.normalize();
  return m;
}

// Flat nx x ny grid of rectangles on [0, Lx] x [0, Ly] (z = 0), each split in two triangles with
// alternating diagonals, counter-clockwise seen from +z. Node (i, j) is j (nx + 1) + i.
TriangleMesh flat_patch(int nx, int ny, double Lx, double Ly) {
  TriangleMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.nodes.emplace_back(Lx * i / nx, Ly * j / ny, 0.0);
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0)
        m.triangles.insert(m.triangles.end(), {{a, b, c}, {a, c, d}});
      else
        m.triangles.insert(m.triangles.end(), {{a, b, d}, {b, c, d}});
    }
  return m;
}

// Rotation by `angle` about `axis`.
Eigen::Matrix3d rotation(Vec<3> axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).matrix();
}

// A general deformation of the rest nodes: an anisotropic linear map plus random node noise.
std::vector<Vec<3>> deformed(const std::vector<Vec<3>>& rest, double noise, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::Matrix3d A;
  A << 1.25, 0.10, -0.05, 0.02, 0.85, 0.12, -0.08, 0.04, 1.05;
  std::vector<Vec<3>> X;
  for (const auto& x : rest) X.push_back(A * x + noise * Vec<3>(U(gen), U(gen), U(gen)));
  return X;
}

std::vector<Vec<3>> forces_of(const FemMembrane& m, const std::vector<Vec<3>>& X) {
  std::vector<Vec<3>> F(X.size());
  m.forces(X, F);
  return F;
}

double max_norm(const std::vector<Vec<3>>& F) {
  double r = 0;
  for (const auto& f : F) r = std::max(r, f.norm());
  return r;
}

double max_difference(const std::vector<Vec<3>>& A, const std::vector<Vec<3>>& B) {
  double r = 0;
  for (std::size_t i = 0; i < A.size(); ++i) r = std::max(r, (A[i] - B[i]).norm());
  return r;
}

const std::vector<std::pair<std::string, MembraneLaw>>& all_laws() {
  static const std::vector<std::pair<std::string, MembraneLaw>> laws{
      {"NH", NeoHookean{3.0}}, {"ZT", ZeroThickness{3.0}}, {"SK", Skalak{2.0, 5.0}}};
  return laws;
}

TEST(FemMembrane, RestStateHasZeroForceAndEnergy) {
  for (const auto& mesh : {octasphere(2), flat_patch(3, 2, 1.5, 0.7)}) {
    for (const auto& [name, law] : all_laws()) {
      const FemMembrane m(mesh, law);
      const auto F = forces_of(m, mesh.nodes);
      // Scale: E x (edge length) is the force of an O(1) strain.
      EXPECT_LT(max_norm(F), 1e-13) << name;
      EXPECT_LT(std::abs(m.energy(mesh.nodes)), 1e-14) << name;
      EXPECT_NEAR(m.min_area_ratio(mesh.nodes), 1.0, 1e-14) << name;
    }
  }
}

TEST(FemMembrane, ForcesAreMinusEnergyGradient) {
  const auto mesh = octasphere(2);
  const auto X0 = deformed(mesh.nodes, 0.04, 7);
  for (const auto& [name, law] : all_laws()) {
    const FemMembrane m(mesh, law);
    ASSERT_GT(m.min_area_ratio(X0), 0.5);
    const auto F = forces_of(m, X0);
    const double h = 1e-5;
    auto X = X0;
    double worst = 0;
    for (std::size_t i = 0; i < X.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        X[i][k] = X0[i][k] + h;
        const double Ep = m.energy(X);
        X[i][k] = X0[i][k] - h;
        const double Em = m.energy(X);
        X[i][k] = X0[i][k];
        worst = std::max(worst, std::abs(-(Ep - Em) / (2 * h) - F[i][k]));
      }
    const double rel = worst / max_norm(F);
    std::printf("  FD gradient, %s: max |F + dE/dx| / max |F| = %.2e (max |F| = %.3e)\n", name.c_str(), rel,
                max_norm(F));
    EXPECT_LT(rel, 1e-6) << name;
  }
}

TEST(FemMembrane, TotalForceAndTorqueVanish) {
  const auto mesh = octasphere(3);
  auto X = deformed(mesh.nodes, 0.02, 11);
  for (auto& x : X) x += Vec<3>(3.0, -2.0, 5.0);  // torque about the origin, away from the capsule
  for (const auto& [name, law] : all_laws()) {
    const FemMembrane m(mesh, law);
    const auto F = forces_of(m, X);
    Vec<3> sum = Vec<3>::Zero(), torque = Vec<3>::Zero();
    double force_scale = 0, torque_scale = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      sum += F[i];
      torque += X[i].cross(F[i]);
      force_scale += F[i].norm();
      torque_scale += X[i].norm() * F[i].norm();
    }
    EXPECT_LT(sum.norm() / force_scale, 1e-14) << name;
    EXPECT_LT(torque.norm() / torque_scale, 1e-14) << name;
  }
}

TEST(FemMembrane, RigidMotionGivesZeroForce) {
  const auto R = rotation(Vec<3>(0.3, -1.0, 0.7), 2.1);
  const Vec<3> shift(-4.0, 1.5, 0.25);
  for (const auto& mesh : {octasphere(2), flat_patch(2, 3, 1.0, 1.2)}) {
    std::vector<Vec<3>> X;
    for (const auto& x : mesh.nodes) X.push_back(R * x + shift);
    for (const auto& [name, law] : all_laws()) {
      const FemMembrane m(mesh, law);
      EXPECT_LT(max_norm(forces_of(m, X)), 1e-13) << name;
      EXPECT_LT(std::abs(m.energy(X)), 1e-14) << name;
    }
  }
}

// Relative difference of the forces of two laws at strain amplitude eps (a smooth non-rigid
// displacement field of the sphere).
double law_difference(const MembraneLaw& a, const MembraneLaw& b, double eps) {
  const auto mesh = octasphere(2);
  std::vector<Vec<3>> X;
  for (const auto& x : mesh.nodes)
    X.push_back(
        x + eps * Vec<3>(x[0] * x[1] + 0.5 * x[0], std::sin(2.0 * x[2]) - 0.3 * x[1], x[0] * x[0] - x[2]));
  const FemMembrane ma(mesh, a), mb(mesh, b);
  const auto Fa = forces_of(ma, X), Fb = forces_of(mb, X);
  return max_difference(Fa, Fb) / max_norm(Fa);
}

TEST(FemMembrane, LawsAgreeAtSmallStrain) {
  // Shear modulus G_s = 1: NH and ZT E = 3 G_s, SK E = 2 G_s with C = 1 (README conventions). The
  // strain energies agree to second order in the strain, so the forces (first order) differ by a
  // second-order amount: the relative difference falls linearly with the strain.
  const double Gs = 1.0;
  const MembraneLaw nh = NeoHookean{3 * Gs}, zt = ZeroThickness{3 * Gs}, sk = Skalak{2 * Gs, 1.0};
  for (const auto& [name, other] : {std::pair<std::string, MembraneLaw>{"ZT", zt}, {"SK", sk}}) {
    const double r1 = law_difference(nh, other, 1e-3), r2 = law_difference(nh, other, 5e-4);
    std::printf("  NH vs %s: relative force difference %.3e at strain 1e-3, %.3e at 5e-4 (ratio %.3f)\n",
                name.c_str(), r1, r2, r1 / r2);
    EXPECT_LT(r1, 1e-2) << name;
    EXPECT_NEAR(r1 / r2, 2.0, 0.1) << name;
  }
  // The comparison must be able to fail: Skalak with E_SK = E_NH has 1.5 times the stiffness.
  // (|F_NH - 1.5 F_NH| / |F_NH| = 0.5).
  EXPECT_NEAR(law_difference(nh, Skalak{3 * Gs, 1.0}, 1e-3), 0.5, 0.01);
}

// ---- Uniaxial tension of a flat patch (Barthes-Biesel, Diaz & Dhenin 2002) ----

// A 2 x 1 patch of 4 x 2 cells in a tilted plane, stretched by lambda1 along its first and lambda2
// along its second in-plane axis; T1, T2 = principal tensions per unit deformed length, from the
// node forces on the x = Lx and y = Ly boundaries.
class UniaxialPatch {
 public:
  explicit UniaxialPatch(MembraneLaw law) : rest_(flat_patch(nx, ny, Lx, Ly)) {
    for (auto& x : rest_.nodes) x = R_ * x + origin_;
    membrane_.emplace(rest_, law);
  }

  std::array<double, 2> tensions(double lambda1, double lambda2) const {
    std::vector<Vec<3>> X;
    for (const auto& x : rest_.nodes) {
      const Vec<3> p = R_.transpose() * (x - origin_);
      X.push_back(R_ * Vec<3>(lambda1 * p[0], lambda2 * p[1], 0.0) + origin_);
    }
    const auto F = forces_of(*membrane_, X);
    const Vec<3> ex = R_.col(0), ey = R_.col(1);
    double load1 = 0, load2 = 0;  // the load that holds the patch: minus the membrane's force
    for (int j = 0; j <= ny; ++j) load1 -= F[j * (nx + 1) + nx].dot(ex);
    for (int i = 0; i <= nx; ++i) load2 -= F[ny * (nx + 1) + i].dot(ey);
    return {load1 / (lambda2 * Ly), load2 / (lambda1 * Lx)};
  }

  /// lambda2 with T2(lambda1, lambda2) = 0, by bisection on the membrane's own forces.
  double free_lambda2(double lambda1) const {
    double lo = 0.2, hi = 1.0;
    EXPECT_LT(tensions(lambda1, lo)[1], 0.0);
    EXPECT_GT(tensions(lambda1, hi)[1], 0.0);
    for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
      const double mid = 0.5 * (lo + hi);
      (tensions(lambda1, mid)[1] > 0.0 ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }

 private:
  static constexpr int nx = 4, ny = 2;
  static constexpr double Lx = 2.0, Ly = 1.0;
  TriangleMesh rest_;
  Eigen::Matrix3d R_ = rotation(Vec<3>(1.0, 2.0, -0.5), 0.9);
  Vec<3> origin_{0.3, -0.7, 1.1};
  std::optional<FemMembrane> membrane_;
};

// The exact curves of the CSV header, in G_s units; lambda1 = sqrt(2 e1 + 1).
double nh_lambda2(double l1) { return 1.0 / std::sqrt(l1); }
double nh_tension(double l1) { return (l1 * l1 * l1 - 1.0) / std::pow(l1, 1.5); }
double sk_lambda2(double l1, double C) { return std::sqrt((1 + C * l1 * l1) / (1 + C * l1 * l1 * l1 * l1)); }
double sk_tension(double l1, double C) {
  const double l2 = sk_lambda2(l1, C);
  return l1 / l2 * ((l1 * l1 - 1) + C * l2 * l2 * (l1 * l1 * l2 * l2 - 1));
}

TEST(FemMembrane, UniaxialTensionMatchesExactCurves) {
  const double Gs = 1.0;
  const UniaxialPatch nh(NeoHookean{3 * Gs}), sk(Skalak{2 * Gs, 1.0});
  double worst_t1 = 0, worst_t2 = 0, worst_l2 = 0;
  for (const double l1 : {1.01, 1.1, 1.25, 1.5, std::sqrt(3.0)}) {
    for (const auto& [patch, l2, T1] : {std::tuple{&nh, nh_lambda2(l1), nh_tension(l1)},
                                        std::tuple{&sk, sk_lambda2(l1, 1.0), sk_tension(l1, 1.0)}}) {
      const auto T = patch->tensions(l1, l2);
      worst_t1 = std::max(worst_t1, std::abs(T[0] / Gs - T1) / T1);
      worst_t2 = std::max(worst_t2, std::abs(T[1] / Gs));
      EXPECT_NEAR(T[0] / Gs, T1, 1e-8 * T1) << "lambda1 " << l1;
      EXPECT_NEAR(T[1] / Gs, 0.0, 1e-10) << "lambda1 " << l1;
      // lambda2 found from the membrane's own forces is the exact one.
      const double root = patch->free_lambda2(l1);
      worst_l2 = std::max(worst_l2, std::abs(root - l2));
      EXPECT_NEAR(root, l2, 1e-10) << "lambda1 " << l1;
    }
  }
  std::printf(
      "  uniaxial exact curves: max |T1 - exact| / exact = %.2e, max |T2| / G_s = %.2e, max |lambda2 root "
      "- exact| = %.2e\n",
      worst_t1, worst_t2, worst_l2);
}

TEST(FemMembrane, ZeroThicknessUniaxialTensionSatisfiesItsClosedForm) {
  // W = G_s/2 [I1 - L + L^2/2], L = ln(lambda1^2 lambda2^2): T2 = 0 gives lambda2^2 = 1 - L, then
  // T1 = G_s (lambda1^2 - lambda2^2) / (lambda1 lambda2).
  const UniaxialPatch zt(ZeroThickness{3.0});
  for (const double l1 : {1.05, 1.3, 1.7}) {
    const double l2 = zt.free_lambda2(l1);
    EXPECT_NEAR(l2 * l2, 1.0 - std::log(l1 * l1 * l2 * l2), 1e-12);
    EXPECT_NEAR(zt.tensions(l1, l2)[0], (l1 * l1 - l2 * l2) / (l1 * l2), 1e-10);
  }
}

struct TensionPoint {
  std::string law;
  double e1, T1;
};

std::vector<TensionPoint> read_bb2002() {
  const std::string path = CAPLAB_SOURCE_DIR "/references/membrane/membrane_uniaxial_tension_BB2002.csv";
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  std::vector<TensionPoint> points;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      EXPECT_EQ(line, "law,e1,T1_over_Gs");
      header = false;
      continue;
    }
    std::istringstream s(line);
    TensionPoint p;
    std::string e1, T1;
    std::getline(s, p.law, ',');
    std::getline(s, e1, ',');
    std::getline(s, T1, ',');
    p.e1 = std::stod(e1);
    p.T1 = std::stod(T1);
    points.push_back(p);
  }
  return points;
}

// Largest excess of |T1_model - T1_digitized| over the tolerance 0.03 + 0.03 |T1_model| (<= 0:
// every point agrees). The stated digitization uncertainty is +-0.03; the points lie
// systematically above the exact curves by up to 3 % of T1 at large strain (an axis-scale error
// of the digitization; see references/membrane/provenance.json), hence the relative part.
double worst_excess(const UniaxialPatch& patch, const std::vector<TensionPoint>& points,
                    const std::string& law, double* worst_abs) {
  double worst = -1e300;
  int count = 0;
  for (const auto& p : points) {
    if (p.law != law) continue;
    ++count;
    const double l1 = std::sqrt(2 * p.e1 + 1);
    const double T1 = patch.tensions(l1, patch.free_lambda2(l1))[0];
    *worst_abs = std::max(*worst_abs, std::abs(T1 - p.T1));
    worst = std::max(worst, std::abs(T1 - p.T1) - (0.03 + 0.03 * std::abs(T1)));
  }
  EXPECT_GE(count, 50) << law;
  return worst;
}

TEST(FemMembrane, UniaxialTensionMatchesBarthesBiesel2002Points) {
  const auto points = read_bb2002();
  const UniaxialPatch nh(NeoHookean{3.0}), sk(Skalak{2.0, 1.0});
  double nh_abs = 0, sk_abs = 0, reject_abs = 0;
  EXPECT_LE(worst_excess(nh, points, "NH", &nh_abs), 0.0);
  EXPECT_LE(worst_excess(sk, points, "SK_C1", &sk_abs), 0.0);
  // The comparator must reject a wrong law: neo-Hookean against the Skalak points.
  EXPECT_GT(worst_excess(nh, points, "SK_C1", &reject_abs), 0.5);
  std::printf(
      "  BB2002 digitized points: max |T1 - point| / G_s = %.4f (NH), %.4f (SK C=1); NH vs SK points "
      "(must fail): %.3f\n",
      nh_abs, sk_abs, reject_abs);
}

TEST(FemMembrane, ElementStrainsArePrincipalStretches) {
  const auto mesh = flat_patch(2, 2, 1.0, 1.0);
  const FemMembrane m(mesh, NeoHookean{1.0});
  const auto R = rotation(Vec<3>(0.2, 0.1, 1.0), 0.6);
  const auto Q = rotation(Vec<3>(0.0, 0.0, 1.0), 0.4);  // principal axes at 0.4 rad in the plane
  const Eigen::Matrix3d A = R * Q * Eigen::Vector3d(0.8, 1.3, 1.0).asDiagonal() * Q.transpose();
  std::vector<Vec<3>> X;
  for (const auto& x : mesh.nodes) X.push_back(A * x);
  std::vector<ElementStrain> s(m.element_count());
  m.element_strains(X, s);
  for (const auto& e : s) {
    EXPECT_NEAR(e.lambda1, 1.3, 1e-14);
    EXPECT_NEAR(e.lambda2, 0.8, 1e-14);
  }
  EXPECT_NEAR(m.min_area_ratio(X), 1.3 * 0.8, 1e-14);
}

TEST(FemMembrane, ForcesDoNotDependOnTheThreadCount) {
  const auto mesh = octasphere(4);  // 2048 elements: above the serial threshold
  const auto X = deformed(mesh.nodes, 0.01, 3);
  const FemMembrane m(mesh, Skalak{2.0, 10.0});
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto F1 = forces_of(m, X);
  omp_set_num_threads(2);
  const auto F2 = forces_of(m, X);
  omp_set_num_threads(3);
  const auto F3 = forces_of(m, X);
  omp_set_num_threads(saved);
  EXPECT_GT(max_norm(F1), 0.0);
  EXPECT_EQ(max_difference(F1, F2), 0.0);
  EXPECT_EQ(max_difference(F1, F3), 0.0);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const core::Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FemMembrane, RejectsBadMeshesAndModuli) {
  auto mesh = flat_patch(1, 1, 1.0, 1.0);
  mesh.nodes.emplace_back(2.0, 0.0, 0.0);  // node 4, collinear with nodes 0 and 1
  mesh.triangles.push_back({0, 1, 4});
  const std::string degenerate = error_of([&] { FemMembrane(mesh, NeoHookean{1.0}); });
  EXPECT_NE(degenerate.find("triangle 2 (nodes 0, 1, 4)"), std::string::npos) << degenerate;
  EXPECT_NE(degenerate.find("reference area 0"), std::string::npos) << degenerate;

  auto repeated = flat_patch(1, 1, 1.0, 1.0);
  repeated.triangles[1] = {2, 3, 2};
  EXPECT_NE(error_of([&] { FemMembrane(repeated, NeoHookean{1.0}); }).find("triangle 1"), std::string::npos);

  auto out_of_range = flat_patch(1, 1, 1.0, 1.0);
  out_of_range.triangles[0][2] = 7;
  EXPECT_NE(error_of([&] { FemMembrane(out_of_range, NeoHookean{1.0}); }).find("refers to node 7"),
            std::string::npos);

  const auto good = flat_patch(1, 1, 1.0, 1.0);
  EXPECT_NE(error_of([&] { FemMembrane(good, NeoHookean{0.0}); }).find("modulus E is 0"), std::string::npos);
  EXPECT_NE(error_of([&] { FemMembrane(good, ZeroThickness{-1.0}); }).find("modulus E"), std::string::npos);
  EXPECT_NE(error_of([&] { FemMembrane(good, ZeroThickness{std::nan("")}); }).find("modulus E"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              FemMembrane(good, Skalak{1.0, 0.0});
            }).find("area-dilation ratio C is 0"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { FemMembrane(good, Skalak{1.0, 1.0}); }), "(no error)");

  const FemMembrane m(good, NeoHookean{1.0});
  std::vector<Vec<3>> X(good.nodes.size() + 1), F(good.nodes.size());
  EXPECT_NE(error_of([&] { m.forces(X, F); }).find("X has 5 entries, expected 4"), std::string::npos);
}

TEST(FemMembrane, LawNames) {
  EXPECT_EQ(law_name(NeoHookean{1.0}), "neo-Hookean");
  EXPECT_EQ(law_name(ZeroThickness{1.0}), "zero-thickness");
  EXPECT_EQ(law_name(Skalak{1.0, 5.0}), "Skalak (C = 5)");
}

// The guards of a run read the worst element: a healthy sphere, a compressed element, a fold.
TEST(FemMembrane, HealthFindsTheSmallestAndTheFoldedElement) {
  const auto mesh = octasphere(3);
  const FemMembrane m(mesh, NeoHookean{1.0});
  const auto ok = m.health(mesh.nodes);
  EXPECT_NEAR(ok.min_ratio, 1.0, 1e-12);
  EXPECT_EQ(ok.folded, -1);
  // Mirror one corner of a triangle across its opposite edge: that triangle turns over.
  const auto& t = mesh.triangles[17];
  auto X = mesh.nodes;
  X[t[0]] = X[t[1]] + X[t[2]] - X[t[0]];
  const auto fold = m.health(X);
  ASSERT_GE(fold.folded, 0);
  const auto& f = mesh.triangles[static_cast<std::size_t>(fold.folded)];
  EXPECT_TRUE(f[0] == t[0] || f[1] == t[0] || f[2] == t[0]);
  // A node pushed deep inward makes a dimple, which is not a fold.
  X = mesh.nodes;
  X[5] *= 0.6;
  EXPECT_EQ(m.health(X).folded, -1);
  EXPECT_LT(fold.min_ratio, 1.0);
  EXPECT_GT(fold.max_ratio, 1.0);
  // A uniform shrink to 0.9 of the radius: every element at 0.81 of its area, nothing folded.
  for (auto& x : X = mesh.nodes) x *= 0.9;
  const auto shrunk = m.health(X);
  EXPECT_NEAR(shrunk.min_ratio, 0.81, 1e-12);
  EXPECT_EQ(shrunk.folded, -1);
}

}  // namespace
}  // namespace caplab::membrane
