#include "dss/bound_jobs.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "dss/inner_points.hpp"
#include "dss/row_reduction.hpp"
#include "pop/constraint_generation.hpp"
#include "pop/moment_lp.hpp"

namespace hw::dss {
namespace fs = std::filesystem;
namespace {

uint64_t fnv(uint64_t h, const std::string& s) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string other_solver(const std::string& s) { return s == "csdp" ? "sdpa" : "csdp"; }

// The run directory's record of the jobs dispatched so far (RunCache::plan).
constexpr const char* kPlanFile = "planned.json";

// The job keys in a plan file, or nothing when it is missing or damaged (then its count is not trusted).
std::optional<std::set<std::string>> ReadPlannedJobs(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return std::nullopt;
  try {
    nlohmann::json j;
    in >> j;
    return j.at("planned_jobs").get<std::set<std::string>>();
  } catch (...) {
    return std::nullopt;
  }
}

}  // namespace

nlohmann::json JobOutcome::to_json() const {
  return {{"status", status}, {"bound", bound}, {"tight", tight}, {"message", message}, {"rounds", rounds},
          {"sdp_iterations", sdp_iterations}, {"seconds", seconds}, {"moments", moments}, {"blocks", blocks},
          {"working_set", working_set}, {"active_set", active_set}, {"verification", verification}, {"float_bound", float_bound},
          {"correction", correction}, {"verify_seconds", verify_seconds}, {"origin", origin},
          {"bound_round", bound_round}, {"unfinished", unfinished},
          {"beyond_known_value", beyond_known_value}, {"first_moments", first_moments}};
}

JobOutcome JobOutcome::from_json(const nlohmann::json& j) {
  JobOutcome o;
  o.status = j.at("status");
  o.bound = j.at("bound");
  o.tight = j.at("tight");
  o.message = j.at("message");
  o.rounds = j.at("rounds");
  o.sdp_iterations = j.at("sdp_iterations");
  o.seconds = j.at("seconds");
  o.moments = j.at("moments");
  o.blocks = j.at("blocks");
  o.working_set = j.at("working_set").get<std::vector<int>>();
  if (j.contains("active_set")) o.active_set = j.at("active_set").get<std::vector<int>>();
  o.verification = j.at("verification");
  o.float_bound = j.at("float_bound");
  o.correction = j.at("correction");
  o.verify_seconds = j.at("verify_seconds");
  o.origin = j.at("origin");
  o.bound_round = j.at("bound_round");
  o.unfinished = j.at("unfinished");
  o.beyond_known_value = j.value("beyond_known_value", false);
  if (j.contains("first_moments")) o.first_moments = j.at("first_moments").get<std::vector<double>>();
  return o;
}

RunCache::RunCache(const std::string& root, const std::string& key, const nlohmann::json& meta) {
  if (root.empty()) return;
  const fs::path dir = fs::path(root) / key;
  fs::create_directories(dir / "jobs");
  if (!fs::exists(dir / "problem.json")) write_text_atomic((dir / "problem.json").string(), meta.dump(2));
  dir_ = dir.string();
  if (auto keys = ReadPlannedJobs(dir / kPlanFile)) {
    planned_ = std::move(*keys);
    planned_by_earlier_runs_ = planned_.size();
    earlier_plan_known_ = true;
  }
}

std::optional<nlohmann::json> RunCache::load(const std::string& name) const {
  if (!enabled()) return std::nullopt;
  std::ifstream in(fs::path(dir_) / "jobs" / (name + ".json"));
  if (!in) return std::nullopt;
  try {
    nlohmann::json j;
    in >> j;
    return j;
  } catch (...) {
    return std::nullopt;
  }
}

void RunCache::store(const std::string& name, const nlohmann::json& j) const {
  if (enabled()) write_text_atomic((fs::path(dir_) / "jobs" / (name + ".json")).string(), j.dump());
}

int RunCache::stored_jobs() const {
  if (!enabled()) return 0;
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(dir_) / "jobs"))
    if (e.path().extension() == ".json") ++n;
  return n;
}

