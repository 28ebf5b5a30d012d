#include "membrane/fem_membrane.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <limits>
#include <sstream>
#include <type_traits>

#include "core/error.hpp"

namespace caplab::membrane {
namespace {

// Elements below which the loops of forces() stay serial (a fork/join costs more than the work).
constexpr std::ptrdiff_t parallel_threshold = 512;

// A reference triangle whose doubled area is below this fraction of its longest edge squared is
// degenerate (collinear nodes up to round-off).
constexpr double degenerate_area_fraction = 1e-12;

void check_modulus(const char* what, double value) {
  std::ostringstream msg;
  msg << "fem membrane: the " << what << " is " << value << ", expected finite and > 0";
  CAPLAB_CHECK(std::isfinite(value) && value > 0.0, msg.str());
}

void check_law(const MembraneLaw& law) {
  std::visit(
      [](const auto& l) {
        check_modulus("modulus E", l.E);
        if constexpr (std::is_same_v<std::decay_t<decltype(l)>, Skalak>)
          check_modulus("Skalak area-dilation ratio C", l.C);
      },
      law);
}

}  // namespace

std::string law_name(const MembraneLaw& law) {
  struct Name {
    std::string operator()(const NeoHookean&) const { return "neo-Hookean"; }
    std::string operator()(const ZeroThickness&) const { return "zero-thickness"; }
    std::string operator()(const Skalak& l) const {
      std::ostringstream s;
      s << "Skalak (C = " << l.C << ")";
      return s.str();
    }
  };
  return std::visit(Name{}, law);
}

FemMembrane::FemMembrane(const geometry::TriangleMesh& rest, MembraneLaw law)
    : law_(law), triangles_(rest.triangles) {
  check_law(law_);
  const std::size_t n = rest.nodes.size();
  const std::size_t ne = triangles_.size();
  CAPLAB_CHECK(ne > 0, "fem membrane: the mesh has no triangles");
  for (std::size_t i = 0; i < n; ++i)
    CAPLAB_CHECK(rest.nodes[i].allFinite(),
                 "fem membrane: rest node " + std::to_string(i) + " is not finite");

  A0_.resize(ne);
  shape_gradients_.resize(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const auto& t = triangles_[e];
    for (const int a : t) {
      std::ostringstream msg;
      msg << "fem membrane: triangle " << e << " (nodes " << t[0] << ", " << t[1] << ", " << t[2]
          << ") refers to node " << a << ", the mesh has " << n << " nodes";
      CAPLAB_CHECK(a >= 0 && static_cast<std::size_t>(a) < n, msg.str());
    }
    // Local rest frame: u along edge 0-1, v in the plane, orthogonal to u.
    const Vec<3> E1 = rest.nodes[t[1]] - rest.nodes[t[0]];
    const Vec<3> E2 = rest.nodes[t[2]] - rest.nodes[t[0]];
    const double l1 = E1.norm();
    const double twice_area = E1.cross(E2).norm();
    const double longest2 = std::max({E1.squaredNorm(), E2.squaredNorm(), (E2 - E1).squaredNorm()});
    A0_[e] = 0.5 * twice_area;
    if (!(twice_area > degenerate_area_fraction * longest2)) {
      std::ostringstream msg;
      msg << "fem membrane: triangle " << e << " (nodes " << t[0] << ", " << t[1] << ", " << t[2]
          << ") has reference area " << A0_[e]
          << ", expected > 0 (degenerate triangle: coincident or collinear "
          << "nodes)";
      CAPLAB_CHECK(false, msg.str());
    }
    // D0 = [X1 - X0, X2 - X0] = [[l1, p], [0, h]] in (u, v); grad N_1, grad N_2 are the rows of
    // D0^-1 = [[1/l1, -p/(l1 h)], [0, 1/h]].
    const double p = E2.dot(E1) / l1;
    const double h = twice_area / l1;
    shape_gradients_[e] = {1.0 / l1, -p / (l1 * h), 0.0, 1.0 / h};
  }

  // Node -> corner incidence (counting sort keeps the corners of each node in increasing order).
  node_offsets_.assign(n + 1, 0);
  for (const auto& t : triangles_)
    for (const int a : t) ++node_offsets_[a + 1];
  for (std::size_t i = 0; i < n; ++i) node_offsets_[i + 1] += node_offsets_[i];
  node_corners_.resize(3 * ne);
  std::vector<int> fill(node_offsets_.begin(), node_offsets_.end() - 1);
  for (std::size_t e = 0; e < ne; ++e)
    for (int k = 0; k < 3; ++k) node_corners_[fill[triangles_[e][k]]++] = static_cast<int>(3 * e + k);
  corner_forces_.resize(3 * ne);
  element_normals_.resize(ne);
  node_normals_.resize(node_count());
}

void FemMembrane::check_size(const char* what, std::size_t size, std::size_t expected) const {
  if (size == expected) return;
  std::ostringstream msg;
  msg << "fem membrane: " << what << " has " << size << " entries, expected " << expected;
  CAPLAB_CHECK(false, msg.str());
}

inline FemMembrane::Deformation FemMembrane::deformation(std::size_t e, std::span<const Vec<3>> X) const {
  const auto& t = triangles_[e];
  const auto& g = shape_gradients_[e];
  // F = sum_a x_a grad N_a^T = (x1 - x0) grad N_1^T + (x2 - x0) grad N_2^T.
  const Vec<3> e1 = X[t[1]] - X[t[0]];
  const Vec<3> e2 = X[t[2]] - X[t[0]];
  Deformation d;
  d.F1 = g[0] * e1 + g[2] * e2;
  d.F2 = g[1] * e1 + g[3] * e2;
  d.c11 = d.F1.squaredNorm(), d.c12 = d.F1.dot(d.F2), d.c22 = d.F2.squaredNorm();
  return d;
}

// Thesis eq. 5.6 in the compact form of the file header: f_a = -A0 F S grad N_a with
// S = 2 W1 Id + 2 W2 adj C (W1, W2 = dW/dI1, dW/dI2).
template <class Law>
void FemMembrane::element_forces(const Law& law, std::span<const Vec<3>> X) const {
  const auto ne = static_cast<std::ptrdiff_t>(triangles_.size());
#pragma omp parallel for schedule(static) if (ne > parallel_threshold)
  for (std::ptrdiff_t e = 0; e < ne; ++e) {
    const auto [F1, F2, c11, c12, c22] = deformation(static_cast<std::size_t>(e), X);
    const auto [W1, W2] = law.derivatives(c11 + c22 - 2.0, c11 * c22 - c12 * c12 - 1.0);
    const double s11 = 2.0 * (W1 + W2 * c22);
    const double s12 = -2.0 * W2 * c12;
    const double s22 = 2.0 * (W1 + W2 * c11);
    // Columns of P = F S, scaled by -A0.
    const double A0 = A0_[e];
    const Vec<3> P1 = -A0 * (s11 * F1 + s12 * F2);
    const Vec<3> P2 = -A0 * (s12 * F1 + s22 * F2);
    const auto& g = shape_gradients_[e];
    const Vec<3> f1 = g[0] * P1 + g[1] * P2;
    const Vec<3> f2 = g[2] * P1 + g[3] * P2;
    Vec<3>* corner = &corner_forces_[3 * e];
    corner[0] = -(f1 + f2);
    corner[1] = f1;
    corner[2] = f2;
  }
}

void FemMembrane::forces(std::span<const Vec<3>> X, std::span<Vec<3>> F) const {
  check_size("X", X.size(), node_count());
  check_size("F", F.size(), node_count());
  std::visit([&](const auto& law) { element_forces(law, X); }, law_);
  const auto n = static_cast<std::ptrdiff_t>(node_count());
  const bool parallel = static_cast<std::ptrdiff_t>(triangles_.size()) > parallel_threshold;
#pragma omp parallel for schedule(static) if (parallel)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    Vec<3> sum = Vec<3>::Zero();
    for (int c = node_offsets_[i]; c < node_offsets_[i + 1]; ++c) sum += corner_forces_[node_corners_[c]];
    F[i] = sum;
  }
}

