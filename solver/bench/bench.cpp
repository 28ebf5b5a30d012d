#include "bench/bench.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "bench/fluid_throughput.hpp"
#include "bench/stream_bandwidth.hpp"
#include "core/error.hpp"
#include "core/threads.hpp"
#include "io/manifest.hpp"
#include "io/run_directory.hpp"

namespace caplab::bench {

namespace {

using nlohmann::json;

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : "|") + x;
  return s;
}

void check_names(const std::vector<std::string>& given, const std::vector<std::string>& supported,
                 const std::string& option) {
  if (given.empty())
    throw core::InputError("bench: option '" + option + "' is empty; choose from " + join(supported));
  for (const auto& g : given)
    if (std::find(supported.begin(), supported.end(), g) == supported.end())
      throw core::InputError("bench: option '" + option + "' has unknown value '" + g +
                             "'; supported: " + join(supported));
}

/// The 1, 5 and 15 minute load averages (other users of a shared machine show up here).
json load_average() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (in >> a >> b >> c) return json::array({a, b, c});
  return nullptr;
}

json stream_json(const StreamResult& s) {
  return {{"threads", s.threads},
          {"array_bytes", s.array_bytes},
          {"arrays", 3},
          {"repetitions", s.repetitions},
          {"copy_gbs", s.copy_gbs},
          {"triad_gbs", s.triad_gbs},
          {"update_gbs", s.update_gbs},
          {"copy_gbs_median", s.copy_gbs_median},
          {"triad_gbs_median", s.triad_gbs_median},
          {"update_gbs_median", s.update_gbs_median},
          {"validated", s.validated}};
}

/// Last-level cache size as the C library reports it (0 where unknown). In a virtual machine
/// this is what the hypervisor reports, possibly the whole socket's L3.
std::size_t llc_bytes() {
  for (int name : {_SC_LEVEL4_CACHE_SIZE, _SC_LEVEL3_CACHE_SIZE, _SC_LEVEL2_CACHE_SIZE}) {
    const long v = sysconf(name);
    if (v > 0) return static_cast<std::size_t>(v);
  }
  return 0;
}

std::string size_text(const std::vector<int>& size) {
  if (size.empty()) return "-";
  return std::to_string(size[0]) + "^" + std::to_string(size.size());
}

}  // namespace

BenchOptions resolve(const BenchOptions& opt) {
  BenchOptions r = opt;
  const bool q = opt.quick;
  if (r.size_d2q9 == 0) r.size_d2q9 = q ? 256 : 2048;
  if (r.size_d3q19 == 0) r.size_d3q19 = q ? 32 : 128;
  if (r.min_seconds == 0) r.min_seconds = q ? 0.1 : 1.0;
  // Each array at least as large as the reported last-level cache (and 64 MiB): with 3 × 64 MiB
  // this machine (L3 reported 508 MB) measured 106 GB/s copy on 2 threads against 70-80 GB/s
  // from 256 MiB up, i.e. the caches still helped.
  if (r.stream_array_mib == 0)
    r.stream_array_mib = q ? 16 : std::max<std::size_t>(64, (llc_bytes() + (1 << 20) - 1) >> 20);
  if (r.stream_repetitions == 0) r.stream_repetitions = q ? 4 : 10;
  if (r.threads.empty()) throw core::InputError("bench: option 'threads' is empty; give e.g. 1,2");
  for (int t : r.threads)
    if (t < 1 || t > 1024)
      throw core::InputError("bench: option 'threads' has " + std::to_string(t) + "; expected 1 ... 1024");
  // The two-level block needs coarse nodes around its ghost ring (refinement/two_level.hpp).
  if (r.size_d2q9 < 8 || r.size_d3q19 < 8)
    throw core::InputError("bench: box sizes must be at least 8 nodes per axis (size_d2q9 " +
                           std::to_string(r.size_d2q9) + ", size_d3q19 " + std::to_string(r.size_d3q19) +
                           ")");
  if (!(r.min_seconds > 0))
    throw core::InputError("bench: option 'min_seconds' must be positive, got " +
                           std::to_string(r.min_seconds));
  if (r.stream_repetitions < 1)
    throw core::InputError("bench: option 'stream_repetitions' must be at least 1");
  check_names(r.lattices, supported_lattices(), "lattices");
  check_names(r.collisions, supported_collisions(), "collisions");
  check_names(r.precisions, supported_precisions(), "precisions");
  return r;
}

