#include "diagnose/nominal_fit.hpp"

#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/input_error.hpp"
#include "diagnose/signal_stats.hpp"

namespace hw::diagnose {
namespace {

using Vec = std::vector<double>;

double Rmse(const AugmentedModel& m, const Segment& s) {
  return s.Count() ? std::sqrt(SumSquaredError(m, s) / s.Count()) : 0.0;
}

StaticMap PolynomialOrIdentity(const Vec& c) { return c.size() > 1 ? StaticMap::Polynomial(c) : StaticMap{}; }

Vec IdentityCoefficients(int degree) {
  Vec c(degree, 0.0);
  c[0] = 1.0;
  return c;
}

// ARX with a constant, then Steiglitz–McBride passes (prefilter by 1/A and re-solve), keeping the
// iterate with the lowest simulation error; `sm` = false returns the plain ARX model.
AugmentedModel LinearStart(const NominalSpec& spec, const Segment& s, bool sm) {
  const Vec& u = *s.u;
  const Vec& y = *s.y;
  Vec a, b;
  double c = 0.0;
  AugmentedModel m;
  if (!FitArx(u, y, spec.na, spec.nb, spec.delay, s.skip, s.End(), true, &a, &b, &c)) {
    a.assign(spec.na, 0.0);
    b.assign(spec.nb, 0.0);
  }
  a = StabilisedDenominator(a);
  double gain = 1.0;
  for (double v : a) gain += v;
  m.nominal.linear = {a, b, spec.delay};
  m.output_offset = std::abs(gain) > 1e-6 ? c / gain : 0.0;
  if (!sm) return m;
  double best = SumSquaredError(m, s);
  for (int it = 0; it < 6 && spec.na > 0; ++it) {
    LinearBlock filt{a, {1.0}, 0};
    const Vec uf = filt.simulate(u), yf = filt.simulate(y);
    Vec a2, b2;
    double c2 = 0.0;
    if (!FitArx(uf, yf, spec.na, spec.nb, spec.delay, s.skip, s.End(), true, &a2, &b2, &c2)) break;
    a2 = StabilisedDenominator(a2);
    AugmentedModel t;
    t.nominal.linear = {a2, b2, spec.delay};
    t.output_offset = c2;
    const double cost = SumSquaredError(t, s);
    a = a2;
    if (cost < best) best = cost, m = t;
  }
  return m;
}

// Output map by least squares on the linear simulation: y - z = offset + sum_{k>=2} c_k z^k.
bool OutputMapStart(AugmentedModel* m, int degree, const Segment& s) {
  AugmentedModel lin = *m;
  lin.output_offset = 0.0;
  const Vec z = lin.simulate(*s.u);
  const std::size_t n = s.Count();
  Eigen::MatrixXd phi(n, degree);
  Eigen::VectorXd r(n);
  for (std::size_t t = s.skip; t < s.End(); ++t) {
    phi(t - s.skip, 0) = 1.0;
    for (int k = 2; k <= degree; ++k) phi(t - s.skip, k - 1) = std::pow(z[t], k);
    r(t - s.skip) = (*s.y)[t] - z[t];
  }
  const Eigen::VectorXd th = phi.colPivHouseholderQr().solve(r);
  if (!th.allFinite()) return false;
  Vec c = IdentityCoefficients(degree);
  for (int k = 2; k <= degree; ++k) c[k - 1] = th(k - 1);
  m->output_offset = th(0);
  m->nominal.output = StaticMap::Polynomial(c);
  return true;
}

// Input map by an over-parametrised Hammerstein least squares at the linear model's poles:
// y = offset + sum_j sum_k theta_jk (u^k / A)_{t-d-j}, then theta ~ b c^T (rank one, c_1 = 1).
// The output map, when the structure has one, starts at identity: the least squares sees the model without it.
bool InputMapStart(AugmentedModel* m, int degree, const Segment& s) {
  const StaticMap output = m->nominal.output;
  m->nominal.output = StaticMap{};
  m->nominal.input = StaticMap::Polynomial(IdentityCoefficients(degree));
  RefitOptions o;
  o.estimate_initial_state = false;
  o.fit_output_offset = true;
  const bool solved = SolveInputMapAndNumerator(m, s, o);
  m->nominal.output = output;
  return solved;
}

// Random map coefficients around identity, scaled to the signal each map sees.
void RandomMaps(AugmentedModel* m, const NominalSpec& spec, const Segment& s, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 0.3);
  const double su = std::max(Rms(*s.u), 1e-12);
  AugmentedModel lin = *m;
  lin.output_offset = 0.0;
  const double sz = std::max(Rms(lin.simulate(*s.u)), 1e-12);
  auto draw = [&](int degree, double scale) {
    Vec c = IdentityCoefficients(degree);
    for (int k = 2; k <= degree; ++k) c[k - 1] = g(rng) / std::pow(scale, k - 1);
    return PolynomialOrIdentity(c);
  };
  m->nominal.input = draw(spec.input_degree, su);
  m->nominal.output = draw(spec.output_degree, sz);
}

}  // namespace

