// Unit tests of the cross-run check of thesis statements (score/claims.hpp) on hand-written run
// directories (case.json, summary.json, manifest.json): which runs a claim is about, trend
// series, brackets read as regimes, modes, bounds, what is "not checked" or undecided, and the
// claims of references/capsule2d/claims.json that must be rejected. The claims with a "check"
// (score/motion_claims.hpp, references/moving/claims.json) on runs with made-up series.h5, each
// check shown to fail where it must, and on the finished quick runs of tests/python/moving_runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/series_writer.hpp"
#include "score/claims.hpp"

namespace caplab::score {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

/// A capsule as the solver copies it into case.json.
struct Capsule {
  std::string shape = "circle";
  double capillary = 0.04, bending_ratio = 0.0, reynolds = 0.05;
  std::string curvature = "initial";
  json extra_shape = json::object(), extra_membrane = json::object();  // e.g. aspect_ratio; law, area_dilation
};

class ScoreClaims : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / ("caplab_test_claims_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes results/<fidelity>/<name>/ with the given capsule and summary metrics.
  fs::path run(const std::string& name, const Capsule& c, const json& metrics,
               const std::string& status = "ok", const std::string& fidelity = "quick",
               const json& acceptance = json::array()) {
    const fs::path d = dir_ / fidelity / name;
    fs::create_directories(d);
    json body = {{"name", "capsule"},
                 {"shape", {{"type", c.shape}, {"diameter", 2.0}}},
                 {"membrane",
                  {{"capillary", c.capillary}, {"bending_ratio", c.bending_ratio}, {"reference_curvature", c.curvature}}}};
    body["shape"].update(c.extra_shape);
    body["membrane"].update(c.extra_membrane);
    const json case_doc = {{"id", chapter_.empty() ? name : chapter_ + "/" + name},
                           {"physics", {{"reynolds", c.reynolds}, {"bodies", {body}}}},
                           {"numerics", {{"grid", {{"fine_spacing", 0.05}}}}},
                           {"acceptance", acceptance}};
    json summary = {{"metrics", json::object()}};
    for (const auto& [k, v] : metrics.items()) summary["metrics"][k] = {{"value", v}, {"unit", "1"}};
    std::ofstream(d / "case.json") << case_doc.dump();
    std::ofstream(d / "summary.json") << summary.dump();
    std::ofstream(d / "manifest.json") << json{{"status", status}, {"fidelity", fidelity}}.dump();
    return d;
  }

  static json claims(std::vector<json> list) { return {{"claims", list}}; }

  /// The result of `claim` against `runs`.
  static json check(const json& claim, const std::vector<fs::path>& runs) {
    return evaluate_claims(claims({claim}), runs)["claims"][0];
  }

  static json run_row(const json& c, const std::string& name) {
    for (const auto& r : c["runs"])
      if (r["run"] == "t/" + name) return r;
    return nullptr;
  }

  fs::path dir_;
  std::string chapter_ = "t";  // the first part of the case ids run() writes
};

const json kDvsG = {{"id", "t.D_vs_G"},
                    {"kind", "trend"},
                    {"parameters", {{"shape", "circle"}, {"bending_ratio", 0}}},
                    {"metric", "taylor_deformation_final"},
                    {"varying", "capillary"},
                    {"direction", "increasing"}};

Capsule circle_Eb(double bending_ratio) {
  Capsule c;
  c.bending_ratio = bending_ratio;
  return c;
}

Capsule circle_G(double g, double re = 0.05) {
  Capsule c;
  c.capillary = g;
  c.reynolds = re;
  return c;
}

TEST_F(ScoreClaims, TrendOverASweepIsConsistent) {
  const std::vector<fs::path> runs{run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}}),
                                   run("G3", circle_G(0.05), {{"taylor_deformation_final", 0.3}}),
                                   run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}})};
  const json c = check(kDvsG, runs);
  EXPECT_EQ(c["verdict"], "consistent") << c.dump(2);
  ASSERT_EQ(c["runs"].size(), 3u);
  EXPECT_EQ(run_row(c, "G3")["parameter"], 0.05);
  EXPECT_EQ(run_row(c, "G3")["value"], 0.3);
  EXPECT_EQ(run_row(c, "G3")["verdict"], "pass");
  EXPECT_TRUE(run_row(c, "G1")["verdict"].is_null());  // the first of its series
  ASSERT_EQ(c["series"].size(), 1u);
  EXPECT_EQ(c["series"][0]["fixed"]["reynolds"], 0.05);
  EXPECT_FALSE(c["series"][0]["fixed"].contains("capillary"));
}

TEST_F(ScoreClaims, TrendReversalIsInconsistentAndFailsStrict) {
  const std::vector<fs::path> runs{run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}}),
                                   run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.3}}),
                                   run("G3", circle_G(0.05), {{"taylor_deformation_final", 0.2}})};
  const json result = evaluate_claims(claims({kDvsG}), runs);
  const json& c = result["claims"][0];
  EXPECT_EQ(c["verdict"], "inconsistent");
  const std::string message = c["message"];
  EXPECT_NE(message.find("t/G2 (quick)"), std::string::npos) << message;
  EXPECT_NE(message.find("t/G3 (quick)"), std::string::npos) << message;
  EXPECT_EQ(run_row(c, "G3")["verdict"], "fail");
  EXPECT_EQ(claims_exit_code(result, true), 1);
  EXPECT_EQ(claims_exit_code(result, false), 0);
  EXPECT_NE(format_claims(result).find("t.D_vs_G"), std::string::npos);
}

TEST_F(ScoreClaims, TrendSeriesKeepOtherParametersFidelityAndGridApart) {
  // One run per Reynolds number, and a second fidelity: no series has two values of G.
  const std::vector<fs::path> runs{
      run("a", circle_G(0.0125, 0.05), {{"taylor_deformation_final", 0.3}}),
      run("b", circle_G(0.025, 1.0), {{"taylor_deformation_final", 0.2}}),
      run("c", circle_G(0.05, 0.05), {{"taylor_deformation_final", 0.1}}, "ok", "standard")};
  const json result = evaluate_claims(claims({kDvsG}), runs);
  EXPECT_EQ(result["claims"][0]["verdict"], "not enough runs");
  EXPECT_EQ(result["claims"][0]["series"].size(), 3u);
  EXPECT_EQ(claims_exit_code(result, true), 0);  // undecided is not a failure
}

