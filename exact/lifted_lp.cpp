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

// Four McCormick rows of prod = x * y over x in X, y in Y.
void AddMcCormick(LpProblem* lp, int prod, int x, Interval X, int y, Interval Y) {
  RowBuilder r(lp);
  // (x - xl)(y - yl) >= 0: prod - yl x - xl y >= -xl yl
  r.Add(prod, 1).Add(x, -Y.lo).Add(y, -X.lo).AtLeast(-(Interval(X.lo) * Y.lo));
  // (xu - x)(yu - y) >= 0: prod - yu x - xu y >= -xu yu
  r.Add(prod, 1).Add(x, -Y.hi).Add(y, -X.hi).AtLeast(-(Interval(X.hi) * Y.hi));
  // (x - xl)(yu - y) >= 0: prod - yu x - xl y <= -xl yu
  r.Add(prod, 1).Add(x, -Y.hi).Add(y, -X.lo).AtMost(-(Interval(X.lo) * Y.hi));
  // (xu - x)(y - yl) >= 0: prod - yl x - xu y <= -xu yl
  r.Add(prod, 1).Add(x, -Y.lo).Add(y, -X.hi).AtMost(-(Interval(X.hi) * Y.lo));
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

LiftedLp BuildLiftedLp(const LiftedData& d, const ParamBox& box, Window window, LiftedForm form) {
  const auto& s = d.structure;
  const auto& lay = d.layout;
  const int na = s.na, n_alpha = static_cast<int>(s.output_basis.size()), n_gamma = static_cast<int>(s.input_basis.size());
  const int j0 = d.first_lag(), nb = s.nb;
  LiftedLp out;
  out.window = window;
  LpProblem& lp = out.lp;
  auto range = [&](int col) { return ColumnRange(lp, col); };

  // Parameter columns, in the layout's order.
  out.param_col.resize(lay.count());
  if (static_cast<int>(box.size()) > lay.count() && box.size() != lay.count() + d.dynamics_forms.size())
    throw InputError("a box with form ranges needs one per dynamics form");
  for (int k = 0; k < lay.count(); ++k) out.param_col[k] = lp.AddColumn(box[k].lo, box[k].hi);
  for (std::size_t f = 0; f < d.dynamics_forms.size() && static_cast<int>(box.size()) > lay.count(); ++f)
    out.param_col.push_back(lp.AddColumn(box[lay.count() + f].lo, box[lay.count() + f].hi));
  auto gamma_col = [&](int k) { return out.param_col[lay.gamma_begin + k - 2]; };  // k = 2..n_gamma
  auto alpha_col = [&](int j) { return out.param_col[lay.alpha_begin + j - 2]; };  // j = 2..n_alpha
  auto a_col = [&](int i) { return out.param_col[lay.a_begin + i - 1]; };          // i = 1..na
  // beta_jk = b_j gamma_k (k = 1: b_j itself).
  out.beta_col.assign(nb - j0 + 1, std::vector<int>(n_gamma, -1));
  for (int j = j0; j <= nb; ++j) {
    const int b = out.param_col[lay.b_begin + j - j0];
    out.beta_col[j - j0][0] = b;
    for (int k = 2; k <= n_gamma; ++k) {
      const Interval prod = range(b) * range(gamma_col(k));
      out.beta_col[j - j0][k - 1] = lp.AddColumn(prod.lo, prod.hi);
    }
  }
  // c_ij = a_i alpha_j.
  std::vector<std::vector<int>> c_col(na + 1, std::vector<int>(n_alpha + 1, -1));
  for (int i = 1; i <= na; ++i)
    for (int j = 2; j <= n_alpha; ++j) {
      const Interval prod = range(a_col(i)) * range(alpha_col(j));
      c_col[i][j] = lp.AddColumn(prod.lo, prod.hi);
    }
  // p(alpha, w) over the alpha box, from basis values at w.
  auto p_range = [&](const std::vector<Interval>& phi) {
    Interval p = phi[0];
    for (int j = 2; j <= n_alpha; ++j) p += range(alpha_col(j)) * phi[j - 1];
    return p;
  };
  // z_t within its band over the alpha box.
  const int T = window.end - window.begin;
  out.z_col.resize(T);
  for (int t = window.begin; t < window.end; ++t)
    out.z_col[t - window.begin] = lp.AddColumn(p_range(d.phi_lo[t]).lo, p_range(d.phi_hi[t]).hi);
  auto z_col = [&](int t) { return out.z_col[t - window.begin]; };
  // Equations for every t whose lags lie in the window (outputs) and in the record (inputs).
  const int t_first = std::max(window.begin + na, nb);
  // w_{i,tau} = a_i z_tau for the lags the equations use.
  std::vector<std::vector<int>> w_col(na + 1, std::vector<int>(T, -1));
  for (int t = t_first; t < window.end; ++t)
    for (int i = 1; i <= na; ++i) {
      int& col = w_col[i][t - i - window.begin];
      if (col >= 0) continue;
      const Interval prod = range(a_col(i)) * range(z_col(t - i));
      col = lp.AddColumn(prod.lo, prod.hi);
    }
  // The slack bound: the largest residual any point of the column box can have.
  double slack_max = 0.0;
  for (int t = t_first; t < window.end; ++t) {
    Interval r = range(z_col(t));
    for (int i = 1; i <= na; ++i) r += range(w_col[i][t - i - window.begin]);
    for (int j = j0; j <= nb; ++j)
      for (int k = 1; k <= n_gamma; ++k) r = r - range(out.beta_col[j - j0][k - 1]) * d.psi[t - j][k - 1];
    slack_max = std::max({slack_max, -r.lo, r.hi});
  }
  out.s_col = lp.AddColumn(0.0, form == LiftedForm::kFeasibility ? RoundUp(slack_max) : 0.0);

  RowBuilder row(&lp);
  // Equations: -s <= residual_t <= s. In the bounding form (s = 0) the first row is the equation itself and the
  // second is left free: the same shape as the feasibility form (so a basis carries over), but no pair of
  // opposite inequalities that would leave an interior-point method no interior.
  for (int t = t_first; t < window.end; ++t) {
    for (int side = 0; side < 2; ++side) {
      row.Add(z_col(t), 1.0);
      for (int i = 1; i <= na; ++i) row.Add(w_col[i][t - i - window.begin], 1.0);
      for (int j = j0; j <= nb; ++j)
        for (int k = 1; k <= n_gamma; ++k) row.Add(out.beta_col[j - j0][k - 1], -d.psi[t - j][k - 1]);
      if (form == LiftedForm::kBounding) {
        row.Add(out.s_col, side == 0 ? -1.0 : 1.0);
        if (side == 0) row.EqualTo(0.0);
        else row.Free();
      } else if (side == 0) {
        row.Add(out.s_col, -1.0).AtMost(0.0);
      } else {
        row.Add(out.s_col, 1.0).AtLeast(0.0);
      }
    }
    ++out.num_equations;
  }
  // Bands: p(alpha, L_t) <= z_t <= p(alpha, H_t).
  for (int t = window.begin; t < window.end; ++t) {
    row.Add(z_col(t), 1.0);
    for (int j = 2; j <= n_alpha; ++j) row.Add(alpha_col(j), -d.phi_lo[t][j - 1]);
    row.AtLeast(d.phi_lo[t][0]);
    row.Add(z_col(t), 1.0);
    for (int j = 2; j <= n_alpha; ++j) row.Add(alpha_col(j), -d.phi_hi[t][j - 1]);
    row.AtMost(d.phi_hi[t][0]);
  }
  // Products of the box factors of a_i with the band factors of z_tau.
  for (int i = 1; i <= na; ++i) {
    const double l = box[lay.a_begin + i - 1].lo, u = box[lay.a_begin + i - 1].hi;
    for (int tau = window.begin; tau < window.end; ++tau) {
      const int w = w_col[i][tau - window.begin];
      if (w < 0) continue;
      const int z = z_col(tau), a = a_col(i);
      const auto& pl = d.phi_lo[tau];
      const auto& ph = d.phi_hi[tau];
      // (a - l)(z - pL) >= 0
      row.Add(w, 1.0).Add(a, -pl[0]).Add(z, -l);
      for (int j = 2; j <= n_alpha; ++j) row.Add(c_col[i][j], -pl[j - 1]).Add(alpha_col(j), Interval(l) * pl[j - 1]);
      row.AtLeast(-(Interval(l) * pl[0]));
      // (u - a)(z - pL) >= 0
      row.Add(w, -1.0).Add(a, pl[0]).Add(z, u);
      for (int j = 2; j <= n_alpha; ++j) row.Add(c_col[i][j], pl[j - 1]).Add(alpha_col(j), -(Interval(u) * pl[j - 1]));
      row.AtLeast(Interval(u) * pl[0]);
      // (a - l)(pH - z) >= 0
      row.Add(w, -1.0).Add(a, ph[0]).Add(z, l);
      for (int j = 2; j <= n_alpha; ++j) row.Add(c_col[i][j], ph[j - 1]).Add(alpha_col(j), -(Interval(l) * ph[j - 1]));
      row.AtLeast(Interval(l) * ph[0]);
      // (u - a)(pH - z) >= 0
      row.Add(w, 1.0).Add(a, -ph[0]).Add(z, -u);
      for (int j = 2; j <= n_alpha; ++j) row.Add(c_col[i][j], -ph[j - 1]).Add(alpha_col(j), Interval(u) * ph[j - 1]);
      row.AtLeast(-(Interval(u) * ph[0]));
    }
  }
  // The forms f = sum_i c_i a_i of the box: (f - l)(z - pL) >= 0 and its three siblings, with f z_tau =
  // sum_i c_i w_{i,tau} and f p(alpha, .) = sum_i c_i (a_i phi_1 + sum_j c_ij phi_j); only where every w_{i,tau}
  // of the form exists (fewer rows stay a valid relaxation).
  for (std::size_t f = 0; f < d.dynamics_forms.size() && static_cast<int>(box.size()) > lay.count(); ++f) {
    const DynamicsForm& form = d.dynamics_forms[f];
    const int fc = out.param_col[lay.count() + f];
    row.Add(fc, 1.0);
    for (int i = 1; i <= na; ++i)
      if (form[i - 1] != 0.0) row.Add(a_col(i), -form[i - 1]);
    row.EqualTo(0.0);
    const double l = box[lay.count() + f].lo, u = box[lay.count() + f].hi;
    for (int tau = window.begin; tau < window.end; ++tau) {
      bool all = true;
      for (int i = 1; i <= na; ++i) all = all && (form[i - 1] == 0.0 || w_col[i][tau - window.begin] >= 0);
      if (!all) continue;
      const int z = z_col(tau);
      // side: +1 for (f - l)(...), -1 for (u - f)(...); band: the factor (z - pL) or (pH - z).
      for (const auto& [edge, side] : {std::pair{l, 1.0}, std::pair{u, -1.0}})
        for (const auto* band : {&d.phi_lo[tau], &d.phi_hi[tau]}) {
          const double zsign = band == &d.phi_lo[tau] ? 1.0 : -1.0;  // z - pL, or pH - z
          const auto& ph = *band;
          const double k = side * zsign;  // the sign of f * z in the product
          for (int i = 1; i <= na; ++i) {
            if (form[i - 1] == 0.0) continue;
            row.Add(w_col[i][tau - window.begin], k * form[i - 1]);
            row.Add(a_col(i), -k * (Interval(form[i - 1]) * ph[0]));
            for (int j = 2; j <= n_alpha; ++j) row.Add(c_col[i][j], -k * (Interval(form[i - 1]) * ph[j - 1]));
          }
          // -side * edge * (z - p) for band lo, i.e. the edge times the band factor.
          row.Add(z, -k * edge);
          for (int j = 2; j <= n_alpha; ++j) row.Add(alpha_col(j), k * (Interval(edge) * ph[j - 1]));
          row.AtLeast(-k * (Interval(edge) * ph[0]));
        }
    }
  }
  // Envelopes of c_ij = a_i alpha_j and beta_jk = b_j gamma_k.
  for (int i = 1; i <= na; ++i)
    for (int j = 2; j <= n_alpha; ++j)
      AddMcCormick(&lp, c_col[i][j], a_col(i), range(a_col(i)), alpha_col(j), range(alpha_col(j)));
  for (int j = j0; j <= nb; ++j)
    for (int k = 2; k <= n_gamma; ++k) {
      const int b = out.beta_col[j - j0][0];
      AddMcCormick(&lp, out.beta_col[j - j0][k - 1], b, range(b), gamma_col(k), range(gamma_col(k)));
    }
  // The assumption: p(alpha, .) increases over the data range, so it increases between grid points.
  for (std::size_t m = 0; m + 1 < d.grid.size(); ++m) {
    for (int j = 2; j <= n_alpha; ++j) row.Add(alpha_col(j), d.phi_grid[m + 1][j - 1] - d.phi_grid[m][j - 1]);
    row.AtLeast(d.phi_grid[m][0] - d.phi_grid[m + 1][0]);
  }
  return out;
}

}  // namespace hw::exact
