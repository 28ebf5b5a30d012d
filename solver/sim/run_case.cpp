#include "sim/run_case.hpp"

#include <fmt/format.h>

#include <cstdlib>

#include "case/load_case.hpp"
#include "core/build_info.hpp"
#include "core/interrupt.hpp"
#include "core/threads.hpp"
#include "io/checkpoint.hpp"
#include "io/manifest.hpp"
#include "lattice/lattice.hpp"

namespace caplab::sim {

namespace {

/// What every template instance of a run needs besides the case.
struct Drive {
  io::RunDirectory& dir;
  const ProgressFn& progress;
  const CheckpointPolicy& policy;
  io::CheckpointReader* restore_from;  // resumed run: the checkpoint to continue from
};

template <class L, class T, class Op>
RunResult run_scene(const cases::CaseSpec& spec, const LatticeUnits& units, const Op& op, const Drive& d) {
  Scene<L, T, Op> scene(spec, units, op);
  if (d.restore_from) scene.restore(*d.restore_from);
  return scene.run(d.dir, d.progress, d.policy);
}

template <class L, class T>
RunResult dispatch_operator(const cases::CaseSpec& spec, const LatticeUnits& units, const Drive& d) {
  const double tau = units.blocks[0].tau;
  const auto& col = spec.numerics.collision;
  const bool trt = col.op == cases::CollisionSpec::Operator::trt;
  if (col.bulk_viscosity_ratio)
    return run_scene<L, T>(spec, units, collision::TrtBulk{tau, col.magic, *col.bulk_viscosity_ratio, !trt}, d);
  if (trt) return run_scene<L, T>(spec, units, collision::Trt{tau, col.magic}, d);
  return run_scene<L, T>(spec, units, collision::Bgk{tau}, d);
}

template <class L>
RunResult dispatch_precision(const cases::CaseSpec& spec, const LatticeUnits& units, const Drive& d) {
  if (spec.numerics.precision == cases::Precision::single) return dispatch_operator<L, float>(spec, units, d);
  return dispatch_operator<L, double>(spec, units, d);
}

/// What a checkpoint stores besides the state: how to rebuild the case exactly (the document as
/// read, the level, the overrides) and what built and ran it.
nlohmann::json checkpoint_meta(const cases::CaseSpec& spec, int threads) {
  const auto& b = core::build_info();
  return {{"format", checkpoint_format},
          {"source_file", spec.source_file},
          {"document", spec.document},
          {"fidelity", spec.fidelity},
          {"overrides", spec.overrides},
          {"resolved", spec.resolved},
          {"threads", threads},
          {"git_sha", std::string(b.git_sha)},
          {"git_dirty", b.git_dirty},
          {"compiler", std::string(b.compiler)},
          {"flags", std::string(b.flags)}};
}

/// Runs the scene of `spec` in `dir` (fresh, or continued from `restore_from`) and finishes the
/// manifest with the final status.
RunResult drive(const cases::CaseSpec& spec, const LatticeUnits& units, int threads, io::RunDirectory& dir,
                const ProgressFn& progress, const RunOptions& options, io::CheckpointReader* restore_from) {
  CheckpointPolicy policy;
  policy.interval = spec.outputs.checkpoint.interval;
  policy.wall_seconds = spec.outputs.checkpoint.wall_seconds;
  policy.meta = checkpoint_meta(spec, threads).dump();
  if (const char* kill = std::getenv("CAPLAB_TEST_KILL_AFTER_CHECKPOINT")) policy.kill_after = std::atoi(kill);
  if (const char* at = std::getenv("CAPLAB_TEST_SIGTERM_AT_STEP")) policy.sigterm_at_step = std::atol(at);
  const Drive d{dir, progress, policy, restore_from};
  try {
    RunResult r = spec.physics.dimension == 2 ? dispatch_precision<lattice::D2Q9>(spec, units, d)
                                              : dispatch_precision<lattice::D3Q19>(spec, units, d);
    dir.write_json("summary.json", r.summary);
    if (!options.keep_checkpoint) std::filesystem::remove(dir.path("checkpoint.h5"));
    nlohmann::json share = nlohmann::json::object();
    for (const auto& [k, v] : r.stage_seconds.items()) share[k] = v.get<double>() / r.wall_seconds;
    dir.finish("ok", {{"wall_time_s", r.wall_seconds},
                      {"steps", r.steps},
                      {"mlups", r.mlups},
                      {"stage_seconds", r.stage_seconds},
                      {"stage_share", share},
                      {"checkpoints", r.checkpoints}});
    return r;
  } catch (const core::Interrupted& e) {
    // Resumable (RunDirectory::check_resumable); the manifest says who stopped it and when.
    dir.finish("failed", {{"error", e.what()},
                          {"interrupted", {{"signal", core::signal_name(e.signal())}, {"step", e.step()}}}});
    throw;
  } catch (const core::NumericalError& e) {
    dir.finish("diverged", {{"error", e.what()}, {"step", e.step()}, {"where", e.where()}, {"cause", e.cause()}});
    throw;
  } catch (const core::InputError& e) {
    dir.finish("input_error", {{"error", e.what()}});
    throw;
  } catch (const std::exception& e) {
    dir.finish("failed", {{"error", e.what()}});
    throw;
  }
}

}  // namespace

void check_checkpoint_format(const nlohmann::json& meta, const std::filesystem::path& file) {
  const int format = meta.value("format", 1);
  if (format == checkpoint_format) return;
  const std::string writer = meta.value("git_sha", std::string("unknown"));
  const std::string fix =
      "resume it with the caplab that wrote it (git " + writer +
      "; scripts/reproduce resumes only with the binary that started the run), or run the case afresh into a new "
      "directory";
  if (format > checkpoint_format)
    throw core::InputError(fmt::format("the checkpoint '{}' has layout format {}, newer than the format {} this caplab "
                                       "(git {}) reads: {}",
                                       file.string(), format, checkpoint_format, core::build_info().git_sha, fix));
  throw core::InputError(fmt::format(
      "the checkpoint '{}' has layout format {}{} and this caplab (git {}) reads format {}: the state it stores is laid "
      "out differently; {}",
      file.string(), format,
      format == 1 ? " (written before 2026-12-07, when the layout was first versioned: entries were added and resized "
                    "under format 1)"
                  : "",
      core::build_info().git_sha, checkpoint_format, fix));
}

void check_series_quantities(const cases::CaseSpec& spec) {
  if (spec.physics.dimension == 2)
    check_series_quantities<2>(spec);
  else
    check_series_quantities<3>(spec);
}

std::string supported_combinations() { return "dimension 2 (D2Q9) or 3 (D3Q19) × precision double|single × collision bgk|trt"; }

RunResult run_case(const cases::CaseSpec& spec, const std::filesystem::path& out, const ProgressFn& progress,
                   const RunOptions& options) {
  const LatticeUnits units = derive_units(spec);  // input errors surface before the directory exists
  check_memory(spec, units, machine_memory_bytes());  // and before anything large is allocated
  const int threads = core::apply_thread_count(spec.numerics.threads);
  if (threads > 1 && options.warn)
    if (const auto w = core::contention_warning(threads, core::other_running_tasks())) options.warn(*w);
  auto dir = io::RunDirectory::create(out, /*overwrite=*/true);
  nlohmann::json resolved = spec.resolved;
  resolved["fidelity_applied"] = spec.fidelity;
  dir.write_json("case.json", resolved);
  dir.update_manifest({{"case_id", spec.id},
                       {"fidelity", spec.fidelity},
                       {"case_file", spec.source_file},
                       {"threads", threads},
                       {"environment", io::environment_json(threads)},
                       {"lattice", units.to_json()}});
  return drive(spec, units, threads, dir, progress, options, nullptr);
}

ResumedRun resume_case(const std::filesystem::path& run_dir, int threads, const ProgressFn& progress,
                       const RunOptions& options) {
  io::RunDirectory::check_resumable(run_dir);  // before anything in the directory changes
  io::CheckpointReader reader(run_dir / "checkpoint.h5");
  std::string meta_text;
  reader("meta", meta_text);
  const auto meta = nlohmann::json::parse(meta_text);
  check_checkpoint_format(meta, run_dir / "checkpoint.h5");
  cases::CaseSpec spec = cases::parse_case(meta.at("document"), meta.at("source_file").get<std::string>(),
                                           meta.at("fidelity").get<std::string>(),
                                           meta.at("overrides").get<std::vector<std::string>>());
  if (spec.resolved != meta.at("resolved"))
    throw core::InputError("the checkpoint in '" + run_dir.string() +
                           "' was written by a caplab whose case defaults differ from this one (git " +
                           meta.at("git_sha").get<std::string>() + "); resume it with that build or run it afresh");
  const int saved_threads = meta.at("threads").get<int>();
  spec.numerics.threads = threads > 0 ? threads : saved_threads;
  const LatticeUnits units = derive_units(spec);
  check_memory(spec, units, machine_memory_bytes());  // the machine resumed on may have less
  const int used = core::apply_thread_count(spec.numerics.threads);
  const auto& b = core::build_info();
  auto warn = [&](const std::string& w) {
    if (options.warn) options.warn(w);
  };
  if (used != saved_threads)
    warn(fmt::format("the run started with {} threads and continues with {}: results agree to round-off, not bit "
                     "for bit",
                     saved_threads, used));
  if (meta.at("git_sha").get<std::string>() != b.git_sha || meta.at("git_dirty").get<bool>() != b.git_dirty ||
      meta.at("flags").get<std::string>() != std::string(b.flags))
    warn("the run started with another build of caplab (git " + meta.at("git_sha").get<std::string>() +
         "): results may differ from an uninterrupted run at round-off");
  if (used > 1)
    if (const auto w = core::contention_warning(used, core::other_running_tasks())) warn(*w);
  auto dir = io::RunDirectory::resume(run_dir);
  dir.update_manifest({{"threads", used}, {"environment", io::environment_json(used)}});
  ResumedRun r{spec, {}};
  r.result = drive(spec, units, used, dir, progress, options, &reader);
  return r;
}

}  // namespace caplab::sim
