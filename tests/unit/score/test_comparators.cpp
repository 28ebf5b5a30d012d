// Unit tests of the score comparators (relative, absolute, bracket, time_series, mode, and the
// sweep comparators trend and mode_bracket) and of the reference CSV reader. Every comparator is shown to
// accept what it should and to reject what it must (DESIGN.md section 7: every check must be able to fail).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "score/comparators.hpp"
#include "score/reference_series.hpp"

namespace caplab::score {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

Series sample(double t0, double t1, double dt, double (*f)(double)) {
  Series s;
  const auto n = static_cast<int>(std::llround((t1 - t0) / dt));
  for (int i = 0; i <= n; ++i) {
    const double t = t0 + i * dt;
    s.t.push_back(t);
    s.y.push_back(f(t));
  }
  return s;
}

double sine(double t) { return std::sin(t); }
double shifted_sine(double t) { return std::sin(t + 0.5); }
double offset_sine(double t) { return std::sin(t) + 0.1; }
double line(double t) { return 2.0 * t + 1.0; }

TEST(ScoreRelative, PassesWithinTolerance) {
  const Comparison c = compare_relative(1.45, 1.438, 0.02);
  EXPECT_TRUE(c.pass);
  EXPECT_NEAR(c.error, 0.012 / 1.438, 1e-15);
  EXPECT_TRUE(c.message.empty());
  EXPECT_TRUE(compare_relative(-1.5, -1.0, 0.5).pass);  // error exactly the tolerance
}

TEST(ScoreRelative, MustFail) {
  const Comparison c = compare_relative(1.60, 1.438, 0.02);
  EXPECT_FALSE(c.pass);
  EXPECT_NEAR(c.error, 0.162 / 1.438, 1e-15);
  EXPECT_NE(c.message.find("exceeds tolerance"), std::string::npos);
  EXPECT_FALSE(compare_relative(1.0, 0.0, 0.1).pass);  // undefined for a zero reference
  EXPECT_NE(compare_relative(1.0, 0.0, 0.1).message.find("absolute"), std::string::npos);
  EXPECT_FALSE(compare_relative(kNaN, 1.0, 0.1).pass);
  EXPECT_FALSE(compare_relative(kInf, 1.0, 0.1).pass);
  EXPECT_FALSE(compare_relative(1.0, kNaN, 0.1).pass);
  EXPECT_FALSE(compare_relative(1.0, 1.0, -0.1).pass);
  EXPECT_FALSE(compare_relative(1.0, 1.0, kNaN).pass);
}

TEST(ScoreAbsolute, PassesWithinTolerance) {
  const Comparison c = compare_absolute(0.165, 0.164, 0.002);
  EXPECT_TRUE(c.pass);
  EXPECT_NEAR(c.error, 0.001, 1e-15);
  EXPECT_TRUE(compare_absolute(1.0, 1.5, 0.5).pass);
  EXPECT_TRUE(compare_absolute(0.0, 0.0, 0.0).pass);
}

TEST(ScoreAbsolute, MustFail) {
  const Comparison c = compare_absolute(0.170, 0.164, 0.002);
  EXPECT_FALSE(c.pass);
  EXPECT_NEAR(c.error, 0.006, 1e-15);
  EXPECT_FALSE(c.message.empty());
  EXPECT_FALSE(compare_absolute(kNaN, 0.0, 1.0).pass);
  EXPECT_FALSE(compare_absolute(0.0, kInf, 1.0).pass);
  EXPECT_FALSE(compare_absolute(0.0, 0.0, -1.0).pass);
}

TEST(ScoreBracket, PassesInside) {
  EXPECT_TRUE(compare_bracket(0.5, 0.0, 1.0).pass);
  EXPECT_EQ(compare_bracket(0.5, 0.0, 1.0).error, 0.0);
  EXPECT_TRUE(compare_bracket(0.0, 0.0, 1.0).pass);
  EXPECT_TRUE(compare_bracket(1.0, 0.0, 1.0).pass);
  EXPECT_TRUE(compare_bracket(1.05, 0.0, 1.0, 0.1).pass);  // within the margin
}

TEST(ScoreBracket, MustFail) {
  const Comparison above = compare_bracket(1.25, 0.0, 1.0);
  EXPECT_FALSE(above.pass);
  EXPECT_DOUBLE_EQ(above.error, 0.25);
  EXPECT_NE(above.message.find("outside"), std::string::npos);
  const Comparison below = compare_bracket(-0.5, 0.0, 1.0, 0.1);
  EXPECT_FALSE(below.pass);
  EXPECT_DOUBLE_EQ(below.error, 0.5);
  EXPECT_FALSE(compare_bracket(0.5, 1.0, 0.0).pass);  // lo > hi
  EXPECT_FALSE(compare_bracket(kNaN, 0.0, 1.0).pass);
  EXPECT_FALSE(compare_bracket(0.5, kNaN, 1.0).pass);
}

TEST(ScoreTimeSeries, LinearDataIsInterpolatedExactly) {
  const Series run = sample(0.0, 10.0, 0.5, line);
  const Series reference = sample(0.1, 9.9, 0.37, line);
  const SeriesDistance d = rms_distance(run, reference);
  EXPECT_LT(d.rms, 1e-13);
  EXPECT_EQ(d.points, reference.t.size());
}

TEST(ScoreTimeSeries, AnalyticSineWithinInterpolationBound) {
  // Linear interpolation of sin with step h errs by at most h^2/8 (|sin''| <= 1).
  const double h = 0.01;
  const Series run = sample(0.0, 10.0, h, sine);
  const Series reference = sample(0.5, 12.0, 0.37, sine);  // extends beyond the run
  const SeriesDistance d = rms_distance(run, reference);
  EXPECT_LE(d.rms, h * h / 8);
  EXPECT_DOUBLE_EQ(d.from, 0.5);
  EXPECT_DOUBLE_EQ(d.to, 10.0);
  std::size_t inside = 0;
  for (double t : reference.t) inside += t <= 10.0 ? 1 : 0;
  EXPECT_EQ(d.points, inside);
  EXPECT_TRUE(compare_time_series(run, reference, 1e-4).pass);
}

TEST(ScoreTimeSeries, PhaseShiftGivesAnalyticRms) {
  // sin(t) − sin(t + φ) has amplitude 2 sin(φ/2): RMS 2 sin(φ/2)/√2 over whole periods.
  const double period = 2 * std::numbers::pi;
  const Series run = sample(0.0, 20 * period, 0.01, sine);
  Series reference;
  for (int i = 0; i < 2000; ++i) {
    const double t = 20 * period * i / 2000.0;
    reference.t.push_back(t);
    reference.y.push_back(shifted_sine(t));
  }
  const double expected = 2 * std::sin(0.25) / std::sqrt(2.0);
  EXPECT_NEAR(rms_distance(run, reference).rms, expected, 1e-4);
  const Comparison c = compare_time_series(run, reference, 0.3);
  EXPECT_FALSE(c.pass);
  EXPECT_NEAR(c.error, expected, 1e-4);
}

TEST(ScoreTimeSeries, OffsetMustFailAndWindowRestricts) {
  const Series run = sample(0.0, 10.0, 0.01, sine);
  const Series reference = sample(0.0, 10.0, 0.25, offset_sine);
  EXPECT_NEAR(rms_distance(run, reference).rms, 0.1, 1e-4);
  EXPECT_FALSE(compare_time_series(run, reference, 0.05).pass);
  SeriesDistance detail;
  EXPECT_TRUE(compare_time_series(run, reference, 0.2, Window{5.0, 8.0}, &detail).pass);
  EXPECT_DOUBLE_EQ(detail.from, 5.0);
  EXPECT_DOUBLE_EQ(detail.to, 8.0);
  EXPECT_EQ(detail.points, 13u);  // 5.0, 5.25, ..., 8.0
}

TEST(ScoreTimeSeries, NoOverlapIsAClearError) {
  const Series run = sample(0.0, 1.0, 0.1, sine);
  const Series reference = sample(2.0, 3.0, 0.1, sine);
  try {
    rms_distance(run, reference);
    FAIL() << "expected core::Error";
  } catch (const core::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("do not overlap"), std::string::npos) << what;
    EXPECT_NE(what.find("[0, 1]"), std::string::npos) << what;
    EXPECT_NE(what.find("[2, 3]"), std::string::npos) << what;
  }
  const Comparison c = compare_time_series(run, reference, 1.0);
  EXPECT_FALSE(c.pass);
  EXPECT_TRUE(std::isnan(c.error));
  EXPECT_NE(c.message.find("do not overlap"), std::string::npos);
  // A window outside both series also leaves nothing to compare.
  EXPECT_FALSE(compare_time_series(run, run, 1.0, Window{5.0, 6.0}).pass);
  // Overlap without any reference abscissa in it.
  const Series sparse{{-1.0, 2.0}, {0.0, 0.0}};
  EXPECT_THROW(rms_distance(run, sparse), core::Error);
}

