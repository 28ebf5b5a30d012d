// Expressions of t: precedence and associativity, exact jets against analytic derivatives of the
// kinematics laws the case files use, d1/d2 against central differences of value() (with a
// mismatch the comparison must reject), domain errors as NaN, parse errors with their position
// and message, and Piecewise selection and continuity (thesis eq. 2.28).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "expr/expression.hpp"

namespace caplab::expr {
namespace {

constexpr double pi = std::numbers::pi;

void expect_jet(const Jet& got, double v, double d1, double d2, double tol = 1e-13) {
  const auto near = [tol](double a, double b) { return std::abs(a - b) <= tol * std::max(1.0, std::abs(b)); };
  EXPECT_TRUE(near(got.v, v)) << "v = " << got.v << ", expected " << v;
  EXPECT_TRUE(near(got.d1, d1)) << "d1 = " << got.d1 << ", expected " << d1;
  EXPECT_TRUE(near(got.d2, d2)) << "d2 = " << got.d2 << ", expected " << d2;
}

TEST(Expression, PrecedenceAndAssociativity) {
  const std::vector<std::pair<std::string, double>> cases = {
      {"1+2*3", 7},         {"(1+2)*3", 9},         {"1-2-3", -4},    {"8/4/2", 1},
      {"2^3^2", 512},       {"(2^3)^2", 64},        {"-2^2", -4},     {"(-2)^2", 4},
      {"2^-1", 0.5},        {"2*3^2", 18},          {"-3*-2", 6},     {"--2", 2},
      {"+-+2", -2},         {"1 - -1", 2},          {"2/-4^0.5", -1}, {" 1 +\t.5e1 ", 6},
      {"123", 123},         {"1.5", 1.5},           {"1e-3", 1e-3},   {"2E+2", 200},
      {"pi", pi},           {"e", std::numbers::e}, {"min(3, 2)", 2}, {"max(3, 2)", 3},
      {"pow(2, 10)", 1024},
  };
  for (const auto& [text, value] : cases) {
    const Expression x = Expression::parse(text);
    EXPECT_DOUBLE_EQ(x.value(0.7), value) << text;
    EXPECT_FALSE(x.depends_on_time()) << text;
    EXPECT_EQ(x.text(), text);
  }
  // Unary minus binds looser than ^ on t as well: -t^2 = -(t^2), not (-t)^2.
  expect_jet(Expression::parse("-t^2").at(3), -9, -6, -2);
  expect_jet(Expression::parse("(-t)^2").at(3), 9, 6, 2);
  EXPECT_TRUE(Expression::parse("t - t").depends_on_time());
}

TEST(Expression, ThesisPathEq228) {
  const Expression x = Expression::parse("16 - 4/pi*sin(pi*t/4)");
  EXPECT_TRUE(x.depends_on_time());
  for (double t : {0.0, 1.0, 2.5, 7.3, 16.0}) {
    const double w = pi / 4;
    expect_jet(x.at(t), 16 - 4 / pi * std::sin(w * t), -std::cos(w * t), w * std::sin(w * t));
  }
}

TEST(Expression, PitchingLawsWithParameters) {
  const double A0 = 0.35, T = 2.5, beta = 0.4, alpha0 = 0.2, zeta = 0.6, w = 2 * pi / T;
  const std::map<std::string, double> p = {
      {"A0", A0}, {"T", T}, {"beta", beta}, {"alpha0", alpha0}, {"zeta", zeta}};
  const Expression a = Expression::parse("0.5*A0*(1+cos(2*pi*t/T))", p);
  const Expression b = Expression::parse("0.5*A0*(1+cos(2*pi*t/T))*cos(beta)", p);
  const Expression c = Expression::parse("alpha0*(1 - sin(2*pi*t/T - zeta))", p);
  for (double t : {0.0, 0.3, 1.1, 4.2}) {
    expect_jet(a.at(t), 0.5 * A0 * (1 + std::cos(w * t)), -0.5 * A0 * w * std::sin(w * t),
               -0.5 * A0 * w * w * std::cos(w * t));
    expect_jet(b.at(t), 0.5 * A0 * (1 + std::cos(w * t)) * std::cos(beta),
               -0.5 * A0 * w * std::sin(w * t) * std::cos(beta),
               -0.5 * A0 * w * w * std::cos(w * t) * std::cos(beta));
    expect_jet(c.at(t), alpha0 * (1 - std::sin(w * t - zeta)), -alpha0 * w * std::cos(w * t - zeta),
               alpha0 * w * w * std::sin(w * t - zeta));
  }
  EXPECT_FALSE(Expression::parse("2*pi/T*A0", p).depends_on_time());
  EXPECT_DOUBLE_EQ(Expression::parse("2*pi/T*A0", p).value(0), 2 * pi / T * A0);
}

TEST(Expression, ElementaryDerivatives) {
  for (double t : {-1.5, 0.0, 0.8, 2.0}) {
    expect_jet(Expression::parse("t^3").at(t), t * t * t, 3 * t * t, 6 * t);
    const double g = std::exp(-t * t);
    expect_jet(Expression::parse("exp(-t^2)").at(t), g, -2 * t * g, (4 * t * t - 2) * g);
    const double th = std::tanh(2 * t), s2 = 1 - th * th;
    expect_jet(Expression::parse("tanh(2*t)").at(t), th, 2 * s2, -8 * th * s2);
    const double sn = std::sin(t), cs = std::cos(t);
    expect_jet(Expression::parse("sin(t)*cos(t)").at(t), sn * cs, cs * cs - sn * sn, -4 * sn * cs);
    const double tn = std::tan(t);
    expect_jet(Expression::parse("tan(t)").at(t), tn, 1 + tn * tn, 2 * tn * (1 + tn * tn));
    expect_jet(Expression::parse("1/(1+t^2)").at(t), 1 / (1 + t * t), -2 * t / std::pow(1 + t * t, 2),
               (6 * t * t - 2) / std::pow(1 + t * t, 3));
  }
  for (double t : {0.5, 1.0, 3.0}) {
    expect_jet(Expression::parse("pow(t, 2.5)").at(t), std::pow(t, 2.5), 2.5 * std::pow(t, 1.5),
               3.75 * std::sqrt(t));
    expect_jet(Expression::parse("sqrt(t)").at(t), std::sqrt(t), 0.5 / std::sqrt(t),
               -0.25 / std::pow(t, 1.5));
    expect_jet(Expression::parse("log(t)").at(t), std::log(t), 1 / t, -1 / (t * t));
    // Exponent depending on t: t^t = exp(t log t).
    const double f = std::pow(t, t), l1 = std::log(t) + 1;
    expect_jet(Expression::parse("t^t").at(t), f, f * l1, f * (l1 * l1 + 1 / t));
    expect_jet(Expression::parse("pow(2, t)").at(t), std::pow(2, t), std::pow(2, t) * std::log(2),
               std::pow(2, t) * std::log(2) * std::log(2));
  }
  // A constant exponent also works for a negative base.
  expect_jet(Expression::parse("(t-3)^2").at(1), 4, -4, 2);
  expect_jet(Expression::parse("t^0").at(0), 1, 0, 0);
  expect_jet(Expression::parse("t^1").at(0), 0, 1, 0);
}

TEST(Expression, BranchFunctionsTakeTheRightHandBranch) {
  expect_jet(Expression::parse("abs(t-1)").at(0.5), 0.5, -1, 0);
  expect_jet(Expression::parse("abs(t-1)").at(1), 0, 1, 0);
  expect_jet(Expression::parse("abs(1-t)").at(1), 0, 1, 0);
  expect_jet(Expression::parse("min(t, 2-t)").at(0.5), 0.5, 1, 0);
  expect_jet(Expression::parse("min(t, 2-t)").at(1), 1, -1, 0);
  expect_jet(Expression::parse("max(t, 2-t)").at(1), 1, 1, 0);
  expect_jet(Expression::parse("max(t^2, 1)").at(0.5), 1, 0, 0);
  expect_jet(Expression::parse("max(t^2, 1)").at(2), 4, 4, 2);
  // Equal value and slope: the curvature decides which branch is active just after t.
  expect_jet(Expression::parse("min(t^2, 0*t)").at(0), 0, 0, 0);
  expect_jet(Expression::parse("max(t^2, 0*t)").at(0), 0, 0, 2);
}

// Largest relative mismatch between the jet of `jet_of` and central differences of `value_of`.
double fd_mismatch(const Expression& jet_of, const Expression& value_of, const std::vector<double>& times) {
  double worst = 0;
  for (double t : times) {
    const Jet j = jet_of.at(t);
    const double h1 = 1e-5, h2 = 1e-4;
    const double d1 = (value_of.value(t + h1) - value_of.value(t - h1)) / (2 * h1);
    const double d2 = (value_of.value(t + h2) - 2 * value_of.value(t) + value_of.value(t - h2)) / (h2 * h2);
    worst = std::max({worst, std::abs(j.d1 - d1) / std::max(1.0, std::abs(d1)),
                      std::abs(j.d2 - d2) / std::max(1.0, std::abs(d2))});
  }
  return worst;
}

TEST(Expression, DerivativesMatchCentralDifferences) {
  const std::map<std::string, double> p = {{"k", 0.3}, {"w", 2.0}};
  const std::string text =
      "exp(-k*t)*sin(w*t+1)^2/(1+t^2) + sqrt(2+cos(t))*tanh(t/3) - log(1+t^2)^1.5"
      " + pow(2+sin(t), cos(t)) + tan(0.2*t) - abs(t-0.1)*min(t, 1) + max(0.5*t, t^2)/(3 - t)";
  const Expression x = Expression::parse(text, p);
  const std::vector<double> times = {-0.7, 0.35, 1.3, 2.2};
  EXPECT_LT(fd_mismatch(x, x, times), 1e-5);
  // The comparison rejects a jet that is not the derivative of the values.
  const Expression shifted = Expression::parse(text + " + 1e-3*sin(t)", p);
  EXPECT_GT(fd_mismatch(shifted, x, times), 1e-4);
}

TEST(Expression, DomainErrorsGiveNaNAndDoNotThrow) {
  const auto all_nan = [](const Jet& j) { return std::isnan(j.v) && std::isnan(j.d1) && std::isnan(j.d2); };
  EXPECT_TRUE(all_nan(Expression::parse("1/(t-1)").at(1)));
  EXPECT_TRUE(all_nan(Expression::parse("log(t)").at(-1)));
  EXPECT_TRUE(all_nan(Expression::parse("log(t)").at(0)));
  EXPECT_TRUE(all_nan(Expression::parse("sqrt(t)").at(-1)));
  EXPECT_TRUE(all_nan(Expression::parse("t^0.5").at(-1)));
  EXPECT_TRUE(all_nan(Expression::parse("exp(t)").at(1000)));
  // An infinite intermediate that a later operation would turn finite is still caught.
  EXPECT_TRUE(all_nan(Expression::parse("1/(1/(t-1))").at(1)));
  EXPECT_TRUE(all_nan(Expression::parse("min(log(t), 5)").at(-1)));
  EXPECT_TRUE(all_nan(Expression::parse("t + 1/0").at(1)));
  // A finite value may have an infinite slope.
  const Jet s = Expression::parse("sqrt(t)").at(0);
  EXPECT_EQ(s.v, 0);
  EXPECT_TRUE(std::isinf(s.d1));
  EXPECT_FALSE(all_nan(Expression::parse("1/(t-1)").at(1.5)));
  // A zero inner derivative absorbs an infinite outer one: (t^2)^1.5 = |t|^3 is smooth enough.
  expect_jet(Expression::parse("(t^2)^1.5").at(0), 0, 0, 0);
  expect_jet(Expression::parse("log(1+t^2)^1.5").at(0), 0, 0, 0);
  const Jet t15 = Expression::parse("t*sqrt(t)").at(0);
  EXPECT_EQ(t15.v, 0);
  EXPECT_EQ(t15.d1, 0);
  EXPECT_TRUE(std::isinf(t15.d2));
}

// Parses `text`, expects a ParseError at `position` whose message contains `message`, and checks
// that what() quotes the text and carries the caret line.
void expect_parse_error(const std::string& text, const std::map<std::string, double>& p, std::size_t position,
                        const std::string& message) {
  try {
    Expression::parse(text, p);
    ADD_FAILURE() << "'" << text << "' was accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.position(), position) << text << "\n" << e.what();
    EXPECT_NE(e.expected().find(message), std::string::npos) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find("\"" + text + "\""), std::string::npos) << what;
    if (position != std::string::npos) {
      const std::string caret = "\n  " + text + "\n  " + std::string(position, ' ') + "^";
      EXPECT_EQ(what.substr(what.size() - caret.size()), caret) << what;
    } else {
      EXPECT_EQ(what.find('^'), std::string::npos) << what;
    }
  }
}

TEST(Expression, ParseErrorsSayWhereAndWhat) {
  const std::map<std::string, double> p = {{"A0", 1}, {"T", 2}};
  const auto npos = std::string::npos;
  expect_parse_error("16 - omega*t", p, 5, "unknown name 'omega' (known: t, pi, e, A0, T)");
  expect_parse_error("sin(t", {}, 5, "expected ')'");
  expect_parse_error("(1 + t * (2 - t)", {}, 16, "expected ')'");
  expect_parse_error("t t", {}, 2, "expected an operator or the end of the expression");
  expect_parse_error("", {}, 0, "empty");
  expect_parse_error("   ", {}, 3, "empty");
  expect_parse_error("sin()", {}, 4, "expected an argument of 'sin'");
  expect_parse_error("2**t", {}, 2, "expected a number, a name or '('");
  expect_parse_error("t", {{"pi", 3}}, npos, "parameter name 'pi' is reserved");
  expect_parse_error("t", {{"t", 3}}, npos, "reserved");
  expect_parse_error("t", {{"sin", 3}}, npos, "reserved");
  expect_parse_error("t", {{"2x", 3}}, npos, "not a name");
  expect_parse_error("t", {{"A", std::numeric_limits<double>::quiet_NaN()}}, npos, "not finite");
  expect_parse_error("sinh(t)", {}, 0, "unknown function 'sinh' (known: sin, cos, tan, exp, log, sqrt, tanh");
  expect_parse_error("sin t", {}, 4, "expected '(' after 'sin'");
  expect_parse_error("min(t)", {}, 5, "expected ',' ('min' takes two arguments)");
  expect_parse_error("sin(t, 1)", {}, 5, "expected ')' ('sin' takes one argument)");
  expect_parse_error("t^", {}, 2, "expected a number, a name or '('");
  expect_parse_error("1 + . * t", {}, 4, "expected a digit");
  expect_parse_error("1e999", {}, 0, "fits a double");
  expect_parse_error("2 # t", {}, 2, "expected an operator");
  expect_parse_error(std::string(40, '(') + "t" + std::string(40, ')'), {}, 32, "nested at most 32 levels");

  // The full message, as a case author sees it; and the type the loader maps to exit code 2.
  try {
    Expression::parse("16 - omega*t", p);
    ADD_FAILURE();
  } catch (const core::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "in expression \"16 - omega*t\": unknown name 'omega' (known: t, pi, e, A0, T)\n"
                 "  16 - omega*t\n"
                 "       ^");
  }
  // Nesting within the limit is fine.
  EXPECT_DOUBLE_EQ(Expression::parse(std::string(20, '(') + "t" + std::string(20, ')')).value(2), 2);
}

