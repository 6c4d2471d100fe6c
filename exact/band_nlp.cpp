#include "exact/band_nlp.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

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
  // The band rows of `samples` only (the working set); the monotonicity rows always.
  BandNlp(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request, const std::vector<int>& samples)
      : d_(data), box_(box), req_(request), samples_(samples), sens_(data), n_(data.layout.count()) {}
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
    for (int r = 0; r < m; ++r) gl[r] = r < 2 * num_bands() ? req_.margin : 0.0, gu[r] = kIpoptInf;
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
    for (int r = 0; r < num_bands(); ++r) {
      const int t = samples_[r];
      g[2 * r] = sens_.z(t) - OutputMapValue(d_.phi_lo[t], alpha);
      g[2 * r + 1] = OutputMapValue(d_.phi_hi[t], alpha) - sens_.z(t);
    }
    for (std::size_t m = 0; m + 1 < d_.phi_grid.size(); ++m)
      g[2 * num_bands() + m] = OutputMapValue(d_.phi_grid[m + 1], alpha) - OutputMapValue(d_.phi_grid[m], alpha);
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
    for (int r = 0; r < num_bands(); ++r) {
      const int t = samples_[r];
      double* lower = values + static_cast<std::size_t>(2 * r) * n;
      double* upper = lower + n;
      const double* dz = sens_.dz(t);
      for (int p = 0; p < n; ++p) lower[p] = dz[p], upper[p] = -dz[p];
      for (int j = 0; j < d_.layout.num_alpha; ++j) {
        lower[alpha_begin + j] -= d_.phi_lo[t][j + 1].mid();
        upper[alpha_begin + j] += d_.phi_hi[t][j + 1].mid();
      }
    }
    for (std::size_t g = 0; g + 1 < d_.phi_grid.size(); ++g) {
      double* row = values + (static_cast<std::size_t>(2 * num_bands()) + g) * n;
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
    std::vector<double> weight(d_.num_samples, 0.0);
    for (int r = 0; r < num_bands(); ++r) weight[samples_[r]] = lambda[2 * r] - lambda[2 * r + 1];
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
    result.initial_state.assign(x + n_, x + sens_.num_vars());
  }

 private:
  int num_bands() const { return static_cast<int>(samples_.size()); }
  int num_rows() const { return 2 * num_bands() + std::max<int>(0, static_cast<int>(d_.phi_grid.size()) - 1); }
  void Update(const double* x) {
    sens_.Evaluate(x);
    evaluated_ = true;
  }
  const LiftedData& d_;
  const ParamBox& box_;
  const BandNlpRequest& req_;
  const std::vector<int>& samples_;
  Sensitivities sens_;
  int n_;
  bool evaluated_ = false;
};

// One Ipopt solve on the band rows of `samples`.
BandNlpResult SolveOnSamples(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request,
                             const std::vector<int>& samples) {
  Ipopt::SmartPtr<BandNlp> nlp = new BandNlp(data, box, request, samples);
  sdp::UseSingleThreadedBlas();  // MUMPS under Ipopt would otherwise start (and spin) one BLAS thread per core
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  auto opts = app->Options();
  opts->SetIntegerValue("print_level", 0);
  opts->SetStringValue("sb", "yes");
  // A stalled search is accepted after a few steps at 1e-5, and a search is cut after 200 iterations: near the
  // stability boundary of the linear block (weakly identified a_i) Ipopt crawls in its restoration phase, having
  // made nearly all its progress in the first few dozen steps. The point's feasibility, which is what counts,
  // is re-checked anyway.
  opts->SetIntegerValue("max_iter", 200);
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

// Band margins min(z_t - lo_t, hi_t - z_t) of every sample at (theta, initial state).
std::vector<double> Margins(const LiftedData& data, const std::vector<double>& theta,
                            const std::vector<double>& initial) {
  const ModelParameters m = DecodeTheta(data, theta);
  const BandEnds bands = ComputeBandEnds(data, m);
  const std::vector<double> z = SimulateOutput(data, m, InputSignal(data, m), initial);
  std::vector<double> margin(z.size());
  for (std::size_t t = 0; t < z.size(); ++t)
    margin[t] = std::isfinite(z[t]) ? std::min(z[t] - bands.lo[t], bands.hi[t] - z[t]) : -kIpoptInf;
  return margin;
}

// The `count` samples outside `taken` with the smallest margins below `threshold`, smallest first.
std::vector<int> TightestSamples(const std::vector<double>& margin, const std::vector<bool>& taken, double threshold,
                                 std::size_t count) {
  std::vector<int> tight;
  for (std::size_t t = 0; t < margin.size(); ++t)
    if (!taken[t] && margin[t] < threshold) tight.push_back(static_cast<int>(t));
  const std::size_t keep = std::min(count, tight.size());
  std::partial_sort(tight.begin(), tight.begin() + keep, tight.end(),
                    [&](int a, int b) { return margin[a] < margin[b] || (margin[a] == margin[b] && a < b); });
  tight.resize(keep);
  return tight;
}

}  // namespace

// Constraint generation: the NLP starts on the samples whose bands are tightest at the start, and the samples
// a solution leaves (margin below half the requested one) join the working set until it leaves none. Most
// bands are far from active, so each solve sees a few hundred rows whatever N is.
BandNlpResult SolveBandNlp(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request) {
  const int N = data.num_samples;
  const std::size_t batch = static_cast<std::size_t>(std::max(100, N / 50));
  std::vector<bool> taken(N, false);
  std::vector<int> samples;
  auto take = [&](const std::vector<int>& more) {
    for (int t : more) taken[t] = true;
    samples.insert(samples.end(), more.begin(), more.end());
    std::sort(samples.begin(), samples.end());
  };
  take(TightestSamples(Margins(data, request.theta, request.initial_state), taken, kIpoptInf, batch));
  BandNlpRequest current = request;
  const auto clock_start = std::chrono::steady_clock::now();
  for (int round = 0;; ++round) {
    BandNlpResult result = SolveOnSamples(data, box, current, samples);
    result.rounds = round + 1;
    result.working_samples = static_cast<int>(samples.size());
    if (!result.returned || static_cast<int>(samples.size()) == N) return result;
    const std::vector<int> left = TightestSamples(Margins(data, result.theta, result.initial_state), taken,
                                                  0.5 * request.margin, 2 * batch);
    const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
    current.cpu_seconds = request.cpu_seconds - spent;
    if (left.empty() || current.cpu_seconds <= 0) return result;
    take(left);
    current.theta = result.theta;
    current.initial_state = result.initial_state;
  }
}

}  // namespace hw::exact
