#include "dss/row_reduction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include <glpk.h>
#include <fmt/format.h>

namespace hw::dss {
namespace {

int ceil_half(int d) { return (d + 1) / 2; }

struct GlpDeleter {
  void operator()(glp_prob* p) const { glp_delete_prob(p); }
};

// The LP of one group: columns = candidate generators (group rows, then fixed constraints, then the constant 1),
// rows = monomials of their joint support; a row g_i is implied iff  A lambda = c_i,  lambda >= 0  is feasible
// with g_i's own column (and the columns of rows already dropped) fixed at zero.
class CombinationLp {
 public:
  CombinationLp(const std::vector<const Polynomial*>& generators, int iteration_limit) : generators_(generators) {
    for (const Polynomial* g : generators)
      for (const auto& [e, c] : g->terms()) monomial_.emplace(e, 0);
    int r = 1;
    for (auto& [e, idx] : monomial_) idx = r++;
    lp_.reset(glp_create_prob());
    glp_set_obj_dir(lp_.get(), GLP_MIN);
    glp_add_rows(lp_.get(), static_cast<int>(monomial_.size()));
    glp_add_cols(lp_.get(), static_cast<int>(generators.size()));
    std::vector<int> ia{0}, ja{0};
    std::vector<double> ar{0.0};
    for (int j = 0; j < static_cast<int>(generators.size()); ++j) {
      glp_set_col_bnds(lp_.get(), j + 1, GLP_LO, 0.0, 0.0);
      for (const auto& [e, c] : generators[j]->terms()) {
        ia.push_back(monomial_.at(e));
        ja.push_back(j + 1);
        ar.push_back(c);
      }
    }
    for (int i = 1; i <= static_cast<int>(monomial_.size()); ++i) glp_set_row_bnds(lp_.get(), i, GLP_FX, 0.0, 0.0);
    glp_load_matrix(lp_.get(), static_cast<int>(ia.size()) - 1, ia.data(), ja.data(), ar.data());
    glp_std_basis(lp_.get());
    glp_init_smcp(&parm_);
    parm_.msg_lev = GLP_MSG_OFF;
    parm_.meth = GLP_PRIMAL;  // measured: the dual simplex is 50x slower on these zero-objective LPs
    parm_.presolve = GLP_OFF;
    parm_.it_lim = iteration_limit;
  }

  // LPs given up after the iteration limit (their rows are kept).
  int iteration_limited() const { return iteration_limited_; }
  // LPs that hit the limit from the warm basis and were solved again from the standard basis.
  int restarts_after_limit() const { return restarts_after_limit_; }

  // Is generator `j` a nonnegative combination of the other active generators? (one LP)
  bool Implied(int j, double residual_tolerance) {
    const Polynomial& g = *generators_[j];
    glp_set_col_bnds(lp_.get(), j + 1, GLP_FX, 0.0, 0.0);
    std::vector<double> rhs(monomial_.size() + 1, 0.0);
    for (const auto& [e, c] : g.terms()) rhs[monomial_.at(e)] = c;
    for (int i = 1; i <= static_cast<int>(monomial_.size()); ++i) glp_set_row_bnds(lp_.get(), i, GLP_FX, rhs[i], rhs[i]);
    int rc = glp_simplex(lp_.get(), &parm_);
    if (rc != 0) {  // the warm basis went bad (singular) or the simplex cycled: start again from the standard basis
      glp_std_basis(lp_.get());
      if (rc == GLP_EITLIM) ++restarts_after_limit_;
      rc = glp_simplex(lp_.get(), &parm_);
      if (rc == GLP_EITLIM) {
        ++iteration_limited_;
        glp_std_basis(lp_.get());  // the next row starts from a basis that has not cycled
      }
    }
    const bool feasible = rc == 0 && glp_get_prim_stat(lp_.get()) == GLP_FEAS;
    bool implied = feasible && ResidualOk(rhs, residual_tolerance);
    if (!implied) glp_set_col_bnds(lp_.get(), j + 1, GLP_LO, 0.0, 0.0);  // kept: it stays a generator
    return implied;
  }

 private:
  // Checks the combination in double precision against the row itself (the LP's own tolerances are relative).
  bool ResidualOk(const std::vector<double>& rhs, double tol) const {
    std::vector<double> r = rhs;
    for (int j = 0; j < static_cast<int>(generators_.size()); ++j) {
      // The simplex may leave a multiplier slightly below zero (within its bound tolerance): count it as zero,
      // and let the residual decide.
      const double lambda = std::max(0.0, glp_get_col_prim(lp_.get(), j + 1));
      if (lambda == 0) continue;
      for (const auto& [e, c] : generators_[j]->terms()) r[monomial_.at(e)] -= lambda * c;
    }
    double worst = 0.0;
    for (std::size_t i = 1; i < r.size(); ++i) worst = std::max(worst, std::abs(r[i]));
    return worst <= tol;
  }