TEST_F(ScoreClaims, TrendSeriesKeepChaptersApart) {
  // Chapter u's grid-study member matches the capsule of chapter t's sweep but stops early (a
  // smaller D): it is no point of that sweep.
  std::vector<fs::path> runs{run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}}),
                             run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}})};
  chapter_ = "u";
  runs.push_back(run("G2_short", circle_G(0.025), {{"taylor_deformation_final", 0.05}}));
  const json c = check(kDvsG, runs);
  EXPECT_EQ(c["verdict"], "consistent") << c.dump(2);
  ASSERT_EQ(c["series"].size(), 2u);
  EXPECT_EQ(c["series"][0]["fixed"]["chapter"], "t");
  EXPECT_EQ(c["series"][1]["verdict"], "not enough runs");
  // A user's own cases, ids without a folder, form one sweep.
  chapter_ = "";
  const fs::path a = run("mine_G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}});
  const fs::path b = run("mine_G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}});
  EXPECT_EQ(check(kDvsG, {a, b})["verdict"], "consistent");
}

TEST_F(ScoreClaims, SwingAmplitudeTrendLeavesTumblingRunsOut) {
  // Thesis 3.2.3: the swing grows with E_b until the capsule tumbles. A tumbling run's half range
  // grows with its window (4.7 rad here against 2.1 at a larger E_b): no amplitude.
  const json claim = {{"id", "t.amplitude_vs_Eb"},
                      {"kind", "trend"},
                      {"parameters", {{"shape", "circle"}}},
                      {"metric", "inclination_amplitude"},
                      {"varying", "bending_ratio"},
                      {"direction", "increasing"}};
  const std::vector<fs::path> runs{
      run("Eb0.005", circle_Eb(0.005), {{"inclination_amplitude", 0.05}, {"mode", "oscillating_tank_treading"}}),
      run("Eb0.015", circle_Eb(0.015), {{"inclination_amplitude", 0.2}, {"mode", "oscillating_tank_treading"}}),
      run("Eb0.02", circle_Eb(0.02), {{"inclination_amplitude", 4.7}, {"mode", "tumbling"}}),
      run("Eb0.2", circle_Eb(0.2), {{"inclination_amplitude", 2.1}, {"mode", "tumbling"}})};
  const json c = check(claim, runs);
  EXPECT_EQ(c["verdict"], "consistent") << c.dump(2);
  EXPECT_EQ(run_row(c, "Eb0.015")["verdict"], "pass");
  EXPECT_EQ(run_row(c, "Eb0.2")["note"], "tumbling: no swing amplitude");
  EXPECT_TRUE(run_row(c, "Eb0.2")["value"].is_null());
}

TEST_F(ScoreClaims, UnfinishedRunsAreListedNotJudged) {
  const std::vector<fs::path> runs{
      run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.3}}, "diverged"),
      run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}}, "running")};
  const json c = check(kDvsG, runs);
  EXPECT_EQ(c["verdict"], "no run");
  EXPECT_EQ(run_row(c, "G1")["status"], "diverged");
  EXPECT_EQ(run_row(c, "G2")["status"], "incomplete");
  EXPECT_TRUE(run_row(c, "G1")["verdict"].is_null());
  EXPECT_EQ(check(kDvsG, {})["verdict"], "no run");
  // A run that names no case (no case.json, no case_id): its id from the directory, as
  // scripts/reproduce names it ("/" as "__").
  const fs::path bare = run("G3", circle_G(0.05), {{"taylor_deformation_final", 0.1}});
  const fs::path renamed = bare.parent_path() / "ch2__sub__G3";
  fs::rename(bare, renamed);
  fs::remove(renamed / "case.json");
  const json ids = evaluate_claims(claims({kDvsG}), {renamed});
  EXPECT_EQ(ids["runs"][0]["run"], "ch2/sub/G3") << ids.dump(2);
}

TEST_F(ScoreClaims, WhichRunsAClaimIsAbout) {
  Capsule ellipse = circle_G(0.025);
  ellipse.shape = "ellipse";
  Capsule bending = circle_G(0.05);
  bending.bending_ratio = 0.1;
  const json acceptance = {{{"metric", "mode"},
                            {"comparison", "mode"},
                            {"reference", "references/capsule2d/claims.json#t.D_vs_G"}}};
  const std::vector<fs::path> runs{run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}}),
                                   run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}}),
                                   run("ellipse", ellipse, {{"taylor_deformation_final", 0.0}}),
                                   run("bending", bending, {{"taylor_deformation_final", 0.0}})};
  const json c = check(kDvsG, runs);
  EXPECT_EQ(c["verdict"], "consistent");
  EXPECT_EQ(c["runs"].size(), 2u);  // neither the ellipse nor the bending-stiff circle
  // A run that names the claim in its acceptance but is not about it makes the claim inconsistent.
  const json named =
      check(kDvsG, {runs[0], runs[1],
                    run("named", bending, {{"taylor_deformation_final", 0.5}}, "ok", "quick", acceptance)});
  EXPECT_EQ(named["verdict"], "inconsistent");
  ASSERT_EQ(named["problems"].size(), 1u);
  EXPECT_NE(named["problems"][0].get<std::string>().find("E_b = 0.1"), std::string::npos) << named.dump(2);
  EXPECT_EQ(run_row(named, "named")["scored"], "not scored");
}

TEST_F(ScoreClaims, CaseDefaultsAndParameterMatching) {
  Capsule ellipse;
  ellipse.shape = "ellipse";  // no aspect_ratio: the case default 2
  Capsule flat = circle_G(0.04);
  flat.curvature = "flat";  // ignored: no bending stiffness
  const json claim = {
      {"id", "t.mode"},
      {"kind", "mode"},
      {"parameters",
       {{"aspect_ratio", 2}, {"capillary", {{"from", 0.0}, {"to", 0.05}}}, {"reynolds", {1, 0.05}}}},
      {"mode", "steady_tank_treading"}};
  const json c = check(claim, {run("e", ellipse, {{"mode", "steady_tank_treading"}}),
                               run("c", circle_G(0.04), {{"mode", "steady_tank_treading"}}),
                               run("f", flat, {{"mode", "steady_tank_treading"}})});
  EXPECT_EQ(c["verdict"], "consistent");
  ASSERT_EQ(c["runs"].size(), 1u);  // aspect_ratio applies to ellipses only
  EXPECT_EQ(c["runs"][0]["run"], "t/e");
  json curvature = {{"id", "t.k"},
                    {"kind", "mode"},
                    {"parameters", {{"reference_curvature", "initial"}}},
                    {"mode", "steady_tank_treading"}};
  EXPECT_EQ(check(curvature, {run("f", flat, {{"mode", "steady_tank_treading"}})})["runs"].size(), 1u);
}

