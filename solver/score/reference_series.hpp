// Reference series for time-series acceptance entries: where a reference named in a case
// ("references/<dir>/<file>.csv#t_column:value_column") lies, and how it is read.
//
// CSV format: blank lines and lines starting with '#' (provenance notes) are skipped; the first
// remaining line is the header of comma-separated column names (surrounding spaces and double
// quotes removed); every further line holds one number per column. Without a "#t:value" key
// the first two columns are used.
#pragma once

#include <filesystem>
#include <string>

#include "score/comparators.hpp"

namespace caplab::score {

/// A reference string split at its last '#': file part and key part (key empty if none).
struct ReferenceLocation {
  std::string file;
  std::string key;
};

/// Splits "path#key" (see ReferenceLocation).
ReferenceLocation split_reference(const std::string& reference);

/// Resolves the file part of a reference: an absolute path is used as is; a relative one is
/// looked up under `reference_root` when that is not empty, else under each ancestor of
/// `run_dir` (nearest first, the run directory included) and then under the current directory.
/// Throws core::InputError listing where it looked when the file is found nowhere.
std::filesystem::path resolve_reference_file(const std::string& file, const std::filesystem::path& run_dir,
                                             const std::filesystem::path& reference_root);

/// Reads columns `t_column` and `value_column` of the CSV `file` (an empty name stands for
/// the first, respectively second, column). Throws core::InputError naming the file (and line) for a missing
/// file, unknown column (listing the available ones), or a field that is not a number.
Series read_reference_series(const std::filesystem::path& file, const std::string& t_column = "",
                             const std::string& value_column = "");

}  // namespace caplab::score