void RunCache::plan(const std::vector<std::string>& names) const {
  if (!enabled()) return;
  const std::size_t before = planned_.size();
  planned_.insert(names.begin(), names.end());
  if (planned_.size() != before || !fs::exists(fs::path(dir_) / kPlanFile))
    write_text_atomic((fs::path(dir_) / kPlanFile).string(), nlohmann::json{{"planned_jobs", planned_}}.dump());
}

std::optional<std::string> RunCache::resume_line() const {
  const int stored = stored_jobs();
  if (stored == 0) return std::nullopt;
  constexpr const char* kRest = "each phase counts only the jobs still to run";
  if (!earlier_plan_known_)  // a directory written before planned.json existed, or a damaged plan
    return fmt::format("resuming: {} finished jobs from {} (the earlier run's plan is not recorded); {}", stored,
                       dir_, kRest);
  std::size_t finished = 0;
  for (const auto& name : planned_) finished += load(name).has_value() ? 1 : 0;
  return fmt::format("resuming: {} of {} jobs planned so far are finished, from {}; later phases may plan more, and {}",
                     finished, planned_by_earlier_runs_, dir_, kRest);
}

ProgressReporter::ProgressReporter(std::function<void(const BoundsProgress&)> sink) : sink_(std::move(sink)) {}

void ProgressReporter::Phase(const std::string& name, int total) {
  phase_ = name;
  done_ = 0;
  total_ = total;
  from_cache_ = uncounted_ = 0;
  phase_start_ = now_seconds();
  if (sink_ && total > 0) sink_({phase_, 0, total_, 0, 0.0, 0.0});
}

void ProgressReporter::FromCache(int jobs) {
  if (jobs <= 0) return;
  total_ = std::max(0, total_ - jobs);
  from_cache_ += jobs;
  uncounted_ += jobs;
  if (sink_) sink_({phase_, done_, total_, from_cache_, now_seconds() - phase_start_, 0.0});
}

void ProgressReporter::Done(int jobs) {
  const int skip = std::min(jobs, uncounted_);
  uncounted_ -= skip;
  jobs -= skip;
  if (jobs <= 0) return;
  done_ += jobs;
  if (!sink_) return;
  const double el = now_seconds() - phase_start_;
  sink_({phase_, done_, total_, from_cache_, el, done_ > 0 ? el / done_ * (total_ - done_) : 0.0});
}

void ProgressReporter::Message(const std::string& text) {
  if (sink_) sink_({text, -1, -1, 0, 0.0, 0.0});
}

std::string BoxHash(const Box& box) { return TextHash(nlohmann::json(box).dump()); }

std::string TextHash(const std::string& text) { return fmt::format("{:016x}", fnv(1469598103934665603ull, text)); }

pop::PolyProblem OrthantObjectiveCore(const HwOuterSet& set, int l, const Objective& objective) {
  pop::PolyProblem core;
  core.num_vars = set.num_vars();
  core.objective = Polynomial::Variable(set.num_vars(), objective.param);
  core.maximize = objective.dir > 0;
  core.inequalities = set.box_constraints();
  for (auto& g : set.sign_constraints(l)) core.inequalities.push_back(std::move(g));
  return core;
}

