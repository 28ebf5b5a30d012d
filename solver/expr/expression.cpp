#include "expr/expression.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <string_view>

namespace caplab::expr {

namespace detail {
// Grouped by arity, which arity() relies on.
// clang-format off
enum class Op : unsigned char {
  constant, time,                                            // push a jet
  neg, pow_const, sin, cos, tan, exp, log, sqrt, tanh, abs,  // replace the top jet
  add, sub, mul, div, pow, min, max,                         // pop two jets, push one
};
// clang-format on
}  // namespace detail

namespace {

using detail::Instruction;
using detail::Op;

// Parentheses, function calls, signs and exponents nested deeper than this are rejected, which
// bounds both the parser's recursion and the evaluation stack (at most 3 slots per level).
constexpr int max_nesting = 32;
constexpr std::size_t stack_size = 3 * max_nesting + 4;

struct Function {
  std::string_view name;
  Op op;
  int arity;
};
constexpr std::array<Function, 11> functions{{{"sin", Op::sin, 1},
                                              {"cos", Op::cos, 1},
                                              {"tan", Op::tan, 1},
                                              {"exp", Op::exp, 1},
                                              {"log", Op::log, 1},
                                              {"sqrt", Op::sqrt, 1},
                                              {"tanh", Op::tanh, 1},
                                              {"abs", Op::abs, 1},
                                              {"min", Op::min, 2},
                                              {"max", Op::max, 2},
                                              {"pow", Op::pow, 2}}};

const Function* find_function(std::string_view name) {
  for (const Function& f : functions)
    if (f.name == name) return &f;
  return nullptr;
}

std::string function_list() {
  std::string s;
  for (const Function& f : functions) s += (s.empty() ? "" : ", ") + std::string(f.name);
  return s;
}

std::size_t arity(Op op) {
  if (op == Op::constant || op == Op::time) return 0;
  return op < Op::add ? 1 : 2;
}

// Products in derivative terms treat an exact zero as absorbing ("strong zero"): a zero inner
// derivative or a zero factor contributes nothing even against an infinite one, so
// (t^2)^1.5 = |t|^3 gets d2 = 0 at t = 0 instead of 0 * inf = NaN.
double times(double a, double b) { return a == 0 || b == 0 ? 0 : a * b; }

// f(u) with f, f', f'' at u.v (chain rule to second order).
Jet chain(double f, double f1, double f2, const Jet& u) {
  return {f, times(f1, u.d1), times(f2, u.d1 * u.d1) + times(f1, u.d2)};
}

Jet product(const Jet& a, const Jet& b) {
  return {a.v * b.v, times(a.d1, b.v) + times(a.v, b.d1),
          times(a.d2, b.v) + 2 * times(a.d1, b.d1) + times(a.v, b.d2)};
}

Jet quotient(const Jet& a, const Jet& b) {
  const double q = a.v / b.v;
  const double q1 = (a.d1 - times(q, b.d1)) / b.v;
  return {q, q1, (a.d2 - 2 * times(q1, b.d1) - times(q, b.d2)) / b.v};
}

// x^n for a constant n: n x^(n-1), which unlike exp(n log x) works for x <= 0.
Jet power_const(const Jet& x, double n) {
  return chain(std::pow(x.v, n), times(n, std::pow(x.v, n - 1)), times(n * (n - 1), std::pow(x.v, n - 2)), x);
}

// x^b = exp(b log x) for b depending on t.
Jet power(const Jet& x, const Jet& b) {
  const Jet log_x = {std::log(x.v), x.d1 / x.v, (x.d2 * x.v - x.d1 * x.d1) / (x.v * x.v)};
  const Jet m = product(b, log_x);
  const double v = std::pow(x.v, b.v);
  return {v, times(v, m.d1), times(v, m.d2 + m.d1 * m.d1)};
}

// Lexicographic order of jets: a < b means a is the smaller one just after t.
bool less(const Jet& a, const Jet& b) {
  if (a.v != b.v) return a.v < b.v;
  if (a.d1 != b.d1) return a.d1 < b.d1;
  return a.d2 < b.d2;
}

// Runs one instruction on the stack s holding n jets; returns the new size.
std::size_t step(const Instruction& in, Jet* s, std::size_t n, double t) {
  switch (in.op) {
    case Op::constant:
      s[n] = {in.c, 0, 0};
      return n + 1;
    case Op::time:
      s[n] = {t, 1, 0};
      return n + 1;
    default:
      break;
  }
  Jet& u = s[n - 1];
  const double x = u.v;
  switch (in.op) {
    case Op::neg:
      u = {-u.v, -u.d1, -u.d2};
      return n;
    case Op::pow_const:
      u = power_const(u, in.c);
      return n;
    case Op::sin: {
      const double sn = std::sin(x);
      u = chain(sn, std::cos(x), -sn, u);
      return n;
    }
    case Op::cos: {
      const double cs = std::cos(x);
      u = chain(cs, -std::sin(x), -cs, u);
      return n;
    }
    case Op::tan: {
      const double f = std::tan(x), sec2 = 1 + f * f;
      u = chain(f, sec2, 2 * f * sec2, u);
      return n;
    }
    case Op::exp: {
      const double f = std::exp(x);
      u = chain(f, f, f, u);
      return n;
    }
    case Op::log:
      u = chain(std::log(x), 1 / x, -1 / (x * x), u);
      return n;
    case Op::sqrt: {
      const double f = std::sqrt(x);
      u = chain(f, 0.5 / f, -0.25 / (f * x), u);
      return n;
    }
    case Op::tanh: {
      const double f = std::tanh(x), sech2 = 1 - f * f;
      u = chain(f, sech2, -2 * f * sech2, u);
      return n;
    }
    case Op::abs: {
      const Jet minus = {-u.v, -u.d1, -u.d2};
      if (less(u, minus)) u = minus;
      return n;
    }
    default:
      break;
  }
  Jet& a = s[n - 2];
  const Jet& b = u;
  switch (in.op) {
    case Op::add:
      a = {a.v + b.v, a.d1 + b.d1, a.d2 + b.d2};
      break;
    case Op::sub:
      a = {a.v - b.v, a.d1 - b.d1, a.d2 - b.d2};
      break;
    case Op::mul:
      a = product(a, b);
      break;
    case Op::div:
      a = quotient(a, b);
      break;
    case Op::pow:
      a = power(a, b);
      break;
    case Op::min:
      if (less(b, a)) a = b;
      break;
    case Op::max:
      if (less(a, b)) a = b;
      break;
    default:
      break;
  }
  return n - 1;
}

bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Recursive descent over the grammar of expression.hpp, emitting postfix code as it goes.
class Parser {
 public:
  Parser(const std::string& text, const std::map<std::string, double>& parameters)
      : text_(text), parameters_(parameters) {}