bool NominalSpec::IsValid(std::string* error) const {
  if (na < 0 || nb < 1 || delay < 0 || input_degree < 1 || output_degree < 1 || na > 20 || nb > 40 ||
      input_degree > 9 || output_degree > 9) {
    if (error) *error = "nominal structure needs 0 <= NA <= 20, 1 <= NB <= 40, DELAY >= 0, 1 <= degrees <= 9";
    return false;
  }
  return true;
}

std::string NominalSpec::Text() const {
  return input_degree > 1 || output_degree > 1
             ? fmt::format("hw:{},{},{},{},{}", na, nb, input_degree, output_degree, delay)
             : fmt::format("linear:{},{},{}", na, nb, delay);
}

NominalSpec NominalSpec::Parse(const std::string& text) {
  const auto colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  std::vector<int> nums;
  if (colon != std::string::npos) {
    std::string rest = text.substr(colon + 1);
    std::size_t pos = 0;
    while (pos <= rest.size()) {
      const auto comma = rest.find(',', pos);
      const std::string tok = rest.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
      try {
        std::size_t used = 0;
        nums.push_back(std::stoi(tok, &used));
        if (used != tok.size()) throw std::invalid_argument(tok);
      } catch (const std::exception&) {
        throw InputError(fmt::format("--fit '{}': '{}' is not an integer; expected linear:NA,NB[,DELAY] or "
                                     "hw:NA,NB,PIN,POUT[,DELAY]", text, tok));
      }
      if (comma == std::string::npos) break;
      pos = comma + 1;
    }
  }
  NominalSpec s;
  if (kind == "linear" && (nums.size() == 2 || nums.size() == 3)) {
    s.na = nums[0];
    s.nb = nums[1];
    if (nums.size() == 3) s.delay = nums[2];
  } else if (kind == "hw" && (nums.size() == 4 || nums.size() == 5)) {
    s.na = nums[0];
    s.nb = nums[1];
    s.input_degree = nums[2];
    s.output_degree = nums[3];
    if (nums.size() == 5) s.delay = nums[4];
  } else {
    throw InputError(fmt::format("--fit '{}' not understood; expected linear:NA,NB[,DELAY] (e.g. linear:2,2) or "
                                 "hw:NA,NB,PIN,POUT[,DELAY] (e.g. hw:2,2,3,1)", text));
  }
  std::string err;
  if (!s.IsValid(&err)) throw InputError(fmt::format("--fit '{}': {}", text, err));
  return s;
}

bool NominalSpec::Of(const HwModel& m, NominalSpec* spec) {
  auto degree = [](const StaticMap& map, int* d) {
    if (map.kind == StaticMap::Kind::kIdentity) return *d = 1, true;
    if (map.kind == StaticMap::Kind::kPolynomial) return *d = static_cast<int>(map.coefficients.size()), true;
    return false;
  };
  NominalSpec s;
  s.na = static_cast<int>(m.linear.a.size());
  s.nb = static_cast<int>(m.linear.b.size());
  s.delay = m.linear.delay;
  if (!degree(m.input, &s.input_degree) || !degree(m.output, &s.output_degree) || !s.IsValid(nullptr)) return false;
  *spec = s;
  return true;
}

bool NominalFitOptions::IsValid(std::string* error) const {
  if (!(holdout_fraction > 0.05 && holdout_fraction < 0.8) || random_starts < 0) {
    if (error) *error = "nominal fit: holdout_fraction must be in (0.05, 0.8) and random_starts >= 0";
    return false;
  }
  return refit.IsValid(error);
}

nlohmann::json NominalFit::to_json() const {
  nlohmann::json s = nlohmann::json::array();
  for (const auto& st : starts) s.push_back(st.to_json());
  return {{"structure", spec},
          {"starts", s},
          {"chosen_start", chosen >= 0 ? starts[chosen].name : ""},
          {"output_offset", model.output_offset},
          {"initial_state", model.initial_state}};
}

