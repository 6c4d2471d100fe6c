// An empty feasible set is a result: when every sign orthant is proven empty, `bounds` says that no
// parameter in the box explains the data (certified model invalidation), lists the certificates, writes
// "invalidated": true with null intervals and exits with status 3. Tested on a recording of a system outside
// the model class: a dead zone (piecewise linear, flat around 0) that no cubic input map can express, with a
// small noise bound.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "tests/test_support.hpp"

#ifdef HW_CLI_PATH
namespace hw {
namespace {

namespace fs = std::filesystem;

using testing_support::Has;

int Cli(const std::string& args, std::string* output) {
  const auto r = testing_support::RunCli(args);
  *output += r.output;
  return r.code;
}

fs::path Dir() {
  const fs::path d = fs::path(::testing::TempDir()) / "model_invalidation";
  fs::create_directories(d);
  return d;
}

TEST(ModelInvalidation, DeadZoneRecordingInvalidatesTheCubicModelClass) {
  const fs::path d = Dir();
  std::ofstream(d / "deadzone.json") << R"({"type": "hammerstein_wiener",
    "input_nonlinearity": {"kind": "piecewise_linear", "x": [-2, -0.5, 0.5, 2], "y": [-1.5, 0, 0, 1.5]},
    "linear": {"a": [-0.5], "b": [0, 1, 0.8]}, "output_nonlinearity": {"kind": "identity"}})";
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  CsvTable u;
  std::vector<double> values(60);
  for (double& v : values) v = uniform(rng);
  u.add_column("u", values);
  write_csv((d / "u.csv").string(), u);
  std::string sim;
  ASSERT_EQ(Cli("simulate --model " + (d / "deadzone.json").string() + " --input " + (d / "u.csv").string() +
                    " --noise-bound 0.001 --out " + (d / "rec.csv").string(),
                &sim),
            0)
      << sim;
  std::string out;
  const int code = Cli("bounds --data " + (d / "rec.csv").string() + " --noise-col noise_bound --horizon 1 --order 1 "
                       "--threads 2 --quiet --json " + (d / "b.json").string(),
                       &out);
  EXPECT_EQ(code, 3) << out;
  EXPECT_TRUE(Has(out, "VERDICT: model invalidated")) << out;
  EXPECT_TRUE(Has(out, "no parameter in the prior box explains the data") ||
              Has(out, "No parameter in the prior box explains the data"))
      << out;
  EXPECT_TRUE(Has(out, "all 16 sign orthants are proven empty")) << out;
  EXPECT_TRUE(Has(out, "orthant  15")) << out;  // one certificate line per orthant
  EXPECT_TRUE(Has(out, "16 of them verified in interval arithmetic")) << out;
  EXPECT_TRUE(Has(out, "): LP screen infeasible, verified in interval arithmetic")) << out;
  EXPECT_TRUE(Has(out, "hwbounds diagnose")) << out;
  EXPECT_FALSE(Has(out, "conservative fallbacks")) << out;
  EXPECT_FALSE(Has(out, "0.000000     0.000000")) << "intervals printed as zeros: " << out;
  nlohmann::json j;
  std::ifstream(d / "b.json") >> j;
  EXPECT_TRUE(j.at("invalidated").get<bool>());
  ASSERT_FALSE(j.at("intervals").empty());
  for (const auto& iv : j.at("intervals")) {
    EXPECT_TRUE(iv.at("lower").at("value").is_null()) << iv.dump();
    EXPECT_TRUE(iv.at("upper").at("value").is_null()) << iv.dump();
  }
  // Each orthant says how its emptiness was certified.
  ASSERT_EQ(j.at("orthants").size(), 16u);
  for (const auto& o : j.at("orthants")) {
    const auto& c = o.at("certificate");
    ASSERT_TRUE(c.is_object()) << o.dump();
    EXPECT_EQ(c.at("kind"), "lp") << o.dump();
    EXPECT_TRUE(c.at("order").is_null()) << o.dump();
    EXPECT_EQ(c.at("contracted_box"), false) << o.dump();
    EXPECT_EQ(c.at("verified"), true) << o.dump();
  }
}

TEST(ModelInvalidation, ARecordingInsideTheClassIsNotInvalidated) {
  const fs::path d = Dir();
  const auto ex = SimulateCeroneExample(2, 40);
  CsvTable t;
  t.add_column("u", ex.u);
  t.add_column("y", ex.y);
  write_csv((d / "inside.csv").string(), t);
  std::string out;
  const int code = Cli("bounds --data " + (d / "inside.csv").string() + " --noise-bound " +
                           std::to_string(ex.noise_bound) + " --horizon 1 --threads 2 --quiet --json " +
                           (d / "inside.json").string(),
                       &out);
  EXPECT_EQ(code, 0) << out;
  EXPECT_FALSE(Has(out, "VERDICT")) << out;
  nlohmann::json j;
  std::ifstream(d / "inside.json") >> j;
  EXPECT_FALSE(j.at("invalidated").get<bool>());
  // An orthant has a certificate exactly when it is proven empty.
  for (const auto& o : j.at("orthants")) {
    const bool empty = o.at("status").get<std::string>().rfind("empty", 0) == 0;
    EXPECT_EQ(o.at("certificate").is_object(), empty) << o.dump();
  }
}

}  // namespace
}  // namespace hw
#endif
