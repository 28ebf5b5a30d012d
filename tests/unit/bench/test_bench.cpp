// Unit tests of the bench module: structure and sanity of a quick run on tiny boxes (every
// number present and positive, roofline arithmetic consistent, bench.json written and equal
// to the returned JSON) and rejection of bad options. No timing thresholds: timings on a
// shared machine are noise, so no test here can depend on how fast anything ran.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <set>

#include "bench/bench.hpp"
#include "bench/stream_bandwidth.hpp"
#include "core/error.hpp"

namespace caplab::bench {
namespace {

namespace fs = std::filesystem;

BenchOptions tiny() {
  BenchOptions o;
  o.quick = true;
  o.threads = {1, 2};
  o.size_d2q9 = 16;
  o.size_d3q19 = 8;
  o.min_seconds = 0.002;
  o.stream_array_mib = 1;
  o.stream_repetitions = 2;
  o.out = nullptr;
  return o;
}

TEST(Bench, StreamKernelsGivePositiveValidatedBandwidth) {
  const auto s = measure_stream_bandwidth(1, 1 << 20, 2);
  EXPECT_TRUE(s.validated);
  EXPECT_GT(s.copy_gbs, 0);
  EXPECT_GT(s.triad_gbs, 0);
  EXPECT_GT(s.update_gbs, 0);
  EXPECT_GE(s.copy_gbs, s.copy_gbs_median);  // best is never below the median
  EXPECT_GE(s.update_gbs, s.update_gbs_median);
  EXPECT_EQ(s.array_bytes, std::size_t(1) << 20);
}

TEST(Bench, QuickRunHasEveryRowAndConsistentRoofline) {
  const fs::path dir = fs::temp_directory_path() / ("caplab_test_bench_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto opt = tiny();
  opt.output_dir = dir;
  const auto j = run_benchmarks(opt);

  ASSERT_TRUE(j.contains("environment"));
  EXPECT_EQ(j["environment"]["threads"], 2);
  EXPECT_TRUE(j["bandwidth"]["convention"].get<std::string>().find("write-allocate") != std::string::npos);
  ASSERT_EQ(j["bandwidth"]["per_threads"].size(), 2u);
  EXPECT_EQ(j["bandwidth"]["runs"].size(), 4u);  // before and after, per thread count
  for (const auto& b : j["bandwidth"]["per_threads"]) {
    EXPECT_GT(b["copy_gbs"].get<double>(), 0);
    EXPECT_GT(b["triad_gbs"].get<double>(), 0);
    EXPECT_GT(b["update_gbs"].get<double>(), 0);
    EXPECT_TRUE(b["validated"].get<bool>());
  }

  // 2 lattices × 2 collisions × 2 precisions × 2 thread counts, plus two-level with the first
  // collision: 2 lattices × 2 precisions × 2 thread counts.
  ASSERT_EQ(j["rows"].size(), 24u);
  std::set<std::string> seen;
  int two_level = 0;
  for (const auto& r : j["rows"]) {
    const auto lattice = r["lattice"].get<std::string>();
    const auto precision = r["precision"].get<std::string>();
    const int q = lattice == "D2Q9" ? 9 : 19;
    const int bytes = precision == "double" ? 8 : 4;
    EXPECT_EQ(r["bytes_per_update"].get<int>(), 2 * q * bytes);
    EXPECT_EQ(r["size"].size(), lattice == "D2Q9" ? 2u : 3u);
    EXPECT_GT(r["mlups"].get<double>(), 0);
    EXPECT_GE(r["mlups_best_batch"].get<double>(), r["mlups"].get<double>() * 0.999);
    EXPECT_GT(r["steps"].get<long>(), 0);
    EXPECT_GT(r["cpu_share"].get<double>(), 0);
    const double roof = r["roofline_mlups"].get<double>();
    EXPECT_NEAR(roof, r["bandwidth_gbs"].get<double>() * 1e3 / r["bytes_per_update"].get<double>(),
                1e-9 * roof);
    EXPECT_NEAR(r["fraction"].get<double>(), r["mlups"].get<double>() / roof, 1e-12);
    // The in-place update bandwidth of the row's thread count; the copy roofline beside it.
    nlohmann::json bw;
    for (const auto& b : j["bandwidth"]["per_threads"])
      if (b["threads"] == r["threads"]) bw = b;
    ASSERT_TRUE(bw.is_object()) << "no bandwidth for " << r["threads"] << " threads";
    EXPECT_NEAR(r["bandwidth_gbs"].get<double>(), bw["update_gbs"].get<double>(), 1e-12);
    EXPECT_NEAR(r["roofline_mlups_copy"].get<double>(),
                bw["copy_gbs"].get<double>() * 1e3 / r["bytes_per_update"].get<double>(), 1e-9 * roof);
    if (r["kind"] == "two_level") {
      ++two_level;
      EXPECT_TRUE(r.contains("overhead_vs_uniform"));
      // The overhead is against the uniform twin timed between the two-level batches.
      EXPECT_GT(r["uniform_twin_mlups"].get<double>(), 0);
      EXPECT_TRUE(std::isfinite(r["overhead_vs_uniform"].get<double>()));
      EXPECT_GT(r["overhead_vs_uniform"].get<double>(), -1.0);
      EXPECT_GT(r["fine_fraction"].get<double>(), 0);
      EXPECT_LT(r["fine_fraction"].get<double>(), 0.5);
      EXPECT_GE(r["coupling_share"].get<double>(), 0);
      EXPECT_LE(r["coupling_share"].get<double>(), 1);
      // coarse + 2 × fine interior nodes per coarse step, less the covered coarse nodes
      // ((n_f + 1)/2 − 1 per axis), for which the fine block stands.
      double coarse = 1, fine = 1, idle = 1;
      for (const auto& n : r["size"]) coarse *= n.get<double>();
      for (const auto& n : r["fine_size"]) {
        fine *= n.get<double>();
        idle *= (n.get<int>() + 1) / 2 - 1;
      }
      EXPECT_DOUBLE_EQ(r["updates_per_step"].get<double>(), coarse - idle + 2 * fine);
    }
    seen.insert(r["kind"].get<std::string>() + lattice + r["collision"].get<std::string>() + precision +
                std::to_string(r["threads"].get<int>()));
  }
  EXPECT_EQ(seen.size(), 24u);
  EXPECT_EQ(two_level, 8);

  std::ifstream in(dir / "bench.json");
  ASSERT_TRUE(in.good());
  EXPECT_EQ(nlohmann::json::parse(in), j);
  EXPECT_NE(format_table(j).find("D3Q19"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Bench, ResolveFillsModeDefaults) {
  BenchOptions o;
  const auto normal = resolve(o);
  EXPECT_EQ(normal.size_d3q19, 128);
  EXPECT_EQ(normal.size_d2q9, 2048);
  EXPECT_DOUBLE_EQ(normal.min_seconds, 1.0);
  EXPECT_GE(normal.stream_array_mib, 64u);
  o.quick = true;
  const auto quick = resolve(o);
  EXPECT_LT(quick.size_d3q19, 128);
  EXPECT_LT(quick.min_seconds, 1.0);
  o.size_d3q19 = 40;
  EXPECT_EQ(resolve(o).size_d3q19, 40);  // explicit values win over the mode
}

TEST(Bench, RejectsBadOptions) {
  auto o = tiny();
  o.lattices = {"D3Q27"};
  EXPECT_THROW(resolve(o), core::InputError);
  o = tiny();
  o.collisions = {"mrt"};
  EXPECT_THROW(resolve(o), core::InputError);
  o = tiny();
  o.precisions = {};
  EXPECT_THROW(resolve(o), core::InputError);
  o = tiny();
  o.threads = {0};
  EXPECT_THROW(resolve(o), core::InputError);
  o = tiny();
  o.size_d3q19 = 4;
  EXPECT_THROW(resolve(o), core::InputError);
  o = tiny();
  o.min_seconds = -1;
  EXPECT_THROW(resolve(o), core::InputError);
  EXPECT_THROW(measure_stream_bandwidth(0, 1 << 20, 1), core::Error);
}

}  // namespace
}  // namespace caplab::bench