TEST_F(ScoreClaims, ModeClaimMustFail) {
  const json claim = {{"id", "t.mode"},
                      {"kind", "mode"},
                      {"parameters", {{"shape", "circle"}}},
                      {"modes", {"steady_tank_treading", "oscillating_tank_treading"}}};
  const fs::path ok = run("ok", circle_G(0.04), {{"mode", "oscillating_tank_treading"}});
  EXPECT_EQ(check(claim, {ok})["verdict"], "consistent");
  const json wrong = check(claim, {ok, run("tumbles", circle_G(0.05), {{"mode", "tumbling"}})});
  EXPECT_EQ(wrong["verdict"], "inconsistent");
  EXPECT_EQ(run_row(wrong, "tumbles")["verdict"], "fail");
  const json none = check(claim, {run("none", circle_G(0.05), {{"taylor_deformation_final", 0.1}})});
  EXPECT_EQ(none["verdict"], "inconsistent");
  EXPECT_EQ(none["runs"][0]["note"], "no mode in summary.json");
}

TEST_F(ScoreClaims, BracketOfTheThesisIsReadAsRegimes) {
  const json doc = evaluate_claims(fs::path(CAPLAB_SOURCE_DIR) / "references/capsule2d/claims.json", {},
                                   ClaimsOptions{"ch3.ellipse.G0.04.transition"});
  ASSERT_EQ(doc["claims"].size(), 1u);
  EXPECT_EQ(doc["claims"][0]["verdict"], "no run");

  std::ifstream in(fs::path(CAPLAB_SOURCE_DIR) / "references/capsule2d/claims.json");
  const json all = json::parse(in);
  json bracket;
  for (const auto& c : all["claims"])
    if (c["id"] == "ch3.ellipse.G0.04.transition") bracket = c;  // E_b in [0.04, 0.06], osc. TT below
  auto ellipse = [](double eb) {
    Capsule c;
    c.shape = "ellipse";
    c.bending_ratio = eb;
    return c;
  };
  const fs::path steady = run("Eb0", ellipse(0.0), {{"mode", "steady_tank_treading"}});
  const fs::path osc = run("Eb0.04", ellipse(0.04), {{"mode", "oscillating_tank_treading"}});
  const fs::path inside = run("Eb0.05", ellipse(0.05), {{"mode", "steady_tank_treading"}});
  const fs::path tumbles = run("Eb0.06", ellipse(0.06), {{"mode", "tumbling"}});
  const json c = check(bracket, {steady, osc, inside, tumbles});
  EXPECT_EQ(c["verdict"], "consistent") << c.dump(2);  // steady tank treading is tank treading too
  EXPECT_TRUE(run_row(c, "Eb0.05")["verdict"].is_null());
  EXPECT_EQ(run_row(c, "Eb0.05")["note"], "inside the bracket");
  EXPECT_EQ(run_row(c, "Eb0.06")["parameter"], 0.06);

  const json one_side = check(bracket, {steady, osc, inside});
  EXPECT_EQ(one_side["verdict"], "not enough runs");
  const fs::path wrong = run("Eb0.4", ellipse(0.4), {{"mode", "oscillating_tank_treading"}});
  const json w = check(bracket, {steady, osc, tumbles, wrong});
  EXPECT_EQ(w["verdict"], "inconsistent");
  EXPECT_NE(w["message"].get<std::string>().find("t/Eb0.4 (quick) at 0.4 (above the bracket)"),
            std::string::npos)
      << w["message"];
}

TEST_F(ScoreClaims, RegimeSequenceAndApproachingTrends) {
  json stages = {{"id", "t.stages"},
                 {"kind", "trend"},
                 {"metric", "mode"},
                 {"varying", "bending_ratio"},
                 {"direction", "sequence"}};
  const std::vector<fs::path> runs{run("a", circle_Eb(0.0), {{"mode", "steady_tank_treading"}}),
                                   run("b", circle_Eb(0.01), {{"mode", "steady_tank_treading"}}),
                                   run("c", circle_Eb(0.02), {{"mode", "oscillating_tank_treading"}}),
                                   run("d", circle_Eb(0.06), {{"mode", "tumbling"}})};
  EXPECT_EQ(check(stages, runs)["verdict"], "consistent");  // the same regime twice is no reversal
  const json back = check(stages, {runs[0], runs[3], run("e", circle_Eb(0.4), {{"mode", "steady_tank_treading"}})});
  EXPECT_EQ(back["verdict"], "inconsistent");
  EXPECT_NE(back["message"].get<std::string>().find("regime order"), std::string::npos);

  json approaches = {{"id", "t.f"},
                     {"kind", "trend"},
                     {"metric", "tank_treading_frequency"},
                     {"varying", "bending_ratio"},
                     {"direction", "approaches"},
                     {"limit", 1.0}};
  const std::vector<fs::path> f{run("f0", circle_Eb(0.0), {{"tank_treading_frequency", 0.8}}),
                                run("f1", circle_Eb(0.1), {{"tank_treading_frequency", 1.1}}),
                                run("f2", circle_Eb(0.4), {{"tank_treading_frequency", 0.98}})};
  EXPECT_EQ(check(approaches, f)["verdict"], "consistent");
  approaches["limit"] = 0.0;
  EXPECT_EQ(check(approaches, f)["verdict"], "inconsistent");
}

/// Writes series.h5 with t and the continuous inclination theta(t) into run directory `d`.
void write_inclination(const fs::path& d, const std::vector<double>& t, double (*theta)(double)) {
  io::SeriesWriter w(d / "series.h5", {{"t", "1/k", "time"}, {"inclination", "rad", "inclination"}});
  for (double x : t) {
    const double row[2] = {x, theta(x)};
    w.append(row);
  }
  w.close();
}

