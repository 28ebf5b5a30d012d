// How an input of tests/fuzz/fuzz_case.cpp is read, shared with the gtest that replays
// tests/fuzz/regressions/ (tests/unit/sim/test_units.cpp): leading "--set path=value" lines
// ("--setN ..." with a digit N choosing the base case) are overrides of a catalogue case;
// anything else is the text of a case file.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace caplab::fuzz {

/// The base cases of the override mode: 2D rigid two-level, 2D capsule, 3D capsule, moving body
/// (paths relative to the source directory).
inline const std::vector<std::string>& base_case_files() {
  static const std::vector<std::string> files{
      "catalogue/ch2/cylinder_re100.json", "catalogue/ch3/circle_G0.04_Eb0.json",
      "catalogue/ch5/sphere_nh_G0.05.json", "catalogue/ch2/hovering_wing_re157.json"};
  return files;
}

struct FuzzInput {
  std::vector<std::string> overrides;  ///< empty: `text` is a case file
  std::size_t base = 0;                ///< index into base_case_files()
  std::string_view text;               ///< the case text (when there are no overrides)
};

inline FuzzInput split_fuzz_input(std::string_view input) {
  FuzzInput in;
  std::string_view rest = input;
  while (rest.substr(0, 5) == "--set") {
    std::size_t skip = 5;
    if (rest.size() > 5 && rest[5] >= '0' && rest[5] <= '9') {
      in.base = static_cast<std::size_t>(rest[5] - '0') % base_case_files().size();
      skip = 6;
    }
    if (rest.size() <= skip || rest[skip] != ' ') break;
    const std::size_t eol = rest.find('\n');
    in.overrides.emplace_back(rest.substr(skip + 1, eol == std::string_view::npos ? eol : eol - skip - 1));
    rest = eol == std::string_view::npos ? std::string_view() : rest.substr(eol + 1);
  }
  in.text = input;
  return in;
}

}  // namespace caplab::fuzz
