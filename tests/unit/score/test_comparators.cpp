// Unit tests of the score comparators (relative, absolute, bracket, time_series, mode) and of the
// reference CSV reader. Every comparator is shown to accept what it should and to reject what
// it must (DESIGN.md section 7: every check must be able to fail).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

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

}  // namespace
}  // namespace caplab::score
