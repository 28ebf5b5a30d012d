// Error types of caplab and the two check tiers.
//
// The library never exits: it throws one of these, and only `main` maps them to
// the exit codes of DESIGN.md section 6 (2 input, 3 numerical instability, 4 other).
//   CAPLAB_CHECK(cond, msg)  always on, throws caplab::core::Error.
//   CAPLAB_ASSERT(cond)      debug builds only (internal invariants in hot code).
#pragma once

#include <stdexcept>
#include <string>

namespace caplab::core {

/// Any failure that is neither bad input nor a numerical instability (exit code 4).
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input: names the file, the JSON path, the offending value and what is expected
/// (exit code 2). `what()` is the full, user-facing message.
class InputError : public Error {
 public:
  InputError(std::string file, std::string json_path, std::string value, std::string expected);
  /// For input problems that are not tied to one JSON value (e.g. a missing file).
  explicit InputError(const std::string& message);

  const std::string& file() const { return file_; }
  const std::string& json_path() const { return json_path_; }
  const std::string& value() const { return value_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string file_, json_path_, value_, expected_;
};

/// A run that became numerically unstable (exit code 3): the step, the place, the
/// quantity that failed the guard and the likely cause with its fix.
class NumericalError : public Error {
 public:
  NumericalError(long step, std::string where, std::string quantity, std::string cause);

  long step() const { return step_; }
  const std::string& where() const { return where_; }
  const std::string& quantity() const { return quantity_; }
  const std::string& cause() const { return cause_; }

 private:
  long step_;
  std::string where_, quantity_, cause_;
};

[[noreturn]] void check_failed(const char* condition, const char* file, int line, const std::string& message);

}  // namespace caplab::core

#define CAPLAB_CHECK(cond, msg)                                                   \
  do {                                                                            \
    if (!(cond)) ::caplab::core::check_failed(#cond, __FILE__, __LINE__, (msg)); \
  } while (0)

#ifdef NDEBUG
#define CAPLAB_ASSERT(cond) ((void)0)
#else
#define CAPLAB_ASSERT(cond) CAPLAB_CHECK(cond, "internal invariant violated")
#endif