double FemMembrane::energy(std::span<const Vec<3>> X) const {
  check_size("X", X.size(), node_count());
  return std::visit(
      [&](const auto& law) {
        double total = 0.0;
        for (std::size_t e = 0; e < triangles_.size(); ++e) {
          const auto d = deformation(e, X);
          total += A0_[e] * law.energy(d.c11 + d.c22 - 2.0, d.det_c() - 1.0);
        }
        return total;
      },
      law_);
}

void FemMembrane::element_strains(std::span<const Vec<3>> X, std::span<ElementStrain> out) const {
  check_size("X", X.size(), node_count());
  check_size("the strain output", out.size(), element_count());
  const auto ne = static_cast<std::ptrdiff_t>(triangles_.size());
#pragma omp parallel for schedule(static) if (ne > parallel_threshold)
  for (std::ptrdiff_t e = 0; e < ne; ++e) {
    const auto [F1, F2, c11, c12, c22] = deformation(static_cast<std::size_t>(e), X);
    const double detC = std::max(0.0, c11 * c22 - c12 * c12);
    // Eigenvalues of C: the larger from the trace, the smaller as det C / larger (no cancellation).
    const double half_gap = std::sqrt(0.25 * (c11 - c22) * (c11 - c22) + c12 * c12);
    const double mu1 = 0.5 * (c11 + c22) + half_gap;
    const double mu2 = mu1 > 0.0 ? detC / mu1 : 0.0;
    out[e] = {std::sqrt(mu1), std::sqrt(mu2)};
  }
}

ElementHealth<3> FemMembrane::health(std::span<const Vec<3>> X) const {
  check_size("X", X.size(), node_count());
  ElementHealth<3> h;
  h.min_ratio = std::numeric_limits<double>::infinity();
  h.max_ratio = 0;
  // Scratch sized at construction: the guards call this during the run (no allocation there).
  std::vector<Vec<3>>& normal = element_normals_;
  std::vector<Vec<3>>& around = node_normals_;
  std::fill(around.begin(), around.end(), Vec<3>::Zero());
  for (std::size_t e = 0; e < triangles_.size(); ++e) {
    const auto& t = triangles_[e];
    normal[e] = 0.5 * (X[t[1]] - X[t[0]]).cross(X[t[2]] - X[t[0]]);  // area-weighted
    const double J = normal[e].norm() / A0_[e];
    if (J < h.min_ratio) h.min_ratio = J, h.worst = e;
    h.max_ratio = std::max(h.max_ratio, J);
    for (const int n : t) around[n] += normal[e];
  }
  for (std::size_t e = 0; e < triangles_.size() && h.folded < 0; ++e) {
    const auto& t = triangles_[e];
    if (normal[e].dot(around[t[0]] + around[t[1]] + around[t[2]]) < 0) h.folded = static_cast<long>(e);
  }
  auto centre = [&](std::size_t e) {
    const auto& t = triangles_[e];
    return Vec<3>((X[t[0]] + X[t[1]] + X[t[2]]) / 3.0);
  };
  h.worst_at = centre(h.worst);
  if (h.folded >= 0) h.folded_at = centre(static_cast<std::size_t>(h.folded));
  return h;
}

}  // namespace caplab::membrane
