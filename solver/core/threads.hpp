// How many OpenMP threads a run may use.
//
// OpenMP counts the processors in the affinity mask, but a container or CI job is often
// limited by a CPU quota instead (cgroup cpu.max): 64 threads spinning at every barrier on
// a 2-CPU quota are throttled for most of each scheduler period, and small-grid runs become
// hundreds of times slower. The default therefore never exceeds the quota.
#pragma once

#include <optional>
#include <string>

namespace caplab::core {

/// The CPU quota of this process's cgroup, rounded up (v2 `cpu.max`, else v1
/// `cpu.cfs_quota_us / cpu.cfs_period_us`); nullopt when there is no quota.
std::optional<int> cgroup_cpu_quota();

/// The processors this process may really use: OpenMP's processor count, capped by the quota.
int usable_processors();

/// Sets the OpenMP thread count and returns it: `requested` when > 0; otherwise what
/// OMP_NUM_THREADS says when it is set; otherwise usable_processors().
int apply_thread_count(int requested);

/// Other work that is running on the machine now: the fewest runnable tasks besides the
/// caller over five samples of /proc/loadavg 10 ms apart (a passing process is not counted);
/// nullopt when it cannot be read.
std::optional<int> other_running_tasks();

/// A warning when `threads` > 1 threads will find fewer cores free than they need: `others`
/// (other_running_tasks()) leave fewer than `threads` of the usable processors. The threads
/// then wait for each other at every barrier while their cores run other work: measured 40-80
/// times slower than with a passive wait, a small 2D case on two threads beside another run on
/// 2 cores (libgomp spins before it sleeps, and the spinning thread holds the core its partner
/// needs).
std::optional<std::string> contention_warning(int threads, std::optional<int> others);

}  // namespace caplab::core
