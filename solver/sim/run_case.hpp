// Running a case: the one place that turns the validated case into template instances
// (dimension × precision × collision operator) and drives a run directory from "running"
// to a final status (DESIGN.md section 6).
#pragma once

#include <filesystem>

#include "case/case_spec.hpp"
#include "sim/scene.hpp"

namespace caplab::sim {

/// Runs `spec` into the run directory `out` (created fresh; a previous run there is
/// replaced). Writes case.json, manifest.json, series.h5, snapshots, summary.json.
/// On a numerical instability the manifest is finished as "diverged" and the
/// core::NumericalError propagates; on any other failure "failed" and the error propagates.
RunResult run_case(const cases::CaseSpec& spec, const std::filesystem::path& out, const ProgressFn& progress);

/// The supported combinations, for messages: "2D/3D × double/single × bgk/trt".
std::string supported_combinations();

}  // namespace caplab::sim
