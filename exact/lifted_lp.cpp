#include "exact/lifted_lp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "core/input_error.hpp"

namespace hw::exact {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Basis values are libm or pow results: within a few ulps of the exact value (glibc documents <= 2 ulps for
// these functions; 8 leaves room).
Interval BasisValue(const dss::BasisFunction& f, double w) { return Interval::WithUlps(f.value(w), 8.0); }

std::vector<Interval> BasisValues(const std::vector<dss::BasisFunction>& basis, double w) {
  std::vector<Interval> v;
  for (const auto& f : basis) v.push_back(BasisValue(f, w));
  return v;
}

// A row under construction: interval coefficients, then added with an interval bound.
class RowBuilder {
 public:
  explicit RowBuilder(LpProblem* lp) : lp_(lp) {}
  RowBuilder& Add(int col, Interval coef) {
    terms_.emplace_back(col, coef);
    return *this;
  }
  // sum >= rhs (the exact rhs lies in the interval).
  void AtLeast(Interval rhs) { Finish(rhs.mid(), kInf, rhs.rad(), 0.0); }
  void AtMost(Interval rhs) { Finish(-kInf, rhs.mid(), 0.0, rhs.rad()); }
  void EqualTo(double rhs) { Finish(rhs, rhs, 0.0, 0.0); }
  void Free() { Finish(-kInf, kInf, 0.0, 0.0); }

 private:
  void Finish(double lo, double hi, double lo_rad, double hi_rad) {
    const int row = lp_->AddRow(lo, hi, lo_rad, hi_rad);
    for (const auto& [col, coef] : terms_) lp_->AddEntry(row, col, coef.mid(), coef.rad());
    terms_.clear();
  }
  LpProblem* lp_;
  std::vector<std::pair<int, Interval>> terms_;
};

Interval ColumnRange(const LpProblem& lp, int col) { return {lp.col_lo[col], lp.col_hi[col]}; }

// Four McCormick rows of x * y = sum_c coefficient_c * column_c over x in X, y in Y (one column with coefficient
// 1 for a product of its own; a combination of products for a form's, exact/parameter_forms.hpp).
void AddMcCormick(LpProblem* lp, const std::vector<std::pair<int, double>>& product, int x, Interval X, int y,
                  Interval Y) {
  RowBuilder r(lp);
  auto add_product = [&] {
    for (const auto& [col, c] : product) r.Add(col, c);
  };
  // (x - xl)(y - yl) >= 0: prod - yl x - xl y >= -xl yl
  add_product();
  r.Add(x, -Y.lo).Add(y, -X.lo).AtLeast(-(Interval(X.lo) * Y.lo));
  // (xu - x)(yu - y) >= 0: prod - yu x - xu y >= -xu yu
  add_product();
  r.Add(x, -Y.hi).Add(y, -X.hi).AtLeast(-(Interval(X.hi) * Y.hi));
  // (x - xl)(yu - y) >= 0: prod - yu x - xl y <= -xl yu
  add_product();
  r.Add(x, -Y.hi).Add(y, -X.lo).AtMost(-(Interval(X.lo) * Y.hi));
  // (xu - x)(y - yl) >= 0: prod - yl x - xu y <= -xu yl
  add_product();
  r.Add(x, -Y.lo).Add(y, -X.hi).AtMost(-(Interval(X.hi) * Y.lo));
}

void AddMcCormick(LpProblem* lp, int prod, int x, Interval X, int y, Interval Y) {
  AddMcCormick(lp, {{prod, 1.0}}, x, X, y, Y);
}

}  // namespace

LiftedData MakeLiftedData(const dss::HwStructure& structure, const dss::HwData& data, int grid_points) {
  std::string error;
  if (!structure.IsValid(&error)) throw InputError(error);
  if (!data.IsValid(&error)) throw InputError(error);
  LiftedData d;
  d.structure = structure;
  d.layout = dss::MakeLayout(structure);
  d.num_samples = static_cast<int>(data.y.size());
  double lo = kInf, hi = -kInf;
  for (int t = 0; t < d.num_samples; ++t) {
    const double L = (Interval(data.y[t]) - Interval(data.noise_bound[t])).lo;
    const double H = (Interval(data.y[t]) + Interval(data.noise_bound[t])).hi;
    if (!std::isfinite(L) || !std::isfinite(H) || !std::isfinite(data.u[t]))
      throw InputError(fmt::format("{}: the sample is not finite", data.where(t)));
    d.band_lo.push_back(L);
    d.band_hi.push_back(H);
    d.phi_lo.push_back(BasisValues(structure.output_basis, L));
    d.phi_hi.push_back(BasisValues(structure.output_basis, H));
    d.psi.push_back(BasisValues(structure.input_basis, data.u[t]));
    lo = std::min(lo, L);
    hi = std::max(hi, H);
  }
  for (int m = 0; m < grid_points; ++m) {
    const double w = m + 1 == grid_points ? hi : lo + (hi - lo) * m / (grid_points - 1);
    d.grid.push_back(w);
    d.phi_grid.push_back(BasisValues(structure.output_basis, w));
  }
  return d;
}

void LiftedLp::SetParameterObjective(const std::vector<double>& weights) {
  std::fill(lp.obj.begin(), lp.obj.end(), 0.0);
  for (std::size_t k = 0; k < weights.size(); ++k) lp.obj[param_col[k]] = weights[k];
}

void LiftedLp::SetSlackObjective() {
  std::fill(lp.obj.begin(), lp.obj.end(), 0.0);
  lp.obj[s_col] = 1.0;
}

void LiftedLp::SetRatioObjective(const std::vector<std::pair<int, double>>& terms, int k, double g) {
  std::fill(lp.obj.begin(), lp.obj.end(), 0.0);
  for (const auto& [j_index, w] : terms) {
    lp.obj[beta_col[j_index][k]] += w;
    lp.obj[beta_col[j_index][0]] -= w * g;
  }
}

namespace {

// BuildLiftedLp's steps, in the order they add columns and rows (the order fixes the LP, and so a simplex
// basis's meaning and the interior point's rounding: keep it).
class LiftedLpBuilder {
 public:
  LiftedLpBuilder(const LiftedData& d, const ParamBox& box, Window window, LiftedForm form)
      : d_(d), lay_(d.layout), box_(box), window_(window), form_(form), na_(d.structure.na),
        n_alpha_(static_cast<int>(d.structure.output_basis.size())),
        n_gamma_(static_cast<int>(d.structure.input_basis.size())), j0_(d.first_lag()), nb_(d.structure.nb),
        t_first_(std::max(window.begin + d.structure.na, d.structure.nb)), row_(&out_.lp) {
    out_.window = window;
  }