  std::vector<Instruction> run() {
    skip_space();
    if (pos_ == text_.size()) fail("expected a number, a name or '(' (the expression is empty)");
    expr();
    if (pos_ != text_.size()) fail("expected an operator or the end of the expression");
    return std::move(program_);
  }

 private:
  [[noreturn]] void fail(std::string expected) const { throw ParseError(text_, pos_, std::move(expected)); }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  bool accept(char c) {
    if (peek() != c) return false;
    ++pos_;
    skip_space();
    return true;
  }
  void expect(char c, const std::string& expected) {
    if (!accept(c)) fail(expected);
  }

  void expr() {
    term();
    for (char c = peek(); c == '+' || c == '-'; c = peek()) {
      accept(c);
      term();
      emit(c == '+' ? Op::add : Op::sub);
    }
  }

  void term() {
    unary();
    for (char c = peek(); c == '*' || c == '/'; c = peek()) {
      accept(c);
      unary();
      emit(c == '*' ? Op::mul : Op::div);
    }
  }

  void unary() {
    if (++nesting_ > max_nesting)
      fail(fmt::format("expected an expression nested at most {} levels deep", max_nesting));
    if (accept('-')) {
      unary();
      emit(Op::neg);
    } else if (accept('+')) {
      unary();
    } else {
      primary();
      if (accept('^')) {
        unary();
        emit_power();
      }
    }
    --nesting_;
  }