// "Initial tumbling, then swinging" (thesis 6.3.2 at G = 0.015) judged on each run's series: the
// last stage starts where the inclination stops spanning pi; it must have turned through pi
// before and swing (two whole swings) after. Each way of missing the sequence fails.
TEST_F(ScoreClaims, TimeSequenceOfTumblingThenSwinging) {
  const json claim = {{"id", "t.sequence"},
                      {"kind", "trend"},
                      {"parameters", {{"shape", "circle"}}},
                      {"metric", nullptr},
                      {"varying", "time"},
                      {"direction", "initial tumbling, then swinging"},
                      {"sequence", {"tumbling", "oscillating_tank_treading"}}};
  std::vector<double> t;
  for (int i = 0; i <= 1600; ++i) t.push_back(0.05 * i);  // k t 0-80
  constexpr double rate = -std::numbers::pi / 9.8;          // half a turn every 9.8/k
  const fs::path both = run("both", Capsule{}, {{"mode", "tumbling"}});
  write_inclination(both, t, [](double x) {
    return x < 53 ? rate * x : rate * 53 + 0.4 * std::sin(2 * std::numbers::pi * (x - 53) / 8.8);
  });
  const fs::path tumbles = run("tumbles", Capsule{}, {{"mode", "tumbling"}});
  write_inclination(tumbles, t, [](double x) { return rate * x; });
  const fs::path swings = run("swings", Capsule{}, {{"mode", "oscillating_tank_treading"}});
  write_inclination(swings, t, [](double x) { return 0.4 * std::sin(2 * std::numbers::pi * x / 8.8); });
  const fs::path stops = run("stops", Capsule{}, {{"mode", "tumbling"}});
  write_inclination(stops, t, [](double x) { return rate * std::min(x, 53.0); });

  const json c = check(claim, {both});
  EXPECT_EQ(c["verdict"], "consistent") << c.dump(2);
  const json row = run_row(c, "both");
  EXPECT_EQ(row["verdict"], "pass");
  // The last stage starts where the turn ends (t = 53, where the swing turns the inclination
  // back up), with the swing's half range of 0.4 rad.
  EXPECT_NEAR(row["parameter"].get<double>(), 53.0, 0.06);
  EXPECT_NE(row["value"].get<std::string>().find("then oscillating_tank_treading"), std::string::npos);
  EXPECT_NE(row["value"].get<std::string>().find("half range 22.9 degrees"), std::string::npos) << row.dump();

  for (const auto& [name, note] : std::vector<std::pair<std::string, std::string>>{
           {"tumbles", "is tumbling"}, {"swings", "no initial tumbling"}, {"stops", "0 reversals"}}) {
    const json r = check(claim, {both, dir_ / "quick" / name});
    EXPECT_EQ(r["verdict"], "inconsistent") << name;
    EXPECT_EQ(run_row(r, name)["verdict"], "fail") << name;
    EXPECT_NE(run_row(r, name)["note"].get<std::string>().find(note), std::string::npos) << r.dump(2);
  }

  json other = claim;
  other["sequence"] = {"oscillating_tank_treading", "tumbling"};
  EXPECT_EQ(check(other, {both})["verdict"], "not checked");
  json plain = claim;  // without "sequence" a time trend stays unjudged
  plain.erase("sequence");
  EXPECT_EQ(check(plain, {both})["verdict"], "not checked");
}

TEST_F(ScoreClaims, BoundClaims) {
  json bound = {{"id", "t.D"},   {"kind", "bound"}, {"metric", "taylor_deformation_final"},
                {"lower", 0.75}, {"strict", true},  {"quantifier", "some"}};
  const std::vector<fs::path> runs{run("low", circle_G(0.01), {{"taylor_deformation_final", 0.3}}),
                                   run("high", circle_G(0.4), {{"taylor_deformation_final", 0.8}})};
  const json some = check(bound, runs);
  EXPECT_EQ(some["verdict"], "consistent");  // one run suffices; the other is shown, not judged
  EXPECT_TRUE(run_row(some, "low")["verdict"].is_null());
  EXPECT_EQ(check(bound, {runs[0]})["verdict"], "inconsistent");
  bound["quantifier"] = "every";
  EXPECT_EQ(check(bound, runs)["verdict"], "inconsistent");
  bound["lower"] = 0.8;  // strict: 0.8 is not above 0.8
  bound.erase("quantifier");
  EXPECT_EQ(run_row(check(bound, runs), "high")["verdict"], "fail");
}

TEST_F(ScoreClaims, WhatIsNotChecked) {
  const std::vector<fs::path> runs{run("G1", circle_G(0.0125), {{"taylor_deformation_final", 0.1}}),
                                   run("G2", circle_G(0.025), {{"taylor_deformation_final", 0.2}})};
  json no_metric = kDvsG;
  no_metric["metric"] = nullptr;
  json several = kDvsG;
  several["varying"] = {"capillary", "reynolds"};
  json oscillation = kDvsG;
  oscillation["direction"] = "damped oscillation";
  const json value = {
      {"id", "t.v"}, {"kind", "value"}, {"metric", "taylor_deformation_final"}, {"value", 0.2}};
  const json no_number = {
      {"id", "t.b"}, {"kind", "bound"}, {"metric", "taylor_deformation_final"}, {"upper", nullptr}};
  for (const json& claim : {no_metric, several, oscillation, value, no_number})
    EXPECT_EQ(check(claim, runs)["verdict"], "not checked") << claim.dump();
  EXPECT_EQ(run_row(check(value, runs), "G1")["value"], 0.1);  // listed, not judged
  EXPECT_TRUE(run_row(check(value, runs), "G1")["verdict"].is_null());
}

TEST_F(ScoreClaims, RunsAndClaimsFileProblems) {
  const fs::path cylinder = dir_ / "quick" / "cylinder";
  fs::create_directories(cylinder);
  std::ofstream(cylinder / "case.json") << R"({"id": "t/cylinder", "physics": {"bodies": [{"shape": {}}]}})";
  std::ofstream(cylinder / "manifest.json") << R"({"status": "ok"})";
  const json result = evaluate_claims(claims({kDvsG, kDvsG, json{{"kind", "mode"}}}),
                                      {cylinder, run("G1", circle_G(0.01), {})});
  EXPECT_EQ(result["runs"].size(), 1u);
  ASSERT_EQ(result["ignored"].size(), 1u);
  EXPECT_EQ(result["ignored"][0]["directory"], cylinder.string());
  EXPECT_EQ(result["claims"].size(), 1u);
  EXPECT_EQ(result["problems"].size(), 2u);  // a duplicate id and a claim without id
  EXPECT_EQ(result["runs"][0]["parameters"]["reference_curvature"], "initial");
  EXPECT_EQ(result["runs"][0]["parameters"]["aspect_ratio"], nullptr);

  EXPECT_THROW(evaluate_claims(json{{"claim", json::array()}}, {}), core::InputError);
  EXPECT_THROW(evaluate_claims(claims({}), {dir_ / "absent"}), core::InputError);
  EXPECT_THROW(evaluate_claims(dir_ / "absent.json", {}), core::InputError);
  EXPECT_EQ(claims_exit_code(json::object(), true), 1);
}

