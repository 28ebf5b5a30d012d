// Comparison of two run directories (`caplab compare A B`): the evidence behind "a resumed run
// is bit for bit an uninterrupted one" and "two thread counts agree to round-off".
//
// Compared: every dataset of series.h5 and snapshots.h5 (names, shapes, values) and every
// number and string of summary.json. Not compared: what legitimately differs between two
// processes (manifest.json: wall time, host, dates; case.json: the thread count).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace caplab::io {

struct RunComparison {
  std::size_t values = 0;            ///< numbers compared
  std::size_t differing = 0;         ///< of which not bitwise equal
  double max_relative = 0;           ///< largest |a - b| / max(|a|, |b|) over the values
  std::string worst;                 ///< where it occurs ("series.h5:/taylor_deformation[123]")
  std::vector<std::string> problems; ///< structural differences and values beyond the tolerance
  bool identical() const { return differing == 0 && problems.empty(); }
};

/// Compares the run directories `a` and `b`; values whose relative difference exceeds
/// `relative_tolerance` (0: any difference) are listed in problems (the first few per file).
/// Throws core::Error when a directory lacks series.h5 or summary.json.
RunComparison compare_runs(const std::filesystem::path& a, const std::filesystem::path& b,
                           double relative_tolerance = 0.0);

}  // namespace caplab::io
