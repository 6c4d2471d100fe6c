// Every JSON reader rejects keys it does not know, naming the key, the file and the allowed keys (issue
// item 2: a typo such as "constraint" silently dropped the constraints).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "compare/scenario.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "estimators/brouri/experiment.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "pop/pop_json.hpp"
#include "tests/test_support.hpp"

namespace hw {
namespace {

using nlohmann::json;

using testing_support::ErrorOf;
using testing_support::Has;

TEST(PopJsonKeys, UnknownKeyIsAnErrorNamingKeyFileAndAllowedKeys) {
  const auto j = json::parse(R"({"variables":["x1"],"minimize":"x1","constraint":["x1 >= 4"]})");
  const std::string e = ErrorOf([&] { pop::ParsePolyProblem(j, "p.json"); });
  EXPECT_TRUE(Has(e, "p.json")) << e;
  EXPECT_TRUE(Has(e, "unknown key 'constraint'")) << e;
  EXPECT_TRUE(Has(e, "constraints")) << e;  // the allowed keys are listed
  EXPECT_THROW(pop::ParsePolyProblem(json::parse(R"({"variables":["x1"],"minimize":"x1","box":{"x1":[0,1],"y":[0,1]}})"),
                                       "p.json"),
               InputError);
  EXPECT_THROW(pop::ParsePolyProblem(json::parse(R"({"variables":["x1","x1"],"minimize":"x1"})"), "p.json"),
               InputError);
  EXPECT_THROW(pop::ParsePolyProblem(json::parse(R"({"variables":["x1"],"minimize":"x1","box":{"x1":["a",1]}})"),
                                       "p.json"),
               InputError);
}

json CeroneModel() {
  return json::parse(R"({"type": "hammerstein_wiener", "name": "m",
    "input_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0.4, -0.1]},
    "linear": {"a": [1.8, 0.9], "b": [0, 1.6, 2.1], "delay": 0},
    "output_nonlinearity": {"kind": "identity"}})");
}

TEST(ModelJson, UnknownKeysAreErrorsAtEveryLevel) {
  EXPECT_NO_THROW(HwModel::from_json(CeroneModel()));
  auto top = CeroneModel();
  top["linar"] = top["linear"];
  const std::string e = ErrorOf([&] { HwModel::from_json(top); });
  EXPECT_TRUE(Has(e, "unknown key 'linar'")) << e;
  EXPECT_TRUE(Has(e, "output_nonlinearity")) << e;
  auto lin = CeroneModel();
  lin["linear"]["dealy"] = 1;
  EXPECT_TRUE(Has(ErrorOf([&] { HwModel::from_json(lin); }), "unknown key 'dealy'"));
  auto map = CeroneModel();
  map["input_nonlinearity"]["coeffs"] = json::array({1});
  EXPECT_TRUE(Has(ErrorOf([&] { HwModel::from_json(map); }), "unknown key 'coeffs'"));
  auto delay = CeroneModel();
  delay["linear"]["delay"] = 1.5;
  EXPECT_THROW(HwModel::from_json(delay), InputError);
  // A caller that reads more keys itself names them.
  auto extended = CeroneModel();
  extended["effect_block"] = json::object();
  EXPECT_THROW(HwModel::from_json(extended), InputError);
  EXPECT_NO_THROW(HwModel::from_json(extended, {"effect_block"}));
}

TEST(ModelJson, FileErrorsNameTheFile) {
  const std::string path = ::testing::TempDir() + "/strict_model.json";
  auto j = CeroneModel();
  j["nmae"] = "typo";
  std::ofstream(path) << j.dump();
  const std::string e = ErrorOf([&] { HwModel::load(path); });
  EXPECT_TRUE(Has(e, path)) << e;
  EXPECT_TRUE(Has(e, "unknown key 'nmae'")) << e;
}

TEST(ScenarioJson, UnknownKeysInsideTheModelAndSystemAreErrors) {
  json s = {{"name", "x"}, {"plant", "hw"}, {"model", CeroneModel()}, {"noise", {{"snr_db", 31}}},
            {"setmembership", {{"samples", 50}, {"horizon", 1}, {"order", 1}}}};
  EXPECT_NO_THROW(compare::Scenario::FromJson(s, "s.json"));
  s["model"]["linear"]["bb"] = json::array({1});
  const std::string e = ErrorOf([&] { compare::Scenario::FromJson(s, "s.json"); });
  EXPECT_TRUE(Has(e, "s.json")) << e;
  EXPECT_TRUE(Has(e, "unknown key 'bb'")) << e;
  json b = {{"name", "b"}, {"plant", "backlash"}, {"system", brouri::BacklashHwSystem::PaperExample().to_json()}};
  EXPECT_NO_THROW(compare::Scenario::FromJson(b, "b.json"));
  b["system"]["noise"] = 0.1;
  EXPECT_TRUE(Has(ErrorOf([&] { compare::Scenario::FromJson(b, "b.json"); }), "unknown key 'noise'"));
}

TEST(ConstraintsJson, UnknownSlopeKeyIsAnError) {
  const auto ok = json::parse(R"({"f": {"slopes": [{"from": 0, "to": 1, "min": 0}]}})");
  EXPECT_NO_THROW(esmaeilani::Constraints::FromJson(ok, "c.json"));
  const auto bad = json::parse(R"({"f": {"slopes": [{"from": 0, "to": 1, "minimum": 0}]}})");
  const std::string e = ErrorOf([&] { esmaeilani::Constraints::FromJson(bad, "c.json"); });
  EXPECT_TRUE(Has(e, "c.json")) << e;
  EXPECT_TRUE(Has(e, "unknown key 'minimum'")) << e;
}

TEST(BrouriJson, PlansEstimatesAndSystemsRejectUnknownKeys) {
  const auto plan = brouri::MakeStepPlan({0, 1, 2}, {1.5, 0.5}, -1, 0.5, 10, 10);
  auto j = plan.to_json();
  EXPECT_NO_THROW(brouri::StepPlan::from_json(j));
  j["averge_samples"] = 20;
  EXPECT_TRUE(Has(ErrorOf([&] { brouri::StepPlan::from_json(j); }), "unknown key 'averge_samples'"));
  auto sys = brouri::BacklashHwSystem::PaperExample().to_json();
  sys["nosie_std"] = 0.1;
  EXPECT_TRUE(Has(ErrorOf([&] { brouri::BacklashHwSystem::from_json(sys); }), "unknown key 'nosie_std'"));
}

}  // namespace
}  // namespace hw
