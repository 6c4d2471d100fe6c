#include "dss/hw_outer_set.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/csv_table.hpp"

namespace hw::dss {

bool HwStructure::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (input_basis.empty()) return fail("the input basis needs at least one function (psi_1, with gamma_1 = 1)");
  if (output_basis.empty()) return fail("the output basis needs at least one function (phi_1, with alpha_1 = 1)");
  if (na < 1) return fail("na must be >= 1");
  if (nb < 0) return fail("nb must be >= 0");
  if (strictly_proper && nb < 1) return fail("a strictly proper block needs nb >= 1");
  return true;
}

bool HwData::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = source + ": " + std::move(m);
    return false;
  };
  if (u.size() != y.size()) return fail(fmt::format("u has {} samples but y has {}", u.size(), y.size()));
  if (noise_bound.size() != y.size())
    return fail(fmt::format("the noise bound has {} samples but y has {}", noise_bound.size(), y.size()));
  if (!lines.empty() && lines.size() != y.size())
    return fail(fmt::format("{} line numbers for {} samples", lines.size(), y.size()));
  for (std::size_t t = 0; t < y.size(); ++t) {
    const int i = static_cast<int>(t);
    if (!std::isfinite(u[t]) || !std::isfinite(y[t])) {
      if (error) *error = where(i) + ": u or y is not finite";
      return false;
    }
    if (!(noise_bound[t] > 0) || !std::isfinite(noise_bound[t])) {
      if (error)
        *error = fmt::format("{}: the noise bound is {}; it must be a positive finite number", where(i), noise_bound[t]);
      return false;
    }
  }
  return true;
}

bool ValidHorizon(int horizon, std::string* error) {
  if (horizon >= 1 && horizon <= kMaxHorizon) return true;
  if (error) *error = fmt::format("horizon {} is out of range; the dynamic horizon n lies in 1..{}", horizon, kMaxHorizon);
  return false;
}

int MinimalOrder(int horizon) { return std::max(1, (horizon + 2) / 2); }

bool ValidNoiseBound(double noise_bound, std::string* error) {
  if (noise_bound > 0 && std::isfinite(noise_bound)) return true;
  if (error)
    *error = fmt::format("noise_bound {} is not a positive finite number; |eta_t| <= noise_bound needs one (or give "
                         "one bound per sample)",
                         noise_bound);
  return false;
}

std::string HwData::where(int t) const {
  if (t >= 0 && static_cast<std::size_t>(t) < lines.size()) return fmt::format("{}:{} (sample {})", source, lines[t], t + 1);
  return fmt::format("{}: sample {}", source, t + 1);
}

HwStructure CeroneExampleStructure() {
  HwStructure s;
  s.input_basis = parse_basis("poly:3");
  s.output_basis = parse_basis("poly:3");
  s.na = 2;
  s.nb = 2;
  s.strictly_proper = true;
  return s;
}

ParameterLayout MakeLayout(const HwStructure& s) {
  ParameterLayout L;
  L.gamma_begin = 0;
  for (std::size_t i = 2; i <= s.input_basis.size(); ++i) L.names.push_back(fmt::format("gamma{}", i));
  L.num_gamma = static_cast<int>(s.input_basis.size()) - 1;
  L.alpha_begin = L.count();
  for (std::size_t j = 2; j <= s.output_basis.size(); ++j) L.names.push_back(fmt::format("alpha{}", j));
  L.num_alpha = static_cast<int>(s.output_basis.size()) - 1;
  L.a_begin = L.count();
  for (int i = 1; i <= s.na; ++i) L.names.push_back(fmt::format("a{}", i));
  L.b_begin = L.count();
  for (int j = s.strictly_proper ? 1 : 0; j <= s.nb; ++j) L.names.push_back(fmt::format("b{}", j));
  return L;
}

Scaling Scaling::FromBox(const std::vector<std::pair<double, double>>& box) {
  Scaling s;
  for (const auto& [lo, hi] : box) {
    s.center.push_back(0.5 * (lo + hi));
    s.radius.push_back(0.5 * (hi - lo));
  }
  return s;
}

std::vector<Polynomial> Scaling::substitution() const {
  const int n = static_cast<int>(center.size());
  std::vector<Polynomial> v;
  for (int i = 0; i < n; ++i) v.push_back(Polynomial::Constant(n, center[i]) + Polynomial::Variable(n, i, radius[i]));
  return v;
}

