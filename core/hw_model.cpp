#include "core/hw_model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/atomic_write.hpp"
#include "core/input_error.hpp"
#include "core/json_input.hpp"

namespace hw {

double StaticMap::operator()(double v) const {
  switch (kind) {
    case Kind::kIdentity:
      return v;
    case Kind::kPolynomial: {
      double acc = 0.0;
      for (std::size_t k = coefficients.size(); k-- > 0;) acc = (acc + coefficients[k]) * v;
      return acc;
    }
    case Kind::kPiecewiseLinear: {
      const std::size_t n = x.size();
      if (n == 1) return y[0];
      std::size_t i = std::upper_bound(x.begin(), x.end(), v) - x.begin();
      i = std::clamp<std::size_t>(i, 1, n - 1);
      const double s = (v - x[i - 1]) / (x[i] - x[i - 1]);
      return y[i - 1] + s * (y[i] - y[i - 1]);
    }
  }
  return v;
}

bool StaticMap::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (kind == Kind::kPolynomial && coefficients.empty()) return fail("polynomial map needs coefficients");
  for (const auto* values : {&coefficients, &x, &y})
    for (double v : *values)
      if (!std::isfinite(v)) return fail("static map: every number must be finite");
  if (kind == Kind::kPiecewiseLinear) {
    if (x.empty() || x.size() != y.size()) return fail("piecewise-linear map needs equally long, non-empty x and y");
    for (std::size_t i = 1; i < x.size(); ++i)
      if (!(x[i] > x[i - 1])) return fail("piecewise-linear breakpoints x must be strictly ascending");
  }
  return true;
}

StaticMap StaticMap::Polynomial(std::vector<double> c) {
  StaticMap m;
  m.kind = Kind::kPolynomial;
  m.coefficients = std::move(c);
  return m;
}

StaticMap StaticMap::PiecewiseLinear(std::vector<double> xs, std::vector<double> ys) {
  StaticMap m;
  m.kind = Kind::kPiecewiseLinear;
  m.x = std::move(xs);
  m.y = std::move(ys);
  return m;
}

nlohmann::json StaticMap::to_json() const {
  switch (kind) {
    case Kind::kIdentity:
      return {{"kind", "identity"}};
    case Kind::kPolynomial:
      return {{"kind", "polynomial"}, {"coefficients", coefficients}};
    case Kind::kPiecewiseLinear:
      return {{"kind", "piecewise_linear"}, {"x", x}, {"y", y}};
  }
  return {};
}

