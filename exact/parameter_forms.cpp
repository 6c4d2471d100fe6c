#include "exact/parameter_forms.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "exact/enum_names.hpp"
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

// The thin principal directions of the points in one block.
void AddThinDirections(const LiftedData& data, const std::vector<std::vector<double>>& points, FormBlock block,
                       double thin_share, std::vector<ParameterForm>& forms) {
  const auto [first, n] = BlockEntries(data, block);
  if (n < 2 || static_cast<int>(points.size()) < n + 1) return;
  Eigen::MatrixXd x(points.size(), n);
  for (std::size_t p = 0; p < points.size(); ++p)
    for (int i = 0; i < n; ++i) x(static_cast<Eigen::Index>(p), i) = points[p][first + i];
  const Eigen::MatrixXd centred = x.rowwise() - x.colwise().mean();
  const Eigen::MatrixXd cov = centred.transpose() * centred / static_cast<double>(points.size());
  double axis_spread = INFINITY;
  for (int i = 0; i < n; ++i) axis_spread = std::min(axis_spread, std::sqrt(cov(i, i)));
  if (!(axis_spread > 0.0)) return;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  for (int e = 0; e < n; ++e) {
    if (std::sqrt(std::max(0.0, eig.eigenvalues()(e))) > thin_share * axis_spread) continue;
    Eigen::VectorXd v = eig.eigenvectors().col(e);
    const Eigen::Index big = [&] {
      Eigen::Index k;
      v.cwiseAbs().maxCoeff(&k);
      return k;
    }();
    v /= v(big);  // largest coefficient +1: the same form whatever sign the eigen solver returns
    ParameterForm form{block, std::vector<double>(n)};
    for (int i = 0; i < n; ++i) form.coef[i] = std::ldexp(std::round(std::ldexp(v(i), 20)), -20);
    forms.push_back(form);
  }
}

}  // namespace

std::string ToString(FormBlock block) {
  switch (block) {
    case FormBlock::kDynamics: return "dynamics";
    case FormBlock::kGain: return "gain";
    case FormBlock::kShape: return "shape";
  }
  return "dynamics";
}

bool FormOptions::IsValid(std::string* error) const {
  if (!(thin_share > 0.0 && thin_share < 1.0)) {
    if (error) *error = "parameter forms: thin_share must lie in (0, 1)";
    return false;
  }
  return true;
}

std::pair<int, int> BlockEntries(const LiftedData& data, FormBlock block) {
  const auto& lay = data.layout;
  switch (block) {
    case FormBlock::kDynamics: return {lay.a_begin, data.structure.na};
    case FormBlock::kGain: return {lay.b_begin, lay.count() - lay.b_begin};
    case FormBlock::kShape: return {lay.gamma_begin, lay.num_gamma};
  }
  return {lay.a_begin, data.structure.na};
}

std::vector<ParameterForm> ThinDirections(const LiftedData& data, const std::vector<std::vector<double>>& points,
                                          const FormOptions& options) {
  std::vector<ParameterForm> forms;
  AddThinDirections(data, points, FormBlock::kDynamics, options.thin_share, forms);
  if (options.gain) AddThinDirections(data, points, FormBlock::kGain, options.thin_share, forms);
  if (options.shape) AddThinDirections(data, points, FormBlock::kShape, options.thin_share, forms);
  return forms;
}

double FormValue(const LiftedData& data, const ParameterForm& form, const std::vector<double>& theta) {
  const int first = BlockEntries(data, form.block).first;
  double v = 0.0;
  for (std::size_t i = 0; i < form.coef.size(); ++i) v += form.coef[i] * theta[first + i];
  return v;
}

Interval FormRange(const LiftedData& data, const ParameterForm& form, const ParamBox& box) {
  const int first = BlockEntries(data, form.block).first;
  Interval r(0.0);
  for (std::size_t i = 0; i < form.coef.size(); ++i) r += box[first + i] * form.coef[i];
  return r;
}

ParamBox WithFormRanges(const LiftedData& data, const ParamBox& box) {
  const std::size_t count = data.layout.count();
  if (box.size() > count) return box;
  ParamBox out = box;
  for (const auto& form : data.forms) out.push_back(FormRange(data, form, box));
  return out;
}

void PropagateForms(const LiftedData& data, ParamBox& box) {
  const int count = data.layout.count();
  if (box.size() <= static_cast<std::size_t>(count)) return;
  for (std::size_t f = 0; f < data.forms.size(); ++f) {
    const std::vector<double>& c = data.forms[f].coef;
    const int first = BlockEntries(data, data.forms[f].block).first;
    Interval& range = box[count + f];
    Intersect(range, FormRange(data, data.forms[f], box));
    // theta_i = (f - sum_{k != i} c_k theta_k) / c_i.
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (c[i] == 0.0) continue;
      Interval rest = range;
      for (std::size_t k = 0; k < c.size(); ++k)
        if (k != i) rest = rest - box[first + k] * c[k];
      Intersect(box[first + i], DivideBy(rest, c[i]));
    }
  }
}

bool IsDynamicsEntry(const LiftedData& data, int k) {
  const int count = data.layout.count();
  if (k >= count) return k - count < static_cast<int>(data.forms.size()) && data.forms[k - count].block == FormBlock::kDynamics;
  return k >= data.layout.a_begin && k < data.layout.a_begin + data.structure.na;
}

nlohmann::json FormsToJson(const std::vector<ParameterForm>& forms) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& f : forms)
    out.push_back(f.block == FormBlock::kDynamics ? nlohmann::json(f.coef)
                                                  : nlohmann::json{{"block", ToString(f.block)}, {"coef", f.coef}});
  return out;
}

std::vector<ParameterForm> FormsFromJson(const nlohmann::json& j) {
  std::vector<ParameterForm> forms;
  for (const auto& f : j) {
    if (f.is_array()) {
      forms.push_back({FormBlock::kDynamics, f.get<std::vector<double>>()});
      continue;
    }
    ParameterForm form;
    if (!ParseByName(f.at("block").get<std::string>(), {FormBlock::kDynamics, FormBlock::kGain, FormBlock::kShape},
                     &form.block))
      throw std::invalid_argument("a parameter form's block must be dynamics, gain or shape");
    form.coef = f.at("coef").get<std::vector<double>>();
    forms.push_back(form);
  }
  return forms;
}

}  // namespace hw::exact