  LiftedLp Build() {
    AddParameterColumns();
    AddBetaColumns();
    AddAlphaProductColumns();
    AddSampleColumns();
    AddSlackColumn();
    AddEquationRows();
    AddBandRows();
    AddDynamicsBandProducts();
    AddFormBandProducts();
    AddEnvelopes();
    AddInputFormEnvelopes();
    AddMonotonicityRows();
    return std::move(out_);
  }

 private:
  Interval range(int col) const { return ColumnRange(out_.lp, col); }
  int gamma_col(int k) const { return out_.param_col[lay_.gamma_begin + k - 2]; }  // k = 2..n_gamma
  int alpha_col(int j) const { return out_.param_col[lay_.alpha_begin + j - 2]; }  // j = 2..n_alpha
  int a_col(int i) const { return out_.param_col[lay_.a_begin + i - 1]; }          // i = 1..na
  int z_col(int t) const { return out_.z_col[t - window_.begin]; }
  bool has_form_ranges() const { return static_cast<int>(box_.size()) > lay_.count(); }
  // p(alpha, w) over the alpha box, from basis values at w.
  Interval p_range(const std::vector<Interval>& phi) const {
    Interval p = phi[0];
    for (int j = 2; j <= n_alpha_; ++j) p += range(alpha_col(j)) * phi[j - 1];
    return p;
  }

