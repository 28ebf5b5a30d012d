// Build information (version, git sha and dirty flag, compiler, flags) compiled into
// the binary; written into every run manifest so results can be traced to the code.
#pragma once

#include <string_view>

namespace caplab::core {

struct BuildInfo {
  std::string_view version;
  std::string_view git_sha;
  bool git_dirty;
  std::string_view compiler;
  std::string_view flags;
  std::string_view build_type;
};

/// The information of the binary that is running.
const BuildInfo& build_info();

}  // namespace caplab::core
