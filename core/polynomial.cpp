#include "core/polynomial.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace hw {

int degree_of(const Exponents& e) {
  int d = 0;
  for (auto v : e) d += v;
  return d;
}

Exponents add_exponents(const Exponents& a, const Exponents& b) {
  Exponents r(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) r[i] = static_cast<uint16_t>(a[i] + b[i]);
  return r;
}

bool GradedLess::operator()(const Exponents& a, const Exponents& b) const {
  const int da = degree_of(a), db = degree_of(b);
  if (da != db) return da < db;
  // Within a degree, x1^d comes first (larger exponent of earlier variable first).
  return std::lexicographical_compare(b.begin(), b.end(), a.begin(), a.end());
}

std::size_t ExponentsHash::operator()(const Exponents& e) const {
  std::size_t h = 1469598103934665603ull;
  for (auto v : e) h = (h ^ v) * 1099511628211ull;
  return h;
}

Polynomial Polynomial::Constant(int n, double c) {
  Polynomial p(n);
  p.add_term(Exponents(n, 0), c);
  return p;
}

Polynomial Polynomial::Variable(int n, int index, double coefficient) {
  if (index < 0 || index >= n) throw std::out_of_range("Polynomial::Variable: index out of range");
  Exponents e(n, 0);
  e[index] = 1;
  Polynomial p(n);
  p.add_term(e, coefficient);
  return p;
}

Polynomial Polynomial::Monomial(const Exponents& e, double coefficient) {
  Polynomial p(static_cast<int>(e.size()));
  p.add_term(e, coefficient);
  return p;
}

int Polynomial::degree() const {
  int d = -1;
  for (const auto& [e, c] : terms_) d = std::max(d, degree_of(e));
  return d;
}

double Polynomial::coefficient(const Exponents& e) const {
  auto it = terms_.find(e);
  return it == terms_.end() ? 0.0 : it->second;
}

double Polynomial::constant_term() const { return coefficient(Exponents(num_vars_, 0)); }

void Polynomial::add_term(const Exponents& e, double c) {
  if (static_cast<int>(e.size()) != num_vars_) throw std::invalid_argument("Polynomial: exponent length mismatch");
  if (c == 0.0) return;
  auto [it, inserted] = terms_.emplace(e, c);
  if (!inserted) {
    it->second += c;
    if (it->second == 0.0) terms_.erase(it);
  }
}

Polynomial& Polynomial::operator+=(const Polynomial& o) {
  if (o.num_vars_ != num_vars_) throw std::invalid_argument("Polynomial: variable count mismatch");
  for (const auto& [e, c] : o.terms_) add_term(e, c);
  return *this;
}

Polynomial& Polynomial::operator-=(const Polynomial& o) {
  if (o.num_vars_ != num_vars_) throw std::invalid_argument("Polynomial: variable count mismatch");
  for (const auto& [e, c] : o.terms_) add_term(e, -c);
  return *this;
}

Polynomial& Polynomial::operator*=(double s) {
  if (s == 0.0) {
    terms_.clear();
    return *this;
  }
  for (auto& [e, c] : terms_) c *= s;
  return *this;
}

Polynomial operator*(const Polynomial& a, const Polynomial& b) {
  if (a.num_vars_ != b.num_vars_) throw std::invalid_argument("Polynomial: variable count mismatch");
  Polynomial r(a.num_vars_);
  for (const auto& [ea, ca] : a.terms_)
    for (const auto& [eb, cb] : b.terms_) r.add_term(add_exponents(ea, eb), ca * cb);
  return r;
}

Polynomial Polynomial::pow(int k) const {
  if (k < 0) throw std::invalid_argument("Polynomial::pow: negative exponent");
  Polynomial r = Constant(num_vars_, 1.0), base = *this;
  while (k) {
    if (k & 1) r = r * base;
    k >>= 1;
    if (k) base = base * base;
  }
  return r;
}

double Polynomial::evaluate(const std::vector<double>& x) const {
  if (static_cast<int>(x.size()) != num_vars_) throw std::invalid_argument("Polynomial::evaluate: wrong point size");
  double s = 0.0;
  for (const auto& [e, c] : terms_) {
    double m = c;
    for (int i = 0; i < num_vars_; ++i)
      for (int k = 0; k < e[i]; ++k) m *= x[i];
    s += m;
  }
  return s;
}

Polynomial Polynomial::substitute(int var, const Polynomial& value) const {
  std::vector<Polynomial> rep;
  for (int i = 0; i < num_vars_; ++i) rep.push_back(i == var ? value : Variable(num_vars_, i));
  return compose(rep);
}

Polynomial Polynomial::compose(const std::vector<Polynomial>& rep) const {
  if (static_cast<int>(rep.size()) != num_vars_) throw std::invalid_argument("Polynomial::compose: wrong arity");
  const int n_out = rep.empty() ? num_vars_ : rep[0].num_vars();
  // Cache powers: compositions here are small (tens of variables, low degree).
  std::vector<std::vector<Polynomial>> powers(num_vars_);
  Polynomial r(n_out);
  for (const auto& [e, c] : terms_) {
    Polynomial m = Constant(n_out, c);
    for (int i = 0; i < num_vars_; ++i) {
      if (!e[i]) continue;
      auto& pw = powers[i];
      if (pw.empty()) pw.push_back(Constant(n_out, 1.0));
      while (static_cast<int>(pw.size()) <= e[i]) pw.push_back(pw.back() * rep[i]);
      m = m * pw[e[i]];
    }
    r += m;
  }
  return r;
}

