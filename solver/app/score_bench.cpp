#include <fmt/format.h>

#include "app/commands.hpp"
#include "bench/bench.hpp"
#include "io/compare_runs.hpp"
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
  bench::BenchOptions opt = args.options;
  opt.quick = args.quick;
  opt.output_dir = args.out;
  bench::run_benchmarks(opt);  // prints its table and writes bench.json
  return 0;
}

int compare(const CompareArgs& args) {
  const auto c = io::compare_runs(args.a, args.b, args.tolerance);
  for (const auto& p : c.problems) fmt::print("  {}\n", p);
  if (c.identical()) {
    fmt::print("identical: {} values, bit for bit\n", c.values);
    return 0;
  }
  fmt::print("{}: {} of {} values differ, largest relative difference {:.3g} at {}\n",
             c.problems.empty() ? "agree within the tolerance" : "differ", c.differing, c.values, c.max_relative,
             c.worst.empty() ? "-" : c.worst);
  return c.problems.empty() ? 0 : 1;
}

}  // namespace caplab::app
