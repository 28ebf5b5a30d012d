#include "io/run_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>
#include <system_error>

#include "core/error.hpp"
#include "io/manifest.hpp"

namespace caplab::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kManifest = "manifest.json";
constexpr std::array<const char*, 4> kFinalStatuses = {"ok", "input_error", "diverged", "failed"};

bool is_final_status(const std::string& s) {
  for (const char* f : kFinalStatuses)
    if (s == f) return true;
  return false;
}

[[noreturn]] void throw_errno(const std::string& what, const fs::path& p, int err) {
  throw core::Error("io: " + what + " '" + p.string() + "': " + std::strerror(err));
}

/// fsync of a file or directory given by path.
void fsync_path(const fs::path& p, bool directory) {
  const int fd = ::open(p.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) throw_errno("cannot open for fsync", p, errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw_errno("fsync failed on", p, err);
}

fs::path parent_or_dot(const fs::path& p) { return p.has_parent_path() ? p.parent_path() : fs::path("."); }

void check_plain_name(const std::string& name) {
  const fs::path p(name);
  if (name.empty() || name == "." || name == ".." || p.filename() != p)
    throw core::Error("io: '" + name + "' is not a plain file name inside the run directory");
}

std::optional<nlohmann::json> read_manifest(const fs::path& dir) {
  std::error_code ec;
  const fs::path file = dir / kManifest;
  if (!fs::is_regular_file(file, ec)) return std::nullopt;
  std::ifstream in(file);
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return nlohmann::json();  // present but unparsable
  return j;
}

}  // namespace

void write_file_atomically(const fs::path& target, std::string_view content) {
  fs::path tmp = target;
  tmp += ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_errno("cannot create", tmp, errno);
  auto fail = [&](const std::string& what) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    throw_errno(what, tmp, err);
  };
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write");
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("fsync failed on");
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw_errno("cannot close", tmp, err);
  }
  if (::rename(tmp.c_str(), target.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw_errno("cannot rename into place", target, err);
  }
  fsync_path(parent_or_dot(target), /*directory=*/true);
}

namespace {

/// An fd of `dir` with `lock` (LOCK_EX or LOCK_SH, non-blocking) taken, or -1 when another open
/// description holds a conflicting lock (or the directory cannot be opened).
int lock_directory(const fs::path& dir, int lock) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return -1;
  if (::flock(fd, lock | LOCK_NB) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

[[noreturn]] void refuse_running(const fs::path& dir) {
  throw core::InputError("the run in '" + dir.string() +
                         "' is going on in another process (it holds the directory's lock): wait for it, stop it "
                         "(Ctrl-C or kill -TERM: it writes a checkpoint), or choose another output directory");
}

}  // namespace

RunDirectory::RunDirectory(fs::path root) : root_(std::move(root)) {
  lock_fd_ = lock_directory(root_, LOCK_EX);
  if (lock_fd_ < 0) refuse_running(root_);
}

RunDirectory::RunDirectory(RunDirectory&& other) noexcept
    : root_(std::move(other.root_)), lock_fd_(other.lock_fd_), manifest_(std::move(other.manifest_)),
      finished_(other.finished_) {
  other.lock_fd_ = -1;
}

RunDirectory::~RunDirectory() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

bool RunDirectory::is_running(const fs::path& dir) {
  const int fd = lock_directory(dir, LOCK_SH);
  if (fd >= 0) {
    ::close(fd);
    return false;
  }
  std::error_code ec;
  return fs::is_directory(dir, ec);  // not lockable although it exists: held by a writer
}

bool RunDirectory::is_run_directory(const fs::path& dir) {
  const auto m = read_manifest(dir);
  return m && m->is_object() && m->contains("status") && (*m)["status"].is_string();
}

std::string RunDirectory::run_status(const fs::path& dir) {
  const auto m = read_manifest(dir);
  if (!m) return "missing";
  if (!m->is_object() || !m->contains("status") || !(*m)["status"].is_string()) return "incomplete";
  const std::string status = (*m)["status"].get<std::string>();
  return is_final_status(status) ? status : "incomplete";
}

RunDirectory RunDirectory::create(const fs::path& out, bool overwrite) {
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec))
      throw core::InputError("output path '" + out.string() +
                             "' exists and is not a directory; choose another output directory");
    if (is_run_directory(out)) {
      if (is_running(out)) refuse_running(out);
      if (!overwrite)
        throw core::InputError("output directory '" + out.string() +
                               "' holds a previous caplab run (status: " + run_status(out) +
                               "); pass --overwrite to replace it, or choose another output directory");
      fs::remove_all(out, ec);
      if (ec)
        throw core::Error("io: cannot remove the previous run directory '" + out.string() +
                          "': " + ec.message());
    } else if (!fs::is_empty(out, ec)) {
      throw core::InputError(
          "output directory '" + out.string() +
          "' exists and is not a caplab run directory (no valid manifest.json); it is left "
          "untouched: choose another output directory or remove this one yourself");
    }
  }
  fs::create_directories(out, ec);
  if (ec) throw core::Error("io: cannot create the run directory '" + out.string() + "': " + ec.message());

  RunDirectory run(out);
  run.manifest_ = {{"status", "running"}, {"started_utc", utc_now_iso8601()}};
  run.write_manifest();
  return run;
}