// 3D capsules (chapter 6): the law and the oblate aspect ratio select runs and split trend series;
// the area dilation selects runs but does not split a sweep over G (the biconcave cells take C from G).
TEST_F(ScoreClaims, LawAspectRatioAndAreaDilationOf3DCapsules) {
  auto oblate = [](double g, double r, const std::string& law, double C = 0) {
    Capsule c;
    c.shape = "oblate_spheroid";
    c.capillary = g;
    c.reynolds = 0.025;
    c.extra_shape = {{"aspect_ratio", r}};
    c.extra_membrane = {{"law", law}};
    if (C > 0) c.extra_membrane["area_dilation"] = C;
    return c;
  };
  const std::vector<fs::path> runs{run("zt_a", oblate(0.05, 1.5, "zero_thickness"), {{"inclination_amplitude", 0.2}}),
                                   run("zt_b", oblate(0.2, 1.5, "zero_thickness"), {{"inclination_amplitude", 0.1}}),
                                   run("zt_c", oblate(0.2, 2.0, "zero_thickness"), {{"inclination_amplitude", 0.5}}),
                                   run("sk_a", oblate(0.05, 1.5, "skalak", 10), {{"inclination_amplitude", 0.1}}),
                                   run("sk_b", oblate(0.2, 1.5, "skalak", 100), {{"inclination_amplitude", 0.05}})};
  const json amplitude = {{"id", "t.amplitude"},          {"kind", "trend"},
                          {"parameters", {{"shape", "oblate_spheroid"}, {"law", "zero_thickness"}}},
                          {"metric", "inclination_amplitude"},
                          {"varying", "capillary"},        {"direction", "decreasing"}};
  const json zt = check(amplitude, runs);
  EXPECT_EQ(zt["verdict"], "consistent") << zt.dump(2);
  EXPECT_EQ(zt["runs"].size(), 3u);    // the law selects; the SK runs are not about it
  EXPECT_EQ(zt["series"].size(), 2u);  // the aspect ratio splits: 1.5 (two runs) and 2 (one)
  json sk = amplitude;
  sk["parameters"]["law"] = "skalak";
  const json sk_any_C = check(sk, runs);
  EXPECT_EQ(sk_any_C["verdict"], "consistent") << sk_any_C.dump(2);  // one series although C differs
  EXPECT_EQ(sk_any_C["series"].size(), 1u);
  sk["parameters"]["area_dilation"] = 100;
  EXPECT_EQ(check(sk, runs)["runs"].size(), 1u);
}

// ---- claims with a "check": moving bodies and the multi-block grid (motion_claims.hpp) ----------

const fs::path kMovingRuns = fs::path(CAPLAB_SOURCE_DIR) / "tests/python/moving_runs/quick";
const fs::path kMovingClaims = fs::path(CAPLAB_SOURCE_DIR) / "references/moving/claims.json";

/// A case.json of the fixture runs (the real case files as the solver copied them).
json fixture_case(const std::string& dir_name) {
  std::ifstream in(kMovingRuns / dir_name / "case.json");
  return json::parse(in);
}

using Columns = std::vector<std::pair<std::string, std::vector<double>>>;

/// t = 0.05, 0.10, ..., 32 as the two-cylinder runs (np.arange(0.05, 32 + 1e-9, 0.05)).
std::vector<double> cylinder_times() {
  std::vector<double> t;
  for (int i = 0; i < 640; ++i) t.push_back(0.05 + i * 0.05);
  return t;
}

/// C_d 1.8, `approach` over 0 < dx <= 3 (22.5 <= t < 24), `separation` over -3 <= dx < 0.
std::vector<double> bump_drag(double approach, double separation) {
  std::vector<double> drag;
  for (double t : cylinder_times())
    drag.push_back(t >= 22.5 && t < 24 ? approach : t > 24 && t <= 25.5 ? separation : 1.8);
  return drag;
}

/// The columns of the two-cylinder case: the prescribed positions of the catalogue (x0 = 8,
/// abreast at t = 24) and the given upper drag.
Columns cylinders(const std::vector<double>& drag, double lift_offset = 0.0, double lower_shift = 0.0) {
  const double pi = std::acos(-1.0);
  Columns c{{"t", {}},
            {"upper.x", {}},
            {"lower.x", {}},
            {"upper.drag_coefficient", drag},
            {"upper.lift_coefficient", {}},
            {"lower.drag_coefficient", {}},
            {"lower.lift_coefficient", {}}};
  const auto t = cylinder_times();
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double s = 4 / pi * std::sin(pi * t[i] / 4), lift = 0.5 * std::sin(t[i]) + lift_offset;
    c[0].second.push_back(t[i]);
    c[1].second.push_back(t[i] < 16 ? 8 + 16 - s : 8 + 32 - t[i]);
    c[2].second.push_back((t[i] < 16 ? 8 + s : 8 + t[i] - 16) + lower_shift);
    c[4].second.push_back(lift);
    c[5].second.push_back(-drag[i]);
    c[6].second.push_back(-lift);
  }
  return c;
}

class MotionClaims : public ScoreClaims {
 protected:
  /// Writes a finished run of `case_doc` with `columns` in series.h5 and the cost in the manifest.
  fs::path moving_run(const std::string& name, const json& case_doc, const Columns& columns,
                      double node_updates = 1e9, const std::string& fidelity = "quick",
                      const std::string& status = "ok") {
    const fs::path d = dir_ / fidelity / name;
    fs::create_directories(d);
    std::ofstream(d / "case.json") << case_doc.dump();
    std::ofstream(d / "manifest.json")
        << json{{"status", status},     {"case_id", case_doc["id"]},
                {"fidelity", fidelity}, {"wall_time_s", 100.0},
                {"threads", 2},         {"lattice", {{"node_updates", node_updates}}}}
               .dump();
    std::vector<io::SeriesColumn> names;
    for (const auto& [n, v] : columns) names.push_back({n, "1", n});
    io::SeriesWriter w(d / "series.h5", names);
    for (std::size_t i = 0; i < columns[0].second.size(); ++i) {
      std::vector<double> row;
      for (const auto& [n, v] : columns) row.push_back(v[i]);
      w.append(row);
    }
    w.close();
    return d;
  }

