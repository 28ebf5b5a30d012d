// Unit tests of run-directory scoring: hand-written run directories (manifest.json, case.json,
// summary.json, series.h5) scored end to end — a passing case, a failing one (strict exit 1),
// a diverged and an unfinished run, a missing and a NaN metric, a tolerance missing for the
// fidelity, mass drift, bracket, time-series and mode entries, string-valued metrics, and the
// scorecard text.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/run_directory.hpp"
#include "io/series_writer.hpp"
#include "score/score_run.hpp"
#include "score/scorecard.hpp"

namespace caplab::score {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

void write_json(const fs::path& p, const json& j) { std::ofstream(p) << j.dump(2); }

/// catalogue/ch2/cylinder_re100.json as the solver copies it into case.json, reduced to its
/// first acceptance entry (the mean drag) so the tests below can name entries by position.
json cylinder_case() {
  json doc = read_json(fs::path(CAPLAB_SOURCE_DIR) / "catalogue/ch2/cylinder_re100.json");
  doc["fidelity_applied"] = "quick";
  doc["acceptance"] = json::array({doc["acceptance"][0]});
  return doc;
}

/// "/acceptance/<i>/reference_mode": where a malformed mode entry's message must point.
std::string fmt_index(std::size_t i) { return "/acceptance/" + std::to_string(i) + "/reference_mode"; }

json metric(double v, const std::string& unit = "1") {
  return {{"value", v}, {"unit", unit}, {"definition", "test"}};
}

class ScoreRun : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / ("caplab_test_score_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    manifest_ = {{"status", "ok"},      {"fidelity", "quick"}, {"case_id", "ch2/cylinder_re100"},
                 {"wall_time_s", 12.5}, {"mlups", 42.0},       {"steps", 3750}};
    case_ = cylinder_case();
    summary_ = {{"case_id", "ch2/cylinder_re100"},
                {"fidelity", "quick"},
                {"metrics",
                 {{"drag_coefficient_mean", metric(1.46)},
                  {"lift_coefficient_rms", metric(0.23)},
                  {"strouhal_number", metric(0.165)}}},
                {"sanity", {{"finite", true}, {"mass_drift", 1e-9}}}};
  }
  void TearDown() override { fs::remove_all(dir_); }

  json score() {
    write_json(dir_ / "manifest.json", manifest_);
    write_json(dir_ / "case.json", case_);
    write_json(dir_ / "summary.json", summary_);
    return score_run(dir_);
  }

  static const json& check(const json& s, const std::string& name) {
    for (const auto& c : s["sanity"]["checks"])
      if (c["name"] == name) return c;
    throw std::runtime_error("no sanity check " + name);
  }

  fs::path dir_;
  json manifest_, case_, summary_;
};

TEST_F(ScoreRun, PassingCase) {
  const json s = score();
  EXPECT_EQ(s["verdict"], "pass");
  EXPECT_EQ(s["case_id"], "ch2/cylinder_re100");
  EXPECT_EQ(s["fidelity"], "quick");
  EXPECT_EQ(s["sanity"]["verdict"], "pass");
  EXPECT_EQ(s["accuracy"]["verdict"], "pass");
  ASSERT_EQ(s["accuracy"]["entries"].size(), 1u);
  const json& e = s["accuracy"]["entries"][0];
  EXPECT_EQ(e["metric"], "drag_coefficient_mean");
  EXPECT_EQ(e["value"], 1.46);
  EXPECT_EQ(e["unit"], "1");
  EXPECT_EQ(e["reference_value"], 1.438);
  EXPECT_EQ(e["reference"], "references/cylinder/table_2_1.csv#Present:cd_re100");
  EXPECT_EQ(e["comparison"], "relative");
  EXPECT_NEAR(e["error"].get<double>(), 0.022 / 1.438, 1e-12);
  EXPECT_EQ(e["tolerance"], 0.06);  // the quick tolerance
  EXPECT_FALSE(e["justification"].get<std::string>().empty());
  EXPECT_EQ(e["verdict"], "pass");
  EXPECT_EQ(s["performance"]["wall_time_s"], 12.5);
  EXPECT_EQ(s["performance"]["mlups"], 42.0);
  EXPECT_EQ(s["performance"]["steps"], 3750);
  EXPECT_EQ(check(s, "status")["verdict"], "pass");
  EXPECT_EQ(check(s, "metrics_finite")["verdict"], "pass");
  EXPECT_EQ(check(s, "finite")["verdict"], "pass");
  EXPECT_EQ(check(s, "mass_drift")["verdict"], "pass");
  EXPECT_EQ(exit_code(s, true), 0);
  EXPECT_EQ(exit_code(s, false), 0);
  // Written atomically and identical to what was returned.
  EXPECT_EQ(read_json(dir_ / "score.json"), s);
  EXPECT_FALSE(fs::exists(dir_ / "score.json.tmp"));
}