  void primary() {
    const char c = peek();
    if (is_digit(c) || c == '.') return number();
    if (is_name_start(c)) return name();
    if (accept('(')) {
      expr();
      expect(')', "expected ')'");
      return;
    }
    fail("expected a number, a name or '('");
  }

  void number() {
    const std::size_t start = pos_;
    auto digits = [&] {
      const std::size_t from = pos_;
      while (is_digit(peek())) ++pos_;
      return pos_ - from;
    };
    std::size_t mantissa = digits();
    if (peek() == '.') {
      ++pos_;
      mantissa += digits();
    }
    if (mantissa == 0) {
      pos_ = start;
      fail("expected a digit");
    }
    // An 'e' not followed by an exponent is left alone, to be reported as what follows a number.
    if (peek() == 'e' || peek() == 'E') {
      std::size_t p = pos_ + 1;
      if (p < text_.size() && (text_[p] == '+' || text_[p] == '-')) ++p;
      if (p < text_.size() && is_digit(text_[p])) {
        pos_ = p;
        digits();
      }
    }
    double value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + start, text_.data() + pos_, value);
    if (ec != std::errc() || end != text_.data() + pos_) {
      pos_ = start;
      fail("expected a number that fits a double");
    }
    skip_space();
    emit(Op::constant, value);
  }

  void name() {
    const std::size_t start = pos_;
    while (is_name_char(peek())) ++pos_;
    const std::string id = text_.substr(start, pos_ - start);
    skip_space();
    const Function* f = find_function(id);
    if (peek() == '(') {
      if (!f) {
        pos_ = start;
        fail(fmt::format("unknown function '{}' (known: {})", id, function_list()));
      }
      return call(*f);
    }
    if (f) fail(fmt::format("expected '(' after '{}'", id));
    if (id == "t") return emit(Op::time);
    if (id == "pi") return emit(Op::constant, std::numbers::pi);
    if (id == "e") return emit(Op::constant, std::numbers::e);
    if (const auto p = parameters_.find(id); p != parameters_.end()) return emit(Op::constant, p->second);
    std::string known = "t, pi, e";
    for (const auto& [parameter, value] : parameters_) known += ", " + parameter;
    pos_ = start;
    fail(fmt::format("unknown name '{}' (known: {})", id, known));
  }

  void call(const Function& f) {
    accept('(');
    if (peek() == ')') fail(fmt::format("expected an argument of '{}'", f.name));
    expr();
    if (f.arity == 2) {
      expect(',', fmt::format("expected ',' ('{}' takes two arguments)", f.name));
      expr();
    } else if (peek() == ',') {
      fail(fmt::format("expected ')' ('{}' takes one argument)", f.name));
    }
    expect(')', "expected ')'");
    if (f.op == Op::pow) return emit_power();
    emit(f.op);
  }

  void emit_power() {
    if (program_.back().op != Op::constant) return emit(Op::pow);
    const double n = program_.back().c;
    program_.pop_back();
    emit(Op::pow_const, n);
  }

  // Appends an instruction, folding it into one constant when all its operands are constants.
  // The fold is sound because an operand that ends in a constant push is that push alone.
  void emit(Op op, double c = 0) {
    const std::size_t k = arity(op);
    const bool foldable = k > 0 && program_.size() >= k &&
                          std::all_of(program_.end() - k, program_.end(),
                                      [](const Instruction& in) { return in.op == Op::constant; });
    program_.push_back({op, c});
    if (!foldable) return;
    std::array<Jet, 2> s;
    std::size_t n = 0;
    for (auto in = program_.end() - k - 1; in != program_.end(); ++in) n = step(*in, s.data(), n, 0);
    program_.resize(program_.size() - k - 1);
    program_.push_back({Op::constant, s[0].v});
  }