  /// The result of the claim `id` of references/moving/claims.json (provenance.json beside it).
  static json moving(const std::string& id, const std::vector<fs::path>& runs) {
    const json result = evaluate_claims(kMovingClaims, runs, ClaimsOptions{id});
    EXPECT_EQ(result["claims"].size(), 1u) << id;
    return result["claims"][0];
  }

  /// The claim `id` of references/moving/claims.json, to be altered by a test.
  static json moving_claim(const std::string& id) {
    std::ifstream in(kMovingClaims);
    const json doc = json::parse(in);
    for (const auto& c : doc["claims"])
      if (c["id"] == id) return c;
    return nullptr;
  }
};

bool contains(const json& text, const std::string& part) {
  return text.is_string() && text.get<std::string>().find(part) != std::string::npos;
}

TEST_F(MotionClaims, ProximityMeansJudgeTheDragAroundTheEncounter) {
  const std::string id = "ch2.two_cylinders.drag_trend";
  const json two = fixture_case("ch2__two_cylinders_re40");
  const json good = moving(id, {moving_run("good", two, cylinders(bump_drag(2.2, 1.2)))});
  EXPECT_EQ(good["verdict"], "consistent") << good.dump(2);
  EXPECT_EQ(good["check"], "proximity_means");
  ASSERT_EQ(good["runs"].size(), 1u);
  const json& row = good["runs"][0];
  EXPECT_EQ(row["verdict"], "pass");
  EXPECT_EQ(row["value"],
            "baseline: 1.8, approaching in close proximity: 2.2, moving away in close proximity: 1.2");
  ASSERT_EQ(row["details"].size(), 4u);
  EXPECT_TRUE(contains(row["details"][0], "baseline (6 ≤ dx ≤ 10, approaching): mean 1.8 over 41 samples"))
      << row["details"][0];
  EXPECT_TRUE(
      contains(row["details"][1], "(0 < dx ≤ 3, approaching): mean 2.2 over 30 samples, t = 22.5–23.95"))
      << row["details"][1];
  EXPECT_TRUE(contains(row["details"][3],
                       "closest approach (dx = 0) at t = 24; the drag opposing the motion is C_d"));

  // No rise, no fall, and a mean equal to the baseline is not above it.
  for (const auto& [approach, separation] : {std::pair(1.5, 1.2), {2.2, 2.0}, {1.8, 1.2}}) {
    const json bad = moving(id, {moving_run("bad", two, cylinders(bump_drag(approach, separation)))});
    EXPECT_EQ(bad["verdict"], "inconsistent") << approach << " " << separation;
    EXPECT_EQ(bad["runs"][0]["verdict"], "fail");
    EXPECT_TRUE(contains(bad["message"], "is not")) << bad["message"];
  }
  // The bodies never pass each other: nothing to judge.
  const json stuck = moving(id, {moving_run("stuck", two, cylinders(bump_drag(2.2, 1.2), 0.0, -40.0))});
  EXPECT_EQ(stuck["verdict"], "not checked");
  EXPECT_TRUE(contains(stuck["runs"][0]["note"], "never changes sign"));
  // An unfinished run is listed, not judged.
  const json diverged =
      moving(id, {moving_run("diverged", two, cylinders(bump_drag(2.2, 1.2)), 1e9, "quick", "diverged")});
  EXPECT_EQ(diverged["verdict"], "no run");
  EXPECT_EQ(diverged["runs"][0]["note"], "run diverged");
}

TEST_F(MotionClaims, ProximityWindowOnTheWrongSideFailsAndTheLowerBodyOpposesWithMinusCd) {
  const json two = fixture_case("ch2__two_cylinders_re40");
  const fs::path run_dir = moving_run("run", two, cylinders(bump_drag(2.2, 1.2)));
  // The drag does rise on the approach: a statement that it falls there must be rejected.
  json wrong = moving_claim("ch2.two_cylinders.drag_trend");
  wrong["check"]["windows"][0]["expect"] = "below";
  const json w = check(wrong, {run_dir});
  EXPECT_EQ(w["verdict"], "inconsistent") << w.dump(2);
  EXPECT_TRUE(
      contains(w["message"], "approaching in close proximity: mean 2.2 is not below the baseline mean 1.8"))
      << w["message"];

  // The lower cylinder moves along +x: its C_d (−1.8 at rest, the made-up series) opposes the
  // motion with the sign flipped, and dx = x_lower − x_upper runs from −16 to 16.
  json lower = moving_claim("ch2.two_cylinders.drag_trend");
  lower["check"]["body"] = "lower";
  lower["check"]["other"] = "upper";
  lower["check"]["baseline"] = {{"dx", "[-10, -6]"}, {"phase", "approaching"}};
  lower["check"]["windows"] = {
      {{"name", "a"}, {"dx", "[-3, 0)"}, {"phase", "approaching"}, {"expect", "above"}},
      {{"name", "s"}, {"dx", "(0, 3]"}, {"phase", "separating"}, {"expect", "below"}}};
  const json l = check(lower, {run_dir});
  EXPECT_EQ(l["verdict"], "consistent") << l.dump(2);
  EXPECT_EQ(l["runs"][0]["value"], "baseline: 1.8, a: 2.2, s: 1.2");
  EXPECT_TRUE(contains(l["runs"][0]["details"][3], "is −C_d (the lower body moves along +x)"));

  // A window that is no interval, a phase that is no phase: the claim is wrong, not the run.
  json malformed = moving_claim("ch2.two_cylinders.drag_trend");
  malformed["check"]["windows"][0]["dx"] = "(3, 0]";
  EXPECT_EQ(check(malformed, {run_dir})["verdict"], "not checked");
  EXPECT_TRUE(contains(check(malformed, {run_dir})["message"], "empty interval"));
  malformed["check"]["windows"][0]["dx"] = "(0, 3]";
  malformed["check"]["baseline"]["phase"] = "before";
  EXPECT_TRUE(contains(check(malformed, {run_dir})["message"], "phase must be approaching or separating"));
  json unknown = moving_claim("ch2.two_cylinders.drag_trend");
  unknown["check"]["type"] = "closeness";
  EXPECT_EQ(check(unknown, {run_dir})["verdict"], "not checked");
}

