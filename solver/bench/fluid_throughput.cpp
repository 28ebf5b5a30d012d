#include "bench/fluid_throughput.hpp"

#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "lattice/lattice.hpp"
#include "sim/fluid.hpp"

namespace caplab::bench {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// User + system CPU time of the whole process (all threads).
double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto sec = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
  return sec(u.ru_utime) + sec(u.ru_stime);
}

/// Sets the OpenMP thread count for its lifetime and restores the previous one.
class ThreadScope {
 public:
  explicit ThreadScope(int threads) : saved_(omp_get_max_threads()) { omp_set_num_threads(threads); }
  ~ThreadScope() { omp_set_num_threads(saved_); }
  ThreadScope(const ThreadScope&) = delete;
  ThreadScope& operator=(const ThreadScope&) = delete;

 private:
  int saved_;
};

template <class T>
constexpr const char* precision_name() {
  return sizeof(T) == 8 ? "double" : "float";
}

/// The periodic box of case c, with the centred fine block when `two_level`.
template <class L, class T, class Op>
std::unique_ptr<sim::Fluid<L, T, Op>> make_fluid(const FluidCase& c, bool two_level) {
  constexpr int D = L::d;
  using FluidT = sim::Fluid<L, T, Op>;
  typename FluidT::Setup s;
  Index<D> n;
  n.fill(c.n);
  s.coarse = field::Grid<D>(n, Vec<D>::Zero(), 1.0);
  if (two_level) {
    // Centred block of `side` coarse cells per axis, side^D ≈ n^D / 8. Its ghost ring lies on
    // coarse nodes lo and hi (the layout of refinement/two_level.hpp).
    const int side = std::max(2, static_cast<int>(std::lround(c.n * std::pow(0.125, 1.0 / D))));
    const int lo = (c.n - side) / 2;
    Index<D> nf;
    Vec<D> of;
    for (int a = 0; a < D; ++a) nf[a] = 2 * side - 1, of[a] = lo + 0.5;
    s.fine = field::Grid<D>(nf, of, 0.5);
  }
  s.boundaries.fill(boundary::Kind::periodic);
  s.imposed_velocity_lu = [](const Vec<D>&) { return Vec<D>::Zero(); };
  s.coarse_op.tau = 0.8;

  auto fluid = std::make_unique<FluidT>(s);
  const double k = 2 * std::numbers::pi / c.n;
  fluid->initialise([&](const Vec<D>& x) {
    Vec<D> u = Vec<D>::Constant(0.02);
    u[0] = 0.05;
    u[0] += 0.01 * std::sin(k * x[0]) * std::cos(k * x[1]);
    u[1] -= 0.01 * std::cos(k * x[0]) * std::sin(k * x[1]);
    return std::pair<double, Vec<D>>(1.0, u);
  });
  return fluid;
}

/// Sanity, separate from speed: a benchmark of a broken flow is not a result.
template <class Fluid>
void check_flow(const Fluid& fluid) {
  constexpr int D = Fluid::D;
  for (std::size_t b = 0; b < fluid.block_count(); ++b) {
    const auto& pop = fluid.block(b).pop;
    Index<D> probe;
    for (int a = 0; a < D; ++a) probe[a] = pop.grid().n()[a] / 2;
    // The coarse middle lies under the fine block (its value is nobody's result): a corner.
    if (b == 0 && fluid.two_level() && fluid.coupling().covered(probe)) probe.fill(0);
    const auto m = collision::node_moments(pop, pop.grid().index(probe));
    CAPLAB_CHECK(std::isfinite(static_cast<double>(m.rho)) && std::abs(m.rho - 1.0) < 0.1,
                 "bench: the benchmark flow is not finite or drifted; the measurement is void");
  }
}

/// Wall seconds of `steps` steps.
template <class Fluid>
double timed_steps(Fluid& fluid, long steps) {
  const double t0 = now_seconds();
  for (long i = 0; i < steps; ++i) fluid.step();
  return now_seconds() - t0;
}

/// Batch length (steps) for about 1/5 of the minimum time, after one warm-up step and one
/// timed step.
template <class Fluid>
long batch_steps(Fluid& fluid, double min_seconds) {
  fluid.step();
  const double t_step = std::max(timed_steps(fluid, 1), 1e-9);
  return std::max(1L, static_cast<long>(std::ceil(min_seconds / 5 / t_step)));
}

