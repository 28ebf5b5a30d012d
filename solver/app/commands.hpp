// The subcommands of `caplab`; each returns the process exit code or throws a core error.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench.hpp"

namespace caplab::app {

struct RunArgs {
  std::filesystem::path case_file, out;
  std::filesystem::path resume;  ///< continue this interrupted run instead of starting one
  bool keep_checkpoint = false;
  std::string fidelity = "standard";
  std::vector<std::string> overrides;
  int threads = 0;
  bool strict = false;
};
struct CheckArgs {
  std::filesystem::path case_file;
  std::string fidelity = "standard";
  std::vector<std::string> overrides;
};
struct ScoreArgs {
  std::filesystem::path run_dir;
  bool strict = false;
};
struct ClaimsArgs {
  std::filesystem::path claims_file, json_out;
  std::vector<std::filesystem::path> run_dirs;
  std::string only;
  bool strict = false;
};
struct CompareArgs {
  std::filesystem::path a, b;
  double tolerance = 0.0;
};
struct BenchArgs {
  std::filesystem::path out;
  bool quick = false;
  bench::BenchOptions options;  // sizes, threads, lattices, ... (zero or empty: the defaults)
};

int run(const RunArgs& args, bool terminal);
int check(const CheckArgs& args);
int list(const std::filesystem::path& dir);
int score(const ScoreArgs& args);
int claims(const ClaimsArgs& args);
int bench(const BenchArgs& args);
int compare(const CompareArgs& args);

}  // namespace caplab::app
