// The default thread count respects an explicit request, OMP_NUM_THREADS and the CPU quota.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdlib>
#include <string>

#include "core/threads.hpp"

namespace caplab::core {
namespace {

TEST(Threads, UsableProcessorsNeverExceedTheQuotaOrTheAffinityMask) {
  const int usable = usable_processors();
  EXPECT_GE(usable, 1);
  EXPECT_LE(usable, omp_get_num_procs());
  if (const auto quota = cgroup_cpu_quota()) {
    EXPECT_LE(usable, *quota);
  }
}

TEST(Threads, AnExplicitRequestWins) {
  const int saved = omp_get_max_threads();
  EXPECT_EQ(apply_thread_count(3), 3);
  EXPECT_EQ(omp_get_max_threads(), 3);
  omp_set_num_threads(saved);
}

TEST(Threads, OmpNumThreadsIsKeptWhenNothingIsRequested) {
  const char* saved_env = std::getenv("OMP_NUM_THREADS");
  const std::string saved = saved_env ? saved_env : "";
  setenv("OMP_NUM_THREADS", "1", 1);
  omp_set_num_threads(1);  // the runtime read the variable at start-up; this is its effect
  EXPECT_EQ(apply_thread_count(0), 1);
  if (saved_env) {
    setenv("OMP_NUM_THREADS", saved.c_str(), 1);
  } else {
    unsetenv("OMP_NUM_THREADS");
  }
}

TEST(Threads, WarnsWhenOtherWorkLeavesTooFewCores) {
  const int usable = usable_processors();
  EXPECT_FALSE(contention_warning(1, usable + 4));   // one thread waits for nobody
  EXPECT_FALSE(contention_warning(2, std::nullopt));  // unknown: no guess
  if (usable >= 2) {
    EXPECT_FALSE(contention_warning(2, usable - 2));  // two cores free
  }
  const auto w = contention_warning(2, usable - 1);  // one core free
  ASSERT_TRUE(w);
  EXPECT_NE(w->find("--threads 1"), std::string::npos) << *w;
}

TEST(Threads, OtherRunningTasksAreReadFromTheKernel) {
  const auto others = other_running_tasks();
  ASSERT_TRUE(others);  // Linux /proc/loadavg
  EXPECT_GE(*others, 0);
}

}  // namespace
}  // namespace caplab::core