void Polynomial::prune(double tol) {
  for (auto it = terms_.begin(); it != terms_.end();)
    it = std::abs(it->second) <= tol ? terms_.erase(it) : std::next(it);
}

double Polynomial::max_abs_coefficient() const {
  double m = 0.0;
  for (const auto& [e, c] : terms_) m = std::max(m, std::abs(c));
  return m;
}

std::string Polynomial::to_string(const std::vector<std::string>& names_in) const {
  const auto names = names_in.empty() ? default_variable_names(num_vars_) : names_in;
  if (terms_.empty()) return "0";
  std::string s;
  for (const auto& [e, c] : terms_) {
    const bool constant = degree_of(e) == 0;
    double mag = std::abs(c);
    s += s.empty() ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + ");
    std::string mono;
    for (int i = 0; i < num_vars_; ++i) {
      if (!e[i]) continue;
      if (!mono.empty()) mono += "*";
      mono += names[i];
      if (e[i] > 1) mono += fmt::format("^{}", e[i]);
    }
    if (constant || mag != 1.0) s += fmt::format("{:.12g}", mag) + (constant ? "" : "*");
    s += mono;
  }
  return s;
}

std::vector<std::string> default_variable_names(int n) {
  std::vector<std::string> v;
  for (int i = 1; i <= n; ++i) v.push_back(fmt::format("x{}", i));
  return v;
}

std::size_t MonomialBasis::count(int n, int d) {
  // C(n + d, d), computed incrementally to stay exact.
  std::size_t r = 1;
  for (int k = 1; k <= d; ++k) r = r * (n + k) / k;
  return r;
}

MonomialBasis::MonomialBasis(int n, int d) : num_vars_(n), max_degree_(d) {
  // Enumerate degree by degree; within a degree, exponents in GradedLess order.
  for (int deg = 0; deg <= d; ++deg) {
    std::vector<Exponents> level;
    Exponents e(n, 0);
    std::function<void(int, int)> rec = [&](int var, int left) {
      if (var == n - 1) {
        e[var] = static_cast<uint16_t>(left);
        level.push_back(e);
        return;
      }
      for (int k = left; k >= 0; --k) {
        e[var] = static_cast<uint16_t>(k);
        rec(var + 1, left - k);
      }
    };
    if (n == 0) {
      if (deg == 0) level.push_back(e);
    } else {
      rec(0, deg);
    }
    for (auto& m : level) {
      index_.emplace(m, static_cast<long>(monomials_.size()));
      monomials_.push_back(std::move(m));
    }
  }
}

long MonomialBasis::index_of(const Exponents& e) const {
  auto it = index_.find(e);
  return it == index_.end() ? -1 : it->second;
}

// ---------------------------------------------------------------------------------------------
// Parser: expr := term (('+'|'-') term)* ; term := unary (('*'|'/') unary)* ; unary := ('-'|'+') unary | power
// power := atom ('^' integer)? ; atom := number | name | '(' expr ')'
// Every product needs its '*': "2x1" or "x1 x2" is a missing operator, not a product, so that a typo such
// as "x1^0.5" (which would otherwise read as x1^0 times .5) is an error with its position.
namespace {

// Limits that keep a mistyped or hostile expression from expanding without bound.
constexpr int kMaxExponent = 64;
constexpr int kMaxDegree = 256;
constexpr std::size_t kMaxTermProducts = 1'000'000;  // work of one product of expanded polynomials
constexpr int kMaxNesting = 200;                     // parentheses and signs: keeps the recursion off the stack limit

class Parser {
 public:
  Parser(const std::string& text, const std::vector<std::string>& names) : s_(text), names_(names) {}

  Polynomial parse() {
    skip();
    if (pos_ >= s_.size()) fail("empty expression; expected a polynomial such as 2*x1^2 - x2 + 1");
    Polynomial p = expr();
    skip();
    if (pos_ < s_.size()) {
      if (starts_atom()) fail(missing_operator());
      fail(fmt::format("unexpected '{}'; expected an operator (+, -, *, /, ^) or the end", s_[pos_]));
    }
    for (const auto& [e, c] : p.terms())
      if (!std::isfinite(c)) {
        pos_ = 0;
        fail("a coefficient overflows double precision; rescale the numbers");
      }
    return p;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw PolynomialParseError(fmt::format("at position {}: {}", pos_ + 1, why), pos_);
  }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool peek(char c) {
    skip();
    return pos_ < s_.size() && s_[pos_] == c;
  }
  int n() const { return static_cast<int>(names_.size()); }
  std::string missing_operator() const {
    std::size_t end = pos_;
    while (end < s_.size() && end < pos_ + 12 && !std::isspace(static_cast<unsigned char>(s_[end]))) ++end;
    return fmt::format("missing operator before '{}'; write '*' for a product (e.g. 2*x1, x1*x2)",
                       s_.substr(pos_, end - pos_));
  }

