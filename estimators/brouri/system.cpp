#include "estimators/brouri/system.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>
#include <unsupported/Eigen/Polynomials>

#include "core/input_error.hpp"
#include "core/json_input.hpp"

namespace hw::brouri {

namespace {
bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}
std::vector<double> StripLeadingZeros(std::vector<double> c) {  // descending powers
  while (c.size() > 1 && c.front() == 0.0) c.erase(c.begin());
  return c;
}
}  // namespace

double PolyEval(const std::vector<double>& c, double x) {
  double acc = 0.0;
  for (std::size_t k = c.size(); k-- > 0;) acc = acc * x + c[k];
  return acc;
}

std::vector<double> PolyShift(const std::vector<double>& c, double shift) {
  // Horner-style synthetic substitution: build p(x + s) by repeated multiplication by (x + s).
  std::vector<double> out;
  for (std::size_t k = c.size(); k-- > 0;) {
    std::vector<double> next(out.size() + 1, 0.0);
    for (std::size_t i = 0; i < out.size(); ++i) {
      next[i + 1] += out[i];
      next[i] += shift * out[i];
    }
    next[0] += c[k];
    out = std::move(next);
  }
  return out;
}

std::vector<double> PolyRealRoots(const std::vector<double>& c, double tol) {
  std::vector<double> q = c;
  while (!q.empty() && q.back() == 0.0) q.pop_back();
  if (q.size() < 2) return {};
  Eigen::VectorXd coeffs = Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
  Eigen::PolynomialSolver<double, Eigen::Dynamic> solver(coeffs);
  std::vector<double> out;
  for (const auto& r : solver.roots())
    if (std::abs(r.imag()) <= tol * (1.0 + std::abs(r.real()))) out.push_back(r.real());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> PolyFit(const std::vector<double>& x, const std::vector<double>& y, int degree) {
  const auto n = static_cast<Eigen::Index>(x.size());
  if (degree < 0 || n < degree + 1)
    throw InputError(fmt::format("a degree-{} polynomial fit needs at least {} points, got {}", degree, degree + 1, n));
  // Fit in the centred, scaled variable t = (x - c)/s for conditioning, then map back.
  const auto [mn, mx] = std::minmax_element(x.begin(), x.end());
  const double c = 0.5 * (*mn + *mx);
  const double s = std::max(0.5 * (*mx - *mn), 1e-12);
  Eigen::MatrixXd vander(n, degree + 1);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = (x[i] - c) / s;
    double pw = 1.0;
    for (int k = 0; k <= degree; ++k, pw *= t) vander(i, k) = pw;
    rhs(i) = y[i];
  }
  const Eigen::VectorXd q = vander.colPivHouseholderQr().solve(rhs);
  std::vector<double> r(degree + 1);
  for (int k = 0; k <= degree; ++k) r[k] = q(k) / std::pow(s, k);  // r(y) = q(y / s)
  return PolyShift(r, -c);                                       // p(x) = r(x - c)
}

bool BacklashParams::IsValid(std::string* error) const {
  for (double v : {slope_up, offset_up, slope_down, offset_down})
    if (!std::isfinite(v)) return Fail(error, "backlash parameters must be finite");
  if (slope_up <= 0 || slope_down <= 0)
    return Fail(error, fmt::format("backlash slopes must be positive (S^a = {}, S^d = {})", slope_up, slope_down));
  return true;
}

const char* ToString(OperatorKind kind) {
  return kind == OperatorKind::kBacklash ? "backlash" : "backlash-inverse";
}

double MemoryOperator::Step(double u) {
  if (kind_ == OperatorKind::kBacklash) {
    const double up = p_.slope_up * (u - p_.offset_up);
    const double down = p_.slope_down * (u - p_.offset_down);
    if (up > v_) v_ = up;            // pushed along the ascending border
    else if (down < v_) v_ = down;   // pushed along the descending border
  } else {
    if (u > last_u_) v_ = u / p_.slope_up + p_.offset_up;
    else if (u < last_u_) v_ = u / p_.slope_down + p_.offset_down;
  }
  last_u_ = u;
  return v_;
}