StaticMap StaticMap::from_json(const nlohmann::json& j) {
  StaticMap m;
  if (!j.is_object() || !j.contains("kind") || !j.at("kind").is_string())
    throw InputError("static map: expected {\"kind\": \"identity\" | \"polynomial\" | \"piecewise_linear\", ...}");
  const std::string kind = j.at("kind").get<std::string>();
  const std::string where = fmt::format("static map of kind '{}'", kind);
  try {
    if (kind == "identity") {
      CheckKeys(j, {"kind"}, where);
      m.kind = Kind::kIdentity;
    } else if (kind == "polynomial") {
      CheckKeys(j, {"kind", "coefficients"}, where);
      m = Polynomial(j.at("coefficients").get<std::vector<double>>());
    } else if (kind == "piecewise_linear") {
      CheckKeys(j, {"kind", "x", "y"}, where);
      m = PiecewiseLinear(j.at("x").get<std::vector<double>>(), j.at("y").get<std::vector<double>>());
    } else {
      throw InputError(fmt::format("static map kind '{}' unknown; expected identity, polynomial or piecewise_linear", kind));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: {}", where, e.what()));
  }
  std::string err;
  if (!m.IsValid(&err)) throw InputError(err);
  return m;
}

bool LinearBlock::IsValid(std::string* error) const {
  for (const auto* values : {&a, &b})
    for (double v : *values)
      if (!std::isfinite(v)) {
        if (error) *error = "linear block: every coefficient must be finite";
        return false;
      }
  if (b.empty()) {
    if (error) *error = "linear block needs at least one b coefficient";
    return false;
  }
  if (delay < 0) {
    if (error) *error = "linear block delay must be >= 0";
    return false;
  }
  return true;
}

bool LinearBlock::is_stable() const {
  // Step-down recursion: A_m(z) -> A_{m-1}(z) with reflection coefficient k_m = last coefficient of A_m;
  // all poles lie inside the unit circle iff every |k_m| < 1.
  std::vector<double> c = {1.0};
  c.insert(c.end(), a.begin(), a.end());
  for (std::size_t m = c.size() - 1; m >= 1; --m) {
    const double k = c[m];
    if (!(std::abs(k) < 1.0)) return false;
    std::vector<double> next(m);
    for (std::size_t i = 0; i < m; ++i) next[i] = (c[i] - k * c[m - i]) / (1.0 - k * k);
    c = std::move(next);
  }
  return true;
}

std::vector<double> LinearBlock::simulate(const std::vector<double>& x) const {
  const std::size_t n = x.size();
  std::vector<double> z(n, 0.0);
  for (std::size_t t = 0; t < n; ++t) {
    double acc = 0.0;
    for (std::size_t i = 1; i <= a.size() && i <= t; ++i) acc -= a[i - 1] * z[t - i];
    for (std::size_t j = 0; j < b.size(); ++j) {
      const long k = static_cast<long>(t) - delay - static_cast<long>(j);
      if (k >= 0) acc += b[j] * x[k];
    }
    z[t] = acc;
  }
  return z;
}

bool HwModel::IsValid(std::string* error) const {
  return input.IsValid(error) && linear.IsValid(error) && output.IsValid(error);
}

std::vector<double> HwModel::simulate(const std::vector<double>& u) const {
  std::vector<double> x(u.size());
  for (std::size_t t = 0; t < u.size(); ++t) x[t] = input(u[t]);
  auto z = linear.simulate(x);
  for (auto& v : z) v = output(v);
  return z;
}

nlohmann::json HwModel::to_json() const {
  return {{"type", "hammerstein_wiener"},
          {"name", name},
          {"input_nonlinearity", input.to_json()},
          {"linear", {{"a", linear.a}, {"b", linear.b}, {"delay", linear.delay}}},
          {"output_nonlinearity", output.to_json()}};
}

HwModel HwModel::from_json(const nlohmann::json& j, const std::vector<std::string_view>& extension_keys) {
  HwModel m;
  std::vector<std::string_view> keys = {"type", "name", "input_nonlinearity", "linear", "output_nonlinearity",
                                        "esmaeilani"};
  keys.insert(keys.end(), extension_keys.begin(), extension_keys.end());
  try {
    CheckKeys(j, keys, "model JSON");
    if (j.value("type", "hammerstein_wiener") != "hammerstein_wiener")
      throw InputError(fmt::format("model type '{}' unknown; expected hammerstein_wiener", j.value("type", "")));
    m.name = j.value("name", "");
    if (j.contains("input_nonlinearity")) m.input = StaticMap::from_json(j.at("input_nonlinearity"));
    if (j.contains("output_nonlinearity")) m.output = StaticMap::from_json(j.at("output_nonlinearity"));
    if (!j.contains("linear")) throw InputError("model JSON: \"linear\": {\"a\": [...], \"b\": [...]} is required");
    const auto& lin = j.at("linear");
    CheckKeys(lin, {"a", "b", "delay"}, "model JSON: linear");
    m.linear.a = lin.value("a", std::vector<double>{});
    m.linear.b = lin.at("b").get<std::vector<double>>();
    if (lin.contains("delay") && !lin.at("delay").is_number_integer())
      throw InputError("model JSON: linear.delay must be a whole number of samples");
    m.linear.delay = lin.value("delay", 0);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("model JSON: {} (expected keys: linear.a, linear.b, linear.delay, "
                                 "input_nonlinearity, output_nonlinearity)", e.what()));
  }
  std::string err;
  if (!m.IsValid(&err)) throw InputError("model JSON: " + err);
  return m;
}

HwModel HwModel::load(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path, "model JSON file");
  try {
    return from_json(j);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
}

void HwModel::save(const std::string& path) const { write_text_atomic(path, to_json().dump(2) + "\n"); }

double rmse(const std::vector<double>& y, const std::vector<double>& yhat) {
  double s = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) s += (y[i] - yhat[i]) * (y[i] - yhat[i]);
  return y.empty() ? 0.0 : std::sqrt(s / y.size());
}

double fit_percent(const std::vector<double>& y, const std::vector<double>& yhat) {
  double mean = 0.0;
  for (double v : y) mean += v;
  mean /= std::max<std::size_t>(1, y.size());
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    num += (y[i] - yhat[i]) * (y[i] - yhat[i]);
    den += (y[i] - mean) * (y[i] - mean);
  }
  return 100.0 * (1.0 - std::sqrt(num / std::max(den, 1e-300)));
}

void CheckStableOrAllowed(const HwModel& model, const std::string& source, bool allow_unstable) {
  if (allow_unstable || model.linear.is_stable()) return;
  throw InputError(fmt::format("{}: the linear block a = [{}] has a pole on or outside the unit circle, so its output "
                               "grows without bound; allow unstable models to simulate it anyway (--allow-unstable, "
                               "allow_unstable=True from Python)",
                               source, fmt::join(model.linear.a, ", ")));
}

void CheckFiniteOutput(const std::vector<double>& w, const std::string& source,
                       const std::function<std::string(std::size_t)>& where) {
  for (std::size_t t = 0; t < w.size(); ++t)
    if (!std::isfinite(w[t]))
      throw InputError(fmt::format("{}: the simulated output overflows double precision at sample {} ({})", source,
                                   t + 1, where(t)));
}

}  // namespace hw
