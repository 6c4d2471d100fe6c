// Every parser of user input, fed random and grammar-aware mutated inputs in-process: CSV recordings,
// polynomial expressions, and every JSON reader (pop problems, models, scenarios, constraints, Brouri plans,
// estimates and systems). Each input must end in a result or a clear InputError (never another exception, a
// crash or a hang), and inputs that are invalid by construction (an unknown key, a typo in a key, truncated
// JSON, a fractional exponent, a missing operator, a duplicate column, a cell that is no number) must be
// rejected. Accepted inputs must mean what they say (invariants checked below). Seeded: reproducible.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <string>

#include "compare/scenario.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "core/json_input.hpp"
#include "core/polynomial.hpp"
#include "estimators/brouri/experiment.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "relax/pop_json.hpp"

namespace hw {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr int kInputsPerParser = 10000;

enum class Expect { kEither, kInvalid };

// Runs one parser over many inputs and keeps the first few failures for the report.
class Harness {
 public:
  explicit Harness(std::string name) : name_(std::move(name)) {}
  ~Harness() {
    EXPECT_TRUE(failures_.empty()) << name_ << ": " << failures_.size() << " failures, first:\n" << first_failures_;
    EXPECT_GE(accepted_ + rejected_, kInputsPerParser) << name_;
    EXPECT_LT(slowest_, 2.0) << name_ << ": slowest input took " << slowest_ << " s: " << slowest_input_;
    std::printf("%-22s %6d inputs: %6d accepted, %6d rejected, slowest %.4f s\n", name_.c_str(), accepted_ + rejected_,
                accepted_, rejected_, slowest_);
  }
  // `parse` returns normally (accepted; it may check invariants by throwing std::logic_error) or throws.
  void Feed(const std::string& input, Expect expect, const std::function<void(const std::string&)>& parse) {
    const auto t0 = Clock::now();
    std::string failure;
    try {
      parse(input);
      ++accepted_;
      if (expect == Expect::kInvalid) failure = "accepted an invalid input";
    } catch (const InputError&) {
      ++rejected_;
    } catch (const PolynomialParseError&) {
      ++rejected_;
    } catch (const std::logic_error& e) {
      failure = std::string("accepted, but ") + e.what();
    } catch (const std::exception& e) {
      failure = std::string("escaped ") + typeid(e).name() + ": " + e.what();
    }
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (s > slowest_) slowest_ = s, slowest_input_ = input.substr(0, 200);
    if (!failure.empty()) {
      failures_.push_back(failure);
      if (failures_.size() <= 5) first_failures_ += failure + " <<" + input.substr(0, 300) + ">>\n";
    }
  }

