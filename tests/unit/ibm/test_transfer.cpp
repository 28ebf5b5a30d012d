// IB transfer: adjointness of interpolation and spreading (2D, 3D, every kernel, with and
// without periodic wrap), exactness on polynomials, conservation, periodic wrap (also on a
// periodic axis shorter than the stencil), the interpolation from a field against the
// node-by-node form, the out-of-block and diverged-marker errors, and the union of the
// stencil nodes (ibm/stencil_union.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <omp.h>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "ibm/transfer.hpp"
#include "ibm_test_util.hpp"

namespace caplab::ibm {
namespace {

using testing::make_grid;
using testing::random_positions;
using testing::random_vec;
using testing::sum_interior;

template <int Dim, class K, bool Periodic>
struct Config {
  static constexpr int D = Dim;
  using Kernel = K;
  static constexpr bool periodic = Periodic;
};

template <class C>
class TransferTest : public ::testing::Test {};
using Configs = ::testing::Types<Config<2, Cosine4, false>, Config<2, Cosine4, true>, Config<2, Roma3, false>,
                                 Config<2, Linear2, true>, Config<3, Cosine4, false>,
                                 Config<3, Cosine4, true>, Config<3, Roma3, true>, Config<3, Linear2, false>>;
TYPED_TEST_SUITE(TransferTest, Configs);

template <class C>
std::array<bool, C::D> periodic_flags() {
  std::array<bool, C::D> p;
  p.fill(C::periodic);
  return p;
}

// Marker lattice coordinates: anywhere (even outside the block) when periodic, otherwise far
// enough from the edges for the stencil.
template <class C>
std::vector<Vec<C::D>> markers(const field::Grid<C::D>& g, int count, std::mt19937& rng) {
  const int n = g.n()[0];
  return C::periodic ? random_positions<C::D>(g, count, -3.0, n + 3.0, rng)
                     : random_positions<C::D>(g, count, 2.0, n - 3.0, rng);
}

TYPED_TEST(TransferTest, InterpolationAndSpreadingAreAdjoint) {
  constexpr int D = TypeParam::D;
  std::mt19937 rng(42);
  const auto g = make_grid<D>(D == 2 ? 24 : 12);
  const auto x = markers<TypeParam>(g, 60, rng);
  std::vector<Vec<D>> u(g.size());
  for (auto& v : u) v = random_vec<D>(rng, -1.0, 1.0);
  std::vector<Vec<D>> force(x.size());
  std::vector<double> w(x.size());
  for (std::size_t m = 0; m < x.size(); ++m) {
    force[m] = random_vec<D>(rng, -1.0, 1.0);
    w[m] = std::uniform_real_distribution<double>(0.3, 1.2)(rng);
  }
  Transfer<D, typename TypeParam::Kernel> t;
  t.update(g, periodic_flags<TypeParam>(), x);
  std::vector<Vec<D>> ux(x.size());
  t.interpolate([&](const Index<D>&, std::ptrdiff_t id) { return u[id]; }, ux);
  field::VectorField<D> f(g.size());
  t.spread(force, w, f);

  double lagrangian = 0.0, scale = 0.0;
  for (std::size_t m = 0; m < x.size(); ++m) {
    lagrangian += ux[m].dot(force[m]) * w[m];
    scale += ux[m].norm() * force[m].norm() * w[m];
  }
  const double eulerian = sum_interior<D>(g, 0.0, [&](const Index<D>&, std::ptrdiff_t id) {
    double s = 0.0;
    for (int a = 0; a < D; ++a) s += u[id][a] * f.comp[a][id];
    return s;
  });
  EXPECT_NEAR(lagrangian, eulerian, 1e-13 * scale);
  // The comparator must be able to fail: a perturbed field breaks the identity.
  std::vector<std::ptrdiff_t> nodes0;
  t.for_each_stencil_node(0, [&](const Index<D>&, std::ptrdiff_t id, double) { nodes0.push_back(id); });
  f.comp[0][nodes0[1]] += 1e-3;
  const double perturbed = sum_interior<D>(g, 0.0, [&](const Index<D>&, std::ptrdiff_t id) {
    double s = 0.0;
    for (int a = 0; a < D; ++a) s += u[id][a] * f.comp[a][id];
    return s;
  });
  EXPECT_GT(std::abs(lagrangian - perturbed), 1e3 * 1e-13 * scale);
}

TYPED_TEST(TransferTest, SpreadingConservesForceAndLeavesGhostsAlone) {
  constexpr int D = TypeParam::D;
  std::mt19937 rng(7);
  const auto g = make_grid<D>(D == 2 ? 20 : 10);
  const auto x = markers<TypeParam>(g, 40, rng);
  std::vector<Vec<D>> force(x.size());
  std::vector<double> w(x.size(), 0.7);
  Vec<D> total = Vec<D>::Zero();
  for (std::size_t m = 0; m < x.size(); ++m) {
    force[m] = random_vec<D>(rng, -1.0, 1.0);
    total += force[m] * w[m];
  }
  Transfer<D, typename TypeParam::Kernel> t;
  t.update(g, periodic_flags<TypeParam>(), x);
  for (std::size_t m = 0; m < x.size(); ++m) {
    double s = 0.0;
    int count = 0;
    t.for_each_stencil_node(m, [&](const Index<D>& ijk, std::ptrdiff_t id, double we) {
      EXPECT_EQ(id, g.index(ijk));
      EXPECT_TRUE(g.is_interior(ijk));
      s += we;
      ++count;
    });
    EXPECT_EQ(count, (Transfer<D, typename TypeParam::Kernel>::stencil_size));
    EXPECT_NEAR(s, 1.0, 1e-14);
  }
  field::VectorField<D> f(g.size());
  t.spread(force, w, f);
  const Vec<D> grid_total =
      sum_interior<D>(g, Vec<D>(Vec<D>::Zero()), [&](const Index<D>&, std::ptrdiff_t id) {
        Vec<D> v;
        for (int a = 0; a < D; ++a) v[a] = f.comp[a][id];
        return v;
      });
  EXPECT_NEAR((grid_total - total).norm(), 0.0, 1e-13 * x.size());
  field::for_each_ghost(g, [&](const Index<D>& ijk) {
    for (int a = 0; a < D; ++a) EXPECT_EQ(f.comp[a][g.index(ijk)], 0.0);
  });
}

TYPED_TEST(TransferTest, SpreadDoesNotDependOnTheThreadCount) {
  // The spread in parallel over ranges of planes sums each node's contributions in a fixed
  // order: the field is the same bit for bit on 1, 2, 3 and 7 threads (more threads than some
  // blocks have planes with markers), and equal to a plain serial sum to round-off.
  constexpr int D = TypeParam::D;
  std::mt19937 rng(11);
  const auto g = make_grid<D>(D == 2 ? 40 : 16);
  const auto x = markers<TypeParam>(g, 2000, rng);  // above the parallel threshold
  std::vector<Vec<D>> force(x.size());
  for (auto& v : force) v = random_vec<D>(rng, -1.0, 1.0);
  const std::vector<double> w(x.size(), 0.9);
  Transfer<D, typename TypeParam::Kernel> t;
  t.update(g, periodic_flags<TypeParam>(), x);
  auto spread_with = [&](int threads) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    field::VectorField<D> f(g.size());
    t.spread(force, w, f);
    omp_set_num_threads(saved);
    return f;
  };
  const auto one = spread_with(1);
  field::VectorField<D> serial(g.size());
  for (std::size_t m = 0; m < x.size(); ++m) {
    t.for_each_stencil_node(m, [&](const Index<D>&, std::ptrdiff_t id, double we) {
      for (int a = 0; a < D; ++a) serial.comp[a][id] += we * force[m][a] * w[m];
    });
  }
  for (int threads : {2, 3, 7}) {
    const auto many = spread_with(threads);
    for (int a = 0; a < D; ++a)
      for (std::ptrdiff_t n = 0; n < g.size(); ++n)
        ASSERT_EQ(one.comp[a][n], many.comp[a][n]) << threads << " threads, node " << n;
  }
  for (int a = 0; a < D; ++a)
    for (std::ptrdiff_t n = 0; n < g.size(); ++n)
      ASSERT_NEAR(one.comp[a][n], serial.comp[a][n], 1e-12) << "node " << n;
}

TYPED_TEST(TransferTest, FieldInterpolationEqualsTheCallableForm) {
  // The capsules interpolate from a block-sized field, by rows of consecutive nodes where a
  // stencil does not wrap (periodic configurations put markers across the edges, so both
  // paths run): the same values as the node-by-node form to round-off, below and above the
  // parallel threshold, on any thread count.
  constexpr int D = TypeParam::D;
  std::mt19937 rng(17);
  const auto g = make_grid<D>(D == 2 ? 20 : 10);
  const int saved = omp_get_max_threads();
  for (int count : {200, 600})
    for (int threads : {1, 2, 3, 7}) {
      omp_set_num_threads(threads);
      const auto x = markers<TypeParam>(g, count, rng);
      Transfer<D, typename TypeParam::Kernel> t;
      t.update(g, periodic_flags<TypeParam>(), x);
      field::VectorField<D> u(g.size());
      for (int a = 0; a < D; ++a)
        for (auto& v : u.comp[a]) v = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
      std::vector<Vec<D>> by_field(x.size(), Vec<D>::Constant(1e300)), by_node(x.size());
      t.interpolate_field(u, by_field);
      t.interpolate(
          [&](const Index<D>&, std::ptrdiff_t id) {
            Vec<D> v;
            for (int a = 0; a < D; ++a) v[a] = u.comp[a][id];
            return v;
          },
          by_node);
      const double tol = 1e-16 * Transfer<D, typename TypeParam::Kernel>::stencil_size;  // sums of that many
      for (std::size_t m = 0; m < x.size(); ++m)
        EXPECT_LT((by_field[m] - by_node[m]).norm(), tol) << count << " markers, " << threads << " threads, marker " << m;
    }
  omp_set_num_threads(saved);
}

TYPED_TEST(TransferTest, InterpolationExactOnUniformAndLinearFields) {
  constexpr int D = TypeParam::D;
  using K = typename TypeParam::Kernel;
  std::mt19937 rng(3);
  const auto g = make_grid<D>(D == 2 ? 20 : 10);
  // Inside the block so that the linear field is not cut by the periodic wrap.
  const auto x = random_positions<D>(g, 30, 2.0, g.n()[0] - 3.0, rng);
  Transfer<D, K> t;
  t.update(g, periodic_flags<TypeParam>(), x);
  const Vec<D> u0 = random_vec<D>(rng, -1.0, 1.0);
  std::vector<Vec<D>> ux(x.size());
  t.interpolate([&](const Index<D>&, std::ptrdiff_t) { return u0; }, ux);
  for (const auto& v : ux) EXPECT_NEAR((v - u0).norm(), 0.0, 1e-14);
  // u(x) = x along every component (lattice units): exact when the first moment vanishes.
  std::vector<double> sx(x.size());
  t.interpolate_scalar([](const Index<D>& ijk, std::ptrdiff_t) { return static_cast<double>(ijk[0]); }, sx);
  for (std::size_t m = 0; m < x.size(); ++m) {
    const double err = std::abs(sx[m] - t.lattice_position(m)[0]);
    if constexpr (std::is_same_v<K, Cosine4>)
      EXPECT_LT(err, 0.02115);
    else
      EXPECT_LT(err, 1e-13);
  }
}

TEST(TransferPeriodic, WrapIsTranslationInvariant) {
  // A periodic field sampled at a marker next to the edge (stencil wraps) equals the same
  // field shifted by 8 nodes sampled at the marker shifted by 8 nodes (no wrap), and a
  // marker shifted by a whole period gives the same stencil.
  constexpr int n = 16;
  constexpr double pi = std::numbers::pi;
  const auto g = make_grid<2>(n, 1.0);
  const std::array<bool, 2> periodic{true, true};
  auto field = [](int i, int j) {
    return Vec<2>(std::sin(2 * pi * i / n) + 0.3 * std::cos(4 * pi * j / n), std::cos(2 * pi * (i + j) / n));
  };
  auto wrap = [](int i) { return ((i % n) + n) % n; };
  const Vec<2> x0 = g.origin() + Vec<2>(0.3, 15.6);
  const Vec<2> shift(8.0, -8.0);
  std::vector<Vec<2>> a(1), b(1), c(1);
  interpolate<Cosine4>(
      g, periodic, std::vector<Vec<2>>{x0},
      [&](const Index<2>& ij, std::ptrdiff_t) { return field(ij[0], ij[1]); }, a);
  interpolate<Cosine4>(
      g, periodic, std::vector<Vec<2>>{x0 + shift},
      [&](const Index<2>& ij, std::ptrdiff_t) { return field(wrap(ij[0] - 8), wrap(ij[1] + 8)); }, b);
  interpolate<Cosine4>(
      g, periodic, std::vector<Vec<2>>{x0 + Vec<2>(-n, 2.0 * n)},
      [&](const Index<2>& ij, std::ptrdiff_t) { return field(ij[0], ij[1]); }, c);
  EXPECT_NEAR((a[0] - b[0]).norm(), 0.0, 1e-14);
  EXPECT_NEAR((a[0] - c[0]).norm(), 0.0, 1e-14);

  // Spreading from the corner reaches nodes on both sides of both periodic edges.
  field::VectorField<2> f(g.size());
  spread<Cosine4>(g, periodic, std::vector<Vec<2>>{x0}, std::vector<Vec<2>>{Vec<2>(1.0, 0.0)},
                  std::vector<double>{1.0}, f);
  EXPECT_GT(f.comp[0][g.index({0, 15})], 0.0);
  EXPECT_GT(f.comp[0][g.index({n - 1, 0})], 0.0);
  EXPECT_GT(f.comp[0][g.index({n - 1, 14})], 0.0);
}

TEST(TransferErrors, StencilOutsideNonPeriodicBlockIsReported) {
  const auto g = make_grid<3>(10, 0.5);
  // Lattice x = 0.5: the cosine stencil needs node -1 along axis 0.
  const Vec<3> x = g.origin() + 0.5 * Vec<3>(0.5, 4.0, 4.0);
  Transfer<3, Cosine4> t;
  try {
    t.update(g, {false, true, true}, std::vector<Vec<3>>{g.origin() + 0.5 * Vec<3>(4.0, 4.0, 4.0), x});
    FAIL() << "expected core::Error";
  } catch (const core::Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("IB marker 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(-0.75, 1.5, 2)"), std::string::npos) << msg;  // physical position
    EXPECT_NE(msg.find("along axis 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("-1 .. 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("10 x 10 x 10"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cosine4"), std::string::npos) << msg;
  }
  // The same marker is fine when the axis is periodic, and with the narrower hat kernel.
  EXPECT_NO_THROW(t.update(g, {true, false, false}, std::vector<Vec<3>>{x}));
  Transfer<3, Linear2> hat;
  EXPECT_NO_THROW(hat.update(g, {false, false, false}, std::vector<Vec<3>>{x}));
  // Upper edge: lattice 7.5 needs node 9 (fine) ... 8.0 needs node 10 (outside).
  EXPECT_NO_THROW(
      t.update(g, {false, false, false}, std::vector<Vec<3>>{g.origin() + 0.5 * Vec<3>(7.5, 4, 4)}));
  EXPECT_THROW(t.update(g, {false, false, false}, std::vector<Vec<3>>{g.origin() + 0.5 * Vec<3>(4, 4, 8.0)}),
               core::Error);
  // Diverged markers are reported, not turned into out-of-range indices: not finite, or finite
  // but too far out for the periodic wrap to keep any digit.
  EXPECT_THROW(t.update(g, {true, true, true}, std::vector<Vec<3>>{Vec<3>(std::nan(""), 0, 0)}), core::Error);
  EXPECT_THROW(t.update(g, {true, true, true}, std::vector<Vec<3>>{Vec<3>(1e300, 0, 0)}), core::Error);
  EXPECT_THROW(t.update(g, {true, true, true}, std::vector<Vec<3>>{Vec<3>(0, -3e17, 0)}), core::Error);
}

// The linear indices of the stencil nodes of the transfers, each once, in increasing order.
template <class... Transfers>
std::vector<std::ptrdiff_t> stencil_node_set(std::ptrdiff_t grid_size, const Transfers&... transfers) {
  std::vector<std::uint8_t> hit(grid_size, 0);
  auto add = [&](const auto& tr) {
    for (std::size_t m = 0; m < tr.marker_count(); ++m)
      tr.for_each_stencil_node(m, [&](const auto&, std::ptrdiff_t id, double) { hit[id] = 1; });
  };
  (add(transfers), ...);
  std::vector<std::ptrdiff_t> nodes;
  for (std::ptrdiff_t n = 0; n < grid_size; ++n)
    if (hit[n]) nodes.push_back(n);
  return nodes;
}

// What StencilUnion collects after the transfers mark their stencils into it.
template <int D, class... Transfers>
std::vector<std::ptrdiff_t> collected_union(StencilUnion& u, const field::Grid<D>& grid,
                                            const Transfers&... transfers) {
  u.begin(grid);
  (transfers.mark_stencil_nodes(u), ...);
  std::vector<std::ptrdiff_t> nodes;
  u.collect(nodes);
  return nodes;
}

TEST(TransferMark, TheUnionIsExactlyTheStencilNodesInMemoryOrder) {
  // The forced collision runs on the union: every stencil node once, also those of rows that
  // wrap around a periodic axis 0 (marked node by node) and those of a second transfer with
  // another support (node by node too), and no other node.
  const auto g = make_grid<3>(12);
  std::mt19937 rng(5);
  auto x = random_positions<3>(g, 300, 2.0, 9.0, rng);
  for (int k = 0; k < 20; ++k) {  // stencil rows that wrap along x, at both ends
    Vec<3> p = random_positions<3>(g, 1, 2.0, 9.0, rng)[0];
    p[0] = g.origin()[0] + g.dx() * (k % 2 ? 0.3 : 11.6);
    x.push_back(p);
  }
  Transfer<3, Cosine4> t;
  t.update(g, {true, false, true}, x);
  Transfer<3, Roma3> r;
  r.update(g, {true, false, true}, random_positions<3>(g, 30, 2.0, 9.0, rng));
  const auto want = stencil_node_set(g.size(), t, r);
  StencilUnion u;
  // The second pass checks that collect() cleared the masks.
  for (int pass = 0; pass < 2; ++pass) EXPECT_EQ(collected_union(u, g, t, r), want) << "pass " << pass;
  // Marking only the Roma3 transfer gives its stencils alone (runs of 3 this time).
  EXPECT_EQ(collected_union(u, g, r), stencil_node_set(g.size(), r));
}

TEST(TransferMark, TheUnionDoesNotDependOnTheThreadCount) {
  // Above the parallel threshold and without a periodic last axis, marking splits the planes
  // among the threads (for_each_marker_by_planes): on 1, 2, 3 and 7 threads (more threads than
  // planes with markers in some ranges) the union is every stencil node once, rows that wrap
  // around the periodic x included.
  const auto g = make_grid<3>(16);
  std::mt19937 rng(23);
  auto x = random_positions<3>(g, 1500, 2.0, 13.0, rng);
  for (int k = 0; k < 40; ++k) {  // stencil rows that wrap along x, at both ends
    Vec<3> p = random_positions<3>(g, 1, 2.0, 13.0, rng)[0];
    p[0] = g.origin()[0] + g.dx() * (k % 2 ? 0.3 : 15.6);
    x.push_back(p);
  }
  ASSERT_GT(static_cast<std::ptrdiff_t>(x.size()), detail::parallel_threshold);
  Transfer<3, Cosine4> t;
  t.update(g, {true, false, false}, x);
  const auto want = stencil_node_set(g.size(), t);
  StencilUnion u;
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2, 3, 7}) {
    omp_set_num_threads(threads);
    EXPECT_EQ(collected_union(u, g, t), want) << threads << " threads";
  }
  omp_set_num_threads(saved);
}

TEST(TransferMark, RowsLongerThanAMaskWordIn2DAnd3D) {
  // Rows of 130 nodes take three 64-bit words of the union's mask: stencil rows that straddle
  // the words' boundaries (x near 64 and 128), that end on the last node, and that wrap around
  // the periodic x are each collected once, in both dimensions, serial and in parallel.
  std::mt19937 rng(41);
  auto check = [&]<int D>(const field::Grid<D>& g, const auto& periodic, int count) {
    auto x = random_positions<D>(g, count, 2.0, 7.0, rng);
    for (auto& p : x) {  // along x: around the word boundaries and both ends
      const double at[] = {62.5, 63.9, 64.2, 126.8, 127.5, 128.1, 129.6, 0.4, 2.0};
      p[0] = g.origin()[0] + g.dx() * at[rng() % 9];
    }
    Transfer<D, Cosine4> t;
    t.update(g, periodic, x);
    StencilUnion u;
    EXPECT_EQ(collected_union(u, g, t), stencil_node_set(g.size(), t)) << D << "D, " << count << " markers";
  };
  check(field::Grid<2>(Index<2>{130, 10}, Vec<2>(-1.0, 0.5), 0.25), std::array<bool, 2>{true, false}, 40);
  check(field::Grid<2>(Index<2>{130, 10}, Vec<2>(-1.0, 0.5), 0.25), std::array<bool, 2>{true, false}, 600);
  check(field::Grid<3>(Index<3>{130, 10, 11}, Vec<3>(-1.0, 0.5, 0.0), 0.25), std::array<bool, 3>{true, false, false},
        900);
}

TEST(TransferPeriodic, AxisShorterThanTheStencilWrapsEveryNode) {
  // A periodic axis of 2 nodes under a 4-node stencil: every node index wraps into 0..1, the
  // weights of the nodes that coincide add up (partition of unity), and the union holds them.
  const field::Grid<3> g(Index<3>{2, 9, 9}, Vec<3>::Zero(), 1.0);
  Transfer<3, Cosine4> t;
  t.update(g, {true, true, true}, std::vector<Vec<3>>{Vec<3>(0.3, 4.2, 4.7), Vec<3>(1.9, 8.6, 0.1)});
  for (std::size_t m = 0; m < 2; ++m) {
    double sum = 0.0;
    t.for_each_stencil_node(m, [&](const Index<3>& ijk, std::ptrdiff_t id, double w) {
      EXPECT_TRUE(g.is_interior(ijk));
      EXPECT_EQ(id, g.index(ijk));
      sum += w;
    });
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
  StencilUnion u;
  EXPECT_EQ(collected_union(u, g, t), stencil_node_set(g.size(), t));
}

TEST(TransferUnits, MeasureToLattice) {
  EXPECT_DOUBLE_EQ(measure_to_lattice<2>(0.3, 0.1), 3.0);
  EXPECT_DOUBLE_EQ(measure_to_lattice<3>(0.03, 0.1), 3.0);
}

}  // namespace
}  // namespace caplab::ibm