json run_benchmarks(const BenchOptions& options) {
  const BenchOptions opt = resolve(options);
  auto say = [&](const std::string& line) {
    if (opt.out) *opt.out << line << std::endl;
  };
  const int max_threads = *std::max_element(opt.threads.begin(), opt.threads.end());

  json result;
  result["schema"] = "caplab.bench/1";
  result["environment"] = io::environment_json(max_threads);
  result["environment"]["omp_num_procs"] = omp_get_num_procs();
  result["environment"]["usable_processors"] = core::usable_processors();
  result["load_average"] = {{"start", load_average()}};
  result["options"] = {{"threads", opt.threads},
                       {"size_d2q9", opt.size_d2q9},
                       {"size_d3q19", opt.size_d3q19},
                       {"min_seconds", opt.min_seconds},
                       {"stream_array_mib", opt.stream_array_mib},
                       {"stream_repetitions", opt.stream_repetitions},
                       {"lattices", opt.lattices},
                       {"collisions", opt.collisions},
                       {"precisions", opt.precisions},
                       {"two_level", opt.two_level},
                       {"quick", opt.quick}};
  if (max_threads > core::usable_processors())
    result["warnings"].push_back(
        fmt::format("{} threads on {} usable processors (affinity and CPU quota): oversubscribed, timings are "
                    "not meaningful",
                    max_threads, core::usable_processors()));

  result["environment"]["llc_bytes_reported"] = llc_bytes();
  if ((opt.stream_array_mib << 20) < llc_bytes())
    result["warnings"].push_back(fmt::format(
        "stream arrays of {} MiB are smaller than the reported last-level cache ({} MiB): the bandwidth "
        "may be cache-inflated and the roofline fractions too low",
        opt.stream_array_mib, llc_bytes() >> 20));

  // 1. Bandwidth before the fluid runs (again after them, below).
  const std::size_t array_bytes = opt.stream_array_mib << 20;
  std::map<int, StreamResult> best;
  json runs = json::array();
  auto measure_bandwidth = [&](const char* when) {
    for (int t : opt.threads) {
      const auto s = measure_stream_bandwidth(t, array_bytes, opt.stream_repetitions);
      auto j = stream_json(s);
      j["when"] = when;
      runs.push_back(j);
      auto& b = best[t];
      if (s.update_gbs > b.update_gbs) b = s;
      say(fmt::format("stream {:>6} threads {:>2}: copy {:7.2f} GB/s, triad {:7.2f} GB/s, update {:7.2f} GB/s", when,
                      t, s.copy_gbs, s.triad_gbs, s.update_gbs));
    }
  };
  measure_bandwidth("before");

  // 2. Fluid throughput.
  json rows = json::array();
  std::vector<std::pair<FluidCase, FluidMeasurement>> uniform;
  auto run_case = [&](const FluidCase& c) {
    const auto m = measure_fluid(c, opt.min_seconds);
    say(fmt::format("fluid {:>5} {:>3} {:>6} {:>2} threads {:>9}{}: {:8.2f} MLUPS", c.lattice, c.collision,
                    c.precision, c.threads, size_text(m.size), c.two_level ? " two-level" : "", m.mlups));
    return m;
  };
  for (const auto& lat : opt.lattices) {
    const int n = lat == "D2Q9" ? opt.size_d2q9 : opt.size_d3q19;
    for (const auto& col : opt.collisions)
      for (const auto& prec : opt.precisions)
        for (int t : opt.threads) {
          FluidCase c{lat, col, prec, t, n, false};
          uniform.emplace_back(c, run_case(c));
        }
    // Two-level with the first collision, in every precision: the coupling's cost is set by the
    // cache lines it touches more than by the bytes, so its share of the step differs between
    // double and single precision.
    if (opt.two_level)
      for (const auto& prec : opt.precisions)
        for (int t : opt.threads) {
          FluidCase c{lat, opt.collisions.front(), prec, t, n, true};
          uniform.emplace_back(c, run_case(c));
        }
  }

  measure_bandwidth("after");
  result["load_average"]["end"] = load_average();

  // 3. Roofline with the best in-place update bandwidth of the row's thread count (the kernel's
  // own access pattern); the copy bandwidth's roofline beside it.
  for (const auto& [c, m] : uniform) {
    const double bw = best.at(c.threads).update_gbs * 1e9;
    const double bw_copy = best.at(c.threads).copy_gbs * 1e9;
    json row = {{"kind", c.two_level ? "two_level" : "uniform"},
                {"lattice", c.lattice},
                {"collision", c.collision},
                {"precision", c.precision},
                {"threads", c.threads},
                {"size", m.size},
                {"updates_per_step", m.updates_per_step},
                {"steps", m.steps},
                {"seconds", m.seconds},
                {"mlups", m.mlups},
                {"mlups_best_batch", m.mlups_best},
                {"cpu_share", m.cpu_share},
                {"bytes_per_update", m.bytes_per_update},
                {"bandwidth_gbs", bw * 1e-9},
                {"roofline_mlups", bw / m.bytes_per_update * 1e-6},
                {"roofline_mlups_copy", bw_copy / m.bytes_per_update * 1e-6}};
    row["fraction"] = m.mlups / row["roofline_mlups"].get<double>();
    if (c.two_level) {
      row["fine_size"] = m.fine_size;
      row["fine_fraction"] = m.fine_fraction;
      row["coupling_share"] = m.coupling_seconds / m.seconds;
      // Against the uniform twin timed between its batches (the separate uniform row was
      // measured at another moment: on a shared machine that ratio is mostly drift).
      row["uniform_twin_mlups"] = m.uniform_twin_mlups;
      row["overhead_vs_uniform"] = m.overhead;
    }
    rows.push_back(row);
  }

  json bandwidth;
  bandwidth["convention"] =
      "STREAM: copy counts 2 x 8 B, triad 3 x 8 B and the in-place update b = s b 2 x 8 B per "
      "element; the write-allocate read of stored lines is not counted (ordinary stores: the "
      "hardware moves 3 x 8 B and 4 x 8 B for copy and triad; the update stores into lines it has "
      "just read and moves what it counts). Best repetition of each run; the roofline uses the "
      "better update run of each thread count.";
  bandwidth["runs"] = runs;
  for (const auto& [t, s] : best) bandwidth["per_threads"].push_back(stream_json(s));
  result["bandwidth"] = bandwidth;
  result["roofline"] =
      "roofline_mlups = in-place update GB/s / bytes_per_update, bytes_per_update = 2 Q sizeof(T) "
      "(the in-place kernel reads Q values of a node and writes them back: the access pattern of "
      "the update kernel); fraction = mlups / roofline_mlups. roofline_mlups_copy divides the copy "
      "bandwidth instead (the basis of caplab's reports before the in-place kernel).";
  result["mlups_definition"] =
      "steps x updates_per_step / seconds of sim::Fluid::step() (fused in-place collide-push, "
      "periodic boundary stage; two-level: coarse + 2 x fine interior nodes per coarse step, less the "
      "covered coarse nodes, for which the fine block stands)";
  result["rows"] = rows;

  if (opt.out) {
    *opt.out << format_table(result);
    if (result.contains("warnings"))
      for (const auto& w : result["warnings"]) *opt.out << "warning: " << w.get<std::string>() << "\n";
  }
  if (!opt.output_dir.empty()) {
    std::filesystem::create_directories(opt.output_dir);
    io::write_file_atomically(opt.output_dir / "bench.json", result.dump(2) + "\n");
  }
  return result;
}

