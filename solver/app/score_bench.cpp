#include <fmt/format.h>

#include "app/commands.hpp"
#include "bench/bench.hpp"
#include "io/run_directory.hpp"
#include "score/claims.hpp"
#include "score/score_run.hpp"
#include "score/scorecard.hpp"

namespace caplab::app {

int score(const ScoreArgs& args) {
  const auto s = score::score_run(args.run_dir);
  fmt::print("{}", score::format_scorecard(s));
  return score::exit_code(s, args.strict);
}

int claims(const ClaimsArgs& args) {
  const auto result =
      score::evaluate_claims(args.claims_file, args.run_dirs, score::ClaimsOptions{args.only});
  fmt::print("{}", score::format_claims(result));
  if (!args.json_out.empty()) io::write_file_atomically(args.json_out, result.dump(2) + "\n");
  return score::claims_exit_code(result, args.strict);
}

int bench(const BenchArgs& args) {
  bench::BenchOptions opt;
  opt.quick = args.quick;
  opt.output_dir = args.out;
  bench::run_benchmarks(opt);  // prints its table and writes bench.json
  return 0;
}

}  // namespace caplab::app
