// libFuzzer target for the case loader (DESIGN.md section 5: every bad input is a
// core::InputError naming the file, the JSON path, the value and what is expected).
//
// Two modes, chosen by the first bytes of the input:
//   "--set path=value" lines (optionally "--setN ..." with a digit N choosing the base case):
//       every leading line of that form is an override, applied in order to a fixed valid
//       catalogue case, as `caplab check <case> --set ...` does;
//   anything else: the bytes are the text of a case file, loaded at fidelity "standard".
// Both go through cases::load_case_text, the code path of cases::load_case (the CLI's), and on
// success through what `caplab check` does next: sim::derive_units and sim::check_memory. A
// case file loaded without overrides must also reload from its resolved JSON to the same case
// (what a run's case.json promises).
//
// core::InputError is the expected outcome of bad input. Anything else — another exception, a
// crash, an AddressSanitizer or UndefinedBehaviorSanitizer report, a hang (libFuzzer -timeout)
// — is a bug: the target aborts so that libFuzzer keeps the input.
//
// Built only with -DCAPLAB_FUZZ=ON and clang (`make fuzz`); not part of the default build.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "case/load_case.hpp"
#include "core/error.hpp"
#include "fuzz_input.hpp"
#include "sim/units.hpp"

namespace {

using namespace caplab;

// The texts of the base cases of the override mode, read once.
const std::vector<std::string>& base_cases() {
  static const std::vector<std::string> texts = [] {
    std::vector<std::string> out;
    for (const auto& file : fuzz::base_case_files()) {
      std::ifstream in(std::string(CAPLAB_SOURCE_DIR) + "/" + file, std::ios::binary);
      if (!in) {
        std::fprintf(stderr, "fuzz_case: cannot read the base case %s\n", file.c_str());
        std::abort();
      }
      out.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    return out;
  }();
  return texts;
}

[[noreturn]] void bug(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_case: BUG: %s: %s\n", what, detail.c_str());
  std::abort();
}

// What `caplab check` does after loading: lattice units and the memory verdict.
void derive(const cases::CaseSpec& spec) {
  const sim::LatticeUnits units = sim::derive_units(spec);
  // Accepted cases have a usable lattice: every derived number finite.
  bool finite =
      std::isfinite(units.mach) && std::isfinite(units.node_updates) && std::isfinite(units.memory_bytes);
  for (const auto& b : units.blocks)
    finite = finite && std::isfinite(b.tau) && std::isfinite(b.nu_lu) && b.dt > 0;
  if (!finite)
    bug("derive_units accepted a lattice with a number that is not finite", units.to_json().dump());
  (void)units.to_json().dump();
  sim::check_memory(spec, units, 64.0 * (1 << 30));  // a fixed machine: the verdict is reproducible
}

void run_one(std::string_view input) {
  const fuzz::FuzzInput in = fuzz::split_fuzz_input(input);
  if (!in.overrides.empty()) {
    derive(cases::load_case_text(base_cases()[in.base], "base.json", "standard", in.overrides));
    return;
  }
  const cases::CaseSpec spec = cases::load_case_text(input, "fuzz.json", "standard");
  (void)spec.resolved.dump();  // throws on a string that is not UTF-8
  derive(spec);
  cases::CaseSpec again;
  try {
    again = cases::parse_case(spec.resolved, "case.json", "standard", {});
  } catch (const core::InputError& e) {
    bug("the resolved case does not reload", e.what());
  }
  if (again.resolved != spec.resolved)
    bug("the resolved case reloads to another case", again.resolved.dump());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  try {
    run_one(input);
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    if (what.empty()) bug("an input error without a message", "");
  } catch (const std::exception& e) {
    bug("an exception other than core::InputError", e.what());
  } catch (...) {
    bug("a non-standard exception", "");
  }
  return 0;
}