bool ValidBoxEntry(const std::string& name, double lo, double hi, const std::vector<std::string>& names,
                   std::string* error) {
  if (!name.empty() && std::find(names.begin(), names.end(), name) == names.end()) {
    if (error) *error = fmt::format("box: no parameter '{}'; the parameters are: {}", name, fmt::join(names, ", "));
    return false;
  }
  if (lo < hi && std::isfinite(lo) && std::isfinite(hi)) return true;
  if (error)
    *error = fmt::format("box{}: ({}, {}) is not an interval; expected (LO, HI) with LO < HI, both finite",
                         name.empty() ? "" : " of " + name, lo, hi);
  return false;
}

HwOuterSet::HwOuterSet(HwStructure structure, HwData data, int horizon, std::vector<std::pair<double, double>> box)
    : structure_(std::move(structure)), data_(std::move(data)), horizon_(horizon), box_(std::move(box)) {
  std::string error;
  if (!structure_.IsValid(&error)) throw InputError(error);
  if (!data_.IsValid(&error)) throw InputError(error);
  layout_ = MakeLayout(structure_);
  const int n = layout_.count();
  if (!ValidHorizon(horizon_, &error)) throw InputError(error);
  const int lag = std::max(structure_.na, structure_.nb);
  if (static_cast<int>(data_.y.size()) < lag + horizon_ + 1)
    throw InputError(fmt::format("{}: {} samples do not fit na = {}, nb = {} and horizon {}: at least {} are needed",
                                 data_.source, data_.y.size(), structure_.na, structure_.nb, horizon_,
                                 lag + horizon_ + 1));
  if (static_cast<int>(box_.size()) != n)
    throw InputError(fmt::format("the prior box has {} intervals; the model has {} parameters", box_.size(), n));
  for (int k = 0; k < n; ++k)
    if (!ValidBoxEntry(layout_.names[k], box_[k].first, box_[k].second, layout_.names, &error)) throw InputError(error);
  scaling_ = Scaling::FromBox(box_);
  scaled_vars_ = scaling_.substitution();

  auto var = [&](int i) { return Polynomial::Variable(n, i); };
  auto one = Polynomial::Constant(n, 1.0);
  std::vector<Polynomial> gamma{one}, alpha{one}, a, b;
  for (int i = 0; i < layout_.num_gamma; ++i) gamma.push_back(var(layout_.gamma_begin + i));
  for (int j = 0; j < layout_.num_alpha; ++j) alpha.push_back(var(layout_.alpha_begin + j));
  for (int i = 0; i < structure_.na; ++i) a.push_back(var(layout_.a_begin + i));
  if (structure_.strictly_proper) b.push_back(Polynomial(n));
  for (int j = structure_.strictly_proper ? 1 : 0; j <= structure_.nb; ++j)
    b.push_back(var(layout_.b_begin + j - (structure_.strictly_proper ? 1 : 0)));

  // Rows r_s = first row of A^s, A = [-a; I 0].
  const int na = structure_.na;
  std::vector<std::vector<Polynomial>> r(horizon_ + 1);
  r[0].assign(na, Polynomial(n));
  r[0][0] = one;
  for (int s = 1; s <= horizon_; ++s) {
    r[s].assign(na, Polynomial(n));
    for (int h = 0; h < na; ++h) {
      r[s][h] = r[s - 1][0] * (-a[h]);
      if (h + 1 < na) r[s][h] += r[s - 1][h + 1];
    }
  }
  // Sign vector q: alpha_2.., then Q_{s,h} = -r_s[h].
  for (int j = 1; j < static_cast<int>(alpha.size()); ++j) {
    q_.push_back(alpha[j]);
    q_names_.push_back(layout_.names[layout_.alpha_begin + j - 1]);
  }
  std::vector<std::vector<int>> q_index(horizon_ + 1, std::vector<int>(na, -1));
  for (int s = 1; s <= horizon_; ++s)
    for (int h = 0; h < na; ++h) {
      q_index[s][h] = static_cast<int>(q_.size());
      q_.push_back(-r[s][h]);
      q_names_.push_back(fmt::format("Q{}_{}", s, h + 1));
    }

  // phi ranges.
  const int N = static_cast<int>(data_.y.size());
  phi_range_.resize(N);
  for (int t = 0; t < N; ++t)
    for (const auto& phi : structure_.output_basis)
      phi_range_[t].push_back(phi.range(data_.y[t] - data_.noise_bound[t], data_.y[t] + data_.noise_bound[t]));

  CheckBasisValues();

  // x_t as polynomials (linear in gamma), cached per sample.
  std::vector<Polynomial> x(N, Polynomial(n));
  for (int t = 0; t < N; ++t)
    for (std::size_t i = 0; i < gamma.size(); ++i) x[t] += gamma[i] * structure_.input_basis[i].value(data_.u[t]);

  for (int s = 1; s <= horizon_; ++s) {
    std::vector<Polynomial> c(s);  // c_m = r_m[0], m = 0..s-1
    for (int m = 0; m < s; ++m) c[m] = r[m][0];
    for (int t = s - 1 + lag; t < N; ++t) {
      Equation eq{t, s, {}, Polynomial(n)};
      for (std::size_t j = 0; j < alpha.size(); ++j)
        eq.lhs.push_back({alpha[j], -1, j == 0 ? -1 : static_cast<int>(j) - 1, t, static_cast<int>(j)});
      for (int h = 0; h < na; ++h) {
        const int tau = t - s - h;  // z_{t-s-h+1} with 1-based h
        for (std::size_t j = 0; j < alpha.size(); ++j)
          eq.lhs.push_back({-r[s][h] * alpha[j], q_index[s][h], j == 0 ? -1 : static_cast<int>(j) - 1, tau,
                            static_cast<int>(j)});
      }
      for (int k = 1; k <= s; ++k) {
        Polynomial v(n);
        for (std::size_t j = 0; j < b.size(); ++j) v += b[j] * x[t - s + k - static_cast<int>(j)];
        eq.rhs += c[s - k] * v;
      }
      equations_.push_back(std::move(eq));
    }
  }
  build(0, true);  // products of finite values can still overflow: fail here, before any solver work
}

