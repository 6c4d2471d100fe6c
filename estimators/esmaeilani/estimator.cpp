#include "estimators/esmaeilani/estimator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "core/input_error.hpp"
#include "core/json_input.hpp"

namespace hw::esmaeilani {
namespace {

constexpr double kInf = 1e20;
using Triplets = std::vector<Eigen::Triplet<double>>;
using Clock = std::chrono::steady_clock;

std::vector<double> Linspace(double lo, double hi, int n) {
  std::vector<double> g(n);
  for (int k = 0; k < n; ++k) g[k] = n == 1 ? lo : lo + (hi - lo) * k / (n - 1);
  return g;
}

// Hat-function weights of s on an ascending grid: (index, weight) pairs; linear extrapolation outside.
std::pair<int, double> Bracket(const std::vector<double>& grid, double s) {
  const int n = static_cast<int>(grid.size());
  int i = static_cast<int>(std::upper_bound(grid.begin(), grid.end(), s) - grid.begin());
  i = std::clamp(i, 1, n - 1);
  return {i - 1, (s - grid[i - 1]) / (grid[i] - grid[i - 1])};  // value = (1-w) g[i-1] + w g[i]
}

double Interpolate(const std::vector<double>& grid, const std::vector<double>& values, double s) {
  if (grid.size() == 1) return values[0];
  const auto [k, w] = Bracket(grid, s);
  return (1 - w) * values[k] + w * values[k + 1];
}

Eigen::SparseMatrix<double> InterpolationMatrix(const std::vector<double>& grid, const std::vector<double>& s) {
  Triplets t;
  for (std::size_t r = 0; r < s.size(); ++r) {
    const auto [k, w] = Bracket(grid, s[r]);
    t.emplace_back(r, k, 1 - w);
    t.emplace_back(r, k + 1, w);
  }
  Eigen::SparseMatrix<double> m(s.size(), grid.size());
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

void CheckFunctionConstraints(const FunctionConstraints& c, const std::string& name) {
  if (c.has_range && !(c.range_lower <= c.range_upper))
    throw InputError(fmt::format("constraints: {} range [{}, {}] is empty (need lower <= upper)", name,
                                 c.range_lower, c.range_upper));
  for (const auto& s : c.slopes)
    if (!(s.lower <= s.upper) || !(s.from <= s.to))
      throw InputError(fmt::format("constraints: {} slope limit on [{}, {}] with [{}, {}] is empty (need from <= "
                                   "to and min <= max)", name, s.from, s.to, s.lower, s.upper));
  for (const auto& p : c.points) {
    if (!(p.lower <= p.upper))
      throw InputError(fmt::format("constraints: {} point at {} has empty range [{}, {}]", name, p.at, p.lower,
                                   p.upper));
    if (c.has_range && (p.upper < c.range_lower || p.lower > c.range_upper))
      throw InputError(fmt::format("constraints: {}({}) in [{}, {}] contradicts the range [{}, {}]", name, p.at,
                                   p.lower, p.upper, c.range_lower, c.range_upper));
  }
}

// The residual is homogeneous in the scale of each function; without two known points (or a positive
// minimum slope) the least-squares minimum is degenerate. Say so instead of returning a trivial model.
void RequirePinned(const FunctionConstraints& c, const std::string& name, const std::string& why) {
  std::vector<double> known;
  for (const auto& p : c.points)
    if (p.lower == p.upper && std::find(known.begin(), known.end(), p.at) == known.end()) known.push_back(p.at);
  bool positive_slope = false;
  for (const auto& s : c.slopes) positive_slope |= s.lower > 0 || s.upper < 0;
  if (known.size() >= 2 || positive_slope) return;
  throw InputError(fmt::format(
      "constraints: {} is not normalised: {}. Give two known points (\"points\": [[at1, v1], [at2, v2]]) or a "
      "slope limit with min > 0 for {} (paper Assumption 2)", name, why, name));
}

FunctionConstraints FunctionFromJson(const nlohmann::json& j, const std::string& where) {
  FunctionConstraints c;
  if (!j.is_object()) throw InputError(where + ": expected an object with range, slopes, points");
  CheckKeys(j, {"range", "slopes", "points"}, where);
  if (j.contains("range")) {
    const auto r = j.at("range").get<std::vector<double>>();
    if (r.size() != 2) throw InputError(where + ".range: expected [lower, upper]");
    c.has_range = true;
    c.range_lower = r[0];
    c.range_upper = r[1];
  }
  for (const auto& s : j.value("slopes", nlohmann::json::array())) {
    CheckKeys(s, {"from", "to", "min", "max"}, where + ".slopes[]");
    FunctionConstraints::Slope sl{-kInf, kInf, -kInf, kInf};
    sl.from = s.value("from", -kInf);
    sl.to = s.value("to", kInf);
    sl.lower = s.value("min", -kInf);
    sl.upper = s.value("max", kInf);
    c.slopes.push_back(sl);
  }
  for (const auto& p : j.value("points", nlohmann::json::array())) {
    const auto v = p.get<std::vector<double>>();
    if (v.size() == 2) c.points.push_back({v[0], v[1], v[1]});
    else if (v.size() == 3) c.points.push_back({v[0], v[1], v[2]});
    else throw InputError(where + ".points: each point is [at, value] or [at, lower, upper]");
  }
  return c;
}

nlohmann::json FunctionToJson(const FunctionConstraints& c) {
  nlohmann::json j = nlohmann::json::object();
  if (c.has_range) j["range"] = {c.range_lower, c.range_upper};
  for (const auto& s : c.slopes) j["slopes"].push_back({{"from", s.from}, {"to", s.to}, {"min", s.lower}, {"max", s.upper}});
  for (const auto& p : c.points) j["points"].push_back({p.at, p.lower, p.upper});
  return j;
}

// Variable layout of alpha = [x (segment by segment, time-major); f'; g'; v; a; b; d].
struct Layout {
  int n = 0, gf = 0, gg = 0, total_samples = 0;
  std::vector<int> seg_start;  // sample offset of each segment
  std::vector<int> seg_len;
  int x(int s, int t, int i) const { return (seg_start[s] + t) * n + i; }
  int f(int k) const { return n * total_samples + k; }
  int g(int k) const { return f(gf) + k; }
  int v(int s, int t) const { return g(gg) + seg_start[s] + t; }
  int a(int i) const { return g(gg) + total_samples + i; }
  int b(int i) const { return a(n) + i; }
  int d() const { return b(n); }
  int offset() const { return d() + 1; }  // m_e: mean of the output-equation disturbance (beta^[1])
  int size() const { return d() + 2; }
  int rows() const {
    int r = 0;
    for (int len : seg_len) r += n * (len - 1) + 2 * len;
    return r;
  }
};

struct Problem {
  Layout L;
  Options opt;
  Eigen::SparseMatrix<double> omega_f, omega_g;  // total_samples x grid
  Eigen::SparseMatrix<double> C;                 // linear constraints on alpha
  Eigen::VectorXd c_lower, c_upper;
  bool fix_d_zero = false;
  std::vector<char> censored;  // per sample: 1 = y at a known saturation (output equation dropped)

  // Residual theta(alpha) and, if J != nullptr, its Jacobian.
  void Evaluate(const Eigen::VectorXd& al, Eigen::VectorXd* r, Eigen::SparseMatrix<double>* J) const {
    const int n = L.n;
    const Eigen::VectorXd F = omega_f * al.segment(L.f(0), L.gf);
    const Eigen::VectorXd G = omega_g * al.segment(L.g(0), L.gg);
    r->resize(L.rows());
    Triplets t;
    if (J) t.reserve(static_cast<std::size_t>(L.rows()) * 10);
    const double ws = opt.weight_state, wo = opt.weight_output, wv = opt.weight_noise;
    const double d = al[L.d()];
    int row = 0;
    auto add_f_row = [&](int row_index, int sample, double coef) {  // coef * (Omega_f f')_sample
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(omega_f_rows, sample); it; ++it)
        t.emplace_back(row_index, L.f(static_cast<int>(it.col())), coef * it.value());
    };
    for (std::size_t s = 0; s < L.seg_len.size(); ++s) {
      const int S = static_cast<int>(s), N = L.seg_len[s], off = L.seg_start[s];
      for (int k = 0; k + 1 < N; ++k) {  // state equations
        const double input = F[off + k] + al[L.v(S, k)];
        const double last = al[L.x(S, k, n - 1)];
        for (int i = 0; i < n; ++i, ++row) {
          const double ai = al[L.a(i)], bi = al[L.b(i)];
          double val = al[L.x(S, k + 1, i)] + ai * last - bi * input;
          if (i > 0) val -= al[L.x(S, k, i - 1)];
          (*r)[row] = ws * val;
          if (!J) continue;
          t.emplace_back(row, L.x(S, k + 1, i), ws);
          if (i > 0) t.emplace_back(row, L.x(S, k, i - 1), -ws);
          t.emplace_back(row, L.x(S, k, n - 1), ws * ai);
          t.emplace_back(row, L.a(i), ws * last);
          t.emplace_back(row, L.b(i), -ws * input);
          add_f_row(row, off + k, -ws * bi);
          t.emplace_back(row, L.v(S, k), -ws * bi);
        }
      }
      for (int k = 0; k < N; ++k, ++row) {  // output equations
        if (!censored.empty() && censored[off + k]) {  // replaced by an inequality row in C
          (*r)[row] = 0.0;
          continue;
        }
        const double input = F[off + k] + al[L.v(S, k)];
        (*r)[row] = wo * (G[off + k] - al[L.x(S, k, n - 1)] - d * input - al[L.offset()]);
        if (!J) continue;
        t.emplace_back(row, L.offset(), -wo);
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(omega_g_rows, off + k); it; ++it)
          t.emplace_back(row, L.g(static_cast<int>(it.col())), wo * it.value());
        t.emplace_back(row, L.x(S, k, n - 1), -wo);
        t.emplace_back(row, L.d(), -wo * input);
        if (d != 0.0) {
          add_f_row(row, off + k, -wo * d);
          t.emplace_back(row, L.v(S, k), -wo * d);
        }
      }
      for (int k = 0; k < N; ++k, ++row) {  // input-noise terms
        (*r)[row] = wv * al[L.v(S, k)];
        if (J) t.emplace_back(row, L.v(S, k), wv);
      }
    }
    if (J) {
      J->resize(L.rows(), L.size());
      J->setFromTriplets(t.begin(), t.end());
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> omega_f_rows, omega_g_rows;
};

// Rows of the constraint matrix for one function's known information.
void AddFunctionConstraints(const FunctionConstraints& c, const std::vector<double>& grid, int first_var,
                            Triplets* t, std::vector<double>* lo, std::vector<double>* hi) {
  auto row = [&] { return static_cast<int>(lo->size()); };
  const int G = static_cast<int>(grid.size());
  if (c.has_range)
    for (int k = 0; k < G; ++k) {
      t->emplace_back(row(), first_var + k, 1.0);
      lo->push_back(c.range_lower);
      hi->push_back(c.range_upper);
    }
  for (const auto& s : c.slopes)
    for (int k = 0; k + 1 < G; ++k) {
      if (grid[k + 1] <= s.from || grid[k] >= s.to) continue;  // interval does not meet [from, to]
      const double h = grid[k + 1] - grid[k];
      t->emplace_back(row(), first_var + k + 1, 1.0);
      t->emplace_back(row(), first_var + k, -1.0);
      lo->push_back(s.lower <= -kInf ? -kInf : s.lower * h);
      hi->push_back(s.upper >= kInf ? kInf : s.upper * h);
    }
  for (const auto& p : c.points) {
    const auto [k, w] = Bracket(grid, p.at);
    t->emplace_back(row(), first_var + k, 1 - w);
    t->emplace_back(row(), first_var + k + 1, w);
    lo->push_back(p.lower);
    hi->push_back(p.upper);
  }
}

double Cost(const Problem& p, const Eigen::VectorXd& al) {
  Eigen::VectorXd r;
  p.Evaluate(al, &r, nullptr);
  return r.squaredNorm();
}

// Observable-canonical (a, b, d) from an ARX least-squares fit on the initial maps (paper step v).
void InitialLinearBlock(const std::vector<Segment>& segs, const EsmaeilaniModel& m0, int n, bool fix_d_zero,
                        std::vector<double>* a, std::vector<double>* b, double* d) {
  const int p = n + n + (fix_d_zero ? 0 : 1);
  Eigen::MatrixXd AtA = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd Atb = Eigen::VectorXd::Zero(p);
  for (const auto& s : segs) {
    const int N = static_cast<int>(s.u.size());
    std::vector<double> z(N), x(N);
    for (int t = 0; t < N; ++t) z[t] = m0.Ginv(s.y[t]), x[t] = m0.F(s.u[t]);
    for (int t = n; t < N; ++t) {
      Eigen::VectorXd phi(p);
      for (int k = 1; k <= n; ++k) phi[k - 1] = -z[t - k], phi[n + k - 1] = x[t - k];
      if (!fix_d_zero) phi[2 * n] = x[t];
      AtA += phi * phi.transpose();
      Atb += phi * z[t];
    }
  }
  AtA.diagonal().array() += 1e-9 * (1.0 + AtA.diagonal().array());
  const Eigen::VectorXd th = AtA.ldlt().solve(Atb);
  *d = fix_d_zero ? 0.0 : th[2 * n];
  a->assign(n, 0.0);
  b->assign(n, 0.0);
  for (int k = 1; k <= n; ++k) {
    (*a)[n - k] = th[k - 1];                       // paper a = [a_n .. a_1]
    (*b)[n - k] = th[n + k - 1] - *d * th[k - 1];  // B_{n-k+1} = c_k - d a_k
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
Constraints Constraints::FromJson(const nlohmann::json& j, const std::string& source) {
  Constraints c;
  try {
    if (!j.is_object()) throw InputError(source + ": constraints must be a JSON object");
    CheckKeys(j, {"f", "g_inverse", "d", "output_range", "saturation_tolerance", "comment"}, source);
    if (j.contains("comment") && !j.at("comment").is_string()) throw InputError(source + ": comment must be a string");
    if (j.contains("f")) c.f = FunctionFromJson(j.at("f"), source + ": f");
    if (j.contains("g_inverse")) c.g_inverse = FunctionFromJson(j.at("g_inverse"), source + ": g_inverse");
    if (j.contains("d")) {
      if (!j.at("d").is_number() || j.at("d").get<double>() != 0.0)
        throw InputError(source + ": d: only \"d\": 0 (no direct feedthrough) is supported");
      c.fix_d_zero = true;
    }
    if (j.contains("output_range")) {
      const auto r = j.at("output_range").get<std::vector<double>>();
      if (r.size() != 2 || !(r[0] < r[1]))
        throw InputError(source + ": output_range: expected [lower, upper] with lower < upper");
      c.has_output_range = true;
      c.output_lower = r[0];
      c.output_upper = r[1];
    }
    if (j.contains("saturation_tolerance")) {
      c.saturation_tolerance = j.at("saturation_tolerance").get<double>();
      if (!c.has_output_range || !(c.saturation_tolerance >= 0))
        throw InputError(source + ": saturation_tolerance needs output_range and a value >= 0 (the bound on the "
                         "output measurement noise, in units of y)");
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  try {
    CheckFunctionConstraints(c.f, "f");
    CheckFunctionConstraints(c.g_inverse, "g_inverse");
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  return c;
}

Constraints Constraints::Load(const std::string& path) { return FromJson(ReadJsonFile(path, "constraints JSON file"), path); }

nlohmann::json Constraints::ToJson() const {
  nlohmann::json j = {{"f", FunctionToJson(f)}, {"g_inverse", FunctionToJson(g_inverse)}};
  if (fix_d_zero) j["d"] = 0;
  if (has_output_range) j["output_range"] = {output_lower, output_upper};
  if (saturation_tolerance >= 0) j["saturation_tolerance"] = saturation_tolerance;
  return j;
}

bool Options::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (order < 1 || order > 20) return fail(fmt::format("order {} out of range; expected 1..20", order));
  if (grid_f < 2 || grid_g < 2) return fail("grid sizes must be at least 2 ordered pairs");
  if (!(weight_state > 0 && weight_output > 0 && weight_noise > 0)) return fail("residual weights must be > 0");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(relative_decrease > 0)) return fail("relative_decrease must be > 0");
  if (!(damping >= 0)) return fail("damping must be >= 0");
  if (oe_max_iterations < 1) return fail("oe_max_iterations must be >= 1");
  return true;
}

double EsmaeilaniModel::F(double u) const { return Interpolate(u_grid, f_values, u); }
double EsmaeilaniModel::Ginv(double y) const { return Interpolate(y_grid, ginv_values, y); }

StaticMap EsmaeilaniModel::OutputMap(bool clamp) const {
  // Monotone version of g^{-1} in its dominant direction, then swap the pairs.
  const int G = static_cast<int>(y_grid.size());
  const bool increasing = ginv_values.back() >= ginv_values.front();
  std::vector<double> z = ginv_values;
  for (int k = 1; k < G; ++k) z[k] = increasing ? std::max(z[k], z[k - 1]) : std::min(z[k], z[k - 1]);
  std::vector<std::pair<double, double>> pairs;  // (z, w)
  for (int k = 0; k < G; ++k) pairs.emplace_back(z[k] - output_offset, y_grid[k]);
  std::sort(pairs.begin(), pairs.end());
  std::vector<double> xs, ws;
  const double span = std::max(std::abs(pairs.back().first - pairs.front().first), 1e-12);
  for (std::size_t k = 0; k < pairs.size();) {  // merge equal z (a flat g^{-1} piece is a jump of g)
    std::size_t e = k;
    double sum = 0.0;
    while (e < pairs.size() && pairs[e].first - pairs[k].first <= 1e-12 * span) sum += pairs[e++].second;
    xs.push_back(pairs[k].first);
    ws.push_back(sum / static_cast<double>(e - k));
    k = e;
  }
  if (xs.size() == 1) return StaticMap::PiecewiseLinear({xs[0] - 1, xs[0] + 1}, {ws[0], ws[0]});
  if (clamp && has_output_range) {
    // Extend the end pieces linearly until they reach the known output limits, then hold: the plant's
    // output saturates at its physical limits, not where the estimation data happened to stop.
    for (double& w : ws) w = std::clamp(w, output_lower, output_upper);
    const std::size_t e = xs.size() - 1;
    const double s0 = (ws[1] - ws[0]) / (xs[1] - xs[0]), s1 = (ws[e] - ws[e - 1]) / (xs[e] - xs[e - 1]);
    if (s1 != 0.0) {
      const double target = s1 > 0 ? output_upper : output_lower;
      if (target != ws[e]) xs.push_back(xs[e] + (target - ws[e]) / s1), ws.push_back(target);
    }
    if (s0 != 0.0) {
      const double target = s0 > 0 ? output_lower : output_upper;
      if (target != ws[0]) xs.insert(xs.begin(), xs[0] + (target - ws[0]) / s0), ws.insert(ws.begin(), target);
    }
  }
  if (clamp) {  // flat end pieces: the piecewise-linear map then extrapolates as a constant
    const double step = (xs.back() - xs.front()) / static_cast<double>(xs.size() - 1);
    xs.insert(xs.begin(), xs.front() - step);
    ws.insert(ws.begin(), ws.front());
    xs.push_back(xs.back() + step);
    ws.push_back(ws.back());
  }
  return StaticMap::PiecewiseLinear(xs, ws);
}

HwModel EsmaeilaniModel::ToHwModel(bool clamp_output) const {
  HwModel m;
  m.name = "esmaeilani";
  m.input = StaticMap::PiecewiseLinear(u_grid, f_values);
  m.output = OutputMap(clamp_output);
  const int n = static_cast<int>(a.size());
  m.linear.a.resize(n);
  std::vector<double> c(n);
  for (int k = 1; k <= n; ++k) {
    m.linear.a[k - 1] = a[n - k];
    c[k - 1] = b[n - k] + d * a[n - k];
  }
  if (d == 0.0) {
    m.linear.b = c;
    m.linear.delay = 1;
  } else {
    m.linear.b = {d};
    m.linear.b.insert(m.linear.b.end(), c.begin(), c.end());
    m.linear.delay = 0;
  }
  return m;
}

std::vector<double> EsmaeilaniModel::SteadyState(double u) const {
  const int n = static_cast<int>(a.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i < n; ++i) A(i, i - 1) = 1.0;
  for (int i = 0; i < n; ++i) A(i, n - 1) = -a[i];
  const Eigen::VectorXd B = Eigen::Map<const Eigen::VectorXd>(b.data(), n);
  const Eigen::MatrixXd M = Eigen::MatrixXd::Identity(n, n) - A;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
  std::vector<double> x(n, 0.0);
  if (!lu.isInvertible()) return x;
  const Eigen::VectorXd xs = lu.solve(B * F(u));
  for (int i = 0; i < n; ++i) x[i] = xs[i];
  return x;
}

std::vector<double> EsmaeilaniModel::Simulate(const std::vector<double>& u, std::vector<double> x0,
                                              bool clamp_output) const {
  const int n = static_cast<int>(a.size());
  if (u.empty()) return {};
  if (x0.empty()) x0 = SteadyState(u[0]);
  const StaticMap g = OutputMap(clamp_output);
  std::vector<double> x = x0, next(n), y(u.size());
  for (std::size_t t = 0; t < u.size(); ++t) {
    const double in = F(u[t]);
    y[t] = g(x[n - 1] + d * in);
    for (int i = 0; i < n; ++i) next[i] = (i > 0 ? x[i - 1] : 0.0) - a[i] * x[n - 1] + b[i] * in;
    x.swap(next);
  }
  return y;
}

nlohmann::json EsmaeilaniModel::ToJson() const {
  return {{"parametrisation", "observable canonical (paper 002 eq. 4): a = [a_n..a_1], b = vec(B)"},
          {"a", a},
          {"b", b},
          {"d", d},
          {"output_offset", output_offset},
          {"output_range", has_output_range ? nlohmann::json{output_lower, output_upper} : nlohmann::json()},
          {"f_pairs", {{"u", u_grid}, {"f", f_values}}},
          {"g_inverse_pairs", {{"y", y_grid}, {"g_inverse", ginv_values}}},
          {"initial_states", initial_states}};
}

nlohmann::json ModelFileJson(const EsmaeilaniModel& m, const Options& options, const Constraints& constraints,
                             const Summary& summary) {
  nlohmann::json j = m.ToHwModel(options.clamp_output).to_json();
  j["esmaeilani"] = m.ToJson();
  j["esmaeilani"]["constraints"] = constraints.ToJson();
  j["esmaeilani"]["final_cost"] = summary.final_cost;
  if (summary.output_error.ran) j["esmaeilani"]["output_error_cost"] = summary.output_error.final_cost;
  return j;
}

// ---------------------------------------------------------------------------------------------
EsmaeilaniModel Estimate(const Options& options, const std::vector<Segment>& segments,
                         const Constraints& constraints, Summary* summary) {
  const auto start = Clock::now();
  Summary local;
  Summary& sum = summary ? *summary : local;
  sum = Summary{};
  std::string err;
  if (!options.IsValid(&err)) throw InputError("esmaeilani options: " + err);
  CheckFunctionConstraints(constraints.f, "f");
  CheckFunctionConstraints(constraints.g_inverse, "g_inverse");
  if (segments.empty()) throw InputError("esmaeilani: no data segments given");
  const int n = options.order;

  Problem P;
  P.opt = options;
  P.fix_d_zero = constraints.fix_d_zero;
  Layout& L = P.L;
  L.n = n;
  L.gf = options.grid_f;
  L.gg = options.grid_g;
  std::vector<double> all_u, all_y;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const auto& seg = segments[s];
    if (seg.u.size() != seg.y.size())
      throw InputError(fmt::format("segment {} ('{}'): u has {} samples but y has {}", s + 1, seg.name,
                                   seg.u.size(), seg.y.size()));
    if (static_cast<int>(seg.u.size()) < n + 2)
      throw InputError(fmt::format("segment {} ('{}') has {} samples; order {} needs at least {}", s + 1, seg.name,
                                   seg.u.size(), n, n + 2));
    L.seg_start.push_back(L.total_samples);
    L.seg_len.push_back(static_cast<int>(seg.u.size()));
    L.total_samples += static_cast<int>(seg.u.size());
    all_u.insert(all_u.end(), seg.u.begin(), seg.u.end());
    all_y.insert(all_y.end(), seg.y.begin(), seg.y.end());
  }
  // Grids over the data range, widened to include every constrained point.
  auto grid_for = [](const std::vector<double>& data, const FunctionConstraints& c, int G, const char* name) {
    double lo = *std::min_element(data.begin(), data.end()), hi = *std::max_element(data.begin(), data.end());
    for (const auto& p : c.points) lo = std::min(lo, p.at), hi = std::max(hi, p.at);
    if (!(hi > lo))
      throw InputError(fmt::format("the {} signal is constant ({}): its nonlinearity cannot be identified", name, lo));
    return Linspace(lo, hi, G);
  };
  EsmaeilaniModel m;
  m.u_grid = grid_for(all_u, constraints.f, L.gf, "input");
  m.y_grid = grid_for(all_y, constraints.g_inverse, L.gg, "output");
  m.has_output_range = constraints.has_output_range;
  m.output_lower = constraints.output_lower;
  m.output_upper = constraints.output_upper;

  sum.unknowns = L.size() - (constraints.fix_d_zero ? 1 : 0) - (options.estimate_output_offset ? 0 : 1);
  RequirePinned(constraints.f, "f", "f -> c f, b -> b / c leaves the model unchanged while the input-noise term v "
                "becomes free as c grows");
  RequirePinned(constraints.g_inverse, "g_inverse",
                "g^{-1} -> c g^{-1}, x -> c x, b -> c b shrinks every residual as c -> 0 (the trivial solution "
                "g^{-1} = const, b = 0)");
  // Samples at a known output saturation (censored): their output equation becomes an inequality.
  int censored_count = 0;
  bool ginv_increasing = true;
  if (constraints.saturation_tolerance >= 0) {
    if (!constraints.has_output_range)
      throw InputError("constraints: saturation_tolerance needs output_range (the known limits of y)");
    if (!constraints.fix_d_zero)
      throw InputError("constraints: saturation handling needs \"d\": 0 (with direct feedthrough the saturated "
                       "output would depend bilinearly on d and f)");
    // The direction of g^{-1} decides which side of the threshold the state is on; it must be known.
    bool up = false, down = false;
    for (const auto& sl : constraints.g_inverse.slopes)
      if (sl.from <= constraints.output_lower && sl.to >= constraints.output_upper) {
        up |= sl.lower >= 0;
        down |= sl.upper <= 0;
      }
    if (up == down)
      throw InputError("constraints: saturation handling needs a monotone g_inverse: give a g_inverse slope limit "
                       "over the whole output range with min >= 0 (or max <= 0)");
    ginv_increasing = up;
    P.censored.assign(all_y.size(), 0);
    for (std::size_t i = 0; i < all_y.size(); ++i)
      if (all_y[i] >= constraints.output_upper - constraints.saturation_tolerance ||
          all_y[i] <= constraints.output_lower + constraints.saturation_tolerance) {
        P.censored[i] = 1;
        ++censored_count;
      }
  }
  sum.censored_samples = censored_count;
  // Each sample gives one output equation and n state equations but adds n states and one noise term;
  // the model is identifiable only if the samples outnumber the remaining unknowns.
  const int free_params = L.gf + L.gg + 2 * n + (constraints.fix_d_zero ? 0 : 1) +
                          (options.estimate_output_offset ? 1 : 0);
  int informative = 0;
  for (int len : L.seg_len) informative += len - n;
  informative -= censored_count;
  sum.equations = L.rows();
  if (informative < free_params)
    throw InputError(fmt::format(
        "too few data: {} samples in {} segment(s) leave {} equations beyond the states, but the model has {} "
        "ordered pairs and linear parameters (grid_f {} + grid_g {} + 2*order{}); record more data or use "
        "smaller grids / a lower order", L.total_samples, L.seg_len.size(), informative, free_params, L.gf, L.gg,
        constraints.fix_d_zero ? "" : " + 1"));

  P.omega_f = InterpolationMatrix(m.u_grid, all_u);
  P.omega_g = InterpolationMatrix(m.y_grid, all_y);
  P.omega_f_rows = P.omega_f;
  P.omega_g_rows = P.omega_g;

  Triplets ct;
  std::vector<double> lo, hi;
  AddFunctionConstraints(constraints.f, m.u_grid, L.f(0), &ct, &lo, &hi);
  AddFunctionConstraints(constraints.g_inverse, m.y_grid, L.g(0), &ct, &lo, &hi);
  if (censored_count > 0) {
    // A sample whose measured y is within `tol` of a known output limit only says that the true output
    // is within 2 tol of the limit: w_t >= upper - 2 tol, i.e. C x_t + m_e >= g^{-1}(upper - 2 tol) for an
    // increasing g^{-1} (<= at the lower limit; mirrored for a decreasing one). This inequality replaces
    // the output equation, which cannot hold there: behind a saturation many states share one y
    // (g^{-1} is not one-to-one, paper Fig. 6b), and their equation residuals would bias f and the
    // linear block (see docs/esmaeilani.md).
    const double tol = constraints.saturation_tolerance;
    for (std::size_t s = 0; s < L.seg_len.size(); ++s)
      for (int k = 0; k < L.seg_len[s]; ++k) {
        const int sample = L.seg_start[s] + k;
        if (!P.censored[sample]) continue;
        const bool at_upper = all_y[sample] >= constraints.output_upper - tol;
        const double level = at_upper ? constraints.output_upper - 2 * tol : constraints.output_lower + 2 * tol;
        const auto [kk, w] = Bracket(m.y_grid, level);
        const int r = static_cast<int>(lo.size());
        ct.emplace_back(r, L.x(static_cast<int>(s), k, n - 1), 1.0);
        ct.emplace_back(r, L.offset(), 1.0);
        ct.emplace_back(r, L.g(kk), -(1 - w));
        ct.emplace_back(r, L.g(kk + 1), -w);
        const bool state_above = at_upper == ginv_increasing;  // C x_t + m_e - g^{-1}(level) >= 0 ?
        lo.push_back(state_above ? 0.0 : -kInf);
        hi.push_back(state_above ? kInf : 0.0);
      }
  }
  P.C.resize(static_cast<int>(lo.size()), L.size());
  P.C.setFromTriplets(ct.begin(), ct.end());
  P.c_lower = Eigen::Map<Eigen::VectorXd>(lo.data(), lo.size());
  P.c_upper = Eigen::Map<Eigen::VectorXd>(hi.data(), hi.size());
  sum.constraints = static_cast<int>(lo.size());

  // Starting point (paper step v): identity maps, ARX linear block; states and noise from the first QP.
  m.f_values = m.u_grid;
  m.ginv_values = m.y_grid;
  double offset0 = 0.0;
  if (options.initial) {
    const EsmaeilaniModel& w = *options.initial;
    if (static_cast<int>(w.a.size()) != n || w.b.size() != w.a.size())
      throw InputError(fmt::format("initial model has order {}, expected {}", w.a.size(), n));
    for (int k = 0; k < L.gf; ++k) m.f_values[k] = w.F(m.u_grid[k]);
    for (int k = 0; k < L.gg; ++k) m.ginv_values[k] = w.Ginv(m.y_grid[k]);
    m.a = w.a;
    m.b = w.b;
    m.d = constraints.fix_d_zero ? 0.0 : w.d;
    offset0 = w.output_offset;
  } else {
    InitialLinearBlock(segments, m, n, constraints.fix_d_zero, &m.a, &m.b, &m.d);
  }
  Eigen::VectorXd al = Eigen::VectorXd::Zero(L.size());
  for (int k = 0; k < L.gf; ++k) al[L.f(k)] = m.f_values[k];
  for (int k = 0; k < L.gg; ++k) al[L.g(k)] = m.ginv_values[k];
  for (int i = 0; i < n; ++i) al[L.a(i)] = m.a[i], al[L.b(i)] = m.b[i];
  al[L.d()] = m.d;
  al[L.offset()] = options.estimate_output_offset ? offset0 : 0.0;

  SparseQp qp;
  qp.A = P.C;
  double cost = Cost(P, al);
  sum.initial_cost = cost;
  sum.cost_history.push_back(cost);
  sum.status = Summary::Status::kMaxIterations;
  double lambda = options.damping;  // Levenberg-Marquardt weight, adapted from the accepted step length
  // One convex QP on the linearised residual and a backtracking line search. hold_linear fixes (a, b, d):
  // the residual is then linear in the remaining unknowns, so the QP (undamped) gives their exact minimiser.
  // Returns false if the QP failed (message set) or no descent was found.
  enum class StepResult { kOk, kNoDescent, kQpFailed };
  auto step_once = [&](bool hold_linear, bool first) -> StepResult {
    const auto setup_start = Clock::now();
    Eigen::VectorXd r;
    Eigen::SparseMatrix<double> J;
    P.Evaluate(al, &r, &J);
    // Jt * J with an explicit transpose: (J^T * J).pruned() took 50x longer (0.5 s at 12k unknowns).
    const Eigen::SparseMatrix<double> Jt = J.transpose();
    Eigen::SparseMatrix<double> JtJ = Jt * J;
    Eigen::VectorXd diag = JtJ.diagonal();
    const double lam = hold_linear ? 0.0 : lambda;
    Eigen::SparseMatrix<double> reg(L.size(), L.size());
    std::vector<Eigen::Triplet<double>> rt;
    for (int i = 0; i < L.size(); ++i) rt.emplace_back(i, i, lam * diag[i] + 1e-12);
    reg.setFromTriplets(rt.begin(), rt.end());
    qp.H = 2.0 * (JtJ + reg);
    qp.c = 2.0 * (Jt * r);
    const Eigen::VectorXd Cal = P.C * al;
    qp.row_lower = P.c_lower - Cal;
    qp.row_upper = P.c_upper - Cal;
    for (int i = 0; i < qp.row_lower.size(); ++i) {  // keep infinite bounds infinite
      if (P.c_lower[i] <= -kInf) qp.row_lower[i] = -kInf;
      if (P.c_upper[i] >= kInf) qp.row_upper[i] = kInf;
    }
    qp.var_lower = Eigen::VectorXd::Constant(L.size(), -kInf);
    qp.var_upper = Eigen::VectorXd::Constant(L.size(), kInf);
    if (hold_linear)
      for (int i = L.a(0); i <= L.d(); ++i) qp.var_lower[i] = qp.var_upper[i] = 0.0;
    if (constraints.fix_d_zero) qp.var_lower[L.d()] = qp.var_upper[L.d()] = -al[L.d()];
    if (!options.estimate_output_offset) qp.var_lower[L.offset()] = qp.var_upper[L.offset()] = -al[L.offset()];
    Eigen::VectorXd step = Eigen::VectorXd::Zero(L.size());
    const auto qp_start = Clock::now();
    sum.setup_seconds += std::chrono::duration<double>(qp_start - setup_start).count();
    const QpSummary qs = SolveQp(options.qp, qp, &step);
    sum.qp_seconds += std::chrono::duration<double>(Clock::now() - qp_start).count();
    sum.qp_iterations += qs.iterations;
    ++sum.qp_solves;
    if (!qs.solved) {
      if (first && qs.infeasible)
        throw InputError(
            "esmaeilani: the constraints contradict each other (no f', g' satisfy all ranges, slopes and known "
            "points); check the constraints file");
      sum.message = qs.message;
      return StepResult::kQpFailed;
    }
    // Backtracking on the step length (every point of the segment satisfies the linear constraints).
    double t = 1.0, new_cost = Cost(P, al + step);
    while (new_cost > cost && t > 1e-6) {
      t *= 0.5;
      new_cost = Cost(P, al + t * step);
    }
    if (new_cost > cost) return StepResult::kNoDescent;
    al += t * step;
    cost = new_cost;
    if (!hold_linear) {
      sum.step_lengths.push_back(t);
      lambda = t == 1.0 ? std::max(lambda / 3.0, options.damping) : std::min(lambda * 4.0 / t, 1e8);
    }
    return StepResult::kOk;
  };
  // Iteration 0 holds (a, b, d): the problem is then linear in the rest and one QP solves it exactly.
  int iter = 0;
  for (iter = 0; iter < options.max_iterations; ++iter) {
    const double before = cost;
    StepResult res = step_once(iter == 0, iter == 0);
    if (res == StepResult::kOk && iter > 0 && options.reproject) res = step_once(true, false);
    if (res == StepResult::kQpFailed) {
      if (iter == 0) {
        sum.status = Summary::Status::kFailed;
        sum.message = "first QP failed: " + sum.message;
      } else {
        sum.status = Summary::Status::kConverged;
        sum.message = "stopped: QP subproblem did not solve (" + sum.message + "); kept the last iterate";
      }
      break;
    }
    if (res == StepResult::kNoDescent) {
      sum.status = Summary::Status::kConverged;
      sum.message = "converged: no descent along the Gauss-Newton step";
      break;
    }
    sum.cost_history.push_back(cost);
    const double decrease = (before - cost) / std::max(before, 1e-300);
    if (iter > 0 && (decrease < options.relative_decrease || cost < 1e-24)) {
      sum.status = Summary::Status::kConverged;
      sum.message = fmt::format("converged: relative decrease {:.3g} below {:.3g}", decrease,
                                options.relative_decrease);
      ++iter;
      break;
    }
  }
  if (sum.status == Summary::Status::kMaxIterations)
    sum.message = fmt::format("stopped after max_iterations = {}", options.max_iterations);
  sum.iterations = iter;
  sum.final_cost = cost;
  for (int k = 0; k < L.gf; ++k) m.f_values[k] = al[L.f(k)];
  for (int k = 0; k < L.gg; ++k) m.ginv_values[k] = al[L.g(k)];
  for (int i = 0; i < n; ++i) m.a[i] = al[L.a(i)], m.b[i] = al[L.b(i)];
  m.d = constraints.fix_d_zero ? 0.0 : al[L.d()];
  m.output_offset = options.estimate_output_offset ? al[L.offset()] : 0.0;
  for (std::size_t s = 0; s < L.seg_len.size(); ++s) {
    std::vector<double> x0(n);
    for (int i = 0; i < n; ++i) x0[i] = al[L.x(static_cast<int>(s), 0, i)];
    m.initial_states.push_back(x0);
  }
  sum.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (options.refine_output_error && sum.ok()) return RefineOutputError(options, segments, constraints, m, &sum.output_error);
  return m;
}

// ---------------------------------------------------------------------------------------------
EsmaeilaniModel RefineOutputError(const Options& options, const std::vector<Segment>& segments,
                                  const Constraints& constraints, const EsmaeilaniModel& start,
                                  OutputErrorSummary* summary) {
  const auto t_start = Clock::now();
  OutputErrorSummary local;
  OutputErrorSummary& sum = summary ? *summary : local;
  sum = OutputErrorSummary{};
  sum.ran = true;
  std::string err;
  if (!options.IsValid(&err)) throw InputError("esmaeilani options: " + err);
  const int n = static_cast<int>(start.a.size());
  const int gf = static_cast<int>(start.f_values.size()), gg = static_cast<int>(start.ginv_values.size());
  const int S = static_cast<int>(segments.size());
  if (n < 1 || static_cast<int>(start.b.size()) != n || gf < 2 || gg < 2 ||
      static_cast<int>(start.u_grid.size()) != gf || static_cast<int>(start.y_grid.size()) != gg)
    throw InputError("output-error refinement: the start model is incomplete (needs a, b, f and g^-1 pairs)");
  const bool est_x0 = options.oe_estimate_initial_states;
  // theta = [f'; g'; a; b; d; m_e; x0 of each segment]
  const int iF = 0, iG = gf, iA = gf + gg, iB = iA + n, iD = iB + n, iM = iD + 1, iX = iM + 1;
  const int P = iX + (est_x0 ? S * n : 0);
  int N = 0;
  for (const auto& s : segments) {
    if (s.u.size() != s.y.size() || s.u.empty())
      throw InputError(fmt::format("output-error refinement: segment '{}' has {} inputs and {} outputs", s.name,
                                   s.u.size(), s.y.size()));
    N += static_cast<int>(s.u.size());
  }
  sum.parameters = P;
  sum.residuals = N;

  Eigen::VectorXd th(P);
  for (int k = 0; k < gf; ++k) th[iF + k] = start.f_values[k];
  for (int k = 0; k < gg; ++k) th[iG + k] = start.ginv_values[k];
  for (int i = 0; i < n; ++i) th[iA + i] = start.a[i], th[iB + i] = start.b[i];
  th[iD] = constraints.fix_d_zero ? 0.0 : start.d;
  th[iM] = start.output_offset;
  if (est_x0)
    for (int s = 0; s < S; ++s) {
      // The SQP's identified x_1 if it has one for this segment, else the steady state at the first input.
      const std::vector<double> x0 = static_cast<int>(start.initial_states.size()) == S &&
                                             static_cast<int>(start.initial_states[s].size()) == n
                                         ? start.initial_states[s]
                                         : start.SteadyState(segments[s].u.front());
      for (int i = 0; i < n; ++i) th[iX + s * n + i] = x0[i];
    }
  auto unpack = [&](const Eigen::VectorXd& p) {
    EsmaeilaniModel m = start;
    for (int k = 0; k < gf; ++k) m.f_values[k] = p[iF + k];
    for (int k = 0; k < gg; ++k) m.ginv_values[k] = p[iG + k];
    for (int i = 0; i < n; ++i) m.a[i] = p[iA + i], m.b[i] = p[iB + i];
    m.d = p[iD];
    m.output_offset = p[iM];
    m.initial_states.assign(S, std::vector<double>(n, 0.0));
    for (int s = 0; s < S; ++s) {
      if (!est_x0) {
        m.initial_states[s] = m.SteadyState(segments[s].u.front());
        continue;
      }
      for (int i = 0; i < n; ++i) m.initial_states[s][i] = p[iX + s * n + i];
    }
    return m;
  };
  // r = y - yhat, simulated exactly as the validation does (same Simulate, same output map).
  auto residual = [&](const Eigen::VectorXd& p, Eigen::VectorXd* r) {
    const EsmaeilaniModel m = unpack(p);
    r->resize(N);
    int row = 0;
    for (int s = 0; s < S; ++s) {
      const auto yh = m.Simulate(segments[s].u, est_x0 ? m.initial_states[s] : std::vector<double>{},
                                 options.clamp_output);
      for (std::size_t t = 0; t < yh.size(); ++t, ++row) (*r)[row] = segments[s].y[t] - yh[t];
    }
    ++sum.simulations;
  };

  // Known information: the SQP's rows on f' and g' (ranges, slopes, known points).
  Triplets ct;
  std::vector<double> lo, hi;
  AddFunctionConstraints(constraints.f, start.u_grid, iF, &ct, &lo, &hi);
  AddFunctionConstraints(constraints.g_inverse, start.y_grid, iG, &ct, &lo, &hi);
  Eigen::SparseMatrix<double> C(static_cast<int>(lo.size()), P);
  C.setFromTriplets(ct.begin(), ct.end());
  const Eigen::VectorXd c_lo = Eigen::Map<Eigen::VectorXd>(lo.data(), lo.size());
  const Eigen::VectorXd c_hi = Eigen::Map<Eigen::VectorXd>(hi.data(), hi.size());
  auto violation = [&](const Eigen::VectorXd& p) {
    const Eigen::VectorXd cp = C * p;
    double v = 0.0;
    for (int i = 0; i < cp.size(); ++i) v = std::max({v, c_lo[i] - cp[i], cp[i] - c_hi[i]});
    return v;
  };

  Eigen::VectorXd r;
  residual(th, &r);
  double cost = r.squaredNorm();
  sum.initial_cost = sum.final_cost = cost;
  sum.cost_history.push_back(cost);
  double lambda = 1e-3;  // Levenberg-Marquardt weight on the scaled diagonal
  SparseQp qp;
  qp.A = C;
  sum.message = fmt::format("stopped after oe_max_iterations = {}", options.oe_max_iterations);
  int it = 0;
  for (it = 0; it < options.oe_max_iterations; ++it) {
    // Forward-difference Jacobian of r (dense: few parameters, every residual depends on most of them).
    Eigen::MatrixXd J(N, P);
    for (int j = 0; j < P; ++j) {
      if ((j == iD && constraints.fix_d_zero) || (j == iM && !options.estimate_output_offset)) {
        J.col(j).setZero();
        continue;
      }
      const double h = 1e-6 * std::max(1.0, std::abs(th[j]));
      Eigen::VectorXd tp = th, rp;
      tp[j] += h;
      residual(tp, &rp);
      J.col(j) = (rp - r) / h;
    }
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd grad = J.transpose() * r;
    // Marquardt scaling diag(J^T J), floored so that directions the data do not see (e.g. the initial
    // state of an operation that starts deep in saturation) stay damped instead of free.
    Eigen::VectorXd D = JtJ.diagonal();
    const double floor = 1e-6 * std::max(D.maxCoeff(), 1e-300);
    for (int j = 0; j < P; ++j) D[j] = std::max(D[j], floor);
    qp.c = 2.0 * grad;
    const Eigen::VectorXd cp = C * th;
    qp.row_lower = c_lo - cp;
    qp.row_upper = c_hi - cp;
    for (int i = 0; i < qp.row_lower.size(); ++i) {
      if (c_lo[i] <= -kInf) qp.row_lower[i] = -kInf;
      if (c_hi[i] >= kInf) qp.row_upper[i] = kInf;
    }
    qp.var_lower = Eigen::VectorXd::Constant(P, -kInf);
    qp.var_upper = Eigen::VectorXd::Constant(P, kInf);
    if (constraints.fix_d_zero) qp.var_lower[iD] = qp.var_upper[iD] = -th[iD];
    if (!options.estimate_output_offset) qp.var_lower[iM] = qp.var_upper[iM] = 0.0;
    bool accepted = false, qp_failed = false;
    double new_cost = cost;
    Eigen::VectorXd new_r;
    for (int tries = 0; tries < 12 && !accepted; ++tries) {
      Eigen::MatrixXd H = JtJ;
      H.diagonal() += lambda * D;
      qp.H = (2.0 * H).sparseView();
      Eigen::VectorXd step = Eigen::VectorXd::Zero(P);
      const auto q0 = Clock::now();
      const QpSummary qs = SolveQp(options.qp, qp, &step);
      sum.qp_seconds += std::chrono::duration<double>(Clock::now() - q0).count();
      ++sum.qp_solves;
      if (!qs.solved) {
        sum.message = "stopped: QP subproblem did not solve (" + qs.message + "); kept the last iterate";
        qp_failed = true;
        break;
      }
      residual(th + step, &new_r);
      new_cost = new_r.squaredNorm();
      if (new_cost < cost) {
        th += step;
        accepted = true;
        lambda = std::max(lambda / 3.0, 1e-9);
      } else {
        lambda = std::min(lambda * 4.0, 1e10);
      }
    }
    if (qp_failed) break;
    if (!accepted) {
      sum.message = "converged: no descent along the damped Gauss-Newton step";
      break;
    }
    const double decrease = (cost - new_cost) / std::max(cost, 1e-300);
    cost = new_cost;
    r = new_r;
    sum.cost_history.push_back(cost);
    if (decrease < options.relative_decrease) {
      sum.message = fmt::format("converged: relative decrease {:.3g} below {:.3g}", decrease,
                                options.relative_decrease);
      ++it;
      break;
    }
  }
  sum.iterations = it;
  sum.final_cost = cost;
  sum.improved = cost < sum.initial_cost;
  sum.max_constraint_violation = violation(th);
  sum.seconds = std::chrono::duration<double>(Clock::now() - t_start).count();
  return unpack(th);
}

}  // namespace hw::esmaeilani