std::string format_table(const json& result) {
  std::ostringstream s;
  s << "\nMemory bandwidth, GB/s (STREAM counting, no write-allocate; best of "
    << result["options"]["stream_repetitions"].get<int>() << ", 3 arrays of "
    << result["options"]["stream_array_mib"].get<std::size_t>() << " MiB)\n";
  s << fmt::format("{:>8} {:>10} {:>10} {:>10}\n", "threads", "copy", "triad", "update");
  for (const auto& b : result["bandwidth"]["per_threads"])
    s << fmt::format("{:>8} {:>10.2f} {:>10.2f} {:>10.2f}\n", b["threads"].get<int>(), b["copy_gbs"].get<double>(),
                     b["triad_gbs"].get<double>(), b["update_gbs"].get<double>());
  s << "\nFluid update (sim::Fluid::step, periodic box); roofline = in-place update bandwidth / (2 Q sizeof T)";
  const auto& load = result["load_average"];
  if (load["start"].is_array() && load["end"].is_array())
    s << fmt::format("; load average {:.2f} at start, {:.2f} at end", load["start"][0].get<double>(),
                     load["end"][0].get<double>());
  s << "\ncpu% = process CPU time / (threads x wall time); well below 100 means other work took the cores.\n";
  s << fmt::format("{:<10} {:<6} {:<5} {:<6} {:>3} {:>8} {:>9} {:>9} {:>9} {:>8} {:>5} {}\n", "kind",
                   "lattice", "coll", "prec", "thr", "size", "MLUPS", "best", "roofline", "fraction", "cpu%",
                   "overhead");
  for (const auto& r : result["rows"]) {
    std::string extra;
    if (r.contains("overhead_vs_uniform"))
      extra =
          fmt::format("{:+.0f}% vs uniform, coupling {:.0f}%", 100 * r["overhead_vs_uniform"].get<double>(),
                      100 * r["coupling_share"].get<double>());
    s << fmt::format("{:<10} {:<6} {:<5} {:<6} {:>3} {:>8} {:>9.2f} {:>9.2f} {:>9.1f} {:>8.2f} {:>5.0f} {}\n",
                     r["kind"].get<std::string>(), r["lattice"].get<std::string>(),
                     r["collision"].get<std::string>(), r["precision"].get<std::string>(),
                     r["threads"].get<int>(), size_text(r["size"].get<std::vector<int>>()),
                     r["mlups"].get<double>(), r["mlups_best_batch"].get<double>(),
                     r["roofline_mlups"].get<double>(), r["fraction"].get<double>(),
                     100 * r["cpu_share"].get<double>(), extra);
  }
  return s.str();
}

}  // namespace caplab::bench
