#include "dss/inner_points.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "sdp/sdp_solver.hpp"

namespace hw::dss {
namespace {

// A polynomial as a flat term list for fast value/gradient evaluation from a table of powers.
struct FlatPolynomial {
  std::vector<double> coef;
  std::vector<std::vector<int>> exps;  // per term, exponent per variable
  explicit FlatPolynomial(const Polynomial& p) {
    for (const auto& [e, c] : p.terms()) {
      coef.push_back(c);
      exps.emplace_back(e.begin(), e.end());
    }
  }
  int degree() const {
    int d = 0;
    for (const auto& e : exps)
      for (int v : e) d = std::max(d, v);
    return d;
  }
  // pw[i * (D + 1) + e] = x_i^e.
  double value(const std::vector<double>& pw, int D, int n) const {
    double v = 0.0;
    for (std::size_t t = 0; t < coef.size(); ++t) {
      double m = coef[t];
      for (int i = 0; i < n; ++i) m *= pw[i * (D + 1) + exps[t][i]];
      v += m;
    }
    return v;
  }
  void gradient(const std::vector<double>& pw, int D, int n, double* g) const {
    std::fill(g, g + n, 0.0);
    for (std::size_t t = 0; t < coef.size(); ++t)
      for (int d = 0; d < n; ++d) {
        if (!exps[t][d]) continue;
        double m = coef[t] * exps[t][d];
        for (int i = 0; i < n; ++i) m *= pw[i * (D + 1) + exps[t][i] - (i == d ? 1 : 0)];
        g[d] += m;
      }
  }
};

std::vector<double> PowerTable(const double* x, int n, int D) {
  std::vector<double> pw(static_cast<std::size_t>(n) * (D + 1));
  for (int i = 0; i < n; ++i) {
    pw[i * (D + 1)] = 1.0;
    for (int e = 1; e <= D; ++e) pw[i * (D + 1) + e] = pw[i * (D + 1) + e - 1] * x[i];
  }
  return pw;
}

class ExtremeNlp : public Ipopt::TNLP {
 public:
  ExtremeNlp(std::vector<FlatPolynomial> cons, int n, int k, int dir, std::vector<double> start, double margin)
      : cons_(std::move(cons)), n_(n), k_(k), dir_(dir), start_(std::move(start)), margin_(margin) {
    for (const auto& c : cons_) D_ = std::max(D_, c.degree());
  }
  std::vector<double> solution;
  Ipopt::SolverReturn status = Ipopt::UNASSIGNED;

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = n_;
    m = static_cast<Ipopt::Index>(cons_.size());
    nnz_jac = n * m;
    nnz_h = 0;
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* xl, Ipopt::Number* xu, Ipopt::Index m, Ipopt::Number* gl,
                       Ipopt::Number* gu) override {
    for (int i = 0; i < n; ++i) xl[i] = -1.0, xu[i] = 1.0;  // the prior box, scaled
    for (int j = 0; j < m; ++j) gl[j] = margin_, gu[j] = 2e19;
    return true;
  }
  bool get_starting_point(Ipopt::Index n, bool, Ipopt::Number* x, bool, Ipopt::Number*, Ipopt::Number*,
                          Ipopt::Index, bool, Ipopt::Number*) override {
    for (int i = 0; i < n; ++i) x[i] = std::clamp(start_[i], -1.0, 1.0);
    return true;
  }
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    f = dir_ * -x[k_];  // Ipopt minimises: min x_k or min -x_k
    return true;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number*, bool, Ipopt::Number* g) override {
    std::fill(g, g + n, 0.0);
    g[k_] = -dir_;
    return true;
  }
  bool eval_g(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Index m, Ipopt::Number* g) override {
    const auto pw = PowerTable(x, n, D_);
    for (int j = 0; j < m; ++j) g[j] = cons_[j].value(pw, D_, n);
    return true;
  }
  bool eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Index m, Ipopt::Index, Ipopt::Index* rows,
                  Ipopt::Index* cols, Ipopt::Number* values) override {
    if (!values) {
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < n; ++i) rows[j * n + i] = j, cols[j * n + i] = i;
      return true;
    }
    const auto pw = PowerTable(x, n, D_);
    for (int j = 0; j < m; ++j) cons_[j].gradient(pw, D_, n, values + j * n);
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn s, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    status = s;
    solution.assign(x, x + n);
  }

 private:
  std::vector<FlatPolynomial> cons_;
  int n_, k_, dir_, D_ = 0;
  std::vector<double> start_;
  double margin_;
};

}  // namespace

bool InnerPointOptions::IsValid(std::string* error) const {
  if (max_iterations < 1) return *error = "max_iterations must be >= 1", false;
  if (!(margin >= 0)) return *error = "margin must be >= 0", false;
  return true;
}

std::vector<std::vector<double>> PseudoRandomPointsInBox(const std::vector<std::pair<double, double>>& box,
                                                         int count, uint64_t seed) {
  std::vector<std::vector<double>> points;
  std::uint64_t state = 0x9E3779B97F4A7C15ull ^ seed;
  for (int s = 0; s < count; ++s) {
    std::vector<double> p;
    for (const auto& [lo, hi] : box) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      const double r = static_cast<double>(state >> 11) * 0x1.0p-53;
      p.push_back(lo + r * (hi - lo));
    }
    points.push_back(std::move(p));
  }
  return points;
}

InnerWitness LocalExtreme(const HwOuterSet& set, int l, int k, int dir, const std::vector<double>& start,
                          const InnerPointOptions& options, const std::vector<int>* rows) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("inner point options: " + error);
  const int n = set.num_vars();
  std::vector<FlatPolynomial> cons;
  for (const auto& g : set.sign_constraints(l)) cons.emplace_back(g);
  const auto data = set.data_constraints(l);
  if (rows) {
    for (int r : *rows) cons.emplace_back(data.at(r).g);
  } else {
    for (const auto& c : data) cons.emplace_back(c.g);
  }
  std::vector<double> x0(n);
  for (int i = 0; i < n; ++i) x0[i] = (start[i] - set.scaling().center[i]) / set.scaling().radius[i];
  Ipopt::SmartPtr<ExtremeNlp> nlp = new ExtremeNlp(std::move(cons), n, k, dir, x0, options.margin);
  sdp::UseSingleThreadedBlas();  // MUMPS under Ipopt would otherwise start (and spin) one BLAS thread per core
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetStringValue("hessian_approximation", "limited-memory");
  app->Options()->SetIntegerValue("max_iter", options.max_iterations);
  app->Options()->SetNumericValue("tol", 1e-9);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-10);
  InnerWitness w;
  w.orthant = l;
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    w.message = "Ipopt failed to initialise";
    return w;
  }
  const auto status = app->OptimizeTNLP(nlp);
  w.message = fmt::format("Ipopt status {}", static_cast<int>(status));
  if (nlp->solution.empty()) return w;
  w.point.resize(n);
  for (int i = 0; i < n; ++i) w.point[i] = set.scaling().to_original(i, nlp->solution[i]);
  w.value = w.point[k];
  // The witness is what plain evaluation says, whatever Ipopt reported.
  if (set.orthant_of(w.point) != l) {
    w.message += "; point left the orthant";
    return w;
  }
  w.min_slack = set.min_slack(w.point);
  w.found = w.min_slack >= 0.0;
  if (!w.found) w.message += fmt::format("; min slack {:.3g} < 0", w.min_slack);
  return w;
}

}  // namespace hw::dss