void RunDirectory::check_resumable(const fs::path& dir) {
  if (is_running(dir)) refuse_running(dir);
  const auto m = read_manifest(dir);
  if (!m || !m->is_object())
    throw core::InputError("'" + dir.string() + "' is not a caplab run directory (no readable manifest.json); "
                           "--resume takes the --out directory of an interrupted run");
  const std::string status = m->value("status", std::string("running"));
  if (status == "ok")
    throw core::InputError("the run in '" + dir.string() + "' finished ok; there is nothing to resume");
  if (status == "diverged")
    throw core::InputError("the run in '" + dir.string() +
                           "' stopped at a numerical instability (see the error in its manifest.json): resumed as is "
                           "it would diverge again; change the case as the message suggests and run it afresh");
  if (status == "input_error")
    throw core::InputError("the run in '" + dir.string() + "' was refused for its input; fix the case and run it afresh");
  std::error_code ec;
  if (!fs::is_regular_file(dir / "checkpoint.h5", ec))
    throw core::InputError("the run in '" + dir.string() +
                           "' stopped before it wrote a checkpoint (checkpoint.h5); run it afresh (outputs.checkpoint "
                           "sets how often a run writes one)");
}

RunDirectory RunDirectory::resume(const fs::path& dir) {
  check_resumable(dir);
  const auto m = read_manifest(dir);
  const std::string status = m->value("status", std::string("running"));
  RunDirectory run(dir);
  run.manifest_ = *m;
  run.manifest_["status"] = "running";
  nlohmann::json entry = {{"at_utc", utc_now_iso8601()}, {"status_before", status}};
  if (run.manifest_.contains("error")) entry["error_before"] = run.manifest_["error"];
  if (run.manifest_.contains("interrupted")) entry["interrupted"] = run.manifest_["interrupted"];
  for (const char* key : {"finished_utc", "error", "interrupted"}) run.manifest_.erase(key);
  run.manifest_["resumed"].push_back(entry);
  run.write_manifest();
  return run;
}

fs::path RunDirectory::path(const std::string& name) const {
  check_plain_name(name);
  return root_ / name;
}

fs::path RunDirectory::partial_path(const std::string& name) const {
  fs::path p = path(name);
  p += ".partial";
  return p;
}

void RunDirectory::write_json(const std::string& name, const nlohmann::json& value) const {
  write_file_atomically(path(name), value.dump(2) + "\n");
}

void RunDirectory::write_text(const std::string& name, std::string_view text) const {
  write_file_atomically(path(name), text);
}

void RunDirectory::commit_file(const std::string& name) const {
  const fs::path partial = partial_path(name);
  const fs::path final_path = path(name);
  std::error_code ec;
  if (!fs::is_regular_file(partial, ec))
    throw core::Error("io: cannot commit '" + name + "': '" + partial.string() + "' does not exist");
  fsync_path(partial, /*directory=*/false);
  if (::rename(partial.c_str(), final_path.c_str()) != 0)
    throw_errno("cannot rename into place", final_path, errno);
  fsync_path(root_, /*directory=*/true);
}

void RunDirectory::update_manifest(const nlohmann::json& fields) {
  CAPLAB_CHECK(fields.is_object(), "io: manifest fields must be a JSON object");
  CAPLAB_CHECK(!fields.contains("status"), "io: the manifest status is set by RunDirectory::finish only");
  CAPLAB_CHECK(!finished_, "io: the manifest is final once finish() was called");
  manifest_.update(fields);
  write_manifest();
}

void RunDirectory::finish(const std::string& status, const nlohmann::json& extra) {
  CAPLAB_CHECK(!finished_, "io: RunDirectory::finish called twice");
  if (!is_final_status(status))
    throw core::Error("io: unknown run status '" + status +
                      "'; expected ok | input_error | diverged | failed");
  CAPLAB_CHECK(extra.is_object() || extra.is_null(), "io: manifest fields must be a JSON object");
  CAPLAB_CHECK(extra.is_null() || !extra.contains("status"), "io: pass the status as the first argument");
  if (status == "ok") {
    for (const auto& entry : fs::directory_iterator(root_)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".partial" || ext == ".tmp")
        throw core::Error("io: run marked ok but '" + entry.path().string() +
                          "' was never committed (close the writer and call commit_file)");
    }
  }
  if (extra.is_object()) manifest_.update(extra);
  manifest_["status"] = status;
  manifest_["finished_utc"] = utc_now_iso8601();
  write_manifest();
  finished_ = true;
}

void RunDirectory::write_manifest() const {
  write_file_atomically(root_ / kManifest, manifest_.dump(2) + "\n");
}

}  // namespace caplab::io