// Performance is its own verdict: judged against the case's budget at the run's level, and
// never part of the run's verdict or of --strict (timings depend on the machine).
TEST_F(ScoreRun, PerformanceIsJudgedAgainstTheBudgetOfTheLevelAndNeverFailsTheRun) {
  EXPECT_EQ(score()["performance"]["verdict"], "not judged");  // no budget in the case
  manifest_["threads"] = 2;
  case_["performance"] = {{"wall_time_budget_s", {{"quick", 20.0}, {"standard", 5.0}}},
                          {"justification", "test budget"}};
  json s = score();
  EXPECT_EQ(s["performance"]["verdict"], "pass");
  EXPECT_EQ(s["performance"]["budget_s"], 20.0);
  EXPECT_EQ(s["performance"]["threads"], 2);
  EXPECT_EQ(s["performance"]["justification"], "test budget");

  manifest_["wall_time_s"] = 20.5;  // over the quick budget
  s = score();
  EXPECT_EQ(s["performance"]["verdict"], "fail");
  EXPECT_NE(s["performance"]["reason"].get<std::string>().find("over the budget of 20 s on 2 thread(s)"),
            std::string::npos);
  EXPECT_EQ(s["verdict"], "pass");
  EXPECT_EQ(exit_code(s, true), 0);
  EXPECT_NE(format_scorecard(s).find("performance: fail"), std::string::npos);

  manifest_["fidelity"] = "thesis";  // a level without a budget
  EXPECT_EQ(score()["performance"]["verdict"], "not judged");
  manifest_["fidelity"] = "quick";
  manifest_["status"] = "diverged";  // a run that did not finish is not judged
  s = score();
  EXPECT_EQ(s["performance"]["verdict"], "not judged");
  EXPECT_NE(s["performance"]["reason"].get<std::string>().find("did not finish"), std::string::npos);
}