std::string NominalFit::Summary() const {
  if (chosen < 0) return fmt::format("nominal {}: no start converged", spec);
  return fmt::format("nominal {} fitted from {} starts; kept '{}' (held-out RMSE {:.4g}; worst start {:.4g})", spec,
                     starts.size(), starts[chosen].name, starts[chosen].holdout_rmse, [&] {
                       double w = 0.0;
                       for (const auto& s : starts) w = std::max(w, s.holdout_rmse);
                       return w;
                     }());
}

NominalFit FitNominal(const NominalSpec& spec, const Segment& data, const NominalFitOptions& o,
                      const std::vector<EffectBlock>& blocks) {
  std::string err;
  if (!spec.IsValid(&err) || !o.IsValid(&err)) throw InputError("nominal fit: " + err);
  const std::size_t end = data.End();
  if (data.Count() < static_cast<std::size_t>(3 * (spec.na + spec.nb * spec.input_degree + spec.output_degree) + 30))
    throw InputError(fmt::format("nominal fit {}: {} samples are too few", spec.Text(), data.Count()));
  const std::size_t nfit = data.skip + static_cast<std::size_t>(data.Count() * (1.0 - o.holdout_fraction));
  const Segment fit{data.u, data.y, data.skip, nfit};
  const Segment held{data.u, data.y, nfit, end};
  NominalFit out;
  out.spec = spec.Text();
  using Tried = std::vector<std::pair<NominalStart, AugmentedModel>>;
  // A start that ends with a map folding back over the data is not a physical nominal: not kept.
  Tried folded;  // finite starts whose maps fold back: kept only when no start has monotone maps
  auto attempt = [&](Tried* tried, const std::string& name, AugmentedModel start) {
    start.blocks = blocks;
    RefitResult r = RefitModel(start, fit, o.refit);
    const double f = Rmse(r.model, fit), h = Rmse(r.model, held);
    if (!std::isfinite(f) || !std::isfinite(h)) return;
    if (MapsMonotone(r.model, *data.u))
      tried->push_back({{name, f, h}, r.model});
    else
      folded.push_back({{name + " (maps fold back over the data)", f, h}, r.model});
  };
  auto best_of = [](const Tried& tried) {
    int best = -1;
    for (std::size_t i = 0; i < tried.size(); ++i)
      if (best < 0 || tried[i].first.holdout_rmse < tried[best].first.holdout_rmse) best = static_cast<int>(i);
    return best;
  };
  Tried linear, tried;
  attempt(&linear, "linear, Steiglitz-McBride", LinearStart(spec, fit, true));
  attempt(&linear, "linear, ARX", LinearStart(spec, fit, false));
  const int lin = best_of(linear);
  if (lin < 0) throw InputError(fmt::format("nominal fit {}: no linear start gave a finite simulation", spec.Text()));
  if (spec.input_degree == 1 && spec.output_degree == 1) {
    tried = linear;
  } else {
    // The linear fit seeds every start of the structure with maps.
    AugmentedModel id = linear[lin].second;
    id.blocks.clear();  // the map starts see the nominal alone; `attempt` puts the blocks back
    id.nominal.input = PolynomialOrIdentity(IdentityCoefficients(spec.input_degree));
    id.nominal.output = PolynomialOrIdentity(IdentityCoefficients(spec.output_degree));
    attempt(&tried, "maps from identity", id);
    AugmentedModel m = id;
    if (spec.output_degree > 1 && OutputMapStart(&m, spec.output_degree, fit))
      attempt(&tried, "output map by least squares", m);
    m = id;
    if (spec.input_degree > 1 && InputMapStart(&m, spec.input_degree, fit))
      attempt(&tried, "input map by Hammerstein least squares", m);
    std::mt19937_64 rng(o.seed);
    for (int i = 0; i < o.random_starts; ++i) {
      m = id;
      RandomMaps(&m, spec, fit, rng);
      attempt(&tried, fmt::format("random maps {}", i + 1), m);
    }
  }
  if (tried.empty()) tried = folded;  // better a folded map, said so in its name, than no nominal at all
  out.chosen = best_of(tried);
  if (out.chosen < 0) throw InputError(fmt::format("nominal fit {}: no start gave a finite simulation with monotone maps", spec.Text()));
  for (const auto& t : tried) out.starts.push_back(t.first);
  out.model = RefitModel(tried[out.chosen].second, data, o.refit).model;
  out.model.nominal.name = spec.Text();
  return out;
}

}  // namespace hw::diagnose
