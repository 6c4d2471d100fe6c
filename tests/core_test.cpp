#include <gtest/gtest.h>

#include "core/csv_table.hpp"
#include "core/hw_model.hpp"

namespace hw {

TEST(CsvTable, ParsesHeaderAndRows) {
  auto t = parse_csv("# comment\nt,u,y\n0,1,2\n1,3,4\n", "mem");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_DOUBLE_EQ(t.column("y")[1], 4.0);
}

TEST(CsvTable, ErrorsNameLineAndColumn) {
  try {
    parse_csv("t,u\n0,1\n1,abc\n", "rec.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rec.csv:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'u'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_csv("t,u\n0,nan\n", "x"), InputError);
  EXPECT_THROW(parse_csv("t,u\n", "x").column("y"), InputError);
}

TEST(HwModel, LinearBlockFollowsPaperConvention) {
  // z_t = -a1 z_{t-1} + b0 x_t: impulse response of 1/(1 + 0.5 q^-1) is (-0.5)^t.
  LinearBlock lin{{0.5}, {1.0}, 0};
  auto z = lin.simulate({1, 0, 0, 0});
  EXPECT_DOUBLE_EQ(z[3], -0.125);
}

TEST(HwModel, JsonRoundTrip) {
  HwModel m;
  m.input = StaticMap::Polynomial({1.0, 0.4, -0.1});
  m.linear = {{1.8, 0.9}, {0.0, 1.6, 2.1}, 0};
  m.output = StaticMap::PiecewiseLinear({-1, 0, 1}, {-2, 0, 1});
  auto back = HwModel::from_json(m.to_json());
  std::vector<double> u{1, -2, 3, 0.5, 0.1};
  EXPECT_EQ(m.simulate(u), back.simulate(u));
  EXPECT_THROW(HwModel::from_json({{"linear", {{"a", {1}}}}}), InputError);
}

}  // namespace hw
