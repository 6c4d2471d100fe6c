#include "diagnose/refit.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "diagnose/signal_stats.hpp"

namespace hw::diagnose {
namespace {

using Vec = std::vector<double>;

Vec LogSpace(double lo, double hi, int n) {
  Vec v(n);
  for (int i = 0; i < n; ++i) v[i] = lo * std::pow(hi / lo, n == 1 ? 0.0 : double(i) / (n - 1));
  return v;
}

// Which model numbers the optimiser may move, and how they map to a flat vector.
struct Packing {
  int na = 0, nb = 0, nin = 0, nout = 0;
  bool offset = false;
  std::vector<int> effect;  // indices into block.params

  static Packing For(const AugmentedModel& m, bool refit_maps, bool with_effect_smooth, bool with_offset) {
    Packing p;
    p.offset = with_offset;
    p.na = static_cast<int>(m.nominal.linear.a.size());
    p.nb = static_cast<int>(m.nominal.linear.b.size());
    if (refit_maps && m.nominal.input.kind == StaticMap::Kind::kPolynomial)
      p.nin = static_cast<int>(m.nominal.input.coefficients.size()) - 1;
    if (refit_maps && m.nominal.output.kind == StaticMap::Kind::kPolynomial)
      p.nout = static_cast<int>(m.nominal.output.coefficients.size()) - 1;
    if (with_effect_smooth)
      for (std::size_t i = 0; i < m.block.params.size(); ++i)
        if (ParameterIsSmooth(m.block.effect, static_cast<int>(i)) && std::isfinite(m.block.params[i]))
          p.effect.push_back(static_cast<int>(i));
    return p;
  }
  Vec Pack(const AugmentedModel& m) const {
    Vec v;
    for (double a : m.nominal.linear.a) v.push_back(a);
    for (double b : m.nominal.linear.b) v.push_back(b);
    for (int i = 0; i < nin; ++i) v.push_back(m.nominal.input.coefficients[i + 1]);
    for (int i = 0; i < nout; ++i) v.push_back(m.nominal.output.coefficients[i + 1]);
    for (int i : effect) v.push_back(m.block.params[i]);
    if (offset) v.push_back(m.output_offset);
    return v;
  }
  void Unpack(const Vec& v, AugmentedModel* m) const {
    std::size_t k = 0;
    for (int i = 0; i < na; ++i) m->nominal.linear.a[i] = v[k++];
    for (int i = 0; i < nb; ++i) m->nominal.linear.b[i] = v[k++];
    for (int i = 0; i < nin; ++i) m->nominal.input.coefficients[i + 1] = v[k++];
    for (int i = 0; i < nout; ++i) m->nominal.output.coefficients[i + 1] = v[k++];
    for (int i : effect) m->block.params[i] = v[k++];
    if (offset) m->output_offset = v[k++];
    Legalise(&m->block);
  }
  // Keeps the optimiser inside each block's domain (widths >= 0, lower < upper).
  static void Legalise(EffectBlock* b) {
    switch (b->effect) {
      case Effect::kBacklash:
      case Effect::kDeadzone:
        b->params[0] = std::abs(b->params[0]);
        break;
      case Effect::kRateLimit:
        b->params[0] = std::max(std::abs(b->params[0]), 1e-12);
        break;
      case Effect::kSaturation:
      case Effect::kStateSaturation:
        if (b->params[0] > b->params[1]) std::swap(b->params[0], b->params[1]);
        break;
      default:
        break;
    }
  }
};

void Residual(const AugmentedModel& m, const Segment& s, Vec* r) {
  Vec yhat;
  m.simulate(*s.u, &yhat);
  const auto& y = *s.y;
  r->resize(y.size() - std::min(s.skip, y.size()));
  for (std::size_t t = s.skip; t < y.size(); ++t) (*r)[t - s.skip] = y[t] - yhat[t];
}

// Exact output-error numerator for fixed poles: y ~ sum_j b_j f_{t-d-j}, f = x / A(q).
bool SolveNumerator(AugmentedModel* m, const Segment& s, bool with_offset) {
  if (m->nominal.output.kind != StaticMap::Kind::kIdentity || m->block.location != Location::kInput) return false;
  Vec x = ApplyInputBlock(m->block, *s.u);
  for (auto& v : x) v = m->nominal.input(v);
  LinearBlock filt{m->nominal.linear.a, {1.0}, 0};
  const Vec f = filt.simulate(x);
  const int nb = static_cast<int>(m->nominal.linear.b.size());
  const long d = m->nominal.linear.delay;
  const std::size_t n = s.y->size();
  if (n <= s.skip + nb) return false;
  Eigen::MatrixXd phi(n - s.skip, nb + (with_offset ? 1 : 0));
  Eigen::VectorXd yy(n - s.skip);
  for (std::size_t t = s.skip; t < n; ++t) {
    for (int j = 0; j < nb; ++j) {
      const long k = static_cast<long>(t) - d - j;
      phi(t - s.skip, j) = k >= 0 ? f[k] : 0.0;
    }
    if (with_offset) phi(t - s.skip, nb) = 1.0;
    yy(t - s.skip) = (*s.y)[t];
  }
  const Eigen::VectorXd b = phi.colPivHouseholderQr().solve(yy);
  if (!b.allFinite()) return false;
  for (int j = 0; j < nb; ++j) m->nominal.linear.b[j] = b(j);
  if (with_offset) m->output_offset = b(nb);
  return true;
}

// Grid of effect parameters, scaled to the recording and to the nominal simulation.
std::vector<Vec> EffectGrid(Effect e, Location l, const Vec& u, const Vec& y, const Vec& zhat, const HwModel& nominal) {
  std::vector<Vec> g;
  const Vec& v = l == Location::kInput ? u : (l == Location::kOutput ? y : zhat);
  double vmax = 0.0;
  for (double x : v) vmax = std::max(vmax, std::abs(x));
  const double range = std::max(Quantile(v, 1.0) - Quantile(v, 0.0), 1e-12);
  vmax = std::max(vmax, 1e-12);
  switch (e) {
    case Effect::kBacklash:
      for (double w : LogSpace(1e-3 * range, 0.3 * range, 36)) g.push_back({w});
      break;
    case Effect::kDeadzone:
      for (double d : LogSpace(2e-3 * vmax, 0.6 * vmax, 36)) g.push_back({d});
      break;
    case Effect::kSaturation:
    case Effect::kStateSaturation: {
      const Vec qs = {0.002, 0.005, 0.01, 0.02, 0.04, 0.07, 0.1, 0.15, 0.2, 0.3};
      Vec lo = {-HUGE_VAL}, hi = {HUGE_VAL};
      for (double q : qs) {
        lo.push_back(Quantile(v, q));
        hi.push_back(Quantile(v, 1 - q));
      }
      for (double a : lo)
        for (double b : hi)
          if (a < b && (std::isfinite(a) || std::isfinite(b))) g.push_back({a, b});
      break;
    }
    case Effect::kRateLimit: {
      Vec du;
      for (std::size_t t = 1; t < u.size(); ++t) du.push_back(std::abs(u[t] - u[t - 1]));
      const double top = std::max(Quantile(du, 1.0), 1e-12);
      const double low = std::max(Quantile(du, 0.3), top * 1e-3);
      for (double r : LogSpace(low, top, 30)) g.push_back({r});
      break;
    }
    case Effect::kDelay: {
      const int kmax = static_cast<int>(std::min<std::size_t>(20, u.size() / 20));
      for (int k = 1; k <= kmax; ++k) g.push_back({double(k)});
      break;
    }
    case Effect::kQuantization:
      for (double q : LogSpace(1e-3 * range, 0.3 * range, 160)) g.push_back({q});
      break;
    case Effect::kHysteresis: {
      Vec au;
      for (double x : u) au.push_back(std::abs(x));
      const double su = Rms(u);
      for (double qb : {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}) {
        const double beta = Quantile(au, qb);
        for (double h : LogSpace(3e-3 * su, 0.3 * su, 12)) {
          g.push_back({beta, h});
          g.push_back({beta, -h});
        }
      }
      break;
    }
    case Effect::kCubicStiffness:
    case Effect::kCoulombFriction: {
      // Forcing scale: the numerator's contribution per step.
      Vec x(u.size());
      for (std::size_t t = 0; t < u.size(); ++t) x[t] = nominal.input(u[t]);
      LinearBlock num{{}, nominal.linear.b, nominal.linear.delay};
      const double s = std::max(Rms(num.simulate(x)), 1e-12);
      const double zr = std::max(Rms(zhat), 1e-12);
      for (double c : LogSpace(1e-4, 10.0, 36)) {
        const double val = e == Effect::kCubicStiffness ? c * s / (zr * zr * zr) : c * s;
        g.push_back({val});
        g.push_back({-val});
      }
      break;
    }
    default:
      break;
  }
  return g;
}

// Finer search around a value for parameters that only a search can move.
Vec LocalValues(Effect e, double v) {
  Vec out;
  if (e == Effect::kDelay) {
    for (int k = -2; k <= 2; ++k)
      if (v + k >= 1) out.push_back(v + k);
    return out;
  }
  for (int i = -20; i <= 20; ++i) out.push_back(v * (1.0 + 0.01 * i));
  if (v == 0.0)
    for (double s : {1e-3, 1e-2}) out.push_back(s);
  return out;
}

RefitResult Polish(AugmentedModel m, const Segment& s, const RefitOptions& o) {
  // LM on the linear block, maps and smooth effect parameters.
  auto lm = [&](AugmentedModel* mm, bool effect_smooth) {
    const Packing pk = Packing::For(*mm, o.refit_maps, effect_smooth, o.fit_output_offset);
    Vec p0 = pk.Pack(*mm);
    Vec scale(p0.size(), 1e-3);
    for (std::size_t i = 0; i < p0.size(); ++i) scale[i] = std::max(std::abs(p0[i]), 1e-3);
    LmSummary sum;
    AugmentedModel work = *mm;
    const Vec p = LevenbergMarquardt(
        [&](const Vec& q, Vec* r) {
          pk.Unpack(q, &work);
          Residual(work, s, r);
        },
        p0, scale, o.lm, &sum);
    pk.Unpack(p, mm);
    mm->nominal.linear.a = StabilisedDenominator(mm->nominal.linear.a);
  };
  lm(&m, true);
  bool has_search = false;
  for (std::size_t i = 0; i < m.block.params.size(); ++i)
    has_search = has_search || !ParameterIsSmooth(m.block.effect, static_cast<int>(i));
  if (has_search) {
    for (std::size_t i = 0; i < m.block.params.size(); ++i) {
      if (ParameterIsSmooth(m.block.effect, static_cast<int>(i))) continue;
      double best = SumSquaredError(m, s), best_v = m.block.params[i];
      for (double v : LocalValues(m.block.effect, m.block.params[i])) {
        AugmentedModel t = m;
        t.block.params[i] = v;
        std::string err;
        if (!t.block.IsValid(&err)) continue;
        SolveNumerator(&t, s, o.fit_output_offset);
        const double c = SumSquaredError(t, s);
        if (c < best) best = c, best_v = v;
      }
      m.block.params[i] = best_v;
    }
    lm(&m, true);
  }
  RefitResult r;
  r.model = m;
  r.sse = SumSquaredError(m, s);
  for (double p : m.block.params) r.extra_parameters += std::isfinite(p) ? 1 : 0;
  return r;
}

Vec PolyFromRoots(const std::vector<std::complex<double>>& roots) {
  std::vector<std::complex<double>> c = {1.0};
  for (const auto& r : roots) {
    std::vector<std::complex<double>> n(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      n[i] += c[i];
      n[i + 1] -= r * c[i];
    }
    c = n;
  }
  Vec a;
  for (std::size_t i = 1; i < c.size(); ++i) a.push_back(c[i].real());
  return a;
}

// Least squares ARX on (x, y) (optionally both prefiltered by 1/A): returns [a; b].
bool Arx(const Vec& x, const Vec& y, int na, int nb, int d, std::size_t skip, Vec* a, Vec* b) {
  const std::size_t n = y.size();
  const std::size_t start = std::max<std::size_t>(skip, std::max(na, d + nb - 1));
  if (n <= start + na + nb) return false;
  Eigen::MatrixXd phi(n - start, na + nb);
  Eigen::VectorXd yy(n - start);
  for (std::size_t t = start; t < n; ++t) {
    for (int i = 1; i <= na; ++i) phi(t - start, i - 1) = -y[t - i];
    for (int j = 0; j < nb; ++j) {
      const long k = static_cast<long>(t) - d - j;
      phi(t - start, na + j) = k >= 0 ? x[k] : 0.0;
    }
    yy(t - start) = y[t];
  }
  const Eigen::VectorXd th = phi.colPivHouseholderQr().solve(yy);
  if (!th.allFinite()) return false;
  a->assign(th.data(), th.data() + na);
  b->assign(th.data() + na, th.data() + na + nb);
  return true;
}

}  // namespace

bool LmOptions::IsValid(std::string* error) const {
  if (max_iterations < 0 || !(relative_tolerance > 0)) {
    if (error) *error = "LmOptions: max_iterations >= 0 and relative_tolerance > 0 required";
    return false;
  }
  return true;
}

bool RefitOptions::IsValid(std::string* error) const {
  if (keep_grid_points < 1) {
    if (error) *error = "RefitOptions: keep_grid_points must be >= 1";
    return false;
  }
  return lm.IsValid(error);
}

Vec LevenbergMarquardt(const std::function<void(const Vec&, Vec*)>& residual, Vec p, const Vec& scale,
                       const LmOptions& options, LmSummary* summary) {
  const std::size_t np = p.size();
  Vec r, rt;
  residual(p, &r);
  auto cost = [](const Vec& v) { return std::inner_product(v.begin(), v.end(), v.begin(), 0.0); };
  double c = cost(r);
  LmSummary s;
  s.initial_cost = c;
  double lambda = 1e-3;
  const std::size_t m = r.size();
  Eigen::MatrixXd J(m, np);
  for (int it = 0; it < options.max_iterations && np > 0; ++it) {
    s.iterations = it + 1;
    for (std::size_t i = 0; i < np; ++i) {
      Vec q = p;
      const double h = 1e-6 * std::max(std::abs(p[i]), i < scale.size() ? scale[i] : 1e-3);
      q[i] += h;
      residual(q, &rt);
      for (std::size_t k = 0; k < m; ++k) J(k, i) = (rt[k] - r[k]) / h;
    }
    const Eigen::Map<const Eigen::VectorXd> rv(r.data(), m);
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * rv;
    bool improved = false;
    for (int tries = 0; tries < 12; ++tries) {
      Eigen::MatrixXd A = JtJ;
      for (std::size_t i = 0; i < np; ++i) A(i, i) += lambda * std::max(JtJ(i, i), 1e-12);
      const Eigen::VectorXd delta = A.ldlt().solve(-g);
      Vec q = p;
      for (std::size_t i = 0; i < np; ++i) q[i] += delta(i);
      residual(q, &rt);
      const double ct = cost(rt);
      if (std::isfinite(ct) && ct < c) {
        const double rel = (c - ct) / std::max(c, 1e-300);
        p = q;
        r = rt;
        c = ct;
        lambda = std::max(lambda / 3.0, 1e-9);
        improved = true;
        if (rel < options.relative_tolerance) s.converged = true;
        break;
      }
      lambda *= 4.0;
    }
    if (!improved) {
      s.converged = true;
      break;
    }
    if (s.converged) break;
  }
  s.final_cost = c;
  if (summary) *summary = s;
  return p;
}

double SumSquaredError(const AugmentedModel& m, const Segment& s) {
  Vec r;
  Residual(m, s, &r);
  return std::inner_product(r.begin(), r.end(), r.begin(), 0.0);
}

Vec StabilisedDenominator(const Vec& a) {
  const int n = static_cast<int>(a.size());
  if (n == 0) return a;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) C(0, i) = -a[i];
  for (int i = 1; i < n; ++i) C(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> es(C, false);
  std::vector<std::complex<double>> roots;
  bool changed = false;
  for (int i = 0; i < n; ++i) {
    std::complex<double> r = es.eigenvalues()(i);
    const double mag = std::abs(r);
    if (mag > 0.9995) {
      r = r / mag * std::min(1.0 / mag, 0.9995);
      changed = true;
    }
    roots.push_back(r);
  }
  return changed ? PolyFromRoots(roots) : a;
}

bool NominalSpec::IsValid(std::string* error) const {
  if (na < 0 || nb < 1 || delay < 0 || input_degree < 1 || output_degree < 1 || na > 20 || nb > 40 ||
      input_degree > 9 || output_degree > 9) {
    if (error) *error = "nominal structure needs 0 <= NA <= 20, 1 <= NB <= 40, DELAY >= 0, 1 <= degrees <= 9";
    return false;
  }
  return true;
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

HwModel FitNominal(const NominalSpec& spec, const Segment& data) {
  const Vec& u = *data.u;
  const Vec& y = *data.y;
  Vec a, b;
  if (!Arx(u, y, spec.na, spec.nb, spec.delay, data.skip, &a, &b)) {
    a.assign(spec.na, 0.0);
    b.assign(spec.nb, 0.0);
  }
  a = StabilisedDenominator(a);
  // Steiglitz–McBride: prefilter by the current 1/A and re-solve; converges towards the OE fit.
  HwModel m;
  m.linear = {a, b, spec.delay};
  double best = SumSquaredError(AugmentedModel{m, {}}, data);
  for (int it = 0; it < 6 && spec.na > 0; ++it) {
    LinearBlock filt{a, {1.0}, 0};
    const Vec uf = filt.simulate(u), yf = filt.simulate(y);
    Vec a2, b2;
    if (!Arx(uf, yf, spec.na, spec.nb, spec.delay, data.skip, &a2, &b2)) break;
    a2 = StabilisedDenominator(a2);
    HwModel t = m;
    t.linear = {a2, b2, spec.delay};
    const double c = SumSquaredError(AugmentedModel{t, {}}, data);
    a = a2;
    if (c < best) best = c, m = t;
  }
  if (spec.input_degree > 1) {
    Vec c(spec.input_degree, 0.0);
    c[0] = 1.0;
    m.input = StaticMap::Polynomial(c);
  }
  if (spec.output_degree > 1) {
    Vec c(spec.output_degree, 0.0);
    c[0] = 1.0;
    m.output = StaticMap::Polynomial(c);
  }
  m.name = spec.input_degree > 1 || spec.output_degree > 1
               ? fmt::format("hw:{},{},{},{},{}", spec.na, spec.nb, spec.input_degree, spec.output_degree, spec.delay)
               : fmt::format("linear:{},{},{}", spec.na, spec.nb, spec.delay);
  RefitOptions o;
  o.lm.max_iterations = 80;
  o.fit_output_offset = false;  // HwModel has no offset; the diagnosis estimates one with every refit
  return RefitNominal(m, data, o).model.nominal;
}

RefitResult RefitNominal(const HwModel& nominal, const Segment& data, const RefitOptions& options) {
  AugmentedModel m{nominal, {}};
  return Polish(m, data, options);
}

RefitResult RefitWithEffect(const HwModel& nominal, Effect effect, Location location, const Segment& data,
                            const RefitOptions& options, double output_offset) {
  if (effect == Effect::kNone) return RefitNominal(nominal, data, options);
  const Vec& u = *data.u;
  Vec zhat = LinearBlock(nominal.linear).simulate([&] {
    Vec x(u.size());
    for (std::size_t t = 0; t < u.size(); ++t) x[t] = nominal.input(u[t]);
    return x;
  }());
  const auto grid = EffectGrid(effect, location, u, *data.y, zhat, nominal);
  std::vector<std::pair<double, AugmentedModel>> scored;
  for (const auto& p : grid) {
    AugmentedModel m{nominal, {effect, location, p}, options.fit_output_offset ? output_offset : 0.0};
    std::string err;
    if (!m.block.IsValid(&err)) continue;
    SolveNumerator(&m, data, options.fit_output_offset);
    const double c = SumSquaredError(m, data);
    if (std::isfinite(c)) scored.emplace_back(c, m);
  }
  std::sort(scored.begin(), scored.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  RefitResult best;
  best.sse = std::numeric_limits<double>::infinity();
  const int keep = std::min<int>(options.keep_grid_points, static_cast<int>(scored.size()));
  for (int i = 0; i < keep; ++i) {
    RefitResult r = Polish(scored[i].second, data, options);
    if (r.sse < best.sse) best = r;
  }
  if (!std::isfinite(best.sse)) {  // no admissible grid point: report the block switched off
    best = RefitNominal(nominal, data, options);
  }
  return best;
}

}  // namespace hw::diagnose
