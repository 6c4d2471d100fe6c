#include "relax/set_membership.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "sdp/job_executor.hpp"

namespace hw::relax {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// One objective: min (dir = -1) or max (dir = +1) of parameter k.
struct Objective {
  int param;
  int dir;
};

struct JobOutcome {
  std::string status;  // "solved", "infeasible", "failed"
  double bound = 0.0;  // in original units
  bool tight = false;
  std::string message;
  int rounds = 0;
  int sdp_iterations = 0;
  double seconds = 0.0;
  std::size_t moments = 0, blocks = 0;
  std::vector<int> working_set;
  // Verification (sdp/verified_bound.hpp) of the bound or of the emptiness certificate: "off", "verified",
  // "unverified"; bound is the verified value when verified, float_bound the solver's; both original units.
  std::string verification = "off";
  double float_bound = 0.0, correction = 0.0, verify_seconds = 0.0;
  nlohmann::json to_json() const {
    return {{"status", status}, {"bound", bound}, {"tight", tight}, {"message", message}, {"rounds", rounds},
            {"sdp_iterations", sdp_iterations}, {"seconds", seconds}, {"moments", moments}, {"blocks", blocks},
            {"working_set", working_set}, {"verification", verification}, {"float_bound", float_bound},
            {"correction", correction}, {"verify_seconds", verify_seconds}};
  }
  static JobOutcome from_json(const nlohmann::json& j) {
    JobOutcome o;
    o.status = j.at("status");
    o.bound = j.at("bound");
    o.tight = j.at("tight");
    o.message = j.at("message");
    o.rounds = j.at("rounds");
    o.sdp_iterations = j.value("sdp_iterations", 0);
    o.seconds = j.at("seconds");
    o.moments = j.at("moments");
    o.blocks = j.at("blocks");
    o.working_set = j.at("working_set").get<std::vector<int>>();
    o.verification = j.value("verification", std::string("off"));
    o.float_bound = j.value("float_bound", o.bound);
    o.correction = j.value("correction", 0.0);
    o.verify_seconds = j.value("verify_seconds", 0.0);
    return o;
  }
};

uint64_t fnv(uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// Cache of finished jobs and per-orthant working sets in run_dir/<problem hash>/.
class RunCache {
 public:
  RunCache(const std::string& root, const std::string& key, const nlohmann::json& meta) {
    if (root.empty()) return;
    dir_ = fs::path(root) / key;
    fs::create_directories(dir_ / "jobs");
    if (!fs::exists(dir_ / "problem.json")) write_text_atomic((dir_ / "problem.json").string(), meta.dump(2));
  }
  bool enabled() const { return !dir_.empty(); }
  std::string path() const { return dir_.string(); }
  std::optional<nlohmann::json> load(const std::string& name) const {
    if (!enabled()) return std::nullopt;
    std::ifstream in(dir_ / "jobs" / (name + ".json"));
    if (!in) return std::nullopt;
    try {
      nlohmann::json j;
      in >> j;
      return j;
    } catch (...) {
      return std::nullopt;  // a damaged file is recomputed, never trusted
    }
  }
  void store(const std::string& name, const nlohmann::json& j) const {
    if (enabled()) write_text_atomic((dir_ / "jobs" / (name + ".json")).string(), j.dump());
  }

 private:
  fs::path dir_;
};

std::string sign_text(const HwOuterSet& set, int l) {
  std::string s;
  const auto signs = set.orthant_signs(l);
  for (std::size_t k = 0; k < signs.size(); ++k)
    s += fmt::format("{}{}{}", k ? " " : "", set.sign_names()[k], signs[k] > 0 ? "+" : "-");
  return s;
}

}  // namespace

bool BoundsOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (order < 1) return fail("order must be >= 1");
  if (threads < 0) return fail("threads must be >= 0");
  if (contraction_passes < 0) return fail("contraction_passes must be >= 0");
  if (contraction_max_rounds < 1) return fail("contraction_max_rounds must be >= 1");
  if (!(contraction_min_shrink >= 0 && contraction_min_shrink < 1)) return fail("contraction_min_shrink must lie in [0, 1)");
  if (solver != "csdp" && solver != "sdpa" && solver != "dsdp") return fail(fmt::format("solver '{}' unknown; expected csdp, sdpa or dsdp", solver));
  ConstraintGenerationOptions g = generation;
  return g.IsValid(error);
}