TEST_F(MotionClaims, TwinDifferenceAgainstTheUniformGrid) {
  const std::string id = "ch2.two_cylinders.uniform_twin";
  const json two = fixture_case("ch2__two_cylinders_re40"),
             uni = fixture_case("ch2__two_cylinders_re40_uniform");
  const Columns cols = cylinders(bump_drag(2.2, 1.2));
  const fs::path a = moving_run("a", two, cols);
  const json same = moving(id, {a, moving_run("b", uni, cols)});
  EXPECT_EQ(same["verdict"], "consistent") << same.dump(2);
  ASSERT_EQ(same["runs"].size(), 1u);  // the claim is about the two-block run; the twin is its partner
  EXPECT_EQ(same["runs"][0]["value"], "upper C_d 0.00 %; upper C_l 0.00 % (at most 2.00 %)");
  EXPECT_EQ(same["runs"][0]["against"], "ch2/two_cylinders_re40_uniform (quick)");
  EXPECT_TRUE(
      contains(same["runs"][0]["details"][0], "against ch2/two_cylinders_re40_uniform (quick), t ≥ 0.5: "))
      << same["runs"][0]["details"];

  // A lift 0.05 off over the twin's peak 0.55 is 9.09 %: above the 2 %.
  const json off = moving(id, {a, moving_run("c", uni, cylinders(bump_drag(2.2, 1.2), 0.05))});
  EXPECT_EQ(off["verdict"], "inconsistent");
  EXPECT_EQ(off["runs"][0]["value"], "upper C_d 0.00 %; upper C_l 9.09 % (at most 2.00 %)");
  EXPECT_TRUE(contains(off["message"], "upper C_l 9.09 % is above 2.00 %"));

  // The impulsive start before t = 0.5 (provenance.json consistency.twin_difference.from) is
  // left out of the difference and of the peak; a non-finite sample after it is never a pass.
  Columns spiky = cols, nan = cols;
  for (std::size_t i = 0; i < spiky[0].second.size(); ++i)
    if (spiky[0].second[i] < 0.5) spiky[3].second[i] = 50.0;
  nan[4].second[300] = std::nan("");
  EXPECT_EQ(moving(id, {a, moving_run("spiky", uni, spiky)})["verdict"], "consistent");
  const json not_a_number = moving(id, {a, moving_run("nan", uni, nan)});
  EXPECT_EQ(not_a_number["verdict"], "inconsistent");
  EXPECT_EQ(not_a_number["runs"][0]["note"], "upper C_l is not a number");

  // Not a twin: other physics, another fine spacing, another fidelity. Without one: not enough runs.
  json other = uni, coarser = uni;
  other["physics"]["reynolds"] = 41;
  coarser["numerics"]["grid"]["fine_spacing"] = 0.05;
  const json none = moving(id, {a, moving_run("d", other, cols), moving_run("e", coarser, cols),
                                moving_run("f", uni, cols, 3e9, "standard")});
  EXPECT_EQ(none["verdict"], "not enough runs") << none.dump(2);
  EXPECT_EQ(none["runs"][0]["note"], "no uniform-grid twin run at fidelity quick");
  EXPECT_EQ(moving(id, {})["verdict"], "no run");

  // A twin that differs in other numerics too: named in the details.
  json faster = uni;
  faster["numerics"]["lattice_velocity"] = 0.1;
  const json differs = moving(id, {a, moving_run("g", faster, cols)});
  EXPECT_EQ(differs["runs"][0]["details"][1], "the runs also differ in numerics.lattice_velocity");
}

TEST_F(MotionClaims, RefinementOfTheStatementsGridAtOneFidelity) {
  const std::string id = "ch2.hovering_wing.refinement";
  json thesis_grid = fixture_case("ch2__hovering_wing_re157");  // the quick run: 1/32
  thesis_grid["numerics"]["grid"]["fine_spacing"] = 1.0 / 64;   // the grid of the statement
  json finer = thesis_grid, quick = thesis_grid;
  finer["id"] = "ch2/hovering_wing_re157_grid128";
  finer["numerics"]["grid"]["fine_spacing"] = 1.0 / 128;
  quick["numerics"]["grid"]["fine_spacing"] = 1.0 / 32;
  auto series = [](double drag_scale) {
    Columns c{{"t", {}}, {"drag_coefficient", {}}, {"lift_coefficient", {}}};
    for (double t = 0.02; t < 31.42; t += 0.02) {
      c[0].second.push_back(t);
      c[1].second.push_back(drag_scale * std::cos(0.8 * t));
      c[2].second.push_back(1 + std::sin(0.8 * t));
    }
    return c;
  };
  const fs::path a = moving_run("a", thesis_grid, series(1.0), 1e9, "standard");
  const json one = moving(id, {a});
  EXPECT_EQ(one["verdict"], "not enough runs");
  EXPECT_TRUE(contains(one["runs"][0]["note"],
                       "no finer grid at fidelity standard to refine against (Δx_f = 0.015625 "
                       "(ch2/hovering_wing_re157)); the statement is about Δx_f = 0.015625"))
      << one["runs"][0];

  // The finer member of the study at the same fidelity is the self-reference.
  const json same = moving(id, {a, moving_run("b", finer, series(1.0), 8e9, "standard")});
  EXPECT_EQ(same["verdict"], "consistent") << same.dump(2);
  EXPECT_EQ(same["runs"][0]["details"][0],
            "Δx_f = 0.015625 against the finer Δx_f = 0.0078125 at fidelity standard (self-reference)");
  EXPECT_EQ(same["runs"][0]["against"], "ch2/hovering_wing_re157_grid128 (standard)");
  const json off = moving(id, {a, moving_run("c", finer, series(1.2), 8e9, "standard")});
  EXPECT_EQ(off["verdict"], "inconsistent");
  EXPECT_TRUE(contains(off["runs"][0]["value"], "; C_l 0.00 % (at most 2.00 %)")) << off["runs"][0]["value"];

  // Levels are not mixed: a finer run at another fidelity has other numerics.
  EXPECT_EQ(moving(id, {a, moving_run("d", finer, series(1.0), 8e9, "quick")})["verdict"], "not enough runs");

  // A grid coarser than the statement's is listed, not judged, even with a finer run beside it.
  const json coarse = moving(id, {moving_run("e", quick, series(1.2), 1e8, "quick"),
                                  moving_run("f", thesis_grid, series(1.0), 1e9, "quick")});
  EXPECT_EQ(coarse["verdict"], "not enough runs") << coarse.dump(2);
  EXPECT_TRUE(
      contains(coarse["runs"][0]["note"], "Δx_f = 0.03125 is coarser than the grid the statement is about"))
      << coarse["runs"][0];
  EXPECT_TRUE(coarse["runs"][0]["verdict"].is_null());
  EXPECT_EQ(coarse["runs"][0]["note"].get<std::string>().rfind("Δx_f", 0), 0u);  // the message adds "not judged"

  // The statement's grid must be a positive number.
  json bad = moving_claim(id);
  bad["check"]["fine_spacing"] = "1/64";
  EXPECT_EQ(check(bad, {a})["verdict"], "not checked");
}

