// How many OpenMP threads a run may use.
//
// OpenMP counts the processors in the affinity mask, but a container or CI job is often
// limited by a CPU quota instead (cgroup cpu.max): 64 threads spinning at every barrier on
// a 2-CPU quota are throttled for most of each scheduler period, and small-grid runs become
// hundreds of times slower. The default therefore never exceeds the quota.
#pragma once

#include <optional>

namespace caplab::core {

/// The CPU quota of this process's cgroup, rounded up (v2 `cpu.max`, else v1
/// `cpu.cfs_quota_us / cpu.cfs_period_us`); nullopt when there is no quota.
std::optional<int> cgroup_cpu_quota();

/// The processors this process may really use: OpenMP's processor count, capped by the quota.
int usable_processors();

/// Sets the OpenMP thread count and returns it: `requested` when > 0; otherwise what
/// OMP_NUM_THREADS says when it is set; otherwise usable_processors().
int apply_thread_count(int requested);

}  // namespace caplab::core