  Polynomial product(const Polynomial& a, const Polynomial& b, std::size_t at) {
    if (a.terms().size() * b.terms().size() > kMaxTermProducts || a.degree() + b.degree() > kMaxDegree) {
      pos_ = at;
      fail(fmt::format("the expression expands beyond {} term products or degree {}; expand it less", kMaxTermProducts,
                       kMaxDegree));
    }
    return a * b;
  }

  Polynomial expr() {
    Polynomial p = term();
    while (true) {
      if (peek('+')) {
        ++pos_;
        p += term();
      } else if (peek('-')) {
        ++pos_;
        p -= term();
      } else {
        return p;
      }
    }
  }
  bool starts_atom() {
    skip();
    if (pos_ >= s_.size()) return false;
    const char c = s_[pos_];
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '(' || c == '.';
  }
  Polynomial term() {
    Polynomial p = unary();
    while (true) {
      if (peek('*')) {
        const std::size_t at = pos_++;
        p = product(p, unary(), at);
      } else if (peek('/')) {
        ++pos_;
        const std::size_t at = pos_;
        const Polynomial d = unary();
        if (d.degree() > 0) {
          pos_ = at;
          fail("division is only by a constant");
        }
        if (d.constant_term() == 0.0) {
          pos_ = at;
          fail("division by zero");
        }
        p *= 1.0 / d.constant_term();
      } else if (starts_atom()) {
        fail(missing_operator());
      } else {
        return p;
      }
    }
  }
  // Counts the recursion depth of one nested construct.
  struct Nested {
    Parser& p;
    explicit Nested(Parser& parser) : p(parser) {
      if (++p.depth_ > kMaxNesting) p.fail(fmt::format("nesting deeper than {} levels", kMaxNesting));
    }
    ~Nested() { --p.depth_; }
  };
  Polynomial unary() {
    const Nested guard(*this);
    if (peek('-')) {
      ++pos_;
      return -unary();
    }
    if (peek('+')) {
      ++pos_;
      return unary();
    }
    return power();
  }
  // The exponent after '^': digits only, at most kMaxExponent.
  int exponent() {
    skip();
    const std::size_t start = pos_;
    while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    if (start == pos_) fail("expected a non-negative integer exponent after '^'");
    if (pos_ < s_.size() && (s_[pos_] == '.' || s_[pos_] == 'e' || s_[pos_] == 'E')) {
      pos_ = start;
      fail("exponents must be non-negative integers (a polynomial has no fractional powers)");
    }
    const std::string digits = s_.substr(start, pos_ - start);
    if (digits.size() > 3 || std::stoi(digits) > kMaxExponent) {
      pos_ = start;
      fail(fmt::format("exponent {} is larger than {}", digits, kMaxExponent));
    }
    return std::stoi(digits);
  }
  Polynomial power() {
    Polynomial base = atom();
    if (!peek('^')) return base;
    const std::size_t at = pos_++;
    const int k = exponent();
    Polynomial r = Polynomial::Constant(n(), 1.0);
    for (int i = 0; i < k; ++i) r = product(r, base, at);
    return r;
  }
  // A decimal number: digits, an optional fraction, an optional exponent (no hex, inf or nan).
  Polynomial number() {
    const std::size_t start = pos_;
    auto digits = [&] {
      const std::size_t b = pos_;
      while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
      return pos_ - b;
    };
    std::size_t mantissa = digits();
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      mantissa += digits();
    }
    if (mantissa == 0) {
      pos_ = start;
      fail("malformed number");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      const std::size_t e = pos_++;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) {
        pos_ = e;
        fail("malformed number: expected digits after the exponent 'e'");
      }
    }
    const double v = std::strtod(s_.substr(start, pos_ - start).c_str(), nullptr);
    if (!std::isfinite(v)) {
      pos_ = start;
      fail("number out of the range of double precision");
    }
    return Polynomial::Constant(n(), v);
  }
  Polynomial atom() {
    skip();
    if (pos_ >= s_.size()) fail("unexpected end; expected a number, a variable or '('");
    const char c = s_[pos_];
    if (c == '(') {
      const Nested guard(*this);
      ++pos_;
      Polynomial p = expr();
      if (!peek(')')) fail("expected ')'");
      ++pos_;
      return p;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
      const std::string name = s_.substr(start, pos_ - start);
      for (int i = 0; i < n(); ++i)
        if (names_[i] == name) return Polynomial::Variable(n(), i);
      pos_ = start;
      std::string known;
      for (const auto& nm : names_) known += (known.empty() ? "" : ", ") + nm;
      fail(fmt::format("unknown variable '{}'; the variables are: {}", name, known));
    }
    fail(fmt::format("unexpected '{}'; expected a number, a variable or '('", c));
  }

  const std::string& s_;
  const std::vector<std::string>& names_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

Polynomial parse_polynomial(const std::string& text, const std::vector<std::string>& names) {
  return Parser(text, names).parse();
}

}  // namespace hw
