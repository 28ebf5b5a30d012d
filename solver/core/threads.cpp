#include "core/threads.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

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

}  // namespace caplab::core