namespace {

// The power of ten nearest to v > 0: the scaling suggested in messages.
double PowerOfTen(double v) { return std::pow(10.0, std::round(std::log10(v))); }

// Largest / smallest of the positive entries (1 when fewer than two).
double Spread(const std::vector<double>& magnitudes) {
  double lo = INFINITY, hi = 0.0;
  for (double m : magnitudes)
    if (m > 0) lo = std::min(lo, m), hi = std::max(hi, m);
  return hi > 0 && lo < hi ? hi / lo : 1.0;
}

// The SDP solvers resolve about 8 significant digits; basis values spanning more make some parameters'
// terms vanish into the others' rounding error.
constexpr double kResolvedSpread = 1e8;

}  // namespace

void HwOuterSet::CheckBasisValues() {
  const int N = static_cast<int>(data_.y.size());
  double u_max = 0.0, y_max = 0.0;
  for (int t = 0; t < N; ++t) u_max = std::max(u_max, std::abs(data_.u[t])), y_max = std::max(y_max, std::abs(data_.y[t]));
  std::vector<double> in_max(structure_.input_basis.size(), 0.0), out_max(structure_.output_basis.size(), 0.0);
  int lost_noise = 0, first_lost = -1;
  for (int t = 0; t < N; ++t) {
    for (std::size_t i = 0; i < in_max.size(); ++i) {
      const auto& psi = structure_.input_basis[i];
      const double v = psi.value(data_.u[t]);
      if (!std::isfinite(v))
        throw InputError(fmt::format("{}: u = {:g} gives {}(u) = {:g}, which overflows double precision, so no "
                                     "constraint of this sample is finite; rescale column u (e.g. divide it by {:g}) "
                                     "and the prior box with it",
                                     data_.where(t), data_.u[t], psi.name, v, PowerOfTen(u_max)));
      in_max[i] = std::max(in_max[i], std::abs(v));
    }
    for (std::size_t j = 0; j < out_max.size(); ++j) {
      const auto [lo, hi] = phi_range_[t][j];
      if (!std::isfinite(lo) || !std::isfinite(hi))
        throw InputError(fmt::format("{}: y = {:g} (noise bound {:g}) gives {}(w) = {:g}..{:g}, which overflows double "
                                     "precision, so no constraint of this sample is finite; rescale column y (e.g. "
                                     "divide it and the noise bound by {:g}) and the prior box with it",
                                     data_.where(t), data_.y[t], data_.noise_bound[t],
                                     structure_.output_basis[j].name, lo, hi, PowerOfTen(y_max)));
      out_max[j] = std::max(out_max[j], std::max(std::abs(lo), std::abs(hi)));
    }
    if (data_.y[t] + data_.noise_bound[t] == data_.y[t] || data_.y[t] - data_.noise_bound[t] == data_.y[t]) {
      if (first_lost < 0) first_lost = t;
      ++lost_noise;
    }
  }
  auto warn_spread = [&](const std::vector<double>& magnitudes, const char* side, double max_abs, const char* column) {
    if (Spread(magnitudes) <= kResolvedSpread) return;
    warnings_.push_back(fmt::format(
        "the {} basis values span {:.1e} (max |{}| = {:g}): the smallest terms lose all relative precision in the "
        "solvers (about 8 digits); scale {} to max |{}| of about 1 (divide column {} by {:g}; the parameters and "
        "the prior box scale with it)",
        side, Spread(magnitudes), column, max_abs, column, column, column, PowerOfTen(max_abs)));
  };
  warn_spread(in_max, "input", u_max, "u");
  warn_spread(out_max, "output", y_max, "y");
  if (lost_noise > 0)
    warnings_.push_back(fmt::format(
        "at {} samples (first {}) the noise bound is below the resolution of y (y +- noise == y in double "
        "precision): their noise band is lost; subtract an offset from y or rescale it",
        lost_noise, data_.where(first_lost)));
}

