#include "dss/relax_job.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "pop/constraint_generation.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::dss {
namespace {

std::string other_solver(const std::string& s) { return s == "csdp" ? "sdpa" : "csdp"; }

// A constraint-generation round's origin as a job's.
JobOrigin OriginOf(pop::BoundOrigin origin) {
  switch (origin) {
    case pop::BoundOrigin::kNone: return JobOrigin::kNone;
    case pop::BoundOrigin::kFinalRound: return JobOrigin::kFinalRound;
    case pop::BoundOrigin::kEarlierRound: return JobOrigin::kEarlierRound;
  }
  return JobOrigin::kNone;
}

}  // namespace

pop::PolyProblem OrthantObjectiveCore(const HwOuterSet& set, int l, const Objective& objective) {
  pop::PolyProblem core;
  core.num_vars = set.num_vars();
  core.objective = Polynomial::Variable(set.num_vars(), objective.param);
  core.maximize = objective.dir > 0;
  core.inequalities = set.box_constraints();
  for (auto& g : set.sign_constraints(l)) core.inequalities.push_back(std::move(g));
  return core;
}

nlohmann::json AnswerRelaxJob(const JobContext& job, const nlohmann::json& spec) {
  const EngineSettings& settings = job.settings();
  const int l = spec.at("l");
  const ParameterBox box = spec.at("box").get<ParameterBox>();
  const HwOuterSet& set = job.set_in(box);
  const auto& all_rows = job.rows_in(box, l);
  const Objective obj{spec.at("param").get<int>(), spec.at("dir").get<int>()};
  const pop::PolyProblem core = OrthantObjectiveCore(set, l, obj);
  std::vector<Polynomial> candidates;
  for (int i : spec.at("rows").get<std::vector<int>>()) candidates.push_back(all_rows.at(i).g);
  pop::ConstraintGenerationOptions gen = settings.generation;
  gen.order = spec.at("d");
  if (spec.contains("max_rounds")) gen.max_rounds = spec.at("max_rounds");
  if (spec.contains("stop_beyond")) {  // original units -> this box's scaled units
    const auto& scaling = set.scaling();
    gen.stop_beyond = (spec.at("stop_beyond").get<double>() - scaling.center[obj.param]) / scaling.radius[obj.param];
  }
  const std::string& backend = settings.backend(gen.order);
  auto solver = sdp::MakeSolver(backend);
  auto other = sdp::MakeSolver(other_solver(backend));
  const std::string label = fmt::format("orthant {} {} {} order {}", l, obj.dir < 0 ? "min" : "max",
                                        set.layout().names[obj.param], gen.order);
  auto on_round = [&](const pop::GenerationRound& r) {
    if (!settings.round_log) return;
    const std::string bound =
        std::isnan(r.bound) ? "none yet"
                            : fmt::format("{} {:.6g}{}", obj.dir < 0 ? ">=" : "<=",
                                          set.scaling().to_original(obj.param, r.bound),
                                          r.bound_verified ? " (verified)" : "");
    settings.round_log(fmt::format("[{}] round {}: {} blocks{} + {} linear rows, {} ({:.1f} s), {} violated, bound {}",
                                  label, r.round, r.blocks,
                                  r.active < 0 ? std::string() : fmt::format(" ({} active)", r.active),
                                  r.linear_rows, r.status, r.seconds,
                                  r.violated < 0 ? std::string("-") : std::to_string(r.violated), bound));
  };
  const auto r = pop::SolveWithConstraintGeneration(gen, core, candidates, spec.at("initial").get<std::vector<int>>(),
                                                    *solver, on_round, other.get());
  JobOutcome out;
  out.rounds = r.rounds;
  out.sdp_iterations = r.sdp_iterations;
  out.seconds = r.solve_seconds;
  out.moments = r.num_moments;
  out.blocks = r.num_blocks;
  out.working_set = r.working_set;
  out.active_set = r.active_set;
  out.message = r.message;
  out.tight = r.tight;
  out.beyond_known_value = r.beyond_known_value;
  out.verification = r.verification.status;
  out.verify_seconds = r.verification.seconds;
  out.origin = OriginOf(r.origin);
  out.bound_round = r.bound_round;
  out.unfinished = r.bound_from_unfinished_solve;
  for (std::size_t i = 0; i < r.first_moments.size(); ++i)
    out.first_moments.push_back(set.scaling().to_original(static_cast<int>(i), r.first_moments[i]));
  if (r.status == pop::RelaxationStatus::kInfeasible) {
    out.status = JobStatus::kInfeasible;
  } else if (r.status == pop::RelaxationStatus::kSolved) {
    out.status = JobStatus::kSolved;
    out.float_bound = set.scaling().to_original(obj.param, r.float_bound);
    // Every parameter lies in the job's box (scaled [-1, 1]), so a bound weaker than its edge (the verified
    // bound of an unfinished iterate can be) is replaced by the edge: still valid.
    const double scaled = obj.dir < 0 ? std::max(r.bound, -1.0) : std::min(r.bound, 1.0);
    out.bound = set.scaling().to_original(obj.param, scaled);
    if (r.verification.verified()) {
      // The affine map back to original units rounds twice: widen outward by a few ulps of its terms.
      const auto [lo, hi] = set.box()[obj.param];
      out.bound += obj.dir * 4 * std::numeric_limits<double>::epsilon() * (std::max(std::abs(lo), std::abs(hi)) + (hi - lo));
      out.correction = std::abs(out.bound - out.float_bound);
    }
  } else {
    out.status = JobStatus::kFailed;
  }
  return out.to_json();
}

