#include <gtest/gtest.h>

#include "core/polynomial.hpp"

namespace hw {

TEST(Polynomial, ArithmeticAndEvaluation) {
  const auto names = default_variable_names(3);
  auto p = parse_polynomial("2*x1^2*x3 - 0.5*x2 + 1", names);
  EXPECT_EQ(p.degree(), 3);
  EXPECT_DOUBLE_EQ(p.evaluate({1, 2, 3}), 2 * 1 * 3 - 1 + 1);
  auto q = parse_polynomial("(x1 + x2)^2", names);
  auto expanded = parse_polynomial("x1^2 + 2*x1*x2 + x2^2", names);
  EXPECT_TRUE((q - expanded).is_zero());
  EXPECT_DOUBLE_EQ((p * q).evaluate({0.5, -1, 2}), p.evaluate({0.5, -1, 2}) * q.evaluate({0.5, -1, 2}));
}

TEST(Polynomial, SubstitutionAndComposition) {
  const auto names = default_variable_names(2);
  auto p = parse_polynomial("x1^2 + x2", names);
  auto r = p.substitute(0, parse_polynomial("x2 + 1", names));
  EXPECT_TRUE((r - parse_polynomial("x2^2 + 3*x2 + 1", names)).is_zero()) << r.to_string();
}

TEST(Polynomial, ParserReportsPositionAndReason) {
  const auto names = default_variable_names(2);
  try {
    parse_polynomial("2*x1 + y", names);
    FAIL();
  } catch (const PolynomialParseError& e) {
    EXPECT_EQ(e.position, 7u);
    EXPECT_NE(std::string(e.what()).find("unknown variable 'y'"), std::string::npos);
  }
  EXPECT_THROW(parse_polynomial("x1^", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("(x1 + x2", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("x1 / x2", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("x1 / 0", names), PolynomialParseError);
  EXPECT_DOUBLE_EQ(parse_polynomial("x1^6/3", names).evaluate({2, 0}), 64.0 / 3);
}

TEST(MonomialBasis, CountsAndIndex) {
  MonomialBasis b(8, 3);
  EXPECT_EQ(b.size(), 165u);
  EXPECT_EQ(MonomialBasis::count(8, 6), 3003u);
  for (std::size_t i = 0; i < b.size(); ++i) EXPECT_EQ(b.index_of(b[i]), static_cast<long>(i));
  EXPECT_EQ(degree_of(b[0]), 0);
  Exponents too_high(8, 0);
  too_high[0] = 4;
  EXPECT_EQ(b.index_of(too_high), -1);
}

}  // namespace hw
