// resume_case's first check on a checkpoint: its layout format (sim/run_case.hpp).
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "sim/run_case.hpp"

namespace caplab::sim {
namespace {

// The message of the InputError check_checkpoint_format throws for `meta`, or "" if none.
std::string refusal(const nlohmann::json& meta) {
  try {
    check_checkpoint_format(meta, "runs/x/checkpoint.h5");
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckpointFormat, TheCurrentFormatIsAccepted) {
  EXPECT_EQ(refusal({{"format", checkpoint_format}, {"git_sha", "abc1234"}}), "");
}

TEST(CheckpointFormat, AnOlderOrUnversionedLayoutIsRefusedNamingTheBuildAndTheFix) {
  // Format 1 checkpoints (and those without the entry) were written while the layout changed
  // under one number: refused up front rather than by a missing or resized entry midway.
  for (const auto& meta : {nlohmann::json{{"format", 1}, {"git_sha", "abc1234"}}, nlohmann::json{{"git_sha", "abc1234"}}}) {
    const std::string m = refusal(meta);
    EXPECT_NE(m.find("runs/x/checkpoint.h5"), std::string::npos) << m;
    EXPECT_NE(m.find("layout format 1"), std::string::npos) << m;
    EXPECT_NE(m.find("git abc1234"), std::string::npos) << m;
    EXPECT_NE(m.find("run the case afresh"), std::string::npos) << m;
  }
}

TEST(CheckpointFormat, ANewerLayoutIsRefused) {
  const std::string m = refusal({{"format", checkpoint_format + 1}, {"git_sha", "fff0000"}});
  EXPECT_NE(m.find("newer"), std::string::npos) << m;
  EXPECT_NE(m.find("git fff0000"), std::string::npos) << m;
}

}  // namespace
}  // namespace caplab::sim