 private:
  std::string name_, first_failures_, slowest_input_;
  std::vector<std::string> failures_;
  int accepted_ = 0, rejected_ = 0;
  double slowest_ = 0.0;
};

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : rng_(seed) {}
  int Int(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool Coin(double p = 0.5) { return std::bernoulli_distribution(p)(rng_); }
  template <class T>
  const T& Pick(const std::vector<T>& v) { return v[Int(0, static_cast<int>(v.size()) - 1)]; }

  // Character-level edits drawn from an alphabet (the format's own characters, so that edits stay near it).
  std::string Text(std::string s, const std::string& alphabet, int edits) {
    for (int k = 0; k < edits; ++k) {
      const int op = Int(0, 4);
      const std::size_t at = s.empty() ? 0 : static_cast<std::size_t>(Int(0, static_cast<int>(s.size()) - 1));
      const char c = alphabet[Int(0, static_cast<int>(alphabet.size()) - 1)];
      if (op == 0 || s.empty()) s.insert(s.begin() + std::min(at, s.size()), c);
      else if (op == 1) s.erase(at, 1);
      else if (op == 2) s[at] = c;
      else if (op == 3) s.insert(at, s.substr(at, Int(1, 8)));  // duplicate a slice
      else s.erase(at, Int(1, 8));
    }
    return s;
  }
  std::string Random(const std::string& alphabet, int length) {
    std::string s;
    for (int k = 0; k < length; ++k) s += alphabet[Int(0, static_cast<int>(alphabet.size()) - 1)];
    return s;
  }

  // Tree-level edits of a JSON document.
  json RandomValue(int depth = 0) {
    switch (Int(0, depth > 1 ? 5 : 7)) {
      case 0: return nullptr;
      case 1: return Coin();
      case 2: return Pick<double>({0, -1, 1.5, 1e308, -1e-300, 3, 1e6, -7});
      case 3: return Int(-5, 5);
      case 4: return Pick<std::string>({"", "x1", "identity", "polynomial", "a", "backlash", "sdpa", "1e999"});
      case 5: return json::array();
      case 6: return json::array({RandomValue(depth + 1), RandomValue(depth + 1)});
      default: return json{{"k", RandomValue(depth + 1)}};
    }
  }
  // A pointer to a random node of `j` (objects and arrays included) and the objects among them.
  void Nodes(json& j, std::vector<json*>* all, std::vector<json*>* objects) {
    all->push_back(&j);
    if (j.is_object()) {
      objects->push_back(&j);
      for (auto& [k, v] : j.items()) Nodes(v, all, objects);
    } else if (j.is_array()) {
      for (auto& v : j) Nodes(v, all, objects);
    }
  }
  // Replaces, removes or duplicates a random node's content (validity unknown).
  json Edit(json j) {
    std::vector<json*> all, objects;
    Nodes(j, &all, &objects);
    json* n = all[Int(0, static_cast<int>(all.size()) - 1)];
    const int op = Int(0, 3);
    if (op == 0 && n != &j) *n = RandomValue();
    else if (op == 1 && n->is_object() && !n->empty()) n->erase(n->begin());
    else if (op == 2 && n->is_array() && !n->empty()) n->push_back(n->back());
    else if (n->is_array()) n->clear();
    else if (n != &j) *n = RandomValue();
    return j;
  }
  // An unknown key in a random object, or a typo in one of its keys: invalid for a strict reader.
  json UnknownKey(json j) {
    std::vector<json*> all, objects;
    Nodes(j, &all, &objects);
    json& o = *objects[Int(0, static_cast<int>(objects.size()) - 1)];
    if (Coin() && !o.empty()) {
      auto it = o.begin();
      std::advance(it, Int(0, static_cast<int>(o.size()) - 1));
      const std::string key = it.key();
      json value = it.value();
      o.erase(key);
      o[key + "_typo"] = value;
    } else {
      o["unknown_" + std::to_string(Int(0, 99))] = RandomValue();
    }
    return j;
  }

 private:
  std::mt19937_64 rng_;
};

// ---------------------------------------------------------------------------------------------------------
// Polynomial expressions.

const std::vector<std::string> kVariables = {"x1", "x2", "x3"};

void ParseExpression(const std::string& text) {
  const Polynomial p = parse_polynomial(text, kVariables);
  for (const auto& [e, c] : p.terms())
    if (!std::isfinite(c)) throw std::logic_error("non-finite coefficient");
  // Accepted text means what it prints: its printed form parses back to the same polynomial.
  const Polynomial q = parse_polynomial(p.to_string(kVariables), kVariables);
  if ((p - q).max_abs_coefficient() > 1e-9 * (1.0 + p.max_abs_coefficient()))
    throw std::logic_error("printed form parses to a different polynomial: " + p.to_string(kVariables));
}

TEST(ParserFuzz, PolynomialExpressions) {
  const std::vector<std::string> seeds = {"2*x1^2*x3 - 0.5*x2 + 1", "(x1 + x2)^2 - 3*x1", "x1^6/3 - 2.1*x1^4 + x2",
                                          "-(x2 - 1)*(x3 + 2)", "1e-3*x1*x2*x3 + .5", "x3^0 - +x1"};
  const std::string alphabet = "x123 .+-*/^()e0579";
  Mutator m(1);
  Harness h("polynomial expression");
  for (const auto& s : seeds) h.Feed(s, Expect::kEither, ParseExpression);
  for (int i = 0; i < kInputsPerParser; ++i) {
    const std::string seed = m.Pick(seeds);
    switch (i % 6) {
      case 0: h.Feed(m.Text(seed, alphabet, m.Int(1, 4)), Expect::kEither, ParseExpression); break;
      case 1: h.Feed(m.Random(alphabet, m.Int(0, 40)), Expect::kEither, ParseExpression); break;
      case 2: {  // a fractional exponent after a variable
        std::string s = seed;
        const auto at = s.find('x');
        s.insert(at + 2, "^0." + std::to_string(m.Int(1, 9)));
        h.Feed(s, Expect::kInvalid, ParseExpression);
        break;
      }
      case 3: {  // a product without its '*'
        std::string s = seed;
        const auto at = s.find('*');
        if (at == std::string::npos) s = "2 " + s;
        else s[at] = ' ';
        h.Feed(s, Expect::kInvalid, ParseExpression);
        break;
      }
      case 4: {  // unbalanced, unknown name, or a dangling operator
        const std::vector<std::string> bad = {"(" + seed, seed + " + y", seed + " +", seed + " ^", seed + ")"};
        h.Feed(m.Pick(bad), Expect::kInvalid, ParseExpression);
        break;
      }
      default:  // nesting far beyond any real expression: refused, not a stack overflow
        h.Feed(std::string(m.Int(250, 20000), m.Coin() ? '(' : '-') + "x1", Expect::kInvalid, ParseExpression);
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// CSV recordings.

void ParseCsv(const std::string& text) {
  const CsvTable t = parse_csv(text, "fuzz.csv");
  std::set<std::string> names(t.names.begin(), t.names.end());
  if (names.size() != t.names.size() || names.count("")) throw std::logic_error("empty or repeated column name");
  if (t.rows() == 0 || t.lines.size() != t.rows()) throw std::logic_error("rows and line numbers disagree");
  for (const auto& c : t.columns) {
    if (c.size() != t.rows()) throw std::logic_error("ragged columns");
    for (double v : c)
      if (!std::isfinite(v)) throw std::logic_error("non-finite cell");
  }
  for (std::size_t r = 1; r < t.lines.size(); ++r)
    if (t.lines[r] <= t.lines[r - 1]) throw std::logic_error("line numbers not increasing");
}

TEST(ParserFuzz, CsvRecordings) {
  const std::vector<std::string> seeds = {"t,u,y\n0,1,2\n1,3,4\n2,-1.5e-3,7\n",
                                          "# recording\nu,y,noise_bound\n0.5,1.25,0.1\n\n-2,3,0.1\n",
                                          "\"t\",\"u\",\"y\"\r\n0,1,2\r\n1,2,3\r\n"};
  const std::string alphabet = "tuy,\n\r#.-e159\" na";
  Mutator m(2);
  Harness h("CSV");
  for (int i = 0; i < kInputsPerParser; ++i) {
    const std::string seed = m.Pick(seeds);
    switch (i % 6) {
      case 0:
      case 1: h.Feed(m.Text(seed, alphabet, m.Int(1, 5)), Expect::kEither, ParseCsv); break;
      case 2: h.Feed(m.Random(alphabet, m.Int(0, 60)), Expect::kEither, ParseCsv); break;
      case 3: {  // a repeated column name in the header
        std::string s = seed;
        std::size_t h0 = 0;
        while (s[h0] == '#') h0 = s.find('\n', h0) + 1;
        const std::size_t h1 = s.find_first_of("\r\n", h0);
        const std::string header = s.substr(h0, h1 - h0);
        s.insert(h1, "," + header.substr(0, header.find(',')));
        h.Feed(s, Expect::kInvalid, ParseCsv);
        break;
      }
      case 4: {  // a cell that is no number, or a short row
        std::string s = seed;
        const auto last = s.rfind(',');
        if (m.Coin()) s.insert(last + 1, "abc");
        else s = s.substr(0, last) + "\n";
        h.Feed(s, Expect::kInvalid, ParseCsv);
        break;
      }
      default: h.Feed(m.Pick<std::string>({"", "\n\n", "# only a comment\n", "t,u\n", ",u\n1,2\n", "t,u\n1,nan\n",
                                           "t,u\n1,1e999\n", "t\n0x10\n", "a,b\n1,2,3\n"}),
                      Expect::kInvalid, ParseCsv);
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// JSON readers: valid seeds, tree edits (validity unknown), unknown keys and typos, truncated text.

struct JsonReader {
  std::string name;
  json seed;
  std::function<void(const json&)> read;
};

json CeroneModelJson() {
  return json::parse(R"({"type": "hammerstein_wiener", "name": "m",
    "input_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0.4, -0.1]},
    "linear": {"a": [1.8, 0.9], "b": [0, 1.6, 2.1], "delay": 0},
    "output_nonlinearity": {"kind": "piecewise_linear", "x": [-1, 0, 1], "y": [-2, 0, 1]}})");
}

std::vector<JsonReader> Readers() {
  const auto steps = brouri::MakeStepPlan({-0.6, 0, 0.6, 1.2}, {1.0, 0.2, -0.6, -1.4}, -0.9, 0.5, 10, 10);
  brouri::NonlinearEstimate est;
  est.degree = 3;
  est.h = {0, 1, 0, -0.2};
  est.params = {1.0, 0.5, 1.0, -0.5};
  est.up = {brouri::HoldAverage{0.1, 0.2, 0.01, 10}};
  const auto sines = brouri::MakeSinePlan(est, {0.05, 0.1}, 1.0, 64, 3, 20);
  return {
      {"pop problem",
       json::parse(R"({"variables": ["x1", "x2"], "minimize": "x1^2 + x2",
                       "constraints": ["x1^2 + x2^2 <= 1", "x1 - x2 == 0", "x2 >= -1"],
                       "box": {"x1": [-2, 2], "x2": [-2, 2]}})"),
       [](const json& j) { relax::ParsePolyProblem(j, "fuzz.json"); }},
      {"model", CeroneModelJson(), [](const json& j) { HwModel::from_json(j); }},
      {"compare scenario",
       json{{"name", "s"}, {"plant", "hw"}, {"model", CeroneModelJson()}, {"output_inverse_polynomial", {1, 0.8}},
            {"input_range", {-2, 2}}, {"noise", {{"snr_db", 31}}},
            {"setmembership", {{"samples", 50}, {"horizon", 1}, {"order", 1}, {"box", 10}, {"parameters", {"a1"}}}},
            {"esmaeilani", {{"segments", 2}, {"samples", 300}, {"hold", {3, 15}}}},
            {"validation", {{"samples", 500}, {"hold", {1, 10}}}},
            {"brouri", {{"periods", 5}, {"omegas", {0.1}}}}},
       [](const json& j) { compare::Scenario::FromJson(j, "fuzz.json"); }},
      {"esmaeilani constraints",
       json::parse(R"({"f": {"range": [0, 1], "slopes": [{"from": 0, "to": 1, "min": 0, "max": 2}],
                             "points": [[0, 0], [1, 0.5, 1]]},
                       "g_inverse": {"points": [[0, 0], [1, 1]]}, "d": 0, "output_range": [0, 100],
                       "saturation_tolerance": 0.5, "comment": "c"})"),
       [](const json& j) { esmaeilani::Constraints::FromJson(j, "fuzz.json"); }},
      {"brouri step plan", steps.to_json(), [](const json& j) { brouri::StepPlan::from_json(j); }},
      {"brouri sine plan", sines.to_json(), [](const json& j) { brouri::SinePlan::from_json(j); }},
      {"brouri estimate", est.to_json(), [](const json& j) { brouri::NonlinearEstimate::from_json(j); }},
      {"brouri system", brouri::BacklashHwSystem::PaperExample().to_json(),
       [](const json& j) { brouri::BacklashHwSystem::from_json(j); }},
  };
}

TEST(ParserFuzz, JsonReaders) {
  Mutator m(3);
  for (const auto& reader : Readers()) {
    Harness h(reader.name);
    auto from_text = [&](const std::string& text) { reader.read(ParseJsonText(text, "fuzz.json", reader.name)); };
    const std::string seed_text = reader.seed.dump();
    h.Feed(seed_text, Expect::kEither, from_text);
    for (int i = 0; i < kInputsPerParser; ++i) {
      switch (i % 5) {
        case 0:
        case 1: h.Feed(m.Edit(m.Coin(0.3) ? m.Edit(reader.seed) : reader.seed).dump(), Expect::kEither, from_text); break;
        case 2: h.Feed(m.UnknownKey(reader.seed).dump(), Expect::kInvalid, from_text); break;
        case 3: {  // truncated before the closing brace: never valid JSON
          const std::string text = reader.seed.dump();
          h.Feed(text.substr(0, m.Int(0, static_cast<int>(text.size()) - 2)), Expect::kInvalid, from_text);
          break;
        }
        default: h.Feed(m.Text(seed_text, "{}[]\":,.-0159etrufanl ", m.Int(1, 4)), Expect::kEither, from_text);
      }
    }
  }
}

}  // namespace
}  // namespace hw