OperatorLines LinesOf(OperatorKind kind, const BacklashParams& p) {
  if (kind == OperatorKind::kBacklash) return {p.slope_up, p.offset_up, p.slope_down, p.offset_down};
  return {1.0 / p.slope_up, -p.slope_up * p.offset_up, 1.0 / p.slope_down, -p.slope_down * p.offset_down};
}

BacklashParams ParamsFromLines(OperatorKind kind, const OperatorLines& l) {
  if (kind == OperatorKind::kBacklash) return {l.slope_up, l.root_up, l.slope_down, l.root_down};
  return {1.0 / l.slope_up, -l.root_up * l.slope_up, 1.0 / l.slope_down, -l.root_down * l.slope_down};
}

bool TransferFunction::IsValid(std::string* error) const {
  const auto n = StripLeadingZeros(num), d = StripLeadingZeros(den);
  if (d.size() < 2 || d.front() == 0.0) return Fail(error, "G(s) denominator must have degree >= 1");
  if (n.size() > d.size()) return Fail(error, "G(s) must be proper (numerator degree <= denominator degree)");
  for (double v : n)
    if (!std::isfinite(v)) return Fail(error, "G(s) numerator has a non-finite coefficient");
  for (double v : d)
    if (!std::isfinite(v)) return Fail(error, "G(s) denominator has a non-finite coefficient");
  std::vector<double> asc(d.rbegin(), d.rend());
  Eigen::VectorXd coeffs = Eigen::Map<const Eigen::VectorXd>(asc.data(), static_cast<Eigen::Index>(asc.size()));
  Eigen::PolynomialSolver<double, Eigen::Dynamic> solver(coeffs);
  for (const auto& r : solver.roots())
    if (r.real() >= 0.0)
      return Fail(error, fmt::format("G(s) must be asymptotically stable; pole {}{:+}j is not", r.real(), r.imag()));
  if (StaticGain() == 0.0) return Fail(error, "the method needs G(0) != 0");
  return true;
}

std::complex<double> TransferFunction::Response(double omega) const {
  const std::complex<double> s(0.0, omega);
  std::complex<double> n = 0.0, d = 0.0;
  for (double c : num) n = n * s + c;
  for (double c : den) d = d * s + c;
  return n / d;
}

double TransferFunction::StaticGain() const { return Response(0.0).real(); }

ZohSystem::ZohSystem(const TransferFunction& g, double sample_time) {
  std::string err;
  if (!g.IsValid(&err)) throw InputError(err);
  if (!(sample_time > 0)) throw InputError("sample time must be positive");
  auto den = StripLeadingZeros(g.den);
  auto num = StripLeadingZeros(g.num);
  const int n = static_cast<int>(den.size()) - 1;
  const double lead = den.front();
  for (double& v : den) v /= lead;
  for (double& v : num) v /= lead;
  num.insert(num.begin(), den.size() - num.size(), 0.0);  // pad to n + 1 coefficients
  d_ = num[0];
  // Controllable canonical form of the strictly proper part.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) a(0, i) = -den[i + 1];
  for (int i = 1; i < n; ++i) a(i, i - 1) = 1.0;
  c_.resize(n);
  for (int i = 0; i < n; ++i) c_(i) = num[i + 1] - d_ * den[i + 1];
  // Exact ZOH: expm([[A, B], [0, 0]] Ts) = [[Phi, Gamma], [0, 1]].
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 1, n + 1);
  m.topLeftCorner(n, n) = a * sample_time;
  m(0, n) = sample_time;
  const Eigen::MatrixXd e = m.exp();
  phi_ = e.topLeftCorner(n, n);
  gamma_ = e.topRightCorner(n, 1);
  x_ = Eigen::VectorXd::Zero(n);
}

double ZohSystem::Step(double v) {
  const double w = c_.dot(x_) + d_ * v;
  x_ = phi_ * x_ + gamma_ * v;
  return w;
}

