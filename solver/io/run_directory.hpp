// The run directory of DESIGN.md section 6 and its atomic-write discipline.
//
// Invariants:
//  - A run directory is recognised by its manifest.json (a JSON object with a "status").
//    It is written first, with "status": "running", and rewritten by finish() with the final
//    status (ok | input_error | diverged | failed). A directory whose manifest still says
//    "running" belongs to a process that was killed: run_status() reports it "incomplete",
//    never as a result. A run stopped on request (SIGINT, SIGTERM: core/interrupt.hpp) writes
//    its checkpoint and finishes "failed" with an "interrupted" entry (signal, step).
//  - Every text file appears complete or not at all: it is written to `name.tmp` in the same
//    directory, fsync'ed, renamed over `name`, and the directory is fsync'ed.
//  - HDF5 files are written as `name.partial` and renamed to `name` by commit_file(); a run
//    finished "ok" has no `.partial` or `.tmp` file left.
//  - Only a previous caplab run directory (or an empty directory) is ever replaced, and only
//    when the caller asked to overwrite; anything else is refused with an InputError.
//  - One writer: the RunDirectory holds an exclusive flock on the directory for its lifetime, so
//    a second `caplab run --out` or `--resume` on a run that is still going is refused instead
//    of writing into it, and is_running() tells a live run from a killed one.
//
// Not thread-safe: one RunDirectory is driven from one thread.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace caplab::io {

/// Writes `content` to `target` atomically: `target.tmp` in the same directory, fsync,
/// rename over `target`, fsync of the directory. Throws core::Error on any failure (the
/// temporary file is removed).
void write_file_atomically(const std::filesystem::path& target, std::string_view content);

/// One run's output directory (see the file header for the invariants).
class RunDirectory {
 public:
  /// Creates the run directory `out` (and its parents) and writes manifest.json with
  /// "status": "running" and "started_utc". If `out` exists: an empty directory is used as is;
  /// a previous caplab run directory is replaced when `overwrite` is true and refused
  /// otherwise; anything else (a file, a directory without manifest.json) is refused.
  /// Refusals throw core::InputError naming the path and the fix.
  static RunDirectory create(const std::filesystem::path& out, bool overwrite);

  /// Reopens the directory of an interrupted run to continue it from its checkpoint.h5
  /// (`caplab run --resume`): the manifest says "running" again and lists the resume under
  /// "resumed" (with the error and "interrupted" entry it had). Only a run that was killed
  /// (status "running"), stopped on request or failed for a reason other than its input or
  /// numerics (both "failed") can be resumed; anything else, or a directory without
  /// checkpoint.h5, is refused with a core::InputError that says why and what to do.
  static RunDirectory resume(const std::filesystem::path& dir);
  /// The checks of resume() without changing anything.
  static void check_resumable(const std::filesystem::path& dir);
  /// Status of the run in `dir`: the manifest's final status (ok | input_error | diverged |
  /// failed), "missing" when there is no manifest.json, "incomplete" when the manifest says
  /// "running", has no status, or cannot be parsed.
  static std::string run_status(const std::filesystem::path& dir);

  /// True if `dir` holds a manifest.json that is a JSON object with a string "status".
  static bool is_run_directory(const std::filesystem::path& dir);
  /// True while a process holds the run in `dir` (its RunDirectory's lock).
  static bool is_running(const std::filesystem::path& dir);

  RunDirectory(RunDirectory&& other) noexcept;
  RunDirectory& operator=(RunDirectory&&) = delete;
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;
  ~RunDirectory();

  /// The directory itself.
  const std::filesystem::path& root() const { return root_; }
  /// Path of the file `name` in the directory (`name` is a plain file name).
  std::filesystem::path path(const std::string& name) const;
  /// Path under which the HDF5 file `name` is written before commit_file(name).
  std::filesystem::path partial_path(const std::string& name) const;

  /// Writes `name` atomically as pretty-printed JSON.
  void write_json(const std::string& name, const nlohmann::json& value) const;
  /// Writes `name` atomically.
  void write_text(const std::string& name, std::string_view text) const;
  /// Renames the closed file `name.partial` to `name` (after fsync). Throws core::Error
  /// if `name.partial` does not exist.
  void commit_file(const std::string& name) const;

  /// Merges `fields` into the manifest while the run is going (e.g. the environment) and
  /// rewrites it. "status" cannot be set this way; use finish().
  void update_manifest(const nlohmann::json& fields);
  /// Finalises the manifest: merges `extra` (wall time, steps, MLUPS, stage shares ...),
  /// sets "status" and "finished_utc". `status` must be ok | input_error | diverged | failed;
  /// "ok" also requires that no `.partial`/`.tmp` file is left. May be called once.
  void finish(const std::string& status, const nlohmann::json& extra = nlohmann::json::object());

  /// The manifest as last written.
  const nlohmann::json& manifest() const { return manifest_; }
  /// True once finish() succeeded.
  bool finished() const { return finished_; }

 private:
  /// Opens `root` and takes its lock; refuses (InputError) a run another process holds.
  explicit RunDirectory(std::filesystem::path root);
  void write_manifest() const;

  std::filesystem::path root_;
  int lock_fd_ = -1;
  nlohmann::json manifest_;
  bool finished_ = false;
};

}  // namespace caplab::io
