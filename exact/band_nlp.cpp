#include "exact/band_nlp.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <algorithm>

#include <fmt/format.h>

#include "exact/model_response.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::exact {
namespace {

constexpr double kIpoptInf = 2e19;

// z_t and its derivatives dz_t/dv for v = (theta, initial state), by running the recursion and its forward
// sensitivity together.
class Sensitivities {
 public:
  explicit Sensitivities(const LiftedData& data) : d_(data), n_(data.layout.count()), T0_(InitialStateSize(data)) {}
  int num_vars() const { return n_ + T0_; }
  void Evaluate(const double* v) {
    const int N = d_.num_samples, nv = num_vars(), j0 = d_.first_lag();
    const auto& lay = d_.layout;
    m_ = DecodeTheta(d_, std::vector<double>(v, v + n_));
    x_ = InputSignal(d_, m_);
    z_.assign(N, 0.0);
    S_.assign(static_cast<std::size_t>(N) * nv, 0.0);
    for (int t = 0; t < std::min(T0_, N); ++t) {
      z_[t] = v[n_ + t];
      S_[static_cast<std::size_t>(t) * nv + n_ + t] = 1.0;
    }
    for (int t = T0_; t < N; ++t) {
      double* s = &S_[static_cast<std::size_t>(t) * nv];
      double zt = 0.0;
      for (int i = 1; i <= d_.structure.na; ++i) {
        const double ai = m_.a[i - 1];
        const double* prev = &S_[static_cast<std::size_t>(t - i) * nv];
        for (int p = 0; p < nv; ++p) s[p] -= ai * prev[p];
        zt -= ai * z_[t - i];
        s[lay.a_begin + i - 1] -= z_[t - i];
      }
      for (std::size_t jj = 0; jj < m_.b.size(); ++jj) {
        const int lag = t - j0 - static_cast<int>(jj);
        zt += m_.b[jj] * x_[lag];
        s[lay.b_begin + jj] += x_[lag];
        for (int k = 2; k <= static_cast<int>(m_.gamma.size()); ++k)
          s[lay.gamma_begin + k - 2] += m_.b[jj] * d_.psi[lag][k - 1].mid();
      }
      z_[t] = zt;
    }
  }
  // sum_t weight[t] d2z_t/dv2 (dense, row-major) at the last evaluated point, from the recursion's second
  // derivatives: x is linear in gamma, so only the products a_i z_{t-i} and b_j x_{t-j} contribute.
  std::vector<double> WeightedHessian(const std::vector<double>& weight) const {
    const int N = d_.num_samples, nv = num_vars(), na = d_.structure.na, j0 = d_.first_lag();
    const auto& lay = d_.layout;
    const std::size_t block = static_cast<std::size_t>(nv) * nv;
    std::vector<double> H(static_cast<std::size_t>(N) * block, 0.0), sum(block, 0.0);
    for (int t = T0_; t < N; ++t) {
      double* h = &H[t * block];
      for (int i = 1; i <= na; ++i) {
        const double ai = m_.a[i - 1];
        const double* prev = &H[(t - i) * block];
        for (std::size_t e = 0; e < block; ++e) h[e] -= ai * prev[e];
        const double* s = dz(t - i);
        const int a = lay.a_begin + i - 1;
        for (int q = 0; q < nv; ++q) h[a * nv + q] -= s[q], h[q * nv + a] -= s[q];
      }
      for (std::size_t jj = 0; jj < m_.b.size(); ++jj) {
        const int lag = t - j0 - static_cast<int>(jj), b = lay.b_begin + static_cast<int>(jj);
        for (int k = 2; k <= static_cast<int>(m_.gamma.size()); ++k) {
          const int g = lay.gamma_begin + k - 2;
          const double psi = d_.psi[lag][k - 1].mid();
          h[b * nv + g] += psi, h[g * nv + b] += psi;
        }
      }
      if (weight[t] != 0.0)
        for (std::size_t e = 0; e < block; ++e) sum[e] += weight[t] * h[e];
    }
    return sum;
  }
  const ModelParameters& model() const { return m_; }
  double z(int t) const { return z_[t]; }
  const double* dz(int t) const { return &S_[static_cast<std::size_t>(t) * num_vars()]; }