  // Parameter columns, in the layout's order, then the forms' (when the box has their ranges).
  void AddParameterColumns() {
    LpProblem& lp = out_.lp;
    out_.param_col.resize(lay_.count());
    if (has_form_ranges() && box_.size() != lay_.count() + d_.forms.size())
      throw InputError("a box with form ranges needs one per parameter form");
    for (int k = 0; k < lay_.count(); ++k) out_.param_col[k] = lp.AddColumn(box_[k].lo, box_[k].hi);
    for (std::size_t f = 0; f < d_.forms.size() && has_form_ranges(); ++f)
      out_.param_col.push_back(lp.AddColumn(box_[lay_.count() + f].lo, box_[lay_.count() + f].hi));
  }

  // beta_jk = b_j gamma_k (k = 1: b_j itself).
  void AddBetaColumns() {
    out_.beta_col.assign(nb_ - j0_ + 1, std::vector<int>(n_gamma_, -1));
    for (int j = j0_; j <= nb_; ++j) {
      const int b = out_.param_col[lay_.b_begin + j - j0_];
      out_.beta_col[j - j0_][0] = b;
      for (int k = 2; k <= n_gamma_; ++k) {
        const Interval prod = range(b) * range(gamma_col(k));
        out_.beta_col[j - j0_][k - 1] = out_.lp.AddColumn(prod.lo, prod.hi);
      }
    }
  }

  // c_ij = a_i alpha_j.
  void AddAlphaProductColumns() {
    c_col_.assign(na_ + 1, std::vector<int>(n_alpha_ + 1, -1));
    for (int i = 1; i <= na_; ++i)
      for (int j = 2; j <= n_alpha_; ++j) {
        const Interval prod = range(a_col(i)) * range(alpha_col(j));
        c_col_[i][j] = out_.lp.AddColumn(prod.lo, prod.hi);
      }
  }

  // z_t within its band over the alpha box; w_{i,tau} = a_i z_tau for the lags the equations use (equations for
  // every t whose lags lie in the window (outputs) and in the record (inputs)).
  void AddSampleColumns() {
    const int T = window_.end - window_.begin;
    out_.z_col.resize(T);
    for (int t = window_.begin; t < window_.end; ++t)
      out_.z_col[t - window_.begin] = out_.lp.AddColumn(p_range(d_.phi_lo[t]).lo, p_range(d_.phi_hi[t]).hi);
    w_col_.assign(na_ + 1, std::vector<int>(T, -1));
    for (int t = t_first_; t < window_.end; ++t)
      for (int i = 1; i <= na_; ++i) {
        int& col = w_col_[i][t - i - window_.begin];
        if (col >= 0) continue;
        const Interval prod = range(a_col(i)) * range(z_col(t - i));
        col = out_.lp.AddColumn(prod.lo, prod.hi);
      }
  }

  // The slack, bounded by the largest residual any point of the column box can have (0 in the bounding form).
  void AddSlackColumn() {
    double slack_max = 0.0;
    for (int t = t_first_; t < window_.end; ++t) {
      Interval r = range(z_col(t));
      for (int i = 1; i <= na_; ++i) r += range(w_col_[i][t - i - window_.begin]);
      for (int j = j0_; j <= nb_; ++j)
        for (int k = 1; k <= n_gamma_; ++k) r = r - range(out_.beta_col[j - j0_][k - 1]) * d_.psi[t - j][k - 1];
      slack_max = std::max({slack_max, -r.lo, r.hi});
    }
    out_.s_col = out_.lp.AddColumn(0.0, form_ == LiftedForm::kFeasibility ? RoundUp(slack_max) : 0.0);
  }

