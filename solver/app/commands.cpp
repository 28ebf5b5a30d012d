#include "app/commands.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "case/load_case.hpp"
#include "collision/operators.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/run_directory.hpp"
#include "score/run_files.hpp"
#include "sim/run_case.hpp"
#include "sim/units.hpp"

namespace caplab::app {

namespace fs = std::filesystem;

namespace {

std::string human_seconds(double s) {
  if (s < 90) return fmt::format("{:.0f} s", s);
  if (s < 5400) return fmt::format("{:.1f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

/// One line with the derived lattice units (the FluidX3D habit): what the case means on the lattice.
void print_units(const cases::CaseSpec& spec, const sim::LatticeUnits& u) {
  fmt::print("{} [{}]: Re = {} ({}), U_lu = {}, Mach = {:.3f}\n", spec.id, spec.fidelity, spec.physics.reynolds,
             u.reynolds_definition, u.velocity_lu, u.mach);
  for (const auto& b : u.blocks) {
    std::string nodes;
    for (std::size_t a = 0; a < b.nodes.size(); ++a) nodes += (a ? " x " : "") + std::to_string(b.nodes[a]);
    // TRT: the odd moments' relaxation time too; far above 1 it lets interface and IB errors persist.
    // A bulk viscosity of its own: the bulk mode's.
    const auto& col = spec.numerics.collision;
    const bool trt = col.op == cases::CollisionSpec::Operator::trt;
    std::string tau_minus = trt ? fmt::format("tau- = {:.3g}", collision::Trt{b.tau, col.magic}.tau_minus()) : "";
    if (col.bulk_viscosity_ratio)
      tau_minus += fmt::format("{}tau_bulk = {:.4g}", trt ? ", " : "",
                               collision::TrtBulk{b.tau, col.magic, *col.bulk_viscosity_ratio, !trt}.tau_bulk(
                                   spec.physics.dimension));
    if (!tau_minus.empty()) tau_minus = " (" + tau_minus + ")";
    fmt::print("  block {:8s} dx = {:.5g} L, dt = {:.5g} L/U, tau = {:.5f}{}, nu_lu = {:.5g}, nodes {}\n", b.name, b.dx,
               b.dt, b.tau, tau_minus, b.nu_lu, nodes);
  }
}

}  // namespace

int check(const CheckArgs& args) {
  const auto spec = cases::load_case(args.case_file, args.fidelity, args.overrides);
  sim::check_series_quantities(spec);
  const auto u = sim::derive_units(spec);
  print_units(spec, u);
  fmt::print("  steps {} (coarse), node updates {:.3g}, memory {:.1f} MiB\n", u.coarse_steps, u.node_updates,
             u.memory_bytes / (1024.0 * 1024.0));
  try {
    sim::check_memory(spec, u, sim::machine_memory_bytes());
  } catch (const core::InputError& e) {  // the case is valid; it only does not fit on this machine
    fmt::print("  warning: `caplab run` refuses this case on this machine: {}\n", e.what());
  }
  for (const auto& b : spec.physics.bodies)
    if (b.membrane) {
      const double E_lu = sim::membrane_lattice_modulus(u, b);
      const double limit = sim::membrane_stiffness_limit(spec.physics.dimension);
      const double factor = sim::membrane_stiffness_factor(*b.membrane);
      fmt::print("  membrane '{}': lattice modulus E_lu = nu U / G{} = {:.3g} (the explicit-coupling limit make stress "
                 "measured without bending stiffness is about {:g}; bending stiffness lowers it)\n",
                 b.name, factor == 1.0 ? "" : fmt::format(" x {:g} (Skalak: the area modulus, (1 + 2C)/2)", factor),
                 E_lu, limit);
      if (E_lu > limit)
        fmt::print("  warning: the membrane of '{}' is likely too stiff for this time step and will blow up; lower "
                   "numerics.lattice_velocity (E_lu grows as its square)\n",
                   b.name);
    }
  fmt::print("  estimated run time: {} at 50 MLUPS, {} at 150 MLUPS\n", human_seconds(u.estimated_seconds(50)),
             human_seconds(u.estimated_seconds(150)));
  fmt::print("ok: {} is valid at fidelity {}\n", args.case_file.string(), spec.fidelity);
  return 0;
}

namespace {

/// A JSON file's object, or an empty object when it is missing or unreadable.
nlohmann::json read_object(const fs::path& file) {
  return score::read_json(file).doc.value_or(nlohmann::json::object());
}

/// One line per run directory: case, level, what became of it, wall time and verdict.
void print_run(const fs::path& run, std::size_t width) {
  const auto m = read_object(run / "manifest.json");
  const std::string status = io::RunDirectory::run_status(run);
  std::string state = status;
  if (status == "incomplete")
    state = io::RunDirectory::is_running(run) ? "running now"
            : fs::exists(run / "checkpoint.h5")
                ? fmt::format("killed (resumable: caplab run --resume {})", run.string())
                : "killed before its first checkpoint";
  if (status == "failed" && m.contains("interrupted"))
    state = fmt::format("stopped by {} after step {} (resumable: caplab run --resume {})",
                        m["interrupted"].value("signal", "?"), m["interrupted"].value("step", 0L), run.string());
  if (status == "diverged") state = fmt::format("diverged at step {}", m.value("step", 0L));
  std::string wall;
  if (m.contains("wall_time_s")) wall = human_seconds(m["wall_time_s"].get<double>());
  const auto score = read_object(run / "score.json");
  fmt::print("{:{}s} {:40s} {:9s} {:7s} {:>9s}  {}\n", run.string(), width, m.value("case_id", std::string("?")),
             m.value("fidelity", std::string("?")), score.value("verdict", std::string("-")), wall, state);
}

}  // namespace

int list(const fs::path& dir) {
  // Case files; a run directory (manifest.json) is listed as a run and not searched, and the
  // records scripts/reproduce keeps beside runs are not cases.
  std::vector<fs::path> files, runs;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const fs::path& p = it->path();
    if (it->is_directory() && io::RunDirectory::is_run_directory(p)) {
      runs.push_back(p);
      it.disable_recursion_pending();
    } else if (p.extension() == ".json" && p.filename() != "schema.json" &&
               !p.filename().string().ends_with(".reproduce.json")) {
      files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());
  std::sort(runs.begin(), runs.end());
  std::size_t width = 13;  // "run directory"
  for (const auto& r : runs) width = std::max(width, r.string().size());
  if (!runs.empty())
    fmt::print("{:{}s} {:40s} {:9s} {:7s} {:>9s}  {}\n", "run directory", width, "case", "fidelity", "verdict", "wall",
               "status");
  for (const auto& r : runs) print_run(r, width);
  for (const auto& f : files) {
    try {
      const auto spec = cases::load_case(f, "standard");
      std::string levels;
      for (const auto& l : cases::fidelity_levels(f)) levels += (levels.empty() ? "" : ",") + l;
      fmt::print("{:40s} {:10s} {}\n", spec.id, levels, spec.title);
    } catch (const core::InputError& e) {
      fmt::print("{:40s} INVALID    {}\n", f.string(), e.what());
    }
  }
  return 0;
}

int run(const RunArgs& args, bool terminal) {
  core::install_stop_handlers();  // Ctrl-C or SIGTERM: checkpoint and stop (core/interrupt.hpp)
  sim::ProgressFn progress = [&](long step, long total, double t, double mlups, double eta) {
    const std::string line =
        fmt::format("step {}/{}  t = {:.2f} L/U  {:.1f} MLUPS  ETA {}", step, total, t, mlups, human_seconds(eta));
    if (terminal)
      fmt::print(stderr, "\r{:<78}", line);
    else if (step % std::max(1L, total / 10) < std::max(1L, total / 200))
      fmt::print(stderr, "{}\n", line);
  };
  const sim::RunOptions options{args.keep_checkpoint,
                                [](const std::string& w) { fmt::print(stderr, "caplab: warning: {}\n", w); }};
  fs::path out = args.out;
  sim::RunResult r;
  if (!args.resume.empty()) {
    out = args.resume;
    fmt::print("resuming {} from its checkpoint\n", out.string());
    auto resumed = sim::resume_case(out, args.threads, progress, options);
    r = std::move(resumed.result);
  } else {
    const auto spec = cases::load_case(args.case_file, args.fidelity, args.overrides);
    auto spec_threads = spec;
    if (args.threads > 0) spec_threads.numerics.threads = args.threads;
    if (out.empty()) {
      // Same layout as scripts/reproduce: results/<fidelity>/<id with "/" as "__">.
      std::string id;
      for (char c : spec.id) id += c == '/' ? std::string("__") : std::string(1, c);
      out = fs::path("results") / spec.fidelity / id;
    }
    print_units(spec_threads, sim::derive_units(spec_threads));
    r = sim::run_case(spec_threads, out, progress, options);
  }
  if (terminal) fmt::print(stderr, "\n");
  fmt::print("ran {} steps in {} ({:.1f} MLUPS) -> {}\n", r.steps, human_seconds(r.wall_seconds), r.mlups, out.string());
  for (const auto& [k, v] : r.summary["metrics"].items()) {
    const auto& value = v["value"];
    if (value.is_string())
      fmt::print("  {:34s} {}\n", k, value.get<std::string>());
    else
      fmt::print("  {:34s} {:.6g}\n", k, value.get<double>());
  }
  return score(ScoreArgs{out, args.strict});
}

}  // namespace caplab::app
