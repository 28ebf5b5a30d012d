#include "bench/stream_bandwidth.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "field/grid.hpp"

namespace caplab::bench {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace

StreamResult measure_stream_bandwidth(int threads, std::size_t array_bytes, int repetitions) {
  CAPLAB_CHECK(threads >= 1, "bench: stream bandwidth needs at least one thread");
  CAPLAB_CHECK(repetitions >= 1, "bench: stream bandwidth needs at least one repetition");
  const long n = static_cast<long>(array_bytes / sizeof(double));
  CAPLAB_CHECK(n >= 1024, "bench: stream arrays must hold at least 1024 doubles");

  // Not std::vector::assign: that would first-touch every page from one thread.
  field::AlignedAllocator<double> alloc;
  double* __restrict a = alloc.allocate(n);
  double* __restrict b = alloc.allocate(n);
  double* __restrict c = alloc.allocate(n);
  const double s = 0.5;
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < n; ++i) a[i] = 1.0, b[i] = 2.0, c[i] = 0.0;

  std::vector<double> t_copy, t_triad, t_update;
  double expected_a = 1.0, expected_b = 2.0;
  const double s_update = 1.0000001;  // b stays near 2 over any repetition count
  for (int r = 0; r <= repetitions; ++r) {
    double t0 = now_seconds();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) c[i] = a[i];
    double t1 = now_seconds();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    double t2 = now_seconds();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) b[i] = s_update * b[i];
    double t3 = now_seconds();
    // The triad read b before this repetition's update scaled it.
    expected_a = expected_b + s * expected_a;
    expected_b *= s_update;
    if (r == 0) continue;  // warm-up: page faults, frequency ramp
    t_copy.push_back(t1 - t0);
    t_triad.push_back(t2 - t1);
    t_update.push_back(t3 - t2);
  }

  bool ok = true;
  for (long i : {0L, n / 3, n / 2, n - 1})
    ok = ok && std::abs(a[i] - expected_a) <= 1e-12 * expected_a && std::abs(b[i] - expected_b) <= 1e-12 * expected_b;
  alloc.deallocate(a, n);
  alloc.deallocate(b, n);
  alloc.deallocate(c, n);
  CAPLAB_CHECK(ok, "bench: stream kernels produced wrong values");

  // Copy and update read one array and write one; triad reads two.
  const double two_arrays = 2.0 * sizeof(double) * n, three_arrays = 3.0 * sizeof(double) * n;
  StreamResult r;
  r.threads = threads;
  r.array_bytes = static_cast<std::size_t>(n) * sizeof(double);
  r.repetitions = repetitions;
  r.copy_gbs = two_arrays / *std::min_element(t_copy.begin(), t_copy.end()) * 1e-9;
  r.triad_gbs = three_arrays / *std::min_element(t_triad.begin(), t_triad.end()) * 1e-9;
  r.update_gbs = two_arrays / *std::min_element(t_update.begin(), t_update.end()) * 1e-9;
  r.copy_gbs_median = two_arrays / median(t_copy) * 1e-9;
  r.triad_gbs_median = three_arrays / median(t_triad) * 1e-9;
  r.update_gbs_median = two_arrays / median(t_update) * 1e-9;
  r.validated = ok;
  return r;
}

}  // namespace caplab::bench