bool BoundsSummary::all_guaranteed() const {
  for (const auto& iv : intervals)
    for (const Endpoint* e : {&iv.lower, &iv.upper})
      // A floating-point bound that verification could not prove is not called guaranteed.
      if (e->status != "guaranteed" || e->verification == "unverified") return false;
  return true;
}

nlohmann::json BoundsSummary::to_json() const {
  nlohmann::json j;
  j["order"] = order;
  j["horizon"] = horizon;
  j["solver"] = solver;
  j["executor"] = executor;
  nlohmann::json box_j = nlohmann::json::array();
  for (std::size_t i = 0; i < box.size(); ++i)
    box_j.push_back({{"parameter", parameter_names[i]}, {"lo", box[i].first}, {"hi", box[i].second}});
  j["prior_box"] = box_j;
  j["prior_box_note"] = "intervals are guaranteed for parameters inside this box (a prior assumption)";
  auto ep = [](const Endpoint& e) {
    return nlohmann::json{{"value", e.value}, {"status", e.status}, {"note", e.note}, {"orthant", e.orthant},
                          {"tight", e.tight}, {"verification", e.verification}, {"correction", e.correction}};
  };
  for (const auto& iv : intervals)
    j["intervals"].push_back({{"parameter", iv.name}, {"lower", ep(iv.lower)}, {"upper", ep(iv.upper)},
                              {"half_width", iv.half_width()}});
  for (const auto& o : orthants) j["orthants"].push_back({{"index", o.index}, {"signs", o.signs}, {"status", o.status}});
  j["counts"] = {{"orthants_total", orthants_total}, {"orthants_proven_empty", orthants_empty},
                 {"orthants_solved", orthants_solved}, {"orthants_failed", orthants_failed},
                 {"sdp_jobs", sdp_jobs}, {"sdp_solves", sdp_solves}, {"jobs_from_cache", jobs_from_cache}};
  j["timing"] = {{"wall_seconds", wall_seconds}, {"median_solve_seconds", median_solve_seconds},
                 {"solve_seconds", solve_seconds}, {"verify_seconds", verify_seconds}};
  j["largest_sdp"] = {{"moments", largest_moments}, {"blocks", largest_blocks}};
  j["all_guaranteed"] = all_guaranteed();
  j["contraction_passes_run"] = contraction_passes_run;
  for (const auto& [l, b] : orthant_boxes) {
    nlohmann::json bj = nlohmann::json::array();
    for (std::size_t i = 0; i < b.size(); ++i)
      bj.push_back({{"parameter", parameter_names[i]}, {"lo", b[i].first}, {"hi", b[i].second}});
    j["contracted_boxes"].push_back({{"orthant", l}, {"box", bj}});
  }
  return j;
}