template <class L, class T, class Op>
FluidMeasurement measure(const FluidCase& c, double min_seconds) {
  ThreadScope scope(c.threads);
  FluidMeasurement r;
  r.size.assign(L::d, c.n);
  auto fluid = make_fluid<L, T, Op>(c, c.two_level);
  if (c.two_level) {
    const auto& nf = fluid->finest().pop.grid().n();
    r.fine_size.assign(nf.begin(), nf.end());
    r.fine_fraction = std::pow(static_cast<double>(nf[0] + 1) / (2 * c.n), L::d);  // covered share
  }
  // Two-level: the uniform box of the same coarse size runs in the batches between, and the
  // overhead is the median over batch pairs of the ratio of their speeds: measurements taken
  // at the same moments, a slow batch on either side rejected (the machine's speed drifts
  // between separate measurements and jumps within seconds).
  auto twin = c.two_level ? make_fluid<L, T, Op>(c, false) : nullptr;
  const long batch = batch_steps(*fluid, min_seconds);
  const long twin_batch = twin ? batch_steps(*twin, min_seconds) : 0;

  const double coupling0 = fluid->coupling_seconds();
  const double cpu0 = process_cpu_seconds();
  double elapsed = 0, twin_elapsed = 0;
  int batches = 0;
  std::vector<double> ratios;  // per batch pair: uniform twin MLUPS / two-level MLUPS
  while (elapsed < min_seconds || batches < 3) {
    const double t = timed_steps(*fluid, batch);
    elapsed += t;
    ++batches;
    r.mlups_best = std::max(r.mlups_best, batch * fluid->updates_per_step() / t * 1e-6);
    if (twin) {
      const double tt = timed_steps(*twin, twin_batch);
      twin_elapsed += tt;
      ratios.push_back((twin_batch * twin->updates_per_step() / tt) / (batch * fluid->updates_per_step() / t));
    }
  }
  r.updates_per_step = fluid->updates_per_step();
  r.steps = batch * batches;
  r.seconds = elapsed;
  r.mlups = r.steps * r.updates_per_step / elapsed * 1e-6;
  r.coupling_seconds = fluid->coupling_seconds() - coupling0;
  r.cpu_share = (process_cpu_seconds() - cpu0) / (c.threads * (elapsed + twin_elapsed));
  if (twin) {
    r.uniform_twin_mlups = twin_batch * batches * twin->updates_per_step() / twin_elapsed * 1e-6;
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    r.overhead = ratios[ratios.size() / 2] - 1.0;
  }
  r.bytes_per_update = field::Populations<L, T>::bytes_per_update();

  check_flow(*fluid);
  if (twin) check_flow(*twin);
  return r;
}

using Measure = FluidMeasurement (*)(const FluidCase&, double);

struct Entry {
  const char* lattice;
  const char* collision;
  const char* precision;
  Measure measure;
};

template <class L, class Op, class T>
constexpr Entry entry() {
  return {L::name, Op::name, precision_name<T>(), &measure<L, T, Op>};
}

// Every supported combination, compiled once; names come from the types themselves.
constexpr std::array<Entry, 8> kEntries{
    entry<lattice::D2Q9, collision::Bgk, double>(),  entry<lattice::D2Q9, collision::Bgk, float>(),
    entry<lattice::D2Q9, collision::Trt, double>(),  entry<lattice::D2Q9, collision::Trt, float>(),
    entry<lattice::D3Q19, collision::Bgk, double>(), entry<lattice::D3Q19, collision::Bgk, float>(),
    entry<lattice::D3Q19, collision::Trt, double>(), entry<lattice::D3Q19, collision::Trt, float>()};

}  // namespace

const std::vector<std::string>& supported_lattices() {
  static const std::vector<std::string> v{lattice::D2Q9::name, lattice::D3Q19::name};
  return v;
}
const std::vector<std::string>& supported_collisions() {
  static const std::vector<std::string> v{collision::Bgk::name, collision::Trt::name};
  return v;
}
const std::vector<std::string>& supported_precisions() {
  static const std::vector<std::string> v{"double", "float"};
  return v;
}

FluidMeasurement measure_fluid(const FluidCase& c, double min_seconds) {
  CAPLAB_CHECK(c.threads >= 1, "bench: a fluid measurement needs at least one thread");
  for (const auto& e : kEntries)
    if (c.lattice == e.lattice && c.collision == e.collision && c.precision == e.precision)
      return e.measure(c, min_seconds);
  throw core::InputError("bench: unsupported configuration " + c.lattice + "/" + c.collision + "/" +
                         c.precision +
                         "; supported: lattice D2Q9|D3Q19, collision bgk|trt, precision double|float");
}

}  // namespace caplab::bench