TEST_F(ScoreRun, ValueOutsideToleranceFailsStrict) {
  manifest_["fidelity"] = "standard";  // 2 %: 1.46 is 1.5 % off, 1.48 is 2.9 % off
  summary_["metrics"]["drag_coefficient_mean"] = metric(1.48);
  const json s = score();
  EXPECT_EQ(s["sanity"]["verdict"], "pass");
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  EXPECT_EQ(s["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["entries"][0]["tolerance"], 0.02);
  EXPECT_NE(s["accuracy"]["entries"][0]["message"].get<std::string>().find("exceeds tolerance"),
            std::string::npos);
  EXPECT_EQ(exit_code(s, true), 1);
  EXPECT_EQ(exit_code(s, false), 0);
}

TEST_F(ScoreRun, DivergedRunFailsSanityAndIsNotScored) {
  manifest_["status"] = "diverged";
  summary_.erase("metrics");
  const json s = score();
  EXPECT_EQ(s["sanity"]["verdict"], "fail");
  EXPECT_EQ(check(s, "status")["value"], "diverged");
  EXPECT_NE(check(s, "status")["message"].get<std::string>().find("diverged"), std::string::npos);
  EXPECT_EQ(s["accuracy"]["verdict"], "none");
  EXPECT_NE(s["accuracy"]["reason"].get<std::string>().find("diverged"), std::string::npos);
  EXPECT_TRUE(s["accuracy"]["entries"].empty());
  EXPECT_EQ(s["verdict"], "fail");
  EXPECT_EQ(exit_code(s, true), 1);
}

TEST_F(ScoreRun, UnfinishedRunIsIncomplete) {
  manifest_["status"] = "running";
  fs::remove(dir_ / "summary.json");
  write_json(dir_ / "manifest.json", manifest_);
  write_json(dir_ / "case.json", case_);
  const json s = score_run(dir_);
  EXPECT_EQ(check(s, "status")["value"], "incomplete");
  EXPECT_EQ(s["sanity"]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["verdict"], "none");
}

TEST_F(ScoreRun, MissingMetricFailsWithAvailableList) {
  summary_["metrics"].erase("drag_coefficient_mean");
  const json s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["entries"][0]["verdict"], "fail");
  EXPECT_EQ(
      s["accuracy"]["entries"][0]["message"],
      "metric drag_coefficient_mean not in summary.json (available: lift_coefficient_rms, strouhal_number)");
  EXPECT_EQ(exit_code(s, true), 1);
}

TEST_F(ScoreRun, NanMetricFailsSanityAndAccuracy) {
  // nlohmann::json writes NaN as null; that is how a NaN reaches summary.json.
  summary_["metrics"]["drag_coefficient_mean"] = metric(std::nan(""));
  summary_["sanity"]["finite"] = false;
  const json s = score();
  EXPECT_EQ(s["sanity"]["verdict"], "fail");
  EXPECT_EQ(check(s, "metrics_finite")["value"], 1);
  EXPECT_NE(check(s, "metrics_finite")["message"].get<std::string>().find("drag_coefficient_mean"),
            std::string::npos);
  EXPECT_EQ(check(s, "finite")["verdict"], "fail");
  const json& e = s["accuracy"]["entries"][0];
  EXPECT_EQ(e["verdict"], "fail");
  EXPECT_TRUE(e["value"].is_null());
  EXPECT_NE(e["message"].get<std::string>().find("not finite"), std::string::npos);
  EXPECT_EQ(exit_code(s, true), 1);
}

TEST_F(ScoreRun, MassDriftAboveLimitFailsSanity) {
  summary_["sanity"]["mass_drift"] = -2e-3;
  const json s = score();
  EXPECT_EQ(check(s, "mass_drift")["verdict"], "fail");
  EXPECT_EQ(check(s, "mass_drift")["limit"], 1e-3);
  EXPECT_EQ(s["sanity"]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["verdict"], "pass");  // separate verdicts
  EXPECT_EQ(s["verdict"], "fail");
  EXPECT_EQ(exit_code(s, true), 1);
}

TEST_F(ScoreRun, ToleranceMissingForFidelityFails) {
  manifest_["fidelity"] = "thesis";
  case_["acceptance"][0]["tolerance"].erase("thesis");
  const json s = score();
  const json& e = s["accuracy"]["entries"][0];
  EXPECT_EQ(e["verdict"], "fail");
  EXPECT_EQ(e["message"],
            "no tolerance for fidelity \"thesis\" in /acceptance/0/tolerance (defined for: quick, standard)");
}

TEST_F(ScoreRun, FidelityFallsBackToCaseJson) {
  manifest_.erase("fidelity");
  const json s = score();
  EXPECT_EQ(s["fidelity"], "quick");
  EXPECT_EQ(s["accuracy"]["entries"][0]["tolerance"], 0.06);
}

TEST_F(ScoreRun, MalformedEntryAndUnknownComparisonFail) {
  case_["acceptance"].push_back({{"metric", "strouhal_number"}, {"comparison", "period"}});
  case_["acceptance"].push_back({{"metric", "lift_coefficient_rms"}, {"comparison", "absolute"}});
  const json s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["entries"][0]["verdict"], "pass");
  EXPECT_NE(s["accuracy"]["entries"][1]["message"].get<std::string>().find("/acceptance/1/comparison"),
            std::string::npos);
  EXPECT_EQ(s["accuracy"]["entries"][2]["message"],
            "/acceptance/2/reference_value is missing: expected a number");
}

TEST_F(ScoreRun, BracketEntries) {
  json entry = {{"metric", "strouhal_number"},
                {"reference", "value"},
                {"comparison", "bracket"},
                {"bracket", {0.16, 0.17}},
                {"justification", "range of published values"}};
  case_["acceptance"] = json::array({entry});
  json s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "pass");
  EXPECT_EQ(s["accuracy"]["entries"][0]["reference_value"], json({0.16, 0.17}));
  EXPECT_EQ(s["accuracy"]["entries"][0]["tolerance"], 0.0);
  summary_["metrics"]["strouhal_number"] = metric(0.18);
  s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  EXPECT_NEAR(s["accuracy"]["entries"][0]["error"].get<double>(), 0.01, 1e-12);
  entry["tolerance"] = {{"quick", 0.02}, {"standard", 0.005}, {"thesis", 0.005}};  // margin per level
  case_["acceptance"] = json::array({entry});
  EXPECT_EQ(score()["accuracy"]["verdict"], "pass");
}