  // Equations: -s <= residual_t <= s. In the bounding form (s = 0) the first row is the equation itself and the
  // second is left free: the same shape as the feasibility form (so a basis carries over), but no pair of
  // opposite inequalities that would leave an interior-point method no interior.
  void AddEquationRows() {
    for (int t = t_first_; t < window_.end; ++t) {
      for (int side = 0; side < 2; ++side) {
        row_.Add(z_col(t), 1.0);
        for (int i = 1; i <= na_; ++i) row_.Add(w_col_[i][t - i - window_.begin], 1.0);
        for (int j = j0_; j <= nb_; ++j)
          for (int k = 1; k <= n_gamma_; ++k) row_.Add(out_.beta_col[j - j0_][k - 1], -d_.psi[t - j][k - 1]);
        if (form_ == LiftedForm::kBounding) {
          row_.Add(out_.s_col, side == 0 ? -1.0 : 1.0);
          if (side == 0) row_.EqualTo(0.0);
          else row_.Free();
        } else if (side == 0) {
          row_.Add(out_.s_col, -1.0).AtMost(0.0);
        } else {
          row_.Add(out_.s_col, 1.0).AtLeast(0.0);
        }
      }
      ++out_.num_equations;
    }
  }

  // Bands: p(alpha, L_t) <= z_t <= p(alpha, H_t).
  void AddBandRows() {
    for (int t = window_.begin; t < window_.end; ++t) {
      row_.Add(z_col(t), 1.0);
      for (int j = 2; j <= n_alpha_; ++j) row_.Add(alpha_col(j), -d_.phi_lo[t][j - 1]);
      row_.AtLeast(d_.phi_lo[t][0]);
      row_.Add(z_col(t), 1.0);
      for (int j = 2; j <= n_alpha_; ++j) row_.Add(alpha_col(j), -d_.phi_hi[t][j - 1]);
      row_.AtMost(d_.phi_hi[t][0]);
    }
  }

  // Products of the box factors of a_i with the band factors of z_tau.
  void AddDynamicsBandProducts() {
    for (int i = 1; i <= na_; ++i) {
      const double l = box_[lay_.a_begin + i - 1].lo, u = box_[lay_.a_begin + i - 1].hi;
      for (int tau = window_.begin; tau < window_.end; ++tau) {
        const int w = w_col_[i][tau - window_.begin];
        if (w < 0) continue;
        const int z = z_col(tau), a = a_col(i);
        const auto& pl = d_.phi_lo[tau];
        const auto& ph = d_.phi_hi[tau];
        // (a - l)(z - pL) >= 0
        row_.Add(w, 1.0).Add(a, -pl[0]).Add(z, -l);
        for (int j = 2; j <= n_alpha_; ++j) row_.Add(c_col_[i][j], -pl[j - 1]).Add(alpha_col(j), Interval(l) * pl[j - 1]);
        row_.AtLeast(-(Interval(l) * pl[0]));
        // (u - a)(z - pL) >= 0
        row_.Add(w, -1.0).Add(a, pl[0]).Add(z, u);
        for (int j = 2; j <= n_alpha_; ++j) row_.Add(c_col_[i][j], pl[j - 1]).Add(alpha_col(j), -(Interval(u) * pl[j - 1]));
        row_.AtLeast(Interval(u) * pl[0]);
        // (a - l)(pH - z) >= 0
        row_.Add(w, -1.0).Add(a, ph[0]).Add(z, l);
        for (int j = 2; j <= n_alpha_; ++j) row_.Add(c_col_[i][j], ph[j - 1]).Add(alpha_col(j), -(Interval(l) * ph[j - 1]));
        row_.AtLeast(Interval(l) * ph[0]);
        // (u - a)(pH - z) >= 0
        row_.Add(w, 1.0).Add(a, -ph[0]).Add(z, -u);
        for (int j = 2; j <= n_alpha_; ++j) row_.Add(c_col_[i][j], -ph[j - 1]).Add(alpha_col(j), Interval(u) * ph[j - 1]);
        row_.AtLeast(-(Interval(u) * ph[0]));
      }
    }
  }