bool BacklashHwSystem::IsValid(std::string* error) const {
  if (!backlash.IsValid(error)) return false;
  if (!g.IsValid(error)) return false;
  if (h.size() < 2) return Fail(error, "h must have degree >= 1");
  if (std::abs(h[0]) > 0) return Fail(error, "the method assumes h(0) = 0 (h[0] must be 0)");
  if (!(noise_std >= 0)) return Fail(error, "noise standard deviation must be >= 0");
  return true;
}

BacklashHwSystem BacklashHwSystem::PaperExample() {
  BacklashHwSystem s;
  s.kind = OperatorKind::kBacklash;
  s.backlash = {1.0, 0.5, 1.0, -0.5};
  s.g.num = {0.2};
  s.g.den = {1.0, 0.7, 0.1};  // (s + 0.5)(s + 0.2)
  s.h = {0.0, 0.25, 0.0, -0.42, 0.0, 0.2};
  s.noise_std = 0.01;
  return s;
}

BacklashHwSystem BacklashHwSystem::Normalised() const {
  BacklashHwSystem out = *this;
  OperatorLines lines = LinesOf(kind, backlash);
  const double sigma = lines.slope_up;
  lines.slope_up = 1.0;
  lines.slope_down /= sigma;
  out.backlash = ParamsFromLines(kind, lines);
  const double g0 = g.StaticGain();
  for (double& c : out.g.num) c /= g0;
  double scale = 1.0;
  for (double& c : out.h) {
    c *= scale;
    scale *= g0 * sigma;
  }
  return out;
}

nlohmann::json BacklashHwSystem::to_json() const {
  return {{"operator", ToString(kind)}, {"S_a", backlash.slope_up}, {"d_plus", backlash.offset_up},
          {"S_d", backlash.slope_down}, {"d_minus", backlash.offset_down}, {"num", g.num}, {"den", g.den},
          {"h", h}, {"noise_std", noise_std}};
}

BacklashHwSystem BacklashHwSystem::from_json(const nlohmann::json& j) {
  CheckKeys(j, {"operator", "S_a", "d_plus", "S_d", "d_minus", "num", "den", "h", "noise_std"}, "system JSON");
  return ParseValidated<BacklashHwSystem>("system", [&] {
    const auto op = j.value("operator", std::string("backlash"));
    if (op != "backlash" && op != "backlash-inverse")
      throw InputError(fmt::format("system JSON: operator '{}' must be 'backlash' or 'backlash-inverse'", op));
    BacklashHwSystem s;
    s.kind = op == "backlash" ? OperatorKind::kBacklash : OperatorKind::kBacklashInverse;
    s.backlash = {j.at("S_a").get<double>(), j.at("d_plus").get<double>(), j.at("S_d").get<double>(),
                  j.at("d_minus").get<double>()};
    s.g.num = j.at("num").get<std::vector<double>>();
    s.g.den = j.at("den").get<std::vector<double>>();
    s.h = j.at("h").get<std::vector<double>>();
    s.noise_std = j.value("noise_std", 0.0);
    return s;
  });
}

SimulationResult Simulate(const BacklashHwSystem& system, const std::vector<double>& u, double sample_time,
                          std::uint64_t seed, const MemoryOperator* precompensator) {
  std::string err;
  if (!system.IsValid(&err)) throw InputError(err);
  MemoryOperator f(system.kind, system.backlash);
  std::optional<MemoryOperator> pre;
  if (precompensator) pre = *precompensator;
  ZohSystem g(system.g, sample_time);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  SimulationResult r;
  r.v.reserve(u.size()), r.w.reserve(u.size()), r.x.reserve(u.size()), r.y.reserve(u.size());
  for (double uk : u) {
    const double in = pre ? pre->Step(uk) : uk;
    const double v = f.Step(in);
    const double w = g.Step(v);
    const double x = PolyEval(system.h, w);
    r.v.push_back(v);
    r.w.push_back(w);
    r.x.push_back(x);
    r.y.push_back(x + system.noise_std * gauss(rng));
  }
  return r;
}

}  // namespace hw::brouri
