// Expressions of time t with exact first and second time derivatives.
//
// Rigid-body kinematics in case files are written as formulas of t, e.g. the thesis eq. 2.28
// path "16 - 4/pi*sin(pi*t/4)" or a pitching law "0.5*A0*(1+cos(2*pi*t/T))". The solver needs
// the value, the velocity and the acceleration, so an Expression is evaluated on a second-order
// jet (v, dv/dt, d2v/dt2) with the exact chain, product and quotient rules: no finite
// differences.
//
// Grammar (whitespace ignored; ^ is right-associative and binds tighter than unary minus,
// so -t^2 = -(t^2) and 2^3^2 = 2^9):
//   expr    = term  { ('+' | '-') term }
//   term    = unary { ('*' | '/') unary }
//   unary   = ('+' | '-') unary | power
//   power   = primary [ '^' unary ]
//   primary = number | name | function '(' expr [ ',' expr ] ')' | '(' expr ')'
//   number  = 123 | 1.5 | 1e-3 | .5
//   name    = [A-Za-z_][A-Za-z0-9_]*  : t, pi, e or a parameter
// Functions: sin cos tan exp log sqrt tanh abs (one argument), min max pow (two).
//
// Parsing compiles to a flat postfix program with constant subexpressions folded; evaluation
// runs it on a fixed-size stack of jets, so at() allocates nothing, is const and thread-safe.
//
// Piecewise joins expressions over time intervals (eq. 2.28 is one such path) and measures the
// jumps across its breakpoints.
//
// Invariants: at() never throws. When any intermediate value is not finite (division by zero,
// log or sqrt of a negative number, overflow, ...) the whole jet is NaN, so checking the value
// alone catches every domain error; a finite value may still have an infinite derivative
// (sqrt(t) at t = 0). An exact zero factor in a derivative term absorbs an infinite one, so
// (t^2)^1.5 = |t|^3 has d2 = 0 at t = 0 rather than 0 * inf = NaN. x^b with b depending on t
// is exp(b log x) and needs x > 0; with a constant b it is n x^(n-1) and allows x <= 0.
// min, max and abs take the derivatives of the branch active just after t (jets compared
// lexicographically): at a tie that is the right-hand derivative, the convention of Piecewise.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace caplab::expr {

/// Value and first two derivatives with respect to t (forward-mode, second-order jet).
struct Jet {
  double v = 0, d1 = 0, d2 = 0;
};

/// A malformed expression or parameter set (bad input, hence an InputError: exit code 2).
/// `what()` quotes the text, marks the position with a caret line and says what was expected.
class ParseError : public core::InputError {
 public:
  /// `position` indexes `text` (text.size() for the end); std::string::npos when the error is
  /// not tied to a place in the text (a bad parameter), and then there is no caret line.
  ParseError(std::string text, std::size_t position, std::string expected);

  const std::string& text() const { return text_; }
  std::size_t position() const { return position_; }
  /// The message without the quoted text, e.g. "expected ')'".
  const std::string& expected() const { return expected_; }

 private:
  std::string text_;
  std::size_t position_;
  std::string expected_;
};

namespace detail {
enum class Op : unsigned char;  // defined in expression.cpp
/// One step of the postfix program.
struct Instruction {
  Op op;
  double c;  // the constant of a push, the exponent of a constant power
};
}  // namespace detail

/// A parsed expression of t.
class Expression {
 public:
  /// Parses `text`; `parameters` are named constants usable in it (besides t, pi, e).
  /// Throws ParseError on a syntax error, an unknown name, or a parameter whose name is not an
  /// identifier, shadows t, pi, e or a function, or whose value is not finite.
  static Expression parse(const std::string& text, const std::map<std::string, double>& parameters = {});

  /// Value, d/dt and d2/dt2 at `t`.
  Jet at(double t) const;
  /// at(t).v
  double value(double t) const { return at(t).v; }
  /// The text it was parsed from.
  const std::string& text() const { return text_; }
  /// Whether t occurs in it (after constant folding; "t - t" counts as time-dependent).
  bool depends_on_time() const;

 private:
  Expression(std::string text, std::vector<detail::Instruction> program)
      : text_(std::move(text)), program_(std::move(program)) {}

  std::string text_;
  std::vector<detail::Instruction> program_;
};

/// A piecewise function of t: pieces [t_k, t_{k+1}) each with an Expression; the last piece
/// extends to +infinity, the first starts at -infinity.
class Piecewise {
 public:
  /// `breakpoints` (size pieces - 1) must be finite and strictly increasing; throws
  /// core::InputError otherwise or when there are no pieces.
  Piecewise(std::vector<double> breakpoints, std::vector<Expression> pieces);

  /// The jet of the piece with t_k <= t < t_{k+1}.
  Jet at(double t) const;
  /// Largest |jump| of the value across any breakpoint (0 for a single piece; NaN when a piece
  /// is not finite there).
  double max_value_jump() const;

  const std::vector<double>& breakpoints() const { return breakpoints_; }
  const std::vector<Expression>& pieces() const { return pieces_; }

 private:
  std::vector<double> breakpoints_;
  std::vector<Expression> pieces_;
};

}  // namespace caplab::expr