  // f = sum_i c_i theta_i for form f (its column equals the combination of its block's columns).
  void AddFormDefinition(std::size_t f) {
    const ParameterForm& form = d_.forms[f];
    const int first = BlockEntries(d_, form.block).first;
    row_.Add(out_.param_col[lay_.count() + f], 1.0);
    for (std::size_t i = 0; i < form.coef.size(); ++i)
      if (form.coef[i] != 0.0) row_.Add(out_.param_col[first + i], -form.coef[i]);
    row_.EqualTo(0.0);
  }

  // The dynamics forms f = sum_i c_i a_i of the box: (f - l)(z - pL) >= 0 and its three siblings, with f z_tau =
  // sum_i c_i w_{i,tau} and f p(alpha, .) = sum_i c_i (a_i phi_1 + sum_j c_ij phi_j); only where every w_{i,tau}
  // of the form exists (fewer rows stay a valid relaxation).
  void AddFormBandProducts() {
    for (std::size_t f = 0; f < d_.forms.size() && has_form_ranges(); ++f) {
      if (d_.forms[f].block != FormBlock::kDynamics) continue;
      const std::vector<double>& form = d_.forms[f].coef;
      AddFormDefinition(f);
      const double l = box_[lay_.count() + f].lo, u = box_[lay_.count() + f].hi;
      for (int tau = window_.begin; tau < window_.end; ++tau) {
        bool all = true;
        for (int i = 1; i <= na_; ++i) all = all && (form[i - 1] == 0.0 || w_col_[i][tau - window_.begin] >= 0);
        if (!all) continue;
        // side: +1 for (f - l)(...), -1 for (u - f)(...); band: the factor (z - pL) or (pH - z).
        for (const auto& [edge, side] : {std::pair{l, 1.0}, std::pair{u, -1.0}})
          for (const auto* band : {&d_.phi_lo[tau], &d_.phi_hi[tau]})
            AddFormBandRow(form, tau, edge, side * (band == &d_.phi_lo[tau] ? 1.0 : -1.0), *band);
      }
    }
  }

  // One product row of a form's edge factor with a band factor; k is the sign of f * z in the product.
  void AddFormBandRow(const std::vector<double>& form, int tau, double edge, double k, const std::vector<Interval>& ph) {
    for (int i = 1; i <= na_; ++i) {
      if (form[i - 1] == 0.0) continue;
      row_.Add(w_col_[i][tau - window_.begin], k * form[i - 1]);
      row_.Add(a_col(i), -k * (Interval(form[i - 1]) * ph[0]));
      for (int j = 2; j <= n_alpha_; ++j) row_.Add(c_col_[i][j], -k * (Interval(form[i - 1]) * ph[j - 1]));
    }
    // -side * edge * (z - p) for band lo, i.e. the edge times the band factor.
    row_.Add(z_col(tau), -k * edge);
    for (int j = 2; j <= n_alpha_; ++j) row_.Add(alpha_col(j), k * (Interval(edge) * ph[j - 1]));
    row_.AtLeast(-k * (Interval(edge) * ph[0]));
  }

  // Envelopes of c_ij = a_i alpha_j and beta_jk = b_j gamma_k.
  void AddEnvelopes() {
    for (int i = 1; i <= na_; ++i)
      for (int j = 2; j <= n_alpha_; ++j)
        AddMcCormick(&out_.lp, c_col_[i][j], a_col(i), range(a_col(i)), alpha_col(j), range(alpha_col(j)));
    for (int j = j0_; j <= nb_; ++j)
      for (int k = 2; k <= n_gamma_; ++k) {
        const int b = out_.beta_col[j - j0_][0];
        AddMcCormick(&out_.lp, out_.beta_col[j - j0_][k - 1], b, range(b), gamma_col(k), range(gamma_col(k)));
      }
  }