TEST(ScoreTimeSeries, RejectsMalformedSeries) {
  const Series good = sample(0.0, 1.0, 0.1, sine);
  EXPECT_THROW(rms_distance(Series{}, good), core::Error);
  EXPECT_THROW(rms_distance(Series{{0.0, 1.0}, {0.0}}, good), core::Error);
  EXPECT_THROW(rms_distance(Series{{0.0, 0.5, 0.5, 1.0}, {0, 0, 0, 0}}, good), core::Error);
  EXPECT_THROW(rms_distance(good, Series{{0.0, 0.5, 1.0}, {0.0, kNaN, 0.0}}), core::Error);
  EXPECT_FALSE(compare_time_series(good, good, -1.0).pass);
}

TEST(ScoreMode, PassesOnOneOfTheReferenceModes) {
  const Comparison c = compare_mode("tumbling", {"tumbling"});
  EXPECT_TRUE(c.pass);
  EXPECT_EQ(c.error, 0.0);
  EXPECT_TRUE(c.message.empty());
  EXPECT_TRUE(
      compare_mode("oscillating_tank_treading", {"steady_tank_treading", "oscillating_tank_treading"}).pass);
}

TEST(ScoreMode, MustFail) {
  const Comparison wrong = compare_mode("steady_tank_treading", {"tumbling"});
  EXPECT_FALSE(wrong.pass);
  EXPECT_EQ(wrong.error, 1.0);
  EXPECT_EQ(wrong.message, "mode \"steady_tank_treading\" is not the reference \"tumbling\"");
  const Comparison neither = compare_mode("tumbling", {"steady_tank_treading", "oscillating_tank_treading"});
  EXPECT_FALSE(neither.pass);
  EXPECT_NE(neither.message.find("\"steady_tank_treading\" or \"oscillating_tank_treading\""),
            std::string::npos);
  EXPECT_FALSE(compare_mode("Tumbling", {"tumbling"}).pass);  // exact, case-sensitive
  EXPECT_FALSE(compare_mode("tumbling", {}).pass);
  EXPECT_FALSE(compare_mode("", {""}).pass);
  EXPECT_FALSE(compare_mode("", {"tumbling"}).pass);
  EXPECT_FALSE(compare_mode("tumbling", {"tumbling", ""}).pass);
  EXPECT_TRUE(std::isnan(compare_mode("tumbling", {}).error));
  EXPECT_FALSE(compare_mode("tumbling", {}).message.empty());
}

class ScoreReferenceCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("caplab_test_score_csv_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

TEST_F(ScoreReferenceCsv, ReadsNamedColumnsSkippingComments) {
  const fs::path f =
      write("ref.csv", "# source: thesis fig. 2.7, digitized\n\n\"t\", cd, cl\n0, 1.5, 0.0\n1, 1.4, 0.3\n");
  const Series s = read_reference_series(f, "t", "cl");
  ASSERT_EQ(s.t.size(), 2u);
  EXPECT_EQ(s.t[1], 1.0);
  EXPECT_EQ(s.y[1], 0.3);
  EXPECT_EQ(read_reference_series(f).y[0], 1.5);  // first two columns by default
  EXPECT_EQ(split_reference("references/a/b.csv#t:cl").file, "references/a/b.csv");
  EXPECT_EQ(split_reference("references/a/b.csv#t:cl").key, "t:cl");
  EXPECT_EQ(split_reference("value").key, "");
}

TEST_F(ScoreReferenceCsv, MustReject) {
  const fs::path f = write("ref.csv", "t,cd\n0,1.5\n1,oops\n");
  try {
    read_reference_series(f, "t", "cl");
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("columns: t, cd"), std::string::npos) << e.what();
  }
  try {
    read_reference_series(f, "t", "cd");
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_reference_series(dir_ / "absent.csv"), core::InputError);
  EXPECT_THROW(resolve_reference_file("references/none.csv", dir_, dir_), core::InputError);
  EXPECT_EQ(resolve_reference_file("ref.csv", dir_ / "runs" / "r1", ""), dir_ / "ref.csv");  // found upward
}

// ---- sweep comparators ---------------------------------------------------------------------------

using Points = std::vector<std::pair<double, double>>;
using Modes = std::vector<std::pair<double, std::string>>;
const std::vector<std::string> kTT{"steady_tank_treading", "oscillating_tank_treading"};

