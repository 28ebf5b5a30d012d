// The terminal scorecard: score.json (score_run.hpp) as a fixed-width text table, printed at
// the end of `caplab run` and by `caplab score`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace caplab::score {

/// Renders `score` as text: a header (case, fidelity), the sanity verdict with every failing
/// check, one row per acceptance entry (metric, value, reference, error, tolerance, verdict)
/// followed by the message of each failing entry, the performance line (not judged) and the
/// overall verdict. Relative errors and tolerances are shown in percent; a mode entry shows
/// its value and reference mode(s) as text ("a or b" for several allowed). Missing fields are
/// shown as "-"; never throws on a well-formed JSON object of another shape.
std::string format_scorecard(const nlohmann::json& score);

}  // namespace caplab::score