  // A factor of beta_jk = b_j gamma_k's two sides: a parameter (one unit coefficient) or a gain or shape form.
  struct InputFactor {
    int col;
    Interval range;
    std::vector<double> coef;  // over the side's entries (b_j0..b_nb, or gamma_2..gamma_ng)
  };

  // The gain forms' and shape forms' definitions, and McCormick envelopes of every product of a gain-side factor
  // (b_j or a gain form) with a shape-side factor (gamma_k or a shape form) that involves a form: the product
  // sum_j sum_k d_j e_k beta_jk is linear in beta. (The products of b_j with gamma_k are beta's own envelopes.)
  void AddInputFormEnvelopes() {
    if (!has_form_ranges()) return;
    std::vector<InputFactor> gain_side, shape_side;
    const int n_b = nb_ - j0_ + 1, n_g = n_gamma_ - 1;
    for (int j = 0; j < n_b; ++j) {
      const int col = out_.beta_col[j][0];
      gain_side.push_back({col, range(col), std::vector<double>(n_b, 0.0)});
      gain_side.back().coef[j] = 1.0;
    }
    for (int k = 0; k < n_g; ++k) {
      const int col = gamma_col(k + 2);
      shape_side.push_back({col, range(col), std::vector<double>(n_g, 0.0)});
      shape_side.back().coef[k] = 1.0;
    }
    const std::size_t parameters_gain = gain_side.size(), parameters_shape = shape_side.size();
    for (std::size_t f = 0; f < d_.forms.size(); ++f) {
      const FormBlock block = d_.forms[f].block;
      if (block == FormBlock::kDynamics) continue;
      AddFormDefinition(f);
      const int col = out_.param_col[lay_.count() + f];
      (block == FormBlock::kGain ? gain_side : shape_side).push_back({col, range(col), d_.forms[f].coef});
    }
    for (std::size_t g = 0; g < gain_side.size(); ++g)
      for (std::size_t h = 0; h < shape_side.size(); ++h) {
        if (g < parameters_gain && h < parameters_shape) continue;
        std::vector<std::pair<int, double>> product;
        for (int j = 0; j < n_b; ++j)
          for (int k = 0; k < n_g; ++k) {
            const double c = gain_side[g].coef[j] * shape_side[h].coef[k];
            if (c != 0.0) product.emplace_back(out_.beta_col[j][k + 1], c);
          }
        AddMcCormick(&out_.lp, product, gain_side[g].col, gain_side[g].range, shape_side[h].col,
                     shape_side[h].range);
      }
  }

  // The assumption: p(alpha, .) increases over the data range, so it increases between grid points.
  void AddMonotonicityRows() {
    for (std::size_t m = 0; m + 1 < d_.grid.size(); ++m) {
      for (int j = 2; j <= n_alpha_; ++j) row_.Add(alpha_col(j), d_.phi_grid[m + 1][j - 1] - d_.phi_grid[m][j - 1]);
      row_.AtLeast(d_.phi_grid[m][0] - d_.phi_grid[m + 1][0]);
    }
  }

  const LiftedData& d_;
  const dss::ParameterLayout& lay_;
  const ParamBox& box_;
  const Window window_;
  const LiftedForm form_;
  const int na_, n_alpha_, n_gamma_, j0_, nb_, t_first_;
  LiftedLp out_;
  RowBuilder row_;
  std::vector<std::vector<int>> c_col_;  // [i][j]: c_ij = a_i alpha_j
  std::vector<std::vector<int>> w_col_;  // [i][tau - window.begin]: w = a_i z_tau (-1: unused)
};

}  // namespace

LiftedLp BuildLiftedLp(const LiftedData& d, const ParamBox& box, Window window, LiftedForm form) {
  return LiftedLpBuilder(d, box, window, form).Build();
}

}  // namespace hw::exact
