// Running a case: the one place that turns the validated case into template instances
// (dimension × precision × collision operator) and drives a run directory from "running"
// to a final status (DESIGN.md section 6).
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "case/case_spec.hpp"
#include "sim/scene.hpp"

namespace caplab::sim {

/// Choices of the command line that are not part of the case.
struct RunOptions {
  bool keep_checkpoint = false;  ///< keep checkpoint.h5 when the run finishes ok
  /// Told, before the first step, what the user should know: the cores are busy with other
  /// work (core::contention_warning), a resume with another thread count or build.
  std::function<void(const std::string&)> warn;
};

/// Runs `spec` into the run directory `out` (created fresh; a previous run there is
/// replaced). Writes case.json, manifest.json, series.h5, snapshots, summary.json, and
/// checkpoint.h5 as outputs.checkpoint asks (removed at the end unless options keep it).
/// On a numerical instability the manifest is finished as "diverged" and the
/// core::NumericalError propagates; on any other failure "failed" and the error propagates.
RunResult run_case(const cases::CaseSpec& spec, const std::filesystem::path& out, const ProgressFn& progress,
                   const RunOptions& options = {});

/// A run continued by resume_case: the case as rebuilt from the checkpoint, and the result.
struct ResumedRun {
  cases::CaseSpec spec;
  RunResult result;
};

/// Continues the interrupted run in `run_dir` from its checkpoint.h5 (`caplab run --resume`):
/// the case is rebuilt from the checkpoint (the document, level and overrides it was started
/// with), with `threads` (0: the thread count it was started with). At the same thread count
/// and build the outputs are bit for bit those of an uninterrupted run. Refuses (InputError)
/// a run that finished, diverged or was refused, and a directory without a checkpoint.
ResumedRun resume_case(const std::filesystem::path& run_dir, int threads, const ProgressFn& progress,
                       const RunOptions& options = {});

/// The layout of the state a checkpoint stores (Scene::checkpoint and what it calls), in the
/// checkpoint's meta as "format". Bump it with every change of an entry's name, size or meaning:
/// resume_case refuses another format before it reads the state.
///   1  until 2026-12-07, unchecked: the layout changed under it ("population_stride" added,
///      the two-level coupling history cut from 19 values to 14 channels per node)
///   2  from 2026-12-07
inline constexpr int checkpoint_format = 2;

/// Throws core::InputError, naming `file`, the build that wrote it and the fix, when the
/// checkpoint meta `meta` has another "format" than checkpoint_format (missing: 1).
void check_checkpoint_format(const nlohmann::json& meta, const std::filesystem::path& file);

/// Throws core::InputError when the case asks for a series quantity its dimension and bodies
/// cannot give (scene.hpp check_series_quantities<D>); `caplab check` calls it.
void check_series_quantities(const cases::CaseSpec& spec);

/// The supported combinations, for messages: "2D/3D × double/single × bgk/trt".
std::string supported_combinations();

}  // namespace caplab::sim