  const std::string& text_;
  const std::map<std::string, double>& parameters_;
  std::size_t pos_ = 0;
  int nesting_ = 0;
  std::vector<Instruction> program_;
};

void check_parameters(const std::string& text, const std::map<std::string, double>& parameters) {
  for (const auto& [name, value] : parameters) {
    const auto fail = [&](const std::string& expected) {
      throw ParseError(text, std::string::npos, expected);
    };
    if (name.empty() || !is_name_start(name[0]) || !std::all_of(name.begin(), name.end(), is_name_char))
      fail(fmt::format("parameter name '{}' is not a name ([A-Za-z_][A-Za-z0-9_]*)", name));
    if (name == "t" || name == "pi" || name == "e" || find_function(name))
      fail(fmt::format("parameter name '{}' is reserved (reserved: t, pi, e, {})", name, function_list()));
    if (!std::isfinite(value)) fail(fmt::format("parameter '{}' = {} is not finite", name, value));
  }
}

// The caret column counts characters, not the bytes of multi-byte UTF-8 sequences.
std::string format_parse_error(const std::string& text, std::size_t position, const std::string& expected) {
  std::string line = text;
  std::replace_if(
      line.begin(), line.end(), [](char c) { return c == '\t' || c == '\n' || c == '\r'; }, ' ');
  std::string message = fmt::format("in expression \"{}\": {}", line, expected);
  if (position == std::string::npos) return message;
  const auto column = std::count_if(line.begin(), line.begin() + std::min(position, line.size()),
                                    [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; });
  return message + fmt::format("\n  {}\n  {}^", line, std::string(column, ' '));
}

}  // namespace

ParseError::ParseError(std::string text, std::size_t position, std::string expected)
    : InputError(format_parse_error(text, position, expected)),
      text_(std::move(text)),
      position_(position),
      expected_(std::move(expected)) {}

Expression Expression::parse(const std::string& text, const std::map<std::string, double>& parameters) {
  check_parameters(text, parameters);
  std::vector<Instruction> program = Parser(text, parameters).run();
  std::size_t n = 0, depth = 0;
  for (const Instruction& in : program) depth = std::max(depth, n = n + 1 - arity(in.op));
  if (depth > stack_size)
    throw ParseError(text, std::string::npos,
                     "expected a simpler expression (the evaluation stack would overflow)");
  return Expression(text, std::move(program));
}

Jet Expression::at(double t) const {
  std::array<Jet, stack_size> s;
  std::size_t n = 0;
  bool finite = true;
  for (const Instruction& in : program_) {
    n = step(in, s.data(), n, t);
    finite = finite && std::isfinite(s[n - 1].v);
  }
  if (!finite) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }
  return s[0];
}

bool Expression::depends_on_time() const {
  return std::any_of(program_.begin(), program_.end(),
                     [](const Instruction& in) { return in.op == Op::time; });
}

Piecewise::Piecewise(std::vector<double> breakpoints, std::vector<Expression> pieces)
    : breakpoints_(std::move(breakpoints)), pieces_(std::move(pieces)) {
  if (pieces_.empty()) throw core::InputError("piecewise function: expected at least one piece");
  if (breakpoints_.size() + 1 != pieces_.size())
    throw core::InputError(fmt::format("piecewise function: {} pieces need {} breakpoints, got {}",
                                       pieces_.size(), pieces_.size() - 1, breakpoints_.size()));
  for (std::size_t k = 0; k < breakpoints_.size(); ++k) {
    if (!std::isfinite(breakpoints_[k]) || (k > 0 && !(breakpoints_[k - 1] < breakpoints_[k])))
      throw core::InputError(
          fmt::format("piecewise function: breakpoint {} = {} is not finite or not greater "
                      "than the one before (breakpoints must increase strictly)",
                      k, breakpoints_[k]));
  }
}

Jet Piecewise::at(double t) const {
  const auto k = std::upper_bound(breakpoints_.begin(), breakpoints_.end(), t) - breakpoints_.begin();
  return pieces_[k].at(t);
}

double Piecewise::max_value_jump() const {
  double jump = 0;
  for (std::size_t k = 0; k < breakpoints_.size(); ++k) {
    const double tk = breakpoints_[k];
    const double d = std::abs(pieces_[k + 1].value(tk) - pieces_[k].value(tk));
    if (std::isnan(d)) return d;
    jump = std::max(jump, d);
  }
  return jump;
}

}  // namespace caplab::expr
