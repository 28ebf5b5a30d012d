// `caplab bench` (DESIGN.md section 8): how close the fluid update comes to the memory
// roofline of this machine, measured in one run.
//
//  1. Memory bandwidth per thread count (stream_bandwidth.hpp), measured before and after
//     the fluid runs; the better of the two is used.
//  2. MLUPS of sim::Fluid::step() on a periodic box (fluid_throughput.hpp) for every selected
//     lattice × collision × precision × thread count, and the two-level case per lattice ×
//     precision × thread count (first selected collision) with its overhead against the
//     uniform box of the same configuration.
//  3. Roofline per row: bytes per node update B_u = Populations::bytes_per_update() = 2 Q
//     sizeof(T) (the in-place kernel reads a node's Q values and writes them back), roofline
//     MLUPS = in-place update bandwidth / B_u, fraction = MLUPS / roofline. The update kernel
//     b = s·b has the fluid kernel's access pattern (read a line, write it back, no
//     write-allocate), so the two are consistent; the row also gives copy bandwidth / B_u.
// Timings are noisy on a shared machine: nothing here is a pass/fail threshold.
#pragma once

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace caplab::bench {

/// What to measure. Zero means "the default of the mode" (normal | quick), given in brackets.
struct BenchOptions {
  std::vector<int> threads{1, 2};
  int size_d2q9 = 0;                 ///< edge of the D2Q9 box [2048 | 256]
  int size_d3q19 = 0;                ///< edge of the D3Q19 box [128 | 32]
  double min_seconds = 0;            ///< minimum time per fluid measurement [1.0 | 0.1]
  std::size_t stream_array_mib = 0;  ///< MiB per stream array, three arrays [max(64, LLC) | 16]
  int stream_repetitions = 0;        ///< timed stream repetitions, best kept [10 | 4]
  std::vector<std::string> lattices{"D2Q9", "D3Q19"};
  std::vector<std::string> collisions{"bgk", "trt"};
  std::vector<std::string> precisions{"double", "float"};
  bool two_level = true;             ///< also measure the two-level multi-block case
  bool quick = false;                ///< small sizes and short times (tests, smoke runs)
  std::filesystem::path output_dir;  ///< bench.json is written here unless empty
  std::ostream* out = &std::cout;    ///< progress and the final table; nullptr: silent
};

/// Fills the mode defaults and validates; throws core::InputError naming the option and
/// the allowed values.
BenchOptions resolve(const BenchOptions& opt);

/// Runs the benchmarks, prints the table to opt.out, writes opt.output_dir/bench.json, and
/// returns the same JSON: {"schema", "environment", "options", "load_average",
/// "bandwidth": {"convention", "runs": [...], "per_threads": [...]}, "rows": [...]}.
nlohmann::json run_benchmarks(const BenchOptions& opt);

/// The human-readable table of a run_benchmarks() result.
std::string format_table(const nlohmann::json& result);

}  // namespace caplab::bench