std::vector<int> HwOuterSet::orthant_signs(int l) const {
  std::vector<int> s(q_.size());
  for (std::size_t k = 0; k < q_.size(); ++k) s[k] = (l >> k) & 1 ? -1 : 1;
  return s;
}

int HwOuterSet::orthant_of(const std::vector<double>& p) const {
  int l = 0;
  for (std::size_t k = 0; k < q_.size(); ++k)
    if (q_[k].evaluate(p) < 0) l |= 1 << k;
  return l;
}

namespace {
Polynomial normalised(Polynomial p) {
  p.prune(1e-14 * p.max_abs_coefficient());
  const double m = p.max_abs_coefficient();
  if (m > 0) p *= 1.0 / m;
  return p;
}
}  // namespace

std::vector<Polynomial> HwOuterSet::sign_constraints(int l) const {
  const auto signs = orthant_signs(l);
  std::vector<Polynomial> out;
  for (std::size_t k = 0; k < q_.size(); ++k) out.push_back(normalised(q_[k].compose(scaled_vars_) * signs[k]));
  return out;
}

std::vector<Polynomial> HwOuterSet::box_constraints() const {
  const int n = layout_.count();
  std::vector<Polynomial> out;
  for (int i = 0; i < n; ++i) {
    const auto x = Polynomial::Variable(n, i);
    out.push_back(Polynomial::Constant(n, 1.0) - x * x);
  }
  return out;
}

std::vector<DataConstraint> HwOuterSet::build(int l, bool scaled) const {
  const auto signs = orthant_signs(l);
  std::vector<DataConstraint> out;
  out.reserve(2 * equations_.size());
  for (const auto& eq : equations_) {
    Polynomial upper = -eq.rhs, lower = eq.rhs;  // upper LHS - rhs >= 0 ; rhs - lower LHS >= 0
    for (const auto& term : eq.lhs) {
      const int sign = (term.sign_kappa < 0 ? 1 : signs[term.sign_kappa]) * (term.sign_alpha < 0 ? 1 : signs[term.sign_alpha]);
      const auto [lo, hi] = phi_range_[term.sample][term.basis];
      upper += term.coefficient * (sign > 0 ? hi : lo);
      lower -= term.coefficient * (sign > 0 ? lo : hi);
    }
    if (scaled) {
      upper = upper.compose(scaled_vars_);
      lower = lower.compose(scaled_vars_);
    }
    for (const auto* g : {&upper, &lower})
      for (const auto& [e, c] : g->terms())
        if (!std::isfinite(c))
          throw InputError(fmt::format("{}: a coefficient of this sample's horizon-{} constraint overflows double "
                                       "precision (products of the data's basis values and the prior box); rescale "
                                       "u and y to magnitudes near 1 and the prior box with them",
                                       data_.where(eq.t), eq.s));
    out.push_back({normalised(upper), eq.t, eq.s, true});
    out.push_back({normalised(lower), eq.t, eq.s, false});
  }
  return out;
}

std::vector<DataConstraint> HwOuterSet::data_constraints(int l) const { return build(l, true); }

std::vector<Polynomial> HwOuterSet::orthant_inequalities(int l) const {
  const auto signs = orthant_signs(l);
  std::vector<Polynomial> out;
  for (std::size_t k = 0; k < q_.size(); ++k) out.push_back(q_[k] * signs[k]);
  for (auto& c : build(l, false)) out.push_back(std::move(c.g));
  return out;
}

double HwOuterSet::min_slack(const std::vector<double>& p) const {
  const int l = orthant_of(p);
  double m = INFINITY;
  for (const auto& c : build(l, false)) m = std::min(m, c.g.evaluate(p));
  return m;
}

}  // namespace hw::dss
