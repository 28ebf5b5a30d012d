// The `caplab` command: run, check, list, score, claims, bench, compare.
//
// The only place that maps errors to exit codes (DESIGN.md section 6): 0 ran (and, with
// --strict, passed), 1 scored outside tolerance, 2 bad input, 3 numerical instability,
// 4 any other failure.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "core/build_info.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"

namespace fs = std::filesystem;
using namespace caplab;

int main(int argc, char** argv) {
  CLI::App app{"caplab — immersed-boundary / multi-block lattice Boltzmann capsules in shear flow (Sui's thesis)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(core::build_info().version) + " (" +
                                        std::string(core::build_info().git_sha) + ")");

  app::RunArgs run;
  auto* run_cmd = app.add_subcommand("run",
                                     "Run a case and write its run directory (then score it). Ctrl-C or SIGTERM ends "
                                     "the current step, writes checkpoint.h5 and stops (continue with --resume)");
  auto* run_case = run_cmd->add_option("case", run.case_file, "Case file (JSON)")->check(CLI::ExistingFile);
  auto* resume = run_cmd->add_option("--resume", run.resume,
                                     "Continue the interrupted run in this run directory from its checkpoint.h5 "
                                     "(same case, level and overrides; bit for bit at the same thread count)")
                     ->check(CLI::ExistingDirectory);
  run_case->excludes(resume);
  run_cmd->add_flag("--keep-checkpoint", run.keep_checkpoint, "Keep checkpoint.h5 when the run finishes ok");
  auto* fidelity = run_cmd->add_option("--fidelity", run.fidelity, "Fidelity level defined by the case: quick | standard | thesis")
      ->default_val("standard");
  auto* out = run_cmd->add_option("--out", run.out, "Run directory (default results/<fidelity>/<case id>)");
  auto* set = run_cmd->add_option("--set", run.overrides, "Override a case value: path=value (repeatable), e.g. physics.reynolds=200");
  for (auto* o : {fidelity, out, set}) o->excludes(resume);
  run_cmd->add_option("--threads", run.threads, "OpenMP threads (0: all)")->default_val(0);
  run_cmd->add_flag("--strict", run.strict, "Exit 1 when the score fails its tolerances");

  app::CheckArgs check;
  auto* check_cmd = app.add_subcommand("check", "Validate a case; print the derived lattice parameters and cost");
  check_cmd->add_option("case", check.case_file, "Case file (JSON)")->required()->check(CLI::ExistingFile);
  check_cmd->add_option("--fidelity", check.fidelity, "Fidelity level")->default_val("standard");
  check_cmd->add_option("--set", check.overrides, "Override a case value: path=value (repeatable)");

  std::string list_dir = "catalogue";
  auto* list_cmd = app.add_subcommand("list", "List the cases of a catalogue directory, or the runs of a results directory");
  list_cmd->add_option("dir", list_dir,
                       "Directory to search (default: catalogue); a run directory is listed with its level, verdict, "
                       "wall time and status (a stopped run with how to resume it)");

  app::ScoreArgs score;
  auto* score_cmd = app.add_subcommand("score", "Score a finished run directory against its references");
  score_cmd->add_option("run_dir", score.run_dir, "Run directory")->required()->check(CLI::ExistingDirectory);
  score_cmd->add_flag("--strict", score.strict, "Exit 1 when sanity or accuracy fails");

  app::ClaimsArgs claims;
  auto* claims_cmd = app.add_subcommand(
      "claims",
      "Check thesis statements (claims.json: trends, brackets, modes, bounds) against several runs");
  claims_cmd->add_option("claims", claims.claims_file, "Claims file, e.g. references/capsule2d/claims.json")
      ->required()
      ->check(CLI::ExistingFile);
  claims_cmd->add_option("run_dirs", claims.run_dirs,
                         "Run directories (capsule runs; other runs for the claims with a \"check\")")
      ->required()
      ->check(CLI::ExistingDirectory);
  claims_cmd->add_option("--json", claims.json_out, "Also write the verdicts as JSON to this file");
  claims_cmd->add_option("--only", claims.only, "Only the claims whose id starts with this, e.g. ch3.");
  claims_cmd->add_flag("--strict", claims.strict, "Exit 1 when a claim is inconsistent with the runs");

  app::BenchArgs bench;
  auto* bench_cmd = app.add_subcommand("bench", "Measure memory bandwidth and fluid MLUPS (roofline)");
  bench_cmd->add_option("--out", bench.out, "Output directory")->default_val("reports/out/bench");
  bench_cmd->add_flag("--quick", bench.quick, "Small sizes and short timings (smoke test)");
  bench_cmd->add_option("--threads", bench.options.threads, "Thread counts to measure, e.g. 1,2")->delimiter(',');
  bench_cmd->add_option("--size-d2q9", bench.options.size_d2q9, "Edge of the D2Q9 box (default 2048, quick 256)");
  bench_cmd->add_option("--size-d3q19", bench.options.size_d3q19, "Edge of the D3Q19 box (default 128, quick 32)");
  bench_cmd->add_option("--lattices", bench.options.lattices, "D2Q9,D3Q19")->delimiter(',');
  bench_cmd->add_option("--collisions", bench.options.collisions, "bgk,trt")->delimiter(',');
  bench_cmd->add_option("--precisions", bench.options.precisions, "double,float")->delimiter(',');
  bench_cmd->add_option("--min-seconds", bench.options.min_seconds, "Minimum time per fluid measurement");

  app::CompareArgs compare;
  auto* compare_cmd = app.add_subcommand(
      "compare", "Compare two run directories (series, snapshots, summary): exit 0 when they agree, 1 otherwise");
  compare_cmd->add_option("run_a", compare.a, "First run directory")->required()->check(CLI::ExistingDirectory);
  compare_cmd->add_option("run_b", compare.b, "Second run directory")->required()->check(CLI::ExistingDirectory);
  compare_cmd->add_option("--tolerance", compare.tolerance,
                          "Largest relative difference accepted (default 0: bit for bit)")
      ->default_val(0.0)
      ->check(CLI::NonNegativeNumber);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a bad command line (a missing case file, a directory given
    // as one, an unknown option) is bad input like a bad case: exit code 2, not CLI11's own.
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (*run_cmd) {
      if (run.case_file.empty() && run.resume.empty())
        throw core::InputError("caplab run needs a case file (caplab run CASE.json) or --resume RUN_DIR");
      return app::run(run, isatty(fileno(stderr)));
    }
    if (*check_cmd) return app::check(check);
    if (*list_cmd) return app::list(list_dir);
    if (*score_cmd) return app::score(score);
    if (*claims_cmd) return app::claims(claims);
    if (*bench_cmd) return app::bench(bench);
    if (*compare_cmd) return app::compare(compare);
  } catch (const core::InputError& e) {
    fmt::print(stderr, "caplab: input error: {}\n", e.what());
    return 2;
  } catch (const core::NumericalError& e) {
    fmt::print(stderr, "caplab: {}\n", e.what());
    return 3;
  } catch (const core::Interrupted& e) {
    // Stopped on request with its checkpoint written: end by the same signal (its default
    // action), so that the shell or batch system that sent it sees the process stopped by it.
    fmt::print(stderr, "\ncaplab: {}\n", e.what());
    std::fflush(nullptr);
    std::signal(e.signal(), SIG_DFL);
    std::raise(e.signal());
    return 128 + e.signal();
  } catch (const std::exception& e) {
    fmt::print(stderr, "caplab: error: {}\n", e.what());
    // An HDF5 file whose close failed (a full disk) makes the HDF5 library's exit handler crash
    // (H5F__close_cb, HDF5 1.10; measured: exit 139 instead of 4). Every file caplab keeps was
    // closed explicitly or is a .partial one, so leave without running the exit handlers.
    std::fflush(nullptr);
    std::_Exit(4);
  }
  return 4;
}