sdp::JobFunction MakeJobFunction(const BoundsOptions& options, const HwOuterSet& prior_set) {
  // Per-process memo of the outer set in each box and of each orthant's data rows (built once, read-only after).
  struct Memo {
    std::mutex mutex;
    std::map<std::string, std::unique_ptr<HwOuterSet>> sets;
    std::map<std::pair<std::string, int>, std::vector<DataConstraint>> rows;
  };
  auto memo = std::make_shared<Memo>();
  auto set_for = [memo, &prior_set](const Box& b) -> const HwOuterSet& {
    if (b == prior_set.box()) return prior_set;
    std::lock_guard<std::mutex> lock(memo->mutex);
    auto& slot = memo->sets[BoxHash(b)];
    if (!slot) slot = std::make_unique<HwOuterSet>(prior_set.WithBox(b));
    return *slot;
  };
  auto rows_for = [memo, set_for](const Box& b, int l) -> const std::vector<DataConstraint>& {
    const HwOuterSet& s = set_for(b);
    std::lock_guard<std::mutex> lock(memo->mutex);
    auto& r = memo->rows[{BoxHash(b), l}];
    if (r.empty()) r = s.data_constraints(l);
    return r;
  };

  return [&options, &prior_set, set_for, rows_for](const std::string& text) -> std::string {
    const auto spec = nlohmann::json::parse(text);
    const int l = spec.at("l");
    const std::string kind = spec.at("kind");
    const int n = prior_set.num_vars();
    const auto& gen_options = options.generation;
    if (kind == "lp") {
      std::vector<Polynomial> cons = prior_set.sign_constraints(l);
      for (const auto& d : rows_for(prior_set.box(), l)) cons.push_back(d.g);
      // An LP: DSDP's LP cone is not used for the screen (its certificates are checked on CSDP's and SDPA's form).
      const std::string backend = SolverForOrder(options.solver, 1);
      auto solver = sdp::MakeSolver(backend == "dsdp" ? "csdp" : backend);
      sdp::SdpOptions lp_options = gen_options.sdp;
      lp_options.keep_dual_matrix = false;
      sdp::VerifiedBound cert;
      const auto s = pop::ScreenWithLinearProgram(cons, n, lp_options, *solver, gen_options.verify.enabled ? &cert : nullptr);
      return nlohmann::json{{"empty", s.status == sdp::SdpStatus::kInfeasible}, {"status", sdp::ToString(s.status)},
                            {"verification", sdp::ToString(cert.status)}}
          .dump();
    }
    if (kind == "witness") {
      // Local extreme of one objective from the given starts in turn, until a start gives a feasible point.
      const std::vector<int> rows = spec.at("rows").get<std::vector<int>>();
      const int param = spec.at("param"), dir = spec.at("dir");
      nlohmann::json answer{{"found", false}, {"solves", 0}};
      for (const auto& start : spec.at("starts")) {
        const auto w = LocalExtreme(prior_set, l, param, dir, start.get<std::vector<double>>(), options.edge_witness.local,
                                    &rows);
        answer["solves"] = answer["solves"].get<int>() + 1;
        if (w.found) {
          answer["found"] = true;
          answer["point"] = w.point;
          break;
        }
      }
      return answer.dump();
    }
    const Box box = spec.at("box").get<Box>();
    const HwOuterSet& set = set_for(box);
    const auto& all_rows = rows_for(box, l);
    if (kind == "reduce") {
      // Rows never combine across horizon steps, so each step may be a job of its own ("step"; 0 = all).
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
      const auto r = ReduceDataRows(options.reduction, rows, steps, fixed);
      std::vector<int> kept;  // indices into all_rows
      for (int k : r.kept) kept.push_back(index[k]);
      nlohmann::json counts = nlohmann::json::array();
      for (const auto& c : r.per_step)
        counts.push_back(
            {{"step", c.step}, {"rows", c.rows}, {"kept", c.kept}, {"iteration_limited", c.iteration_limited}});
      return nlohmann::json{{"kept", kept}, {"per_step", counts}, {"linear_programs", r.linear_programs},
                            {"seconds", r.seconds}}
          .dump();
    }
    // kind == "relax"
    const Objective obj{spec.at("param").get<int>(), spec.at("dir").get<int>()};
    const pop::PolyProblem core = OrthantObjectiveCore(set, l, obj);
    std::vector<Polynomial> candidates;
    for (int i : spec.at("rows").get<std::vector<int>>()) candidates.push_back(all_rows.at(i).g);
    pop::ConstraintGenerationOptions gen = gen_options;
    gen.order = spec.at("d");
    if (spec.contains("max_rounds")) gen.max_rounds = spec.at("max_rounds");
    if (spec.contains("stop_beyond")) {  // original units -> this box's scaled units
      const auto& scaling = set.scaling();
      gen.stop_beyond = (spec.at("stop_beyond").get<double>() - scaling.center[obj.param]) / scaling.radius[obj.param];
    }
    const std::string backend = SolverForOrder(options.solver, gen.order, gen.block_order_cap);
    auto solver = sdp::MakeSolver(backend);
    auto other = sdp::MakeSolver(other_solver(backend));
    const std::string label = fmt::format("orthant {} {} {} order {}", l, obj.dir < 0 ? "min" : "max",
                                          set.layout().names[obj.param], gen.order);
    auto on_round = [&](const pop::GenerationRound& r) {
      if (!options.round_log) return;
      const std::string bound =
          std::isnan(r.bound) ? "none yet"
                              : fmt::format("{} {:.6g}{}", obj.dir < 0 ? ">=" : "<=",
                                            set.scaling().to_original(obj.param, r.bound),
                                            r.bound_verified ? " (verified)" : "");
      options.round_log(fmt::format("[{}] round {}: {} blocks{} + {} linear rows, {} ({:.1f} s), {} violated, bound {}",
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
    out.verification = sdp::ToString(r.verification.status);
    out.verify_seconds = r.verification.seconds;
    out.origin = ToString(r.origin);
    out.bound_round = r.bound_round;
    out.unfinished = r.bound_from_unfinished_solve;
    for (std::size_t i = 0; i < r.first_moments.size(); ++i)
      out.first_moments.push_back(set.scaling().to_original(static_cast<int>(i), r.first_moments[i]));
    if (r.status == pop::RelaxationStatus::kInfeasible) {
      out.status = "infeasible";
    } else if (r.status == pop::RelaxationStatus::kSolved) {
      out.status = "solved";
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
      out.status = "failed";
    }
    return out.to_json().dump();
  };
}

void DispatchJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                  const std::function<void(std::size_t, const nlohmann::json&, bool)>& on_done) {
  std::vector<std::string> specs;
  std::vector<std::size_t> spec_job;
  std::vector<std::pair<std::size_t, nlohmann::json>> cached;
  std::vector<std::string> keys;
  for (const auto& job : jobs) keys.push_back(job.second);
  ctx.cache.plan(keys);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (auto j = ctx.cache.load(jobs[i].second)) {
      cached.push_back({i, std::move(*j)});
      continue;
    }
    specs.push_back(jobs[i].first);
    spec_job.push_back(i);
  }
  ctx.counters.jobs_from_cache += static_cast<int>(cached.size());
  ctx.progress.FromCache(static_cast<int>(cached.size()));
  for (const auto& [i, j] : cached) on_done(i, j, true);
  ctx.executor.Map(specs, ctx.job, [&](std::size_t s, const sdp::JobResult& r) {
    const std::size_t i = spec_job[s];
    if (!r.ok) {  // a crashed or throwing job: reported by the caller, never dropped, not cached
      on_done(i, nlohmann::json{{"job_error", r.error}}, false);
      return;
    }
    auto j = nlohmann::json::parse(r.text);
    ctx.cache.store(jobs[i].second, j);
    on_done(i, j, false);
  });
}

std::vector<int> RowsOfWorkingSet(const OrthantWork& orthant, const std::vector<int>& working_set) {
  std::vector<int> rows;
  for (int i : working_set) rows.push_back(orthant.rows.at(i));
  return rows;
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
      outs[i].status = "infeasible";
      outs[i].message = "orthant already proven empty (" + o.status + ")";
      ctx.progress.Done();
      continue;
    }
    // Data rows enter the spec as orthant row indices; the initial blocks as positions among them.
    nlohmann::json spec{{"kind", "relax"}, {"l", o.index}, {"param", job.objective.param}, {"dir", job.objective.dir},
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
      out.status = "failed";
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
    if (out.status == "infeasible") {
      OrthantWork& o = orthants.at(static_cast<std::size_t>(&*jobs[i].orthant - orthants.data()));
      if (!o.empty())
        o.ProveEmpty({"relaxation", jobs[i].order, o.box != ctx.set.box(), out.verification == "verified"});
    }
    ctx.progress.Done();
  });
  return outs;
}

}  // namespace hw::dss