  std::vector<const Polynomial*> generators_;
  std::map<Exponents, int> monomial_;
  std::unique_ptr<glp_prob, GlpDeleter> lp_;
  glp_smcp parm_;
  int iteration_limited_ = 0;
  int restarts_after_limit_ = 0;
};

}  // namespace

bool RowReductionOptions::IsValid(std::string* error) const {
  if (!(residual_tolerance > 0 && residual_tolerance < 1e-3)) {
    if (error) *error = "row reduction residual_tolerance must lie in (0, 1e-3)";
    return false;
  }
  if (simplex_iteration_limit < 1) {
    if (error) *error = "row reduction simplex_iteration_limit must be positive";
    return false;
  }
  return true;
}

RowReductionResult ReduceDataRows(const RowReductionOptions& options, const std::vector<Polynomial>& rows,
                                  const std::vector<int>& step, const std::vector<Polynomial>& fixed) {
  const auto t0 = std::chrono::steady_clock::now();
  RowReductionResult out;
  std::map<int, RowGroupCount> counts;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    counts[step[i]].step = step[i];
    ++counts[step[i]].rows;
  }
  // Groups: rows of one step with one localizing order (ceil(deg / 2)); only they combine with each other.
  std::map<std::pair<int, int>, std::vector<int>> groups;
  for (std::size_t i = 0; i < rows.size(); ++i)
    groups[{step[i], ceil_half(rows[i].degree())}].push_back(static_cast<int>(i));
  std::vector<char> keep(rows.size(), 1);
  if (options.enabled && !rows.empty()) {
    const Polynomial one = Polynomial::Constant(rows.front().num_vars(), 1.0);
    for (const auto& [key, members] : groups) {
      std::vector<const Polynomial*> generators;
      for (int i : members) generators.push_back(&rows[i]);
      for (const auto& f : fixed)
        if (ceil_half(f.degree()) <= key.second) generators.push_back(&f);
      generators.push_back(&one);
      CombinationLp lp(generators, options.simplex_iteration_limit);
      for (std::size_t k = 0; k < members.size(); ++k) {
        ++out.linear_programs;
        if (lp.Implied(static_cast<int>(k), options.residual_tolerance)) keep[members[k]] = 0;
      }
      counts[key.first].iteration_limited += lp.iteration_limited();
      out.restarts_after_limit += lp.restarts_after_limit();
    }
  }
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (keep[i]) {
      out.kept.push_back(static_cast<int>(i));
      ++counts[step[i]].kept;
    }
  for (const auto& [s, c] : counts) out.per_step.push_back(c);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace hw::dss

namespace hw::dss {

nlohmann::json AnswerReduceJob(const JobContext& job, const nlohmann::json& spec) {
  const int l = spec.at("l");
  const ParameterBox box = spec.at("box").get<ParameterBox>();
  const HwOuterSet& set = job.set_in(box);
  const auto& all_rows = job.rows_in(box, l);
  const int only_step = spec.value("step", 0);
  std::vector<Polynomial> rows;
  std::vector<int> steps, index;
  for (std::size_t i = 0; i < all_rows.size(); ++i) {
    if (only_step != 0 && all_rows[i].s != only_step) continue;
    rows.push_back(all_rows[i].g);
    steps.push_back(all_rows[i].s);
    index.push_back(static_cast<int>(i));
  }
  std::vector<Polynomial> fixed = set.box_constraints();
  for (auto& g : set.sign_constraints(l)) fixed.push_back(std::move(g));
  const auto r = ReduceDataRows(job.settings().reduction, rows, steps, fixed);
  std::vector<int> kept;  // indices into all_rows
  for (int k : r.kept) kept.push_back(index[k]);
  nlohmann::json counts = nlohmann::json::array();
  for (const auto& c : r.per_step)
    counts.push_back({{"step", c.step}, {"rows", c.rows}, {"kept", c.kept}, {"iteration_limited", c.iteration_limited}});
  return {{"kept", kept}, {"per_step", counts}, {"linear_programs", r.linear_programs}, {"seconds", r.seconds}};
}

void ReduceOrthantRows(EngineContext& ctx, std::vector<OrthantWork>& orthants) {
  // One job per (orthant, horizon step): rows of different steps never combine, so the result is the same as one
  // job per orthant, while the steps run in parallel and each finished step shows in the progress.
  struct StepJob {
    std::size_t orthant;
    int step;
  };
  std::vector<std::pair<std::string, std::string>> jobs;
  std::vector<StepJob> job_of;
  for (std::size_t k = 0; k < orthants.size(); ++k) {
    const OrthantWork& o = orthants[k];
    if (o.empty()) continue;
    for (int s = 1; s <= ctx.set.horizon(); ++s) {
      std::string key = fmt::format("reduce_l{}_s{}", o.index, s);
      if (o.box != ctx.set.box()) key += "_b" + BoxHash(o.box);
      if (!ctx.settings.reduction.enabled) key += "_off";
      jobs.push_back({nlohmann::json{{"kind", kReduceJob}, {"l", o.index}, {"box", o.box}, {"step", s}}.dump(), key});
      job_of.push_back({k, s});
    }
  }
  ctx.progress.Phase("exact reduction of data rows", static_cast<int>(jobs.size()));
  std::map<std::size_t, std::map<int, nlohmann::json>> answers;  // orthant -> step -> answer
  DispatchJobs(ctx, jobs, [&](std::size_t i, const nlohmann::json& answer, bool) {
    answers[job_of[i].orthant][job_of[i].step] = answer;
    ctx.progress.Done();
  });
  for (auto& [k, by_step] : answers) {
    OrthantWork& o = orthants[k];
    std::vector<int> kept;
    std::vector<nlohmann::json> per_step;
    bool failed = false;
    for (const auto& [s, answer] : by_step) {
      if (answer.contains("job_error")) {
        failed = true;
        per_step.push_back({{"step", s}, {"error", answer.at("job_error")}});
        continue;
      }
      for (int r : answer.at("kept").get<std::vector<int>>()) kept.push_back(r);
      for (const auto& c : answer.at("per_step")) per_step.push_back(c);
    }
    o.reduction = per_step;
    if (failed) continue;  // the reduction only saves work: an orthant with a failed step keeps every row
    std::sort(kept.begin(), kept.end());
    o.rows = kept;
  }
}

}  // namespace hw::dss
