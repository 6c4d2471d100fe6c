#pragma once
// Sparse multivariate polynomials with real coefficients over a fixed number of variables.
// A monomial is its exponent vector; a polynomial maps monomials to coefficients (zero terms dropped).
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace hw {

using Exponents = std::vector<uint16_t>;

int degree_of(const Exponents& e);
Exponents add_exponents(const Exponents& a, const Exponents& b);

// Graded lexicographic order: lower total degree first, then lexicographic (x1 before x2).
struct GradedLess {
  bool operator()(const Exponents& a, const Exponents& b) const;
};

struct ExponentsHash {
  std::size_t operator()(const Exponents& e) const;
};

class Polynomial {
 public:
  using Terms = std::map<Exponents, double, GradedLess>;

  explicit Polynomial(int num_vars = 0) : num_vars_(num_vars) {}
  static Polynomial Constant(int num_vars, double c);
  static Polynomial Variable(int num_vars, int index, double coefficient = 1.0);  // coefficient * x_index
  static Polynomial Monomial(const Exponents& e, double coefficient = 1.0);

  int num_vars() const { return num_vars_; }
  const Terms& terms() const { return terms_; }
  bool is_zero() const { return terms_.empty(); }
  int degree() const;  // -1 for the zero polynomial
  double coefficient(const Exponents& e) const;
  double constant_term() const;
  void add_term(const Exponents& e, double c);

  Polynomial& operator+=(const Polynomial& o);
  Polynomial& operator-=(const Polynomial& o);
  Polynomial& operator*=(double s);
  friend Polynomial operator+(Polynomial a, const Polynomial& b) { return a += b; }
  friend Polynomial operator-(Polynomial a, const Polynomial& b) { return a -= b; }
  friend Polynomial operator*(const Polynomial& a, const Polynomial& b);
  friend Polynomial operator*(Polynomial a, double s) { return a *= s; }
  friend Polynomial operator*(double s, Polynomial a) { return a *= s; }
  Polynomial operator-() const { return *this * -1.0; }
  Polynomial pow(int k) const;

  double evaluate(const std::vector<double>& x) const;
  // Replaces variable `var` by polynomial `value` (same number of variables).
  Polynomial substitute(int var, const Polynomial& value) const;
  // Replaces every variable i by replacement[i] (all with the same number of variables).
  Polynomial compose(const std::vector<Polynomial>& replacement) const;
  // Drops terms with |coefficient| <= tol.
  void prune(double tol = 0.0);
  double max_abs_coefficient() const;

  std::string to_string(const std::vector<std::string>& names = {}) const;

 private:
  int num_vars_ = 0;
  Terms terms_;
};

// All monomials of total degree <= d in n variables, in graded order, with a reverse index.
class MonomialBasis {
 public:
  MonomialBasis(int num_vars, int max_degree);
  int num_vars() const { return num_vars_; }
  int max_degree() const { return max_degree_; }
  std::size_t size() const { return monomials_.size(); }
  const Exponents& operator[](std::size_t i) const { return monomials_[i]; }
  const std::vector<Exponents>& monomials() const { return monomials_; }
  // Index of a monomial, or -1 when its degree exceeds max_degree.
  long index_of(const Exponents& e) const;
  // Number of monomials of degree <= d in n variables: C(n + d, d).
  static std::size_t count(int num_vars, int max_degree);

 private:
  int num_vars_, max_degree_;
  std::vector<Exponents> monomials_;
  std::unordered_map<Exponents, long, ExponentsHash> index_;
};

struct PolynomialParseError : std::runtime_error {
  PolynomialParseError(const std::string& what, std::size_t position)
      : std::runtime_error(what), position(position) {}
  std::size_t position;  // 0-based character offset in the parsed text
};

// Parses text such as "2*x1^2*x3 - 0.5*x2 + 1" or "(x1 + x2)^2 - 3*x1" over the given variable names.
// Every product needs '*' ("2x1" is an error), exponents are integers 0..64, numbers are decimal; errors give
// the position and the reason.
Polynomial parse_polynomial(const std::string& text, const std::vector<std::string>& names);

// Names x1..xn.
std::vector<std::string> default_variable_names(int n);

}  // namespace hw