TEST(Piecewise, ThesisEq228IsContinuousWithUnitVelocity) {
  const Piecewise x({16.0}, {Expression::parse("16 - 4/pi*sin(pi*t/4)"), Expression::parse("32 - t")});
  EXPECT_LT(x.max_value_jump(), 1e-12);
  expect_jet(x.at(16), 16, -1, 0);
  expect_jet(x.at(20), 12, -1, 0);
  expect_jet(x.at(std::nextafter(16.0, 0.0)), 16, -1, 0, 1e-12);
  expect_jet(x.at(2), 16 - 4 / pi, 0, pi / 4);  // first piece: at rest velocity 0 at t = 2
  expect_jet(x.at(-4), 16, 1, 0);
}

TEST(Piecewise, SelectsThePieceOnTheRightOfABreakpoint) {
  const Piecewise x({0.0, 1.0, 2.0}, {Expression::parse("-1"), Expression::parse("t"),
                                      Expression::parse("t + 0.1"), Expression::parse("3*t - 3.5")});
  EXPECT_EQ(x.at(-1e300).v, -1);
  EXPECT_EQ(x.at(std::nextafter(0.0, -1.0)).v, -1);
  EXPECT_EQ(x.at(0).v, 0);
  EXPECT_EQ(x.at(0.5).d1, 1);
  EXPECT_EQ(x.at(std::nextafter(1.0, 0.0)).v, std::nextafter(1.0, 0.0));
  EXPECT_DOUBLE_EQ(x.at(1).v, 1.1);
  EXPECT_DOUBLE_EQ(x.at(2).v, 2.5);
  EXPECT_EQ(x.at(2).d1, 3);
  EXPECT_DOUBLE_EQ(x.at(1e6).v, 3e6 - 3.5);
  // Jumps 1, 0.1 and 0.4: the largest is reported.
  EXPECT_DOUBLE_EQ(x.max_value_jump(), 1.0);

  const Piecewise single({}, {Expression::parse("t")});
  EXPECT_EQ(single.max_value_jump(), 0);
  EXPECT_EQ(single.at(-5).v, -5);

  const Piecewise discontinuous({1.0}, {Expression::parse("t"), Expression::parse("t + 0.25")});
  EXPECT_DOUBLE_EQ(discontinuous.max_value_jump(), 0.25);
  const Piecewise undefined({0.0}, {Expression::parse("log(t)"), Expression::parse("t")});
  EXPECT_TRUE(std::isnan(undefined.max_value_jump()));
}

TEST(Piecewise, RejectsBadBreakpoints) {
  const Expression a = Expression::parse("t");
  EXPECT_THROW(Piecewise({}, {}), core::InputError);
  EXPECT_THROW(Piecewise({1.0}, {a}), core::InputError);
  EXPECT_THROW(Piecewise({}, {a, a}), core::InputError);
  EXPECT_THROW(Piecewise({1.0, 1.0}, {a, a, a}), core::InputError);
  EXPECT_THROW(Piecewise({2.0, 1.0}, {a, a, a}), core::InputError);
  EXPECT_THROW(Piecewise({std::numeric_limits<double>::quiet_NaN()}, {a, a}), core::InputError);
  EXPECT_NO_THROW(Piecewise({1.0, 2.0}, {a, a, a}));
}

}  // namespace
}  // namespace caplab::expr