 private:
  const LiftedData& d_;
  int n_, T0_;
  ModelParameters m_;
  std::vector<double> x_, z_, S_;
};

class BandNlp : public Ipopt::TNLP {
 public:
  BandNlp(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request)
      : d_(data), box_(box), req_(request), sens_(data), n_(data.layout.count()) {}
  BandNlpResult result;

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = sens_.num_vars();
    m = num_rows();
    nnz_jac = n * m;
    nnz_h = n * (n + 1) / 2;
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* xl, Ipopt::Number* xu, Ipopt::Index m, Ipopt::Number* gl,
                       Ipopt::Number* gu) override {
    for (int p = 0; p < n; ++p) {
      xl[p] = p < n_ ? box_[p].lo : -kIpoptInf;
      xu[p] = p < n_ ? box_[p].hi : kIpoptInf;
    }
    for (int r = 0; r < m; ++r) gl[r] = r < 2 * d_.num_samples ? req_.margin : 0.0, gu[r] = kIpoptInf;
    return true;
  }
  bool get_starting_point(Ipopt::Index n, bool, Ipopt::Number* x, bool, Ipopt::Number*, Ipopt::Number*,
                          Ipopt::Index, bool, Ipopt::Number*) override {
    for (int p = 0; p < n; ++p)
      x[p] = p < n_ ? std::clamp(req_.theta[p], box_[p].lo, box_[p].hi) : req_.initial_state.at(p - n_);
    return true;
  }
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    f = -req_.direction * x[req_.parameter];
    return true;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number*, bool, Ipopt::Number* g) override {
    std::fill(g, g + n, 0.0);
    g[req_.parameter] = -req_.direction;
    return true;
  }
  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool new_x, Ipopt::Index, Ipopt::Number* g) override {
    if (new_x || !evaluated_) Update(x);
    const auto& alpha = sens_.model().alpha;
    for (int t = 0; t < d_.num_samples; ++t) {
      g[2 * t] = sens_.z(t) - OutputMapValue(d_.phi_lo[t], alpha);
      g[2 * t + 1] = OutputMapValue(d_.phi_hi[t], alpha) - sens_.z(t);
    }
    for (std::size_t m = 0; m + 1 < d_.phi_grid.size(); ++m)
      g[2 * d_.num_samples + m] = OutputMapValue(d_.phi_grid[m + 1], alpha) - OutputMapValue(d_.phi_grid[m], alpha);
    return true;
  }
  bool eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Index m, Ipopt::Index,
                  Ipopt::Index* rows, Ipopt::Index* cols, Ipopt::Number* values) override {
    if (!values) {
      for (int r = 0; r < m; ++r)
        for (int p = 0; p < n; ++p) rows[r * n + p] = r, cols[r * n + p] = p;
      return true;
    }
    if (new_x || !evaluated_) Update(x);
    std::fill(values, values + static_cast<std::size_t>(n) * m, 0.0);
    const int alpha_begin = d_.layout.alpha_begin;
    for (int t = 0; t < d_.num_samples; ++t) {
      double* lower = values + static_cast<std::size_t>(2 * t) * n;
      double* upper = lower + n;
      const double* dz = sens_.dz(t);
      for (int p = 0; p < n; ++p) lower[p] = dz[p], upper[p] = -dz[p];
      for (int j = 0; j < d_.layout.num_alpha; ++j) {
        lower[alpha_begin + j] -= d_.phi_lo[t][j + 1].mid();
        upper[alpha_begin + j] += d_.phi_hi[t][j + 1].mid();
      }
    }
    for (std::size_t g = 0; g + 1 < d_.phi_grid.size(); ++g) {
      double* row = values + (static_cast<std::size_t>(2 * d_.num_samples) + g) * n;
      for (int j = 0; j < d_.layout.num_alpha; ++j)
        row[alpha_begin + j] = d_.phi_grid[g + 1][j + 1].mid() - d_.phi_grid[g][j + 1].mid();
    }
    return true;
  }
  bool eval_h(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number, Ipopt::Index,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* rows, Ipopt::Index* cols,
              Ipopt::Number* values) override {
    int e = 0;
    if (!values) {
      for (int p = 0; p < n; ++p)
        for (int q = 0; q <= p; ++q) rows[e] = p, cols[e] = q, ++e;
      return true;
    }
    if (new_x || !evaluated_) Update(x);
    // The objective and the alpha terms are linear: only z_t is curved, with weight lambda_lower - lambda_upper.
    std::vector<double> weight(d_.num_samples);
    for (int t = 0; t < d_.num_samples; ++t) weight[t] = lambda[2 * t] - lambda[2 * t + 1];
    const std::vector<double> h = sens_.WeightedHessian(weight);
    for (int p = 0; p < n; ++p)
      for (int q = 0; q <= p; ++q) values[e++] = h[static_cast<std::size_t>(p) * n + q];
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    result.returned = true;
    result.status = fmt::format("Ipopt status {}", static_cast<int>(status));
    result.theta.resize(n_);
    for (int p = 0; p < n_; ++p) result.theta[p] = std::clamp(x[p], box_[p].lo, box_[p].hi);
  }

 private:
  int num_rows() const { return 2 * d_.num_samples + std::max<int>(0, static_cast<int>(d_.phi_grid.size()) - 1); }
  void Update(const double* x) {
    sens_.Evaluate(x);
    evaluated_ = true;
  }
  const LiftedData& d_;
  const ParamBox& box_;
  const BandNlpRequest& req_;
  Sensitivities sens_;
  int n_;
  bool evaluated_ = false;
};

}  // namespace

BandNlpResult SolveBandNlp(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request) {
  Ipopt::SmartPtr<BandNlp> nlp = new BandNlp(data, box, request);
  sdp::UseSingleThreadedBlas();  // MUMPS under Ipopt would otherwise start (and spin) one BLAS thread per core
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  auto opts = app->Options();
  opts->SetIntegerValue("print_level", 0);
  opts->SetStringValue("sb", "yes");
  // A stalled search is accepted after a few steps at 1e-5 (the point's feasibility, which is what counts, is
  // re-checked anyway).
  opts->SetIntegerValue("max_iter", 500);
  opts->SetNumericValue("tol", 1e-8);
  opts->SetNumericValue("acceptable_tol", 1e-5);
  opts->SetIntegerValue("acceptable_iter", 10);
  opts->SetNumericValue("constr_viol_tol", 1e-10);
  opts->SetNumericValue("max_cpu_time", std::max(0.1, request.cpu_seconds));
  BandNlpResult failed;
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    failed.status = "Ipopt failed to initialise";
    return failed;
  }
  app->OptimizeTNLP(nlp);
  return nlp->result;
}

}  // namespace hw::exact
