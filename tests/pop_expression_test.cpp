// A polynomial expression that is not what it seems is an error with its position, never a different
// problem (issue item 1: "x1^0.5" was read as x1^0 times .5, and juxtaposition multiplied).
#include <gtest/gtest.h>

#include <string>

#include "core/csv_table.hpp"
#include "core/polynomial.hpp"
#include "pop/pop_json.hpp"
#include "tests/test_support.hpp"

namespace hw {
namespace {

using nlohmann::json;

using testing_support::ErrorOf;
using testing_support::Has;

TEST(PolynomialParser, FractionalExponentIsAnErrorAtItsPosition) {
  const std::vector<std::string> names = {"x1"};
  try {
    parse_polynomial("x1^0.5", names);
    FAIL() << "x1^0.5 was accepted";
  } catch (const PolynomialParseError& e) {
    EXPECT_EQ(e.position, 3u) << e.what();
    EXPECT_TRUE(Has(e.what(), "non-negative integers")) << e.what();
  }
  EXPECT_THROW(parse_polynomial("x1^2.", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("x1^1e2", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("x1^-1", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("x1^99999999999999", names), PolynomialParseError);
  EXPECT_DOUBLE_EQ(parse_polynomial("x1^0 + x1^3", names).evaluate({2}), 9.0);
}

TEST(PolynomialParser, MissingOperatorIsAnErrorWithItsPosition) {
  const std::vector<std::string> names = {"x1", "x2"};
  for (const auto& [text, position] : std::vector<std::pair<std::string, std::size_t>>{
           {"2x1", 1}, {"x1 x1", 3}, {"2 x1 + 1", 2}, {"(x1 + 1)(x2 - 1)", 8}, {"x1 .5", 3}}) {
    try {
      parse_polynomial(text, names);
      ADD_FAILURE() << "'" << text << "' was accepted";
    } catch (const PolynomialParseError& e) {
      EXPECT_EQ(e.position, position) << text << ": " << e.what();
      EXPECT_TRUE(Has(e.what(), "missing operator")) << text << ": " << e.what();
    }
  }
  EXPECT_DOUBLE_EQ(parse_polynomial("2*x1*x2 - x2/4", names).evaluate({1.5, 2}), 5.5);
}

TEST(PolynomialParser, NumbersAreDecimalAndFinite) {
  const std::vector<std::string> names = {"x1"};
  EXPECT_THROW(parse_polynomial("0x10 + x1", names), PolynomialParseError);  // hex is not read as 16
  EXPECT_THROW(parse_polynomial("1e999 * x1", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("1e", names), PolynomialParseError);
  EXPECT_THROW(parse_polynomial("(1e300 * x1)^2", names), PolynomialParseError);  // overflowing coefficient
  EXPECT_THROW(parse_polynomial("((x1 + 1)^64)^64", names), PolynomialParseError);  // expands without bound
  EXPECT_DOUBLE_EQ(parse_polynomial("2.5e1*x1 + .5", names).evaluate({1}), 25.5);
}

TEST(PopJson, TheIssuesFractionalPowerProblemIsRejected) {
  const auto j = json::parse(R"({"variables":["x1"],"minimize":"x1^0.5","constraints":["x1 >= 4","x1 <= 9"]})");
  const std::string e = ErrorOf([&] { pop::ParsePolyProblem(j, "p.json"); });
  EXPECT_TRUE(Has(e, "p.json: minimize")) << e;
  EXPECT_TRUE(Has(e, "position 4")) << e;
}

}  // namespace
}  // namespace hw