BoundsSummary ComputeBounds(const BoundsOptions& options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("bounds options: " + error);
  // In scaled coordinates every feasible moment vector has |y_alpha| <= 1 (the box localizers bound the even
  // moments by 1 and the moment matrix bounds the rest; the LP screen states |y| <= 1 explicitly), so a
  // multiplier X >= 0 with sum_i |F_i . X| < F_0 . X already proves emptiness; 0.5 leaves a margin.
  BoundsOptions opts = options;
  opts.generation.sdp.infeasibility_tolerance = std::max(opts.generation.sdp.infeasibility_tolerance, 0.5);
  // Endpoints come from the dual side, whose validity needs dual feasibility, not a small gap: accept
  // near-optimal stops up to 1e-5 (the gap costs at most that much tightness on the scaled parameters).
  opts.generation.sdp.acceptable_gap = std::max(opts.generation.sdp.acceptable_gap, 1e-5);
  // The engine's own fallbacks (the other backend, then the last solved round) follow a failed round, so a
  // second SDPA attempt with other parameters would only add a full solve to each failing round.
  opts.generation.sdp.retry_with_default_parameters = false;
  const auto t0 = Clock::now();
  const int n = set.num_vars();
  const int L = set.num_orthants();
  const std::shared_ptr<sdp::JobExecutor> executor =
      options.executor ? options.executor : std::make_shared<sdp::ForkExecutor>(options.threads);
  // Minimal order from the constraint degrees: Remark 3, ceil((n + 1) / 2), and >= 1 for the box.
  const int min_order = std::max(1, (set.horizon() + 2) / 2);
  if (options.order < min_order)
    throw InputError(fmt::format("order {} is below the minimal order {} for horizon {}", options.order, min_order,
                                 set.horizon()));

  // Objectives: min and max of every wanted parameter.
  std::vector<int> wanted;
  for (int k = 0; k < n; ++k)
    if (options.parameters.empty() ||
        std::find(options.parameters.begin(), options.parameters.end(), set.layout().names[k]) != options.parameters.end())
      wanted.push_back(k);
  for (const auto& name : options.parameters)
    if (std::find(set.layout().names.begin(), set.layout().names.end(), name) == set.layout().names.end()) {
      std::string all;
      for (const auto& nm : set.layout().names) all += (all.empty() ? "" : ", ") + nm;
      throw InputError(fmt::format("no parameter '{}'; the parameters are: {}", name, all));
    }
  // Box contraction needs the bounds of every parameter; only the wanted ones are reported and go to full order.
  std::vector<int> objective_params = wanted;
  if (options.contraction_passes > 0) {
    objective_params.clear();
    for (int k = 0; k < n; ++k) objective_params.push_back(k);
  }
  std::vector<Objective> objectives;
  for (int k : objective_params) {
    objectives.push_back({k, -1});
    objectives.push_back({k, +1});
  }
  const int num_obj = static_cast<int>(objectives.size());
  auto objective_index = [&](int k, int dir) {
    const int w = static_cast<int>(std::find(objective_params.begin(), objective_params.end(), k) - objective_params.begin());
    return 2 * w + (dir > 0 ? 1 : 0);
  };
  auto is_wanted = [&](int o) { return std::find(wanted.begin(), wanted.end(), objectives[o].param) != wanted.end(); };

  // The outer set in each box a job names (the prior box, or an orthant's contracted box), and each orthant's
  // data inequalities in it, built once per process (before forking, the workers inherit them).
  using Box = std::vector<std::pair<double, double>>;
  std::mutex sets_mutex;
  std::map<std::string, std::unique_ptr<HwOuterSet>> sets_by_box;
  std::map<std::pair<std::string, int>, std::vector<Polynomial>> candidates_by_box;
  auto box_key = [](const Box& b) { return nlohmann::json(b).dump(); };
  auto set_for = [&](const Box& b) -> const HwOuterSet& {
    if (b == set.box()) return set;
    std::lock_guard<std::mutex> lock(sets_mutex);
    auto& slot = sets_by_box[box_key(b)];
    if (!slot) slot = std::make_unique<HwOuterSet>(set.WithBox(b));
    return *slot;
  };
  auto candidates_for = [&](const Box& b, int l) -> const std::vector<Polynomial>& {
    const HwOuterSet& s = set_for(b);
    std::lock_guard<std::mutex> lock(sets_mutex);
    auto& c = candidates_by_box[{box_key(b), l}];
    if (c.empty())
      for (auto& d : s.data_constraints(l)) c.push_back(std::move(d.g));
    return c;
  };
  auto candidates_of = [&](int l) -> const std::vector<Polynomial>& { return candidates_for(set.box(), l); };
  std::vector<Box> boxes(L, set.box());  // each orthant's current box

  // One job, as text, so that it can run in a forked worker or on another MPI rank. A job depends only on
  // (options, set) and its spec: {"kind": "lp", "l"} screens orthant l; {"kind": "relax", "l", "o", "d",
  // "initial"} bounds objective o over orthant l at order d, starting from the given working set.
  const sdp::JobFunction job_function = [&](const std::string& text) -> std::string {
    const auto spec = nlohmann::json::parse(text);
    const int l = spec.at("l");
    if (spec.at("kind") == "lp") {
      std::vector<Polynomial> cons = set.sign_constraints(l);
      for (const auto& g : candidates_of(l)) cons.push_back(g);
      auto solver = sdp::MakeSolver(options.solver);
      sdp::SdpOptions lp_options = opts.generation.sdp;
      lp_options.keep_dual_matrix = false;
      // With verification on, emptiness needs a verified certificate (else the status is numerical trouble).
      sdp::VerifiedBound cert;
      const auto s = ScreenWithLinearProgram(cons, n, lp_options, *solver,
                                             opts.generation.verify.enabled ? &cert : nullptr);
      return nlohmann::json{{"empty", s.status == sdp::SdpStatus::kInfeasible}, {"status", sdp::ToString(s.status)},
                            {"verification", sdp::ToString(cert.status)}}
          .dump();
    }
    const Objective obj = objectives.at(spec.at("o").get<std::size_t>());
    const Box job_box = spec.contains("box") ? spec.at("box").get<Box>() : set.box();
    const HwOuterSet& set = set_for(job_box);  // the job's box (shadows the prior-box set on purpose)
    PolyProblem core;
    core.num_vars = n;
    core.objective = Polynomial::Variable(n, obj.param);
    core.maximize = obj.dir > 0;
    core.inequalities = set.box_constraints();
    for (auto& g : set.sign_constraints(l)) core.inequalities.push_back(std::move(g));
    ConstraintGenerationOptions gen = opts.generation;
    gen.order = spec.at("d");
    if (spec.contains("max_rounds")) gen.max_rounds = spec.at("max_rounds");
    auto solver = sdp::MakeSolver(options.solver);
    auto other = sdp::MakeSolver(options.solver == "csdp" ? "sdpa" : "csdp");
    const auto r = SolveWithConstraintGeneration(gen, core, candidates_for(job_box, l), spec.at("initial").get<std::vector<int>>(),
                                                 *solver, {}, options.retry_with_other_solver ? other.get() : nullptr);
    JobOutcome out;
    out.rounds = r.rounds;
    out.sdp_iterations = r.sdp_iterations;
    out.seconds = r.solve_seconds;
    out.moments = r.num_moments;
    out.blocks = r.num_blocks;
    out.working_set = r.working_set;
    out.message = r.message;
    out.tight = r.tight;
    out.verification = sdp::ToString(r.verification.status);
    out.verify_seconds = r.verification.seconds;
    if (r.status == RelaxationStatus::kInfeasible) {
      out.status = "infeasible";
    } else if (r.status == RelaxationStatus::kSolved) {
      out.status = "solved";
      out.float_bound = set.scaling().to_original(obj.param, r.float_bound);
      out.bound = set.scaling().to_original(obj.param, r.bound);
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

  // Worker ranks (MPI) answer jobs until the coordinator ends the session; they report nothing themselves.
  if (!executor->is_coordinator()) {
    executor->Serve(job_function);
    BoundsSummary worker;
    worker.worker_rank = true;
    return worker;
  }
  struct SessionEnd {  // also when the coordinator throws, so that no worker is left waiting
    sdp::JobExecutor& e;
    ~SessionEnd() { e.EndSession(); }
  } session_end{*executor};

  // Problem hash for the run directory: everything that changes the numbers.
  nlohmann::json meta = {{"parameters", set.layout().names}, {"horizon", set.horizon()}, {"order", options.order},
                         {"cheap_pass", options.cheap_pass},
                         {"solver", options.solver}, {"box", set.box()},
                         {"violation_tolerance", options.generation.violation_tolerance},
                         {"gap_tolerance", options.generation.sdp.gap_tolerance},
                         {"verify", options.generation.verify.enabled},
                         {"contraction_passes", options.contraction_passes},
                         {"contraction_min_shrink", options.contraction_min_shrink},
                         {"contraction_max_rounds", options.contraction_max_rounds}};
  uint64_t h = 1469598103934665603ull;
  const std::string meta_text = meta.dump();
  h = fnv(h, meta_text.data(), meta_text.size());
  for (int l = 0; l < std::min(L, 1); ++l)
    for (const auto& c : set.data_constraints(l)) {
      const std::string t = c.g.to_string();
      h = fnv(h, t.data(), t.size());
    }
  const RunCache cache(options.run_dir, fmt::format("{:016x}", h), meta);

  BoundsSummary summary;
  summary.order = options.order;
  summary.horizon = set.horizon();
  summary.solver = options.solver;
  summary.executor = fmt::format("{} ({} workers)", executor->name(), executor->workers());
  summary.box = set.box();
  summary.parameter_names = set.layout().names;
  summary.orthants_total = L;

  std::vector<double> solve_times;
  std::vector<std::string> orthant_status(L, "undecided");
  std::map<std::pair<int, int>, std::set<int>> working;  // (orthant, order) -> data constraints in use
  auto report = [&](const std::string& phase, int done, int total) {
    if (!progress) return;
    const double el = seconds_since(t0);
    progress({phase, done, total, el, done > 0 ? el / done * (total - done) : 0.0});
  };
  auto is_empty = [&](int l) { return orthant_status[l].rfind("empty", 0) == 0; };

  // 1. LP screen.
  std::vector<int> alive;
  for (int l = 0; l < L; ++l) alive.push_back(l);
  if (options.lp_screen) {
    std::vector<char> empty(L, 0);
    std::vector<std::string> specs;
    std::vector<int> spec_orthant;
    for (int l = 0; l < L; ++l) {
      if (auto j = cache.load(fmt::format("lp_l{}", l))) {
        empty[l] = j->at("empty").get<bool>();
        ++summary.jobs_from_cache;
        continue;
      }
      specs.push_back(nlohmann::json{{"kind", "lp"}, {"l", l}}.dump());
      spec_orthant.push_back(l);
    }
    int done = L - static_cast<int>(specs.size());
    executor->Map(specs, job_function, [&](std::size_t i, const sdp::JobResult& r) {
      const int l = spec_orthant[i];
      if (r.ok) {  // a failed screen proves nothing: the orthant stays
        const auto j = nlohmann::json::parse(r.text);
        empty[l] = j.at("empty").get<bool>();
        cache.store(fmt::format("lp_l{}", l), j);
      }
      report("LP screen of orthants", ++done, L);
    });
    alive.clear();
    for (int l = 0; l < L; ++l) {
      if (empty[l]) {
        orthant_status[l] = "empty (LP)";
      } else {
        alive.push_back(l);
      }
    }
  }

  // Cheap order at the minimal order (also the final pass when order == minimal).
  // The cheap pass needs informative bounds to skip anything: order 1 (Shor) returns the box edges for these
  // problems, so the cheap order is at least 2; with nothing cheaper than the target order, no cheap pass.
  const int cheap_order = options.cheap_pass ? std::min(options.order, std::max(min_order, 2)) : options.order;

  // Relaxation jobs (orthant l, objective o, order d): cached ones are read, the rest run on the executor.
  // Bookkeeping (working sets shared between jobs of one orthant, emptiness, statistics) stays here.
  // max_rounds > 0 caps constraint generation (contraction passes); such jobs have their own cache entries.
  auto run_jobs = [&](const std::vector<std::tuple<int, int, int>>& jobs, const std::string& phase,
                      const std::function<void()>& on_each, int max_rounds = 0) {
    std::vector<JobOutcome> outs(jobs.size());
    std::vector<std::string> specs;
    std::vector<std::size_t> spec_job;
    auto key_of = [&](int l, int o, int d) {
      const Objective obj = objectives[o];
      std::string key = fmt::format("o{}_l{}_{}_{}", d, l, set.layout().names[obj.param], obj.dir < 0 ? "min" : "max");
      if (boxes[l] != set.box()) {  // a contracted box: its own job
        const std::string b = box_key(boxes[l]);
        key += fmt::format("_b{:016x}", fnv(1469598103934665603ull, b.data(), b.size()));
      }
      if (max_rounds > 0) key += fmt::format("_r{}", max_rounds);
      return key;
    };
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const auto [l, o, d] = jobs[i];
      if (auto j = cache.load(key_of(l, o, d))) {
        outs[i] = JobOutcome::from_json(*j);
        ++summary.jobs_from_cache;
        working[{l, d}].insert(outs[i].working_set.begin(), outs[i].working_set.end());
        if (on_each) on_each();
        continue;
      }
      if (is_empty(l)) {
        outs[i] = {"infeasible", 0, false, "orthant already proven empty"};
        if (on_each) on_each();
        continue;
      }
      // A first job at a higher order starts from the inequalities the cheap order found active.
      const auto& ws = working[{l, d}].empty() ? working[{l, cheap_order}] : working[{l, d}];
      candidates_for(boxes[l], l);  // built here, inherited by forked workers
      nlohmann::json spec{{"kind", "relax"}, {"l", l}, {"o", o}, {"d", d}, {"box", boxes[l]},
                          {"initial", std::vector<int>(ws.begin(), ws.end())}};
      if (max_rounds > 0) spec["max_rounds"] = max_rounds;
      specs.push_back(spec.dump());
      spec_job.push_back(i);
    }
    executor->Map(specs, job_function, [&](std::size_t s, const sdp::JobResult& r) {
      const std::size_t i = spec_job[s];
      const auto [l, o, d] = jobs[i];
      JobOutcome& out = outs[i];
      if (r.ok) {
        out = JobOutcome::from_json(nlohmann::json::parse(r.text));
      } else {  // a crashed or throwing job is a failed solve: reported, never dropped, not cached
        out.status = "failed";
        out.message = "job failed: " + r.error;
      }
      ++summary.sdp_jobs;
      summary.sdp_solves += out.rounds;
      summary.solve_seconds += out.seconds;
      summary.verify_seconds += out.verify_seconds;
      if (out.rounds) solve_times.push_back(out.seconds / out.rounds);
      summary.largest_moments = std::max(summary.largest_moments, out.moments);
      summary.largest_blocks = std::max(summary.largest_blocks, out.blocks);
      working[{l, d}].insert(out.working_set.begin(), out.working_set.end());
      if (out.status == "infeasible") orthant_status[l] = fmt::format("empty (order {})", d);
      if (r.ok) cache.store(key_of(l, o, d), out.to_json());
      (void)phase;
      if (on_each) on_each();
    });
    return outs;
  };

  // 2. Cheap pass at the cheap order, repeated in contracted boxes (box contraction, see BoundsOptions).
  std::map<std::pair<int, int>, JobOutcome> cheap;  // (orthant, objective)
  const bool verify_on = opts.generation.verify.enabled;
  for (int pass = 0;; ++pass) {
    std::vector<std::tuple<int, int, int>> jobs;
    for (int l : alive)
      if (!is_empty(l))
        for (int o = 0; o < num_obj; ++o) jobs.push_back({l, o, cheap_order});
    int done = 0;
    // Passes before the last contract boxes with capped jobs; the last one is the cheap pass proper.
    const bool contracting = pass < options.contraction_passes;
    const std::string phase = contracting ? fmt::format("order {} box contraction {}", cheap_order, pass + 1)
                                          : fmt::format("order {} relaxations", cheap_order);
    const auto outs = run_jobs(
        jobs, phase, [&] { report(phase, ++done, static_cast<int>(jobs.size())); },
        contracting ? std::min(options.contraction_max_rounds, opts.generation.max_rounds) : 0);
    for (std::size_t i = 0; i < jobs.size(); ++i) cheap[{std::get<0>(jobs[i]), std::get<1>(jobs[i])}] = outs[i];
    if (options.contraction_passes == 0) break;
    // Contract every orthant's box to its cheap bounds (a bound only counts when verified, or when
    // verification is off); the largest relative shrink decides whether another pass is worth it.
    double shrink = 0.0;
    for (int l : alive) {
      if (is_empty(l)) continue;
      Box next = boxes[l];
      bool crossed = false;
      for (int k = 0; k < n; ++k) {
        const double width = next[k].second - next[k].first;
        for (int dir : {-1, +1}) {
          const auto& r = cheap.at({l, objective_index(k, dir)});
          if (r.status != "solved" || (verify_on && r.verification != "verified")) continue;
          if (dir < 0) next[k].first = std::max(next[k].first, r.bound);
          else next[k].second = std::min(next[k].second, r.bound);
        }
        if (next[k].first > next[k].second) {
          crossed = true;  // rigorous bounds that cross: no point of the orthant in the box
          break;
        }
        // A box side of (near) zero width would break the scaling: keep a sliver (widening stays valid).
        const double prior_width = set.box()[k].second - set.box()[k].first;
        const double min_width = 1e-6 * prior_width;
        if (next[k].second - next[k].first < min_width) {
          const double mid = 0.5 * (next[k].first + next[k].second);
          next[k] = {std::max(set.box()[k].first, mid - min_width), std::min(set.box()[k].second, mid + min_width)};
        }
        shrink = std::max(shrink, 1.0 - (next[k].second - next[k].first) / width);
      }
      if (crossed) {
        orthant_status[l] = fmt::format("empty (order {}, contracted box)", cheap_order);
        continue;
      }
      boxes[l] = next;
    }
    if (!contracting) break;
    summary.contraction_passes_run = pass + 1;
    // Little movement: skip the remaining contraction passes and run the last (full) cheap pass.
    if (shrink < options.contraction_min_shrink) pass = std::max(pass, options.contraction_passes - 1);
  }

  // 3. Full pass: per objective, orthants by cheap bound (most extreme first), skipped when unable to move it.
  std::map<std::pair<int, int>, JobOutcome> full = cheap;
  if (options.order > cheap_order) {
    full.clear();
    // current[o] = aggregated endpoint from finished full-order jobs (min for dir -1, max for dir +1).
    std::vector<double> current(num_obj, NAN);
    std::set<std::pair<int, int>> done_jobs;
    int total_est = 0;
    for (int o = 0; o < num_obj; ++o)
      for (int l : alive)
        if (!is_empty(l) && is_wanted(o)) ++total_est;
    int finished = 0;
    while (true) {
      std::vector<std::pair<int, int>> wave;
      for (int o = 0; o < num_obj; ++o) {
        if (!is_wanted(o)) continue;
        const int dir = objectives[o].dir;
        int best = -1;
        double best_val = 0.0;
        for (int l : alive) {
          if (is_empty(l) || done_jobs.count({l, o})) continue;
          const auto& c = cheap.at({l, o});
          // A failed cheap job cannot be used to skip: it must be solved.
          const double v = c.status == "solved" ? c.bound : (dir < 0 ? -INFINITY : INFINITY);
          const bool can_move = std::isnan(current[o]) || (dir < 0 ? v < current[o] : v > current[o]);
          if (!can_move) continue;
          if (best < 0 || (dir < 0 ? v < best_val : v > best_val)) {
            best = l;
            best_val = v;
          }
        }
        if (best >= 0) wave.push_back({best, o});
      }
      if (wave.empty()) break;
      std::vector<std::tuple<int, int, int>> wave_jobs;
      for (const auto& [l, o] : wave) wave_jobs.push_back({l, o, options.order});
      const std::string phase = fmt::format("order {} relaxations", options.order);
      const auto outs = run_jobs(wave_jobs, phase, [&] { report(phase, ++finished, total_est); });
      for (std::size_t i = 0; i < wave.size(); ++i) {
        const auto [l, o] = wave[i];
        done_jobs.insert({l, o});
        full[{l, o}] = outs[i];
        if (outs[i].status == "solved") {
          const int dir = objectives[o].dir;
          if (std::isnan(current[o]) || (dir < 0 ? outs[i].bound < current[o] : outs[i].bound > current[o]))
            current[o] = outs[i].bound;
        }
      }
    }
    // Orthants not solved at full order for an objective keep their cheap outcome (valid, and never more
    // extreme than the aggregate, or they would have been solved).
    for (int l : alive)
      for (int o = 0; o < num_obj; ++o)
        if (!full.count({l, o}) && !is_empty(l) && is_wanted(o)) {
          auto c = cheap.at({l, o});
          c.message = "skipped at full order: its order-" + std::to_string(cheap_order) + " bound cannot move the interval";
          c.status = c.status == "solved" ? "skipped" : c.status;
          full[{l, o}] = c;
        }
  }

  // 4. Aggregate (eqs. 31-33) with fallbacks.
  for (std::size_t w = 0; w < wanted.size(); ++w) {
    const int k = wanted[w];
    ParameterInterval iv;
    iv.name = set.layout().names[k];
    for (int dir : {-1, +1}) {
      const int o = objective_index(k, dir);
      Endpoint ep;
      ep.status = "empty";
      bool any = false;
      // Verification: the endpoint is verified when every orthant value entering it is; float_value aggregates
      // the solvers' floating-point bounds, so |value - float_value| is the endpoint's correction.
      const bool verify = opts.generation.verify.enabled;
      double float_value = 0.0;
      std::string unverified;
      for (int l : alive) {
        if (is_empty(l)) continue;
        const auto& r = full.at({l, o});
        double v, fv;
        std::string status = "guaranteed", note, ver;
        bool tight = r.tight;
        if (r.status == "solved" || r.status == "skipped") {
          v = r.bound;
          fv = r.float_bound;
          ver = r.verification;
        } else if (r.status == "infeasible") {
          continue;  // proven empty in this orthant
        } else {
          const auto& c = cheap.at({l, o});
          if (c.status == "solved" && options.order > cheap_order) {
            v = c.bound;
            fv = c.float_bound;
            ver = c.verification;
            note = fmt::format("order-{} solve failed in orthant {} ({}); order-{} bound used", options.order, l,
                               r.message, cheap_order);
          } else {
            // The orthant's box edge: the prior box, or a contracted box proven to contain the orthant's points.
            v = fv = dir < 0 ? boxes[l][k].first : boxes[l][k].second;
            ver = verify ? "verified" : "off";
            note = fmt::format("solve failed in orthant {} ({}); box edge used", l, r.message);
          }
          status = "conservative";
          tight = false;
        }
        if (verify && ver != "verified") unverified += (unverified.empty() ? "" : ", ") + std::to_string(l);
        if (!any || (dir < 0 ? fv < float_value : fv > float_value)) float_value = fv;
        const bool better = !any || (dir < 0 ? v < ep.value : v > ep.value);
        // The endpoint's status is that of the orthant attaining it: a fallback that is not extreme
        // leaves the endpoint exact, since the fallback still bounds that orthant.
        if (better) {
          ep.value = v;
          ep.orthant = l;
          ep.tight = tight;
          ep.status = status;
        }
        if (!note.empty()) ep.note += (ep.note.empty() ? "" : "; ") + note;
        any = true;
      }
      if (!any) ep.note = "every orthant is proven empty: the data are inconsistent with the model class and box";
      if (any) {
        ep.verification = !verify ? "off" : unverified.empty() ? "verified" : "unverified";
        ep.correction = std::abs(ep.value - float_value);
        if (!unverified.empty())
          ep.note += (ep.note.empty() ? "" : "; ") +
                     fmt::format("floating-point bound not verified in orthant(s) {} (value is the solver's)", unverified);
      }
      (dir < 0 ? iv.lower : iv.upper) = ep;
    }
    summary.intervals.push_back(iv);
  }

  for (int l = 0; l < L; ++l) {
    bool failed = false;
    if (!is_empty(l) && orthant_status[l] == "undecided") {
      for (int o = 0; o < num_obj; ++o)
        if (full.count({l, o}) && full.at({l, o}).status == "failed") failed = true;
      orthant_status[l] = failed ? "failed (conservative fallback)" : "solved";
    }
    if (is_empty(l)) ++summary.orthants_empty;
    else if (failed) ++summary.orthants_failed;
    else ++summary.orthants_solved;
    summary.orthants.push_back({l, sign_text(set, l), orthant_status[l]});
  }
  for (int l : alive)
    if (!is_empty(l) && boxes[l] != set.box()) summary.orthant_boxes.push_back({l, boxes[l]});
  std::sort(solve_times.begin(), solve_times.end());
  if (!solve_times.empty()) summary.median_solve_seconds = solve_times[solve_times.size() / 2];
  summary.wall_seconds = seconds_since(t0);
  return summary;
}

}  // namespace hw::relax
