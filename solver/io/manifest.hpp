// Provenance written into every run manifest (DESIGN.md section 6): which binary ran
// (version, git sha and dirty flag, compiler, flags, build type), where (host, CPU model),
// with how many threads, and when (UTC, ISO 8601).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace caplab::io {

/// Current UTC date and time in ISO 8601 with a 'Z' suffix, e.g. "2024-05-01T12:34:56Z".
std::string utc_now_iso8601();

/// CPU model name from /proc/cpuinfo ("unknown" where it cannot be read).
std::string cpu_model();

/// Host name of this machine ("unknown" where it cannot be read).
std::string host_name();

/// The environment of this run, for the manifest:
/// {"build": {"version", "git_sha", "git_dirty", "compiler", "flags", "build_type"},
///  "host", "cpu_model", "hardware_threads", "threads", "date_utc"}.
/// `threads` is the number of threads the run uses (e.g. OpenMP threads).
nlohmann::json environment_json(int threads);

}  // namespace caplab::io
