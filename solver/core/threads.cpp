#include "core/threads.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

namespace caplab::core {
namespace {

std::optional<int> cpus_from(double quota, double period) {
  if (quota <= 0 || period <= 0) return std::nullopt;
  return std::max(1, static_cast<int>(std::ceil(quota / period)));
}

}  // namespace

std::optional<int> cgroup_cpu_quota() {
  // cgroup v2: "max 100000" (no quota) or "200000 100000".
  if (std::ifstream v2("/sys/fs/cgroup/cpu.max"); v2) {
    std::string quota;
    double period = 0;
    if (v2 >> quota >> period && quota != "max") return cpus_from(std::atof(quota.c_str()), period);
    return std::nullopt;
  }
  // cgroup v1: quota -1 means none.
  std::ifstream q("/sys/fs/cgroup/cpu/cpu.cfs_quota_us"), p("/sys/fs/cgroup/cpu/cpu.cfs_period_us");
  double quota = -1, period = 0;
  if (q >> quota && p >> period) return cpus_from(quota, period);
  return std::nullopt;
}

int usable_processors() {
  const int procs = omp_get_num_procs();
  const auto quota = cgroup_cpu_quota();
  return quota ? std::min(procs, *quota) : procs;
}

int apply_thread_count(int requested) {
  if (requested > 0) {
    omp_set_num_threads(requested);
  } else if (std::getenv("OMP_NUM_THREADS") == nullptr) {
    omp_set_num_threads(usable_processors());
  }
  return omp_get_max_threads();
}

std::optional<int> other_running_tasks() {
  std::optional<int> fewest;
  for (int k = 0; k < 5; ++k) {
    if (k > 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    // "0.52 0.58 0.59 3/467 12345": the fourth field is runnable / total scheduling entities.
    std::ifstream f("/proc/loadavg");
    double avg;
    int running = 0;
    char slash = 0;
    if (!(f >> avg >> avg >> avg >> running >> slash) || slash != '/') return std::nullopt;
    fewest = std::min(fewest.value_or(running), running);
  }
  return std::max(0, *fewest - 1);  // less the reading thread
}

std::optional<std::string> contention_warning(int threads, std::optional<int> others) {
  if (threads <= 1 || !others) return std::nullopt;
  const int usable = usable_processors();
  const int free_cores = std::max(0, usable - *others);
  if (free_cores >= threads) return std::nullopt;
  return fmt::format(
      "{} other task(s) are running on {} usable processors, so {} threads will not find {} free cores: threads that "
      "wait for each other while their cores run other work can make a run many times slower. If the progress line's "
      "MLUPS is low, run with --threads {}",
      *others, usable, threads, threads, std::max(1, free_cores));
}

}  // namespace caplab::core