std::vector<JobOutcome> RunRelaxationJobs(EngineContext& ctx, const std::vector<RelaxJob>& jobs,
                                          std::vector<OrthantWork>& orthants) {
  std::vector<JobOutcome> outs(jobs.size());
  std::vector<std::pair<std::string, std::string>> specs;
  std::vector<std::size_t> spec_job;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const RelaxJob& job = jobs[i];
    const OrthantWork& o = *job.orthant;
    if (o.empty()) {  // proven empty by an earlier job of this stage
      outs[i].status = JobStatus::kInfeasible;
      outs[i].message = "orthant already proven empty (" + o.certificate->status() + ")";
      ctx.progress.Done();
      continue;
    }
    // Data rows enter the spec as orthant row indices; the initial blocks as positions among them.
    nlohmann::json spec{{"kind", kRelaxJob}, {"l", o.index}, {"param", job.objective.param}, {"dir", job.objective.dir},
                        {"d", job.order}, {"box", o.box}, {"rows", o.rows}, {"initial", job.initial}};
    std::string key = fmt::format("o{}_l{}_{}_{}", job.order, o.index, ctx.set.layout().names[job.objective.param],
                                  job.objective.dir < 0 ? "min" : "max");
    if (o.box != ctx.set.box()) key += "_b" + BoxHash(o.box);
    if (job.max_rounds > 0) {
      spec["max_rounds"] = job.max_rounds;
      key += fmt::format("_r{}", job.max_rounds);
    }
    if (std::isfinite(job.stop_beyond)) {
      spec["stop_beyond"] = job.stop_beyond;
      key += fmt::format("_s{:.17g}", job.stop_beyond);
    }
    specs.push_back({spec.dump(), key});
    spec_job.push_back(i);
  }
  DispatchJobs(ctx, specs, [&](std::size_t s, const nlohmann::json& answer, bool cached) {
    const std::size_t i = spec_job[s];
    JobOutcome& out = outs[i];
    if (answer.contains("job_error")) {
      out.status = JobStatus::kFailed;
      out.message = "job failed: " + answer.at("job_error").get<std::string>();
    } else {
      out = JobOutcome::from_json(answer);
    }
    if (!cached) {
      ++ctx.counters.sdp_jobs;
      ctx.counters.sdp_solves += out.rounds;
      ctx.counters.jobs_stopped_beyond_witness += out.beyond_known_value ? 1 : 0;
      ctx.counters.solve_seconds += out.seconds;
      ctx.counters.verify_seconds += out.verify_seconds;
      if (out.rounds) ctx.counters.solve_times.push_back(out.seconds / out.rounds);
    }
    ctx.counters.largest_moments = std::max(ctx.counters.largest_moments, out.moments);
    ctx.counters.largest_blocks = std::max(ctx.counters.largest_blocks, out.blocks);
    if (out.status == JobStatus::kInfeasible) {
      OrthantWork& o = orthants.at(static_cast<std::size_t>(&*jobs[i].orthant - orthants.data()));
      if (!o.empty())
        o.ProveEmpty({CertificateKind::kRelaxation, jobs[i].order, o.box != ctx.set.box(),
                      out.verification == sdp::VerifyStatus::kVerified});
    }
    if (out.status == JobStatus::kSolved)
      ctx.progress.Bound(ctx.set.layout().names[jobs[i].objective.param], jobs[i].objective.dir, out.bound);
    ctx.progress.Done();
  });
  return outs;
}

}  // namespace hw::dss