TEST_F(MotionClaims, FineFractionAndTheSavingOfTheTwoBlockGrid) {
  const std::string id = "ch2.two_cylinders.fine_fraction";
  const json two = fixture_case("ch2__two_cylinders_re40"),
             uni = fixture_case("ch2__two_cylinders_re40_uniform");
  const Columns cols = cylinders(bump_drag(2.2, 1.2));
  const fs::path a = moving_run("a", two, cols, 1e9), b = moving_run("b", uni, cols, 3e9);
  const json ok = moving(id, {a, b});
  EXPECT_EQ(ok["verdict"], "consistent") << ok.dump(2);
  ASSERT_EQ(ok["runs"].size(), 3u);
  EXPECT_EQ(ok["runs"][0]["part"], "fine fraction");
  EXPECT_EQ(ok["runs"][0]["value"], "24.06 % as set, – as built (thesis 24.1 %, within 0.05 %)");
  EXPECT_EQ(ok["runs"][1]["value"],
            "node updates twin/two-block 3 (saving 66.67 %); wall time 1 (saving 0.00 %, not judged: noisy)");
  EXPECT_EQ(ok["runs"][2]["part"], "saving less than ch2/cylinder_re100");
  EXPECT_TRUE(ok["runs"][2]["verdict"].is_null());
  EXPECT_TRUE(contains(ok["message"], "not judged: ch2/two_cylinders_re40 (quick): saving less than"));

  // The uniform grid cheaper than the two-block one: no saving.
  EXPECT_EQ(moving(id, {a, moving_run("c", uni, cols, 0.5e9)})["verdict"], "inconsistent");
  // A fine block of another size than the thesis's 24.1 %.
  json bigger = two;
  bigger["numerics"]["grid"]["fine_region"]["max"] = {28, 11.6};
  const json big = moving(id, {moving_run("d", bigger, cols), b});
  EXPECT_EQ(big["verdict"], "inconsistent");
  EXPECT_EQ(big["runs"][0]["note"], "25.16 % is not within 0.05 % of 24.1 %");
  // No twin: the fraction alone decides, the saving waits for runs.
  EXPECT_EQ(moving(id, {a})["verdict"], "consistent");

  // The saving must be smaller than that of the fixed cylinder of section 2.2.1 (a fixed body:
  // not a moving run, read all the same because the check names its case).
  std::ifstream c1(fs::path(CAPLAB_SOURCE_DIR) / "catalogue/ch2/cylinder_re100.json");
  std::ifstream c2(fs::path(CAPLAB_SOURCE_DIR) / "catalogue/ch2/cylinder_re100_uniform.json");
  const json cyl = json::parse(c1);
  json cyl_uni = json::parse(c2);
  cyl_uni["numerics"]["grid"]["fine_spacing"] = cyl["numerics"]["grid"]["fine_spacing"];
  const Columns cyl_cols{{"t", {0, 1, 2}}, {"drag_coefficient", {1, 1, 1}}};
  for (const auto& [ratio, verdict] : {std::pair(10.0, "consistent"), {2.0, "inconsistent"}}) {
    const fs::path p = moving_run("cyl" + std::to_string(int(ratio)), cyl, cyl_cols, 1e9);
    const fs::path q = moving_run("cyl_uniform" + std::to_string(int(ratio)), cyl_uni, cyl_cols, ratio * 1e9);
    const json result = evaluate_claims(kMovingClaims, {a, b, p, q}, ClaimsOptions{id});
    EXPECT_EQ(result["claims"][0]["verdict"], verdict) << ratio;
    EXPECT_EQ(result["claims"][0]["runs"][2]["verdict"], ratio > 3 ? "pass" : "fail");
    EXPECT_EQ(result["moving_runs"].size(), 2u);  // the fixed cylinders are not moving runs
    EXPECT_EQ(result["ignored"].size(), 2u);
  }
}

// The finished quick runs of the moving-body cases: the verdicts and numbers that the report
// showed when it checked these statements itself (tests/python/test_moving_report.py).
TEST_F(MotionClaims, QuickRunsOfTheCatalogue) {
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(kMovingRuns)) runs.push_back(e.path());
  std::sort(runs.begin(), runs.end());
  const json result = evaluate_claims(kMovingClaims, runs);
  EXPECT_EQ(result["moving_runs"].size(), 5u);
  std::map<std::string, json> by_id;
  for (const auto& c : result["claims"]) by_id[c["id"]] = c;
  const json& trend = by_id["ch2.two_cylinders.drag_trend"];
  EXPECT_EQ(trend["verdict"], "inconsistent");
  ASSERT_EQ(trend["runs"].size(), 2u);
  EXPECT_EQ(trend["runs"][0]["value"],
            "baseline: 1.86, approaching in close proximity: 1.585, moving away in close proximity: 1.558");
  EXPECT_TRUE(contains(trend["runs"][0]["details"][1], "max 2.287 at dx = 1.8, min 0.8544 at dx = 0.202"));
  EXPECT_EQ(by_id["ch2.two_cylinders.uniform_twin"]["verdict"], "inconsistent");
  EXPECT_EQ(by_id["ch2.two_cylinders.uniform_twin"]["runs"][0]["value"],
            "upper C_d 1.78 %; upper C_l 3.50 % (at most 2.00 %)");
  EXPECT_EQ(by_id["ch2.two_cylinders.fine_fraction"]["verdict"], "consistent");
  EXPECT_EQ(by_id["ch2.two_cylinders.fine_fraction"]["runs"][0]["value"],
            "24.06 % as set, 23.79 % as built (thesis 24.1 %, within 0.05 %)");
  EXPECT_TRUE(contains(by_id["ch2.two_cylinders.fine_fraction"]["runs"][1]["value"],
                       "node updates twin/two-block 2.75 (saving 63.60 %)"));
  EXPECT_EQ(by_id["ch2.hovering_wing.twin"]["verdict"], "consistent");
  EXPECT_EQ(by_id["ch2.hovering_wing.twin"]["runs"][0]["value"], "C_d 0.44 %; C_l 0.36 % (at most 2.00 %)");
  EXPECT_EQ(by_id["ch2.hovering_wing.refinement"]["verdict"], "not enough runs");
}
}  // namespace
}  // namespace caplab::score