TEST_F(ScoreRun, TimeSeriesEntries) {
  {
    io::SeriesWriter w(dir_ / "series.h5",
                       {{"t", "D/U", "time"}, {"lift_coefficient", "1", "F_y / (0.5 rho U^2 D)"}});
    for (int i = 0; i <= 1000; ++i) {
      const double t = 0.01 * i;
      const double row[] = {t, 0.3 * std::sin(t)};
      w.append(row);
    }
    w.close();
  }
  json reference = {{"t", json::array()}, {"value", json::array()}};
  std::ofstream csv(dir_ / "lift.csv");
  csv << "# analytic reference\nt,cl\n";
  for (int i = 0; i <= 40; ++i) {
    const double t = 2.0 + 0.3 * i;  // [2, 14]: beyond the run's end at 10
    reference["t"].push_back(t);
    reference["value"].push_back(0.3 * std::sin(t));
    csv << t << "," << 0.3 * std::sin(t) << "\n";
  }
  csv.close();
  json inline_entry = {{"metric", "lift_coefficient"},
                       {"reference", "analytic"},
                       {"comparison", "time_series"},
                       {"reference_series", reference},
                       {"window", {3.0, 20.0}},
                       {"tolerance", {{"quick", 1e-4}, {"standard", 1e-4}, {"thesis", 1e-4}}},
                       {"justification", "linear interpolation error of a sampled sine"}};
  json csv_entry = inline_entry;
  csv_entry.erase("reference_series");
  csv_entry["reference"] = "lift.csv#t:cl";  // resolved upward from the run directory
  json far_entry = inline_entry;
  far_entry["window"] = {50.0, 60.0};
  case_["acceptance"] = json::array({inline_entry, csv_entry, far_entry});
  const json s = score();
  const json& entries = s["accuracy"]["entries"];
  EXPECT_EQ(entries[0]["verdict"], "pass") << entries[0].dump();
  EXPECT_LT(entries[0]["error"].get<double>(), 1e-5);
  EXPECT_EQ(entries[0]["compared"]["from"], 3.0);
  EXPECT_EQ(entries[0]["compared"]["to"], 10.0);
  EXPECT_EQ(entries[0]["compared"]["points"], 23);  // t = 3.2, 3.5, ..., 9.8
  EXPECT_EQ(entries[0]["unit"], "1");
  EXPECT_EQ(entries[1]["verdict"], "pass") << entries[1].dump();
  EXPECT_EQ(entries[2]["verdict"], "fail");
  EXPECT_NE(entries[2]["message"].get<std::string>().find("do not overlap"), std::string::npos);
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");

  // A shifted reference must fail.
  for (auto& v : inline_entry["reference_series"]["value"]) v = v.get<double>() + 0.01;
  case_["acceptance"] = json::array({inline_entry});
  const json shifted = score();
  EXPECT_EQ(shifted["accuracy"]["verdict"], "fail");
  EXPECT_NEAR(shifted["accuracy"]["entries"][0]["error"].get<double>(), 0.01, 1e-5);
}

TEST_F(ScoreRun, TimeSeriesWithoutSeriesFileFails) {
  case_["acceptance"] = json::array({{{"metric", "lift_coefficient"},
                                      {"reference", "analytic"},
                                      {"comparison", "time_series"},
                                      {"reference_series", {{"t", {0, 1}}, {"value", {0, 1}}}},
                                      {"tolerance", {{"quick", 0.1}}},
                                      {"justification", "x"}}});
  const json s = score();
  EXPECT_NE(s["accuracy"]["entries"][0]["message"].get<std::string>().find("series.h5 is missing"),
            std::string::npos);
}

/// A mode acceptance entry (capsule flow regime against a thesis statement).
json mode_entry(const json& reference_mode) {
  json entry = {{"metric", "mode"},
                {"reference", "references/capsule2d/claims.json#ch3.ellipse.G0.04.Eb0.06"},
                {"comparison", "mode"},
                {"justification", "thesis section 3.2.2: tumbling at E_b = 0.06"}};
  if (!reference_mode.is_null()) entry["reference_mode"] = reference_mode;
  return entry;
}

json mode_metric(const json& value) {
  return {{"value", value}, {"unit", "1"}, {"definition", "flow regime over t >= average_from"}};
}

