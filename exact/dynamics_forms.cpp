#include "exact/dynamics_forms.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "exact/lifted_lp.hpp"

namespace hw::exact {
namespace {

// c / d for a nonzero exact d, rounded outward.
Interval DivideBy(Interval c, double d) {
  const double p = c.lo / d, q = c.hi / d;
  return {RoundDown(std::min(p, q)), RoundUp(std::max(p, q))};
}

bool Intersect(Interval& range, Interval with) {
  const Interval both{std::max(range.lo, with.lo), std::min(range.hi, with.hi)};
  if (both.lo > both.hi) return false;
  range = both;
  return true;
}

}  // namespace

bool DynamicsFormOptions::IsValid(std::string* error) const {
  if (!(thin_share > 0.0 && thin_share < 1.0)) {
    if (error) *error = "dynamics forms: thin_share must lie in (0, 1)";
    return false;
  }
  return true;
}

std::vector<DynamicsForm> ThinDirections(const LiftedData& data, const std::vector<std::vector<double>>& points,
                                         const DynamicsFormOptions& options) {
  const int na = data.structure.na, a0 = data.layout.a_begin;
  std::vector<DynamicsForm> forms;
  if (na < 2 || static_cast<int>(points.size()) < na + 1) return forms;
  Eigen::MatrixXd x(points.size(), na);
  for (std::size_t p = 0; p < points.size(); ++p)
    for (int i = 0; i < na; ++i) x(static_cast<Eigen::Index>(p), i) = points[p][a0 + i];
  const Eigen::MatrixXd centred = x.rowwise() - x.colwise().mean();
  const Eigen::MatrixXd cov = centred.transpose() * centred / static_cast<double>(points.size());
  double axis_spread = INFINITY;
  for (int i = 0; i < na; ++i) axis_spread = std::min(axis_spread, std::sqrt(cov(i, i)));
  if (!(axis_spread > 0.0)) return forms;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  for (int e = 0; e < na; ++e) {
    if (std::sqrt(std::max(0.0, eig.eigenvalues()(e))) > options.thin_share * axis_spread) continue;
    Eigen::VectorXd v = eig.eigenvectors().col(e);
    const Eigen::Index big = [&] {
      Eigen::Index k;
      v.cwiseAbs().maxCoeff(&k);
      return k;
    }();
    v /= v(big);  // largest coefficient +1: the same form whatever sign the eigen solver returns
    DynamicsForm form(na);
    for (int i = 0; i < na; ++i) form[i] = std::ldexp(std::round(std::ldexp(v(i), 20)), -20);
    forms.push_back(form);
  }
  return forms;
}

double FormValue(const LiftedData& data, const DynamicsForm& form, const std::vector<double>& theta) {
  double v = 0.0;
  for (std::size_t i = 0; i < form.size(); ++i) v += form[i] * theta[data.layout.a_begin + i];
  return v;
}

Interval FormRange(const LiftedData& data, const DynamicsForm& form, const ParamBox& box) {
  Interval r(0.0);
  for (std::size_t i = 0; i < form.size(); ++i) r += box[data.layout.a_begin + i] * form[i];
  return r;
}

ParamBox WithFormRanges(const LiftedData& data, const ParamBox& box) {
  const std::size_t count = data.layout.count();
  if (box.size() > count) return box;
  ParamBox out = box;
  for (const auto& form : data.dynamics_forms) out.push_back(FormRange(data, form, box));
  return out;
}

void PropagateForms(const LiftedData& data, ParamBox& box) {
  const int a0 = data.layout.a_begin, count = data.layout.count();
  if (box.size() <= static_cast<std::size_t>(count)) return;
  for (std::size_t f = 0; f < data.dynamics_forms.size(); ++f) {
    const DynamicsForm& c = data.dynamics_forms[f];
    Interval& range = box[count + f];
    Intersect(range, FormRange(data, c, box));
    // a_i = (f - sum_{k != i} c_k a_k) / c_i.
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (c[i] == 0.0) continue;
      Interval rest = range;
      for (std::size_t k = 0; k < c.size(); ++k)
        if (k != i) rest = rest - box[a0 + k] * c[k];
      Intersect(box[a0 + i], DivideBy(rest, c[i]));
    }
  }
}

nlohmann::json FormsToJson(const std::vector<DynamicsForm>& forms) { return forms; }

std::vector<DynamicsForm> FormsFromJson(const nlohmann::json& j) { return j.get<std::vector<DynamicsForm>>(); }

}  // namespace hw::exact
