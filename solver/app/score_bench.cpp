#include <fmt/format.h>

#include "app/commands.hpp"
#include "score/score_run.hpp"
#include "score/scorecard.hpp"

namespace caplab::app {

int score(const ScoreArgs& args) {
  const auto s = score::score_run(args.run_dir);
  fmt::print("{}", score::format_scorecard(s));
  return score::exit_code(s, args.strict);
}

int bench(const BenchArgs&) {
  fmt::print("caplab bench: not yet built\n");
  return 4;
}

}  // namespace caplab::app
