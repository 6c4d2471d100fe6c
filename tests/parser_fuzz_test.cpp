// Every parser of user input, fed random and grammar-aware mutated inputs in-process: CSV recordings,
// polynomial expressions, every JSON reader (pop problems, models, diagnose's augmented models, scenarios,
// constraints, Brouri plans, estimates and systems), the recording specs (FILE:u=VAR,y=VAR,t=VAR, and
// diagnose's), diagnose's --fit and --effects texts, and .mat files (v5 and v7.3 bytes, mutated, read from temp
// files). Each input must end in a result or a clear InputError (never another exception, a crash or a hang),
// and inputs that are invalid by construction (an unknown key, a typo in a key, truncated JSON or .mat bytes, a
// fractional exponent, a missing operator, a duplicate column, a cell that is no number, a column mapped twice)
// must be rejected. Accepted inputs must mean what they say (invariants checked below). Seeded: reproducible.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <set>
#include <string>

#include "compare/scenario.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "core/json_input.hpp"
#include "core/polynomial.hpp"
#include "core/recording.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/nominal_fit.hpp"
#include "diagnose/recording.hpp"
#include "estimators/brouri/experiment.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "pop/pop_json.hpp"

namespace hw {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr int kInputsPerParser = 10000;

enum class Expect { kEither, kInvalid };

// Runs one parser over many inputs and keeps the first few failures for the report.
class Harness {
 public:
  // `minimum`: the inputs this parser must have been fed.
  explicit Harness(std::string name, int minimum = kInputsPerParser) : name_(std::move(name)), minimum_(minimum) {}
  ~Harness() {
    EXPECT_TRUE(failures_.empty()) << name_ << ": " << failures_.size() << " failures, first:\n" << first_failures_;
    EXPECT_GE(accepted_ + rejected_, minimum_) << name_;
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
  int minimum_;
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

// diagnose's model: a nominal model with two effect blocks, an output offset and an initial state.
json DiagnoseModelJson() {
  json j = CeroneModelJson();
  j["type"] = "augmented_hammerstein_wiener";
  j["effect_blocks"] = json::parse(R"([{"effect": "backlash", "location": "input", "parameters": {"half_width": 0.1}},
    {"effect": "saturation", "location": "output", "parameters": {"lower": -1, "upper": 2}}])");
  j["output_offset"] = 0.25;
  j["initial_state"] = {0.1, -0.2};
  return j;
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
       [](const json& j) { pop::ParsePolyProblem(j, "fuzz.json"); }},
      {"model", CeroneModelJson(), [](const json& j) { HwModel::from_json(j); }},
      {"diagnose model", DiagnoseModelJson(), [](const json& j) { diagnose::AugmentedModel::from_json(j); }},
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

// ---------------------------------------------------------------------------------------------------------
// diagnose's texts: --fit (NominalSpec), --effects (candidate blocks), --data/--validate (its recording spec).

void ParseNominalSpec(const std::string& text) {
  const auto spec = diagnose::NominalSpec::Parse(text);
  std::string error;
  if (!spec.IsValid(&error)) throw std::logic_error("accepted an invalid structure: " + error);
  const auto again = diagnose::NominalSpec::Parse(spec.Text());  // its printed form means the same
  if (again.Text() != spec.Text()) throw std::logic_error("printed form reads back as " + again.Text());
}

void ParseCandidateList(const std::string& text) {
  const auto blocks = diagnose::ParseCandidates(text);
  if (blocks.empty()) throw std::logic_error("no block");
  for (const auto& [e, l] : blocks)
    if (!diagnose::IsDefined(e, l)) throw std::logic_error("an undefined block");
}

void ParseDiagnoseRecordingSource(const std::string& text) {
  const auto spec = diagnose::RecordingSource::Parse(text, diagnose::ColumnNames{});
  if (spec.path.empty()) throw std::logic_error("no path");
  for (const auto* name : {&spec.columns.u, &spec.columns.y, &spec.columns.t})
    if (name->empty() || name->find(',') != std::string::npos) throw std::logic_error("column name '" + *name + "'");
}

// One text parser: half its inputs are edits of a valid seed (over `alphabet`), a quarter random text over it (either
// outcome), a quarter invalid by construction (`invalid(seed)` lists such texts; each must be rejected).
struct TextTarget {
  std::string name;
  std::vector<std::string> seeds;
  std::string alphabet;
  std::function<std::vector<std::string>(const std::string& seed)> invalid;
  std::function<void(const std::string&)> parse;
};

void FuzzText(Mutator& m, const TextTarget& target, int inputs) {
  Harness h(target.name, inputs);
  for (int i = 0; i < inputs; ++i) {
    const std::string seed = m.Pick(target.seeds);
    if (i % 4 < 2) h.Feed(m.Text(seed, target.alphabet, m.Int(1, 3)), Expect::kEither, target.parse);
    else if (i % 4 == 2) h.Feed(m.Random(target.alphabet, m.Int(0, 30)), Expect::kEither, target.parse);
    else h.Feed(m.Pick(target.invalid(seed)), Expect::kInvalid, target.parse);
  }
}

TEST(ParserFuzz, DiagnoseTexts) {
  constexpr int kInputs = 3000;
  Mutator m(4);
  // --fit: a number that is not an integer, a missing count, an unknown kind.
  FuzzText(m,
           {"diagnose --fit", {"linear:2,2", "linear:2,3,1", "hw:2,2,3,3", "hw:1,2,3,1,0"}, "linearhw:,0123-9 ",
            [](const std::string& seed) {
              return std::vector<std::string>{seed + ".5", seed + ",", "arx" + seed.substr(seed.find(':')), "hw:2,2",
                                              seed + ",x", "linear:", "linear:2,2,0,0"};
            },
            ParseNominalSpec},
           kInputs);
  // --effects: an empty item, an unknown effect or location, a block that is not defined.
  FuzzText(m,
           {"diagnose --effects",
            {"backlash@input,deadzone@output", "coulomb_friction@state", "saturation@input,quantization@output"},
            "@,_ ",
            [](const std::string& seed) {
              return std::vector<std::string>{seed + ",", "," + seed, seed + ",backlash", seed + ",friction@input",
                                              seed + ",backlash@output", seed + ",deadzone@nowhere", ""};
            },
            ParseCandidateList},
           kInputs);
  // --data, --validate: an unknown key, an empty name, a column mapped twice, no file name.
  FuzzText(m,
           {"diagnose recording",
            {"rec.csv", "rec.csv:u=vin,y=vout", "d/r.mat:u=vir,y=qm,t=time", "C:/data/r.csv:t=time"},
            "uyt=,:rec.sv/ ",
            [](const std::string&) {
              return std::vector<std::string>{"rec.csv:z=a", "rec.csv:u=",      "rec.csv:u=a,,y=b",
                                              "rec.csv:u=a,u=b", ":u=a", "rec.csv:u=a,y"};
            },
            ParseDiagnoseRecordingSource},
           kInputs);
}

// ---------------------------------------------------------------------------------------------------------
// Recording specs FILE[:COLUMN=VARIABLE,...] (core/recording.hpp): parsed, and read from the CSV fixture.

const std::string kData = std::string(HW_SOURCE_DIR) + "/tests/data";

// An accepted recording has u and y (and t when given) of one length, every value finite, t increasing.
void CheckRecordingTable(const CsvTable& t) {
  if (!t.has("u") || !t.has("y")) throw std::logic_error("u or y missing");
  const std::size_t n = t.column("u").size();
  if (n == 0) throw std::logic_error("no samples");
  for (const auto& c : t.columns) {
    if (c.size() != n) throw std::logic_error("columns of different lengths");
    for (double v : c)
      if (!std::isfinite(v)) throw std::logic_error("non-finite sample");
  }
  if (!t.has("t")) return;
  const auto& time = t.column("t");
  for (std::size_t i = 1; i < time.size(); ++i)
    if (!(time[i] > time[i - 1])) throw std::logic_error("t does not increase");
}

void ParseRecordingSpec(const std::string& text) {
  const RecordingSpec spec = RecordingSpec::Parse(text);
  std::set<std::string> columns;
  for (const auto& c : spec.map) {
    if (c.column.empty() || c.variable.empty()) throw std::logic_error("an empty name in the map");
    if (!columns.insert(c.column).second) throw std::logic_error("column '" + c.column + "' mapped twice");
  }
}

TEST(ParserFuzz, RecordingSpecs) {
  constexpr int kInputs = 3000;
  const std::string csv = kData + "/recording.csv";  // columns t, u, y
  auto read = [](const std::string& text) { CheckRecordingTable(read_recording(text, {"u", "y"}, {"t"})); };
  Mutator m(5);
  const std::vector<std::string> maps = {"u=u,y=y", "u=y,y=u,t=t", "y=u", "t=t", "u=u, y=y"};
  std::vector<std::string> specs;
  for (const auto& map : maps) specs.push_back("r.mat:" + map);
  // Nothing after ':', an item without '=' or a name, a column mapped twice.
  FuzzText(m,
           {"recording spec", specs, "uyt=,:.matcsv ",
            [](const std::string&) {
              return std::vector<std::string>{"r.mat:",   "r.mat: ",         "r.mat:u",       "r.mat:=a",   "r.mat:u=",
                                              "r.mat:u=a,,y=b", "r.mat:u=a,u=b", "r.csv:u=a,", "r.CSV:,u=a"};
            },
            ParseRecordingSpec},
           kInputs);
  Harness h("recording spec, read", kInputs);
  for (int i = 0; i < kInputs; ++i) {
    const std::string map = m.Pick(maps);
    if (i % 3 == 2)  // a column the command does not read, or one mapped twice, or a source column not in the file
      h.Feed(csv + ":" + map + m.Pick<std::string>({",z=u", ",q=y", ",t=time,t=u", ",u=time"}), Expect::kInvalid, read);
    else
      h.Feed(csv + ":" + m.Text(map, "uyt=, ", m.Int(1, 3)), Expect::kEither, read);
  }
}

// ---------------------------------------------------------------------------------------------------------
// .mat files: the bytes of the v5 and v7.3 fixtures, mutated, written to a temp file and read as a recording.

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Format-aware byte mutations: the tags, sizes and dimensions of both formats are aligned 4- and 8-byte words,
// so besides random bytes and slices, aligned words are set to values that stress a reader (0, 1, -1, huge).
std::string MutateBytes(Mutator& m, std::string b) {
  const int edits = m.Int(1, 4);
  for (int k = 0; k < edits && !b.empty(); ++k) {
    const std::size_t at = static_cast<std::size_t>(m.Int(0, static_cast<int>(b.size()) - 1));
    switch (m.Int(0, 5)) {
      case 0: b[at] = static_cast<char>(m.Int(0, 255)); break;
      case 1: b[at] = static_cast<char>(b[at] ^ (1 << m.Int(0, 7))); break;
      case 2: b.erase(at, m.Int(1, 16)); break;
      case 3: b.insert(at, b.substr(m.Int(0, static_cast<int>(b.size()) - 1), m.Int(1, 16))); break;
      default: {
        const std::size_t word = at / 4 * 4;
        const std::uint32_t values[] = {0u, 1u, 2u, 8u, 0x7fffffffu, 0xffffffffu, 0x80000000u, 40u, 41u, 0xffffu};
        const std::uint32_t v = values[m.Int(0, 9)];
        for (int byte = 0; byte < 4 && word + byte < b.size(); ++byte) b[word + byte] = static_cast<char>(v >> (8 * byte));
      }
    }
  }
  return b;
}

TEST(ParserFuzz, MatFiles) {
  constexpr int kInputsPerFile = 800;  // each read forks a reader (core/mat_recording.cpp)
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "parser_fuzz_mat";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "fuzz.mat").string();
  auto read = [&path](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    CheckRecordingTable(read_recording(path + ":u=vir,y=qm,t=time", {"u", "y"}, {"t"}));
  };
  Mutator m(6);
  for (const char* fixture : {"recording_v5.mat", "recording_v73.mat", "recording_v73_nullpad.mat"}) {
    const std::string bytes = FileBytes(kData + "/" + fixture);
    ASSERT_FALSE(bytes.empty()) << fixture;
    Harness h(std::string(".mat ") + fixture, kInputsPerFile);
    h.Feed(bytes, Expect::kEither, read);
    for (int i = 0; i < kInputsPerFile; ++i) {
      switch (i % 7) {
        case 0: {  // cut short: the last variable's data is incomplete
          h.Feed(bytes.substr(0, m.Int(0, static_cast<int>(bytes.size()) - 1)), Expect::kInvalid, read);
          break;
        }
        case 1: h.Feed(m.Random(bytes.substr(0, 200), m.Int(0, 600)), Expect::kEither, read); break;
        default: h.Feed(MutateBytes(m, bytes), Expect::kEither, read);
      }
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hw