TEST_F(ScoreRun, ModeEntryPassesOnTheStatedRegime) {
  summary_["metrics"]["mode"] = mode_metric("tumbling");
  summary_["metrics"]["tumbling_period"] = metric(7.9, "1/k");
  const json alternatives = {"steady_tank_treading", "tumbling"};
  // The same metric twice is fine for the scorer (the loader rejects it in a catalogue case).
  case_["acceptance"] = json::array({mode_entry("tumbling"), mode_entry(alternatives)});
  const json s = score();
  EXPECT_EQ(s["sanity"]["verdict"], "pass");  // a string metric is sane
  EXPECT_EQ(check(s, "metrics_finite")["value"], 0);
  EXPECT_EQ(s["accuracy"]["verdict"], "pass") << s.dump(2);
  const json& e = s["accuracy"]["entries"][0];
  EXPECT_EQ(e["value"], "tumbling");
  EXPECT_EQ(e["reference_value"], "tumbling");
  EXPECT_EQ(e["comparison"], "mode");
  EXPECT_EQ(e["error"], 0.0);
  EXPECT_TRUE(e["tolerance"].is_null());
  EXPECT_EQ(e["reference"], "references/capsule2d/claims.json#ch3.ellipse.G0.04.Eb0.06");
  EXPECT_EQ(e["verdict"], "pass");
  EXPECT_FALSE(e.contains("message"));
  EXPECT_EQ(s["accuracy"]["entries"][1]["reference_value"], alternatives);  // as written
  EXPECT_EQ(s["accuracy"]["entries"][1]["verdict"], "pass");
  EXPECT_EQ(exit_code(s, true), 0);
}

TEST_F(ScoreRun, ModeEntryMustFail) {
  // the wrong regime
  summary_["metrics"]["mode"] = mode_metric("steady_tank_treading");
  case_["acceptance"] =
      json::array({mode_entry("tumbling"), mode_entry({"tumbling", "oscillating_tank_treading"})});
  json s = score();
  EXPECT_EQ(s["sanity"]["verdict"], "pass");
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  const json& wrong = s["accuracy"]["entries"][0];
  EXPECT_EQ(wrong["verdict"], "fail");
  EXPECT_EQ(wrong["error"], 1.0);
  EXPECT_EQ(wrong["value"], "steady_tank_treading");
  EXPECT_EQ(wrong["message"], "mode \"steady_tank_treading\" is not the reference \"tumbling\"");
  EXPECT_EQ(s["accuracy"]["entries"][1]["verdict"], "fail");
  EXPECT_EQ(exit_code(s, true), 1);

  // the mode metric missing
  summary_["metrics"].erase("mode");
  case_["acceptance"] = json::array({mode_entry("tumbling")});
  s = score();
  EXPECT_EQ(s["accuracy"]["entries"][0]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["entries"][0]["message"],
            "metric mode not in summary.json (available: drag_coefficient_mean, lift_coefficient_rms, "
            "strouhal_number)");

  // a number where a mode is expected
  summary_["metrics"]["mode"] = metric(2.0);
  s = score();
  EXPECT_EQ(s["accuracy"]["entries"][0]["verdict"], "fail");
  EXPECT_EQ(s["accuracy"]["entries"][0]["value"], 2.0);
  EXPECT_NE(s["accuracy"]["entries"][0]["message"].get<std::string>().find(
                "metric mode is the number 2.0: a mode comparison needs a string"),
            std::string::npos)
      << s["accuracy"]["entries"][0]["message"];
  EXPECT_EQ(s["sanity"]["verdict"], "pass");  // a finite number is sane; it is the entry that fails
}

TEST_F(ScoreRun, MalformedReferenceModeFails) {
  summary_["metrics"]["mode"] = mode_metric("tumbling");
  const std::vector<json> malformed = {
      nullptr, 3, json::array(), json::array({"tumbling", 3}), "", json::object({{"mode", "tumbling"}})};
  case_["acceptance"] = json::array();
  for (const auto& m : malformed) case_["acceptance"].push_back(mode_entry(m));
  const json s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "fail");
  const auto& entries = s["accuracy"]["entries"];
  ASSERT_EQ(entries.size(), malformed.size());
  EXPECT_EQ(
      entries[0]["message"],
      "/acceptance/0/reference_mode is missing: expected a mode name such as \"tumbling\" or a non-empty "
      "array of mode names");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(entries[i]["verdict"], "fail");
    EXPECT_NE(entries[i]["message"].get<std::string>().find(fmt_index(i)), std::string::npos)
        << entries[i]["message"];
  }
  EXPECT_NE(entries[1]["message"].get<std::string>().find("reference_mode is 3: expected"),
            std::string::npos);
}

