// Unit tests of the cross-run check of thesis statements (score/claims.hpp) on hand-written run
// directories (case.json, summary.json, manifest.json): which runs a claim is about, trend
// series, brackets read as regimes, modes, bounds, what is "not checked" or undecided, and the
// claims of references/capsule2d/claims.json that must be rejected.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
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
    const json case_doc = {{"id", "t/" + name},
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
};

const json kDvsG = {{"id", "t.D_vs_G"},
                    {"kind", "trend"},
                    {"parameters", {{"shape", "circle"}, {"bending_ratio", 0}}},
                    {"metric", "taylor_deformation_final"},
                    {"varying", "capillary"},
                    {"direction", "increasing"}};

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
  auto eb = [](double v) {
    Capsule c;
    c.bending_ratio = v;
    return c;
  };
  const std::vector<fs::path> runs{run("a", eb(0.0), {{"mode", "steady_tank_treading"}}),
                                   run("b", eb(0.01), {{"mode", "steady_tank_treading"}}),
                                   run("c", eb(0.02), {{"mode", "oscillating_tank_treading"}}),
                                   run("d", eb(0.06), {{"mode", "tumbling"}})};
  EXPECT_EQ(check(stages, runs)["verdict"], "consistent");  // the same regime twice is no reversal
  const json back = check(stages, {runs[0], runs[3], run("e", eb(0.4), {{"mode", "steady_tank_treading"}})});
  EXPECT_EQ(back["verdict"], "inconsistent");
  EXPECT_NE(back["message"].get<std::string>().find("regime order"), std::string::npos);

  json approaches = {{"id", "t.f"},
                     {"kind", "trend"},
                     {"metric", "tank_treading_frequency"},
                     {"varying", "bending_ratio"},
                     {"direction", "approaches"},
                     {"limit", 1.0}};
  const std::vector<fs::path> f{run("f0", eb(0.0), {{"tank_treading_frequency", 0.8}}),
                                run("f1", eb(0.1), {{"tank_treading_frequency", 1.1}}),
                                run("f2", eb(0.4), {{"tank_treading_frequency", 0.98}})};
  EXPECT_EQ(check(approaches, f)["verdict"], "consistent");
  approaches["limit"] = 0.0;
  EXPECT_EQ(check(approaches, f)["verdict"], "inconsistent");
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

}  // namespace
}  // namespace caplab::score