TEST(ScoreTrend, MonotoneIncreasingPassesInAnyInputOrder) {
  PointVerdicts v;
  const Comparison c =
      compare_trend(Points{{0.04, 0.3}, {0.01, 0.1}, {0.02, 0.2}}, Direction::increasing, 0.0, {}, &v);
  EXPECT_TRUE(c.pass);
  EXPECT_TRUE(c.decided);
  EXPECT_TRUE(c.message.empty());
  EXPECT_NEAR(c.error, -0.1, 1e-15);  // the smallest rise, as a negative step against the direction
  ASSERT_EQ(v.size(), 3u);
  EXPECT_FALSE(v[1].has_value());  // the lowest parameter value is not judged
  EXPECT_EQ(v[0], true);
  EXPECT_EQ(v[2], true);
}

TEST(ScoreTrend, SingleReversalFailsNamingBothRuns) {
  PointVerdicts v;
  const Comparison c = compare_trend(Points{{1, 0.1}, {2, 0.2}, {3, 0.15}, {4, 0.3}}, Direction::increasing,
                                     0.0, {"ch2/G1", "ch2/G2", "ch2/G3", "ch2/G4"}, &v);
  EXPECT_FALSE(c.pass);
  EXPECT_TRUE(c.decided);
  EXPECT_NEAR(c.error, 0.05, 1e-15);
  EXPECT_EQ(c.message, "not increasing: 1 of 3 steps go against it: 0.2 at 2 (ch2/G2) -> 0.15 at 3 (ch2/G3)");
  EXPECT_EQ(v, (PointVerdicts{std::nullopt, true, false, true}));
  EXPECT_TRUE(compare_trend(Points{{1, 0.1}, {2, 0.2}, {3, 0.15}}, Direction::increasing, 0.06).pass);
  EXPECT_NE(compare_trend(Points{{1, 0.2}, {2, 0.1}}, Direction::increasing).message.find("point 1"),
            std::string::npos);  // without labels, points are named by position
}

TEST(ScoreTrend, DecreasingDirection) {
  EXPECT_TRUE(compare_trend(Points{{0, 3.0}, {1, 2.0}, {2, 1.0}}, Direction::decreasing).pass);
  const Comparison c = compare_trend(Points{{0, 3.0}, {1, 2.0}, {2, 2.5}}, Direction::decreasing);
  EXPECT_FALSE(c.pass);
  EXPECT_NEAR(c.error, 0.5, 1e-15);
  EXPECT_NE(c.message.find("not decreasing"), std::string::npos);
  EXPECT_FALSE(compare_trend(Points{{0, 1.0}, {1, 2.0}}, Direction::decreasing).pass);
}

TEST(ScoreTrend, Ties) {
  // An equal value fails a strict direction at tolerance 0, passes a non-strict one.
  const Comparison flat = compare_trend(Points{{0, 1.0}, {1, 1.0}}, Direction::increasing);
  EXPECT_FALSE(flat.pass);
  EXPECT_EQ(flat.error, 0.0);
  EXPECT_TRUE(compare_trend(Points{{0, 1.0}, {1, 1.0}}, Direction::increasing, 1e-9).pass);
  EXPECT_TRUE(compare_trend(Points{{0, 1.0}, {1, 1.0}, {2, 2.0}}, Direction::non_decreasing).pass);
  EXPECT_TRUE(compare_trend(Points{{0, 2.0}, {1, 2.0}, {2, 0.0}}, Direction::non_increasing).pass);
  EXPECT_FALSE(compare_trend(Points{{0, 0.0}, {1, 1.0}, {2, 0.0}}, Direction::non_decreasing).pass);
  // Runs at the same parameter value are not compared with each other, only with the next value.
  PointVerdicts v;
  EXPECT_TRUE(
      compare_trend(Points{{1, 0.5}, {1, 0.2}, {2, 0.6}, {2, 0.7}}, Direction::increasing, 0, {}, &v).pass);
  EXPECT_EQ(v, (PointVerdicts{std::nullopt, std::nullopt, true, true}));
  const Comparison c =
      compare_trend(Points{{1, 0.5}, {1, 0.7}, {2, 0.6}}, Direction::increasing, 0, {"a", "b", "c"});
  EXPECT_FALSE(c.pass);
  EXPECT_EQ(c.message, "not increasing: 1 of 2 steps go against it: 0.7 at 1 (b) -> 0.6 at 2 (c)");
}

TEST(ScoreTrend, TooFewPointsIsUndecided) {
  for (const Points& p : {Points{}, Points{{0.04, 0.3}}, Points{{0.04, 0.3}, {0.04, 0.2}}}) {
    const Comparison c = compare_trend(p, Direction::increasing);
    EXPECT_FALSE(c.decided);
    EXPECT_FALSE(c.pass);
    EXPECT_TRUE(std::isnan(c.error));
    EXPECT_NE(c.message.find("needs two values"), std::string::npos) << c.message;
  }
}