TEST_F(ScoreRun, StringMetricsAreSaneButNotNumbers) {
  summary_["metrics"]["mode"] = mode_metric("oscillating_tank_treading");
  summary_["metrics"]["regime_note"] = "tumbling";  // a bare string is a metric too
  json s = score();
  EXPECT_EQ(check(s, "metrics_finite")["verdict"], "pass");
  EXPECT_EQ(s["sanity"]["verdict"], "pass");
  // an empty string, a boolean and a NaN number are not
  summary_["metrics"]["mode"] = mode_metric("");
  summary_["metrics"]["flag"] = metric(0);
  summary_["metrics"]["flag"]["value"] = true;
  summary_["metrics"]["strouhal_number"] = metric(std::nan(""));
  s = score();
  EXPECT_EQ(check(s, "metrics_finite")["value"], 3);
  for (const char* name : {"mode", "flag", "strouhal_number"})
    EXPECT_NE(check(s, "metrics_finite")["message"].get<std::string>().find(name), std::string::npos) << name;
  EXPECT_EQ(s["sanity"]["verdict"], "fail");
  // a numeric comparison of a string metric says to use "mode"
  summary_["metrics"]["drag_coefficient_mean"] = mode_metric("tumbling");
  s = score();
  const json& e = s["accuracy"]["entries"][0];
  EXPECT_EQ(e["verdict"], "fail");
  EXPECT_EQ(e["value"], "tumbling");
  EXPECT_NE(e["message"].get<std::string>().find("a relative comparison needs a number"), std::string::npos)
      << e["message"];
  EXPECT_NE(e["message"].get<std::string>().find("\"mode\""), std::string::npos);
}

TEST_F(ScoreRun, ScorecardShowsModesAsText) {
  summary_["metrics"]["mode"] = mode_metric("steady_tank_treading");
  case_["acceptance"] = json::array({mode_entry({"tumbling", "oscillating_tank_treading"})});
  const std::string card = format_scorecard(score());
  for (const char* part : {"mode", "steady_tank_treading", "tumbling or oscillating_tank_treading", "fail",
                           "is not the reference"})
    EXPECT_NE(card.find(part), std::string::npos) << part << " missing in\n" << card;
}

TEST_F(ScoreRun, CaseWithoutAcceptanceIsNotJudged) {
  case_["acceptance"] = json::array();
  const json s = score();
  EXPECT_EQ(s["accuracy"]["verdict"], "none");
  EXPECT_EQ(s["verdict"], "pass");
  EXPECT_EQ(exit_code(s, true), 0);
}

TEST_F(ScoreRun, NotARunDirectoryIsAnInputError) {
  EXPECT_THROW(score_run(dir_), core::InputError);
  EXPECT_THROW(score_run(dir_ / "absent"), core::InputError);
}

TEST(ScoreExitCode, MalformedScoreFailsStrict) {
  EXPECT_EQ(exit_code(json::object(), true), 1);
  EXPECT_EQ(exit_code(json::object(), false), 0);
  EXPECT_EQ(exit_code({{"sanity", {{"verdict", "pass"}}}, {"accuracy", {{"verdict", "none"}}}}, true), 0);
  EXPECT_EQ(exit_code({{"sanity", {{"verdict", "fail"}}}, {"accuracy", {{"verdict", "none"}}}}, true), 1);
}

TEST_F(ScoreRun, ScorecardShowsEveryColumn) {
  manifest_["fidelity"] = "standard";
  summary_["metrics"]["drag_coefficient_mean"] = metric(1.48);
  const std::string card = format_scorecard(score());
  for (const char* part : {"ch2/cylinder_re100", "standard", "metric", "value", "reference", "error",
                           "tolerance", "verdict", "drag_coefficient_mean", "1.48", "1.438", "2.92%", "2%",
                           "fail", "exceeds tolerance", "42 MLUPS", "3750 steps"})
    EXPECT_NE(card.find(part), std::string::npos) << part << " missing in\n" << card;
  EXPECT_NO_THROW(format_scorecard(json::object()));
  EXPECT_NO_THROW(format_scorecard(json::array()));
}

}  // namespace
}  // namespace caplab::score
