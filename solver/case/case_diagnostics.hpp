// Error reporting for case files: every rejection goes through CaseDiagnostics::fail, so
// every message has the same four parts (file, JSON path, offending value, what is expected;
// see core::InputError) and says when the offending value came from a fidelity level or a
// `--set` override rather than from the file itself.
//
// JSON paths are JSON pointers (RFC 6901): "/physics/bodies/0/shape/center".
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace caplab::cases {

/// Collects where values came from and throws core::InputError for bad ones.
class CaseDiagnostics {
 public:
  explicit CaseDiagnostics(std::string source) : source_(std::move(source)) {}

  /// The file (or other source) being read, as it appears in messages.
  const std::string& source() const { return source_; }

  /// Records that the value at `pointer` was set by `origin` (e.g. "--set a.b=1").
  void note_origin(std::string pointer, std::string origin);

  /// Throws core::InputError for the value `value` found at `pointer`.
  [[noreturn]] void fail(const std::string& pointer, const nlohmann::json& value,
                         const std::string& expected) const;

  /// As fail(), with the offending value already written out (e.g. `unknown key "x"`).
  [[noreturn]] void fail_text(const std::string& pointer, std::string value_text,
                              const std::string& expected) const;

 private:
  std::string source_;
  std::vector<std::pair<std::string, std::string>> origins_;  // pointer, origin; later wins
};

/// The JSON pointer of member `key` of the value at `pointer` (escapes '~' and '/').
std::string child_pointer(const std::string& pointer, std::string_view key);
/// The JSON pointer of element `index` of the array at `pointer`.
std::string child_pointer(const std::string& pointer, std::size_t index);

/// A short, single-line rendering of a JSON value for messages (long values are cut; strings
/// that are not UTF-8, which only programmatic documents and `--set` text can hold, are shown
/// with U+FFFD in place of the bad bytes).
std::string describe(const nlohmann::json& value);

/// `text` made safe for a message: valid UTF-8 kept, every other byte and every control
/// character written as \xNN, cut to `max_length` bytes (with "...") when longer.
std::string printable(std::string_view text, std::size_t max_length = 200);

/// True when `text` is well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates).
bool is_utf8(std::string_view text);

/// `"a", "b", "c"`: the candidates quoted and comma-separated.
std::string quoted_list(const std::vector<std::string>& words);

/// ` (did you mean "x"?)` for the candidate closest to `word` in edit distance, or "" when
/// none is close enough to be a plausible typo.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace caplab::cases