TEST(ScoreTrend, MustFail) {
  for (const Comparison& c :
       {compare_trend(Points{{0, 1.0}, {1, kNaN}}, Direction::increasing),
        compare_trend(Points{{kInf, 1.0}, {1, 2.0}}, Direction::increasing),
        compare_trend(Points{{0, 1.0}, {1, 2.0}}, Direction::increasing, -1.0),
        compare_trend(Points{{0, 1.0}, {1, 2.0}}, Direction::increasing, kNaN),
        compare_trend(Points{{0, 1.0}, {1, 2.0}}, Direction::increasing, 0.0, {"only one label"})}) {
    EXPECT_FALSE(c.pass);
    EXPECT_TRUE(c.decided);
    EXPECT_FALSE(c.message.empty());
  }
}

TEST(ScoreModeBracket, PassesWithTheRegimesOnEachSide) {
  PointVerdicts v;
  const Comparison c = compare_mode_bracket(Modes{{0.0, "steady_tank_treading"},
                                                  {0.04, "oscillating_tank_treading"},
                                                  {0.05, "steady_tank_treading"},  // inside: either
                                                  {0.06, "tumbling"},
                                                  {0.4, "tumbling"}},
                                            0.04, 0.06, kTT, {"tumbling"}, {}, &v);
  EXPECT_TRUE(c.pass);
  EXPECT_TRUE(c.decided);
  EXPECT_EQ(c.error, 0.0);
  EXPECT_EQ(v, (PointVerdicts{true, true, std::nullopt, true, true}));
}

TEST(ScoreModeBracket, ModeOnTheWrongSideFails) {
  PointVerdicts v;
  const Comparison c = compare_mode_bracket(
      Modes{{0.04, "oscillating_tank_treading"}, {0.06, "oscillating_tank_treading"}}, 0.04, 0.06,
      {"oscillating_tank_treading"}, {"tumbling"}, {"ch3/Eb0.04", "ch3/Eb0.06"}, &v);
  EXPECT_FALSE(c.pass);
  EXPECT_TRUE(c.decided);
  EXPECT_EQ(c.error, 1.0);
  EXPECT_EQ(c.message,
            "1 of 2 points on the wrong side of [0.04, 0.06]: ch3/Eb0.06 at 0.06 (above the bracket) is "
            "\"oscillating_tank_treading\", expected \"tumbling\"");
  EXPECT_EQ(v, (PointVerdicts{true, false}));
  // A point without a mode on a side is wrong; a wrong point decides even a one-sided sweep.
  const Comparison none = compare_mode_bracket(Modes{{0.0, ""}}, 0.04, 0.06, kTT, {"tumbling"});
  EXPECT_FALSE(none.pass);
  EXPECT_TRUE(none.decided);
  EXPECT_NE(none.message.find("without a mode"), std::string::npos);
}

TEST(ScoreModeBracket, NoRunOnOneSideIsUndecided) {
  for (const Modes& m : {Modes{{0.01, "oscillating_tank_treading"}, {0.02, "steady_tank_treading"}},
                         Modes{{0.1, "tumbling"}}, Modes{{0.05, "tumbling"}}, Modes{}}) {
    const Comparison c = compare_mode_bracket(m, 0.04, 0.06, kTT, {"tumbling"});
    EXPECT_FALSE(c.decided);
    EXPECT_FALSE(c.pass);
    EXPECT_NE(c.message.find("a point on each side"), std::string::npos) << c.message;
  }
}

TEST(ScoreModeBracket, MustFail) {
  const Modes m{{0.0, "steady_tank_treading"}, {1.0, "tumbling"}};
  for (const Comparison& c : {compare_mode_bracket(m, 0.06, 0.04, kTT, {"tumbling"}),
                              compare_mode_bracket(m, kNaN, 0.06, kTT, {"tumbling"}),
                              compare_mode_bracket(m, 0.04, 0.06, {}, {"tumbling"}),
                              compare_mode_bracket(m, 0.04, 0.06, kTT, {"tumbling", ""}),
                              compare_mode_bracket(Modes{{kNaN, "tumbling"}}, 0.04, 0.06, kTT, {"tumbling"}),
                              compare_mode_bracket(m, 0.04, 0.06, kTT, {"tumbling"}, {"one label"})}) {
    EXPECT_FALSE(c.pass);
    EXPECT_TRUE(c.decided);
    EXPECT_FALSE(c.message.empty());
  }
}

}  // namespace
}  // namespace caplab::score
