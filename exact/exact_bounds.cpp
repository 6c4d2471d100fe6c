#include "exact/exact_bounds.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "dss/run_cache.hpp"
#include "exact/exact_jobs.hpp"

namespace hw::exact {
namespace {

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Runs specs on the executor, reading and storing answers in the run directory. A failed job's answer is
// null: the caller keeps what it concerned (a box stays live; an endpoint falls back to the box edge).
class JobRunner {
 public:
  JobRunner(sdp::JobExecutor& executor, const dss::RunCache& cache, const sdp::JobFunction& fn, ExactBoundsSummary& s)
      : executor_(executor), cache_(cache), fn_(fn), summary_(s) {}
  // `on_done(done, total)` after each job run here (jobs read from the run directory count as done at once).
  std::vector<nlohmann::json> Run(const std::vector<nlohmann::json>& specs,
                                  const std::function<void(int, int)>& on_done = {}) {
    std::vector<nlohmann::json> answers(specs.size());
    std::vector<std::string> texts, keys;
    std::vector<std::size_t> to_run;  // indices of specs not answered by the run directory
    for (std::size_t i = 0; i < specs.size(); ++i) {
      const std::string text = specs[i].dump();
      const std::string key = JobKey(text);
      if (auto cached = cache_.load(key)) {
        answers[i] = *cached;
        ++summary_.jobs_from_cache;
        continue;
      }
      texts.push_back(text);
      keys.push_back(key);
      to_run.push_back(i);
    }
    int done = static_cast<int>(specs.size() - to_run.size());
    const auto results = executor_.Map(texts, fn_, [&](std::size_t, const sdp::JobResult&) {
      if (on_done) on_done(++done, static_cast<int>(specs.size()));
    });
    for (std::size_t n = 0; n < to_run.size(); ++n) {
      ++summary_.jobs;
      if (!results[n].ok) continue;  // stays null
      answers[to_run[n]] = nlohmann::json::parse(results[n].text);
      cache_.store(keys[n], answers[to_run[n]]);
    }
    return answers;
  }

 private:
  sdp::JobExecutor& executor_;
  const dss::RunCache& cache_;
  const sdp::JobFunction& fn_;
  ExactBoundsSummary& summary_;
};

struct LiveBox {
  ParamBox box;
  LpBasis basis;
  std::vector<double> point;
};

// Stage 1: halve and test until the live boxes are small against their hull.
std::vector<LiveBox> Prune(const LiftedData& data, const ParamBox& start, const PruneStop& stop, JobRunner& runner,
                           ExactBoundsSummary& s, const std::function<void(const ExactBoundsProgress&)>& progress,
                           Clock::time_point t0) {
  std::vector<LiveBox> live = {{start, {}, {}}};
  int level = 0;
  bool cheap_windows = true;  // until a level's cheap windows prune nothing
  while (level == 0 || !PruneSearchDone(data, [&] {
           std::vector<ParamBox> b;
           for (const auto& l : live) b.push_back(l.box);
           return b;
         }(), level, stop)) {
    std::vector<LiveBox> children;
    std::vector<nlohmann::json> specs;
    for (const auto& l : live) {
      auto [lower, upper] = HalveBox(l.box, SplitParameter(data, l.box, start));
      for (auto& c : {lower, upper}) {
        children.push_back({c, l.basis, l.point});
        specs.push_back(EmptinessJobSpec(c, l.basis, cheap_windows));
      }
    }
    const auto answers = runner.Run(specs);
    std::vector<LiveBox> next;
    bool window_pruned = false;
    for (std::size_t i = 0; i < children.size(); ++i) {
      ++s.boxes_evaluated;
      if (answers[i].is_null()) {  // the job failed: the box stays
        next.push_back(children[i]);
        continue;
      }
      const EmptinessAnswer a = EmptinessAnswer::from_json(answers[i]);
      s.lps += a.lps;
      s.lp_failures += a.lp_failures;
      if (a.verdict == BoxVerdict::kPruned) {
        ++s.boxes_pruned;
        window_pruned = window_pruned || !(a.certificate->window == WholeRecord(data));
        s.certificates.push_back({{"box", BoxToJson(children[i].box)}, {"certificate", a.certificate->to_json()}});
        continue;
      }
      next.push_back({children[i].box, a.basis, a.point});
    }
    live = std::move(next);
    cheap_windows = cheap_windows && window_pruned;
    ++level;
    if (progress && !live.empty()) {
      std::vector<ParamBox> b;
      for (const auto& l : live) b.push_back(l.box);
      const ParamBox hull = HullOf(b);
      const int a1 = data.layout.a_begin;
      progress({"prune (levels)", level, stop.max_levels,
                fmt::format("{} boxes live, {} in [{:.6g}, {:.6g}]", live.size(), data.layout.names[a1], hull[a1].lo,
                            hull[a1].hi),
                SecondsSince(t0)});
    }
    if (live.empty()) break;
    if (static_cast<int>(live.size()) > stop.max_boxes || level >= stop.max_levels) break;
  }
  s.prune_levels = level;
  return live;
}

std::vector<int> WantedParameters(const ExactBoundsOptions& options, const dss::ParameterLayout& lay) {
  std::vector<int> wanted;
  for (int k = 0; k < lay.count(); ++k)
    if (options.parameters.empty() ||
        std::find(options.parameters.begin(), options.parameters.end(), lay.names[k]) != options.parameters.end())
      wanted.push_back(k);
  return wanted;
}

using InnerRanges = std::vector<std::optional<std::pair<double, double>>>;

// The inner hull's ranges for every entry of a box with forms: the parameters', then each form's over the points.
InnerRanges InnerRangesWithForms(const LiftedData& data, const InnerHull& inner) {
  InnerRanges ranges = inner.ranges;
  for (const auto& form : data.forms) {
    std::optional<std::pair<double, double>> r;
    for (const auto& p : inner.points) {
      const double v = FormValue(data, form, p.theta);
      r = r ? std::pair{std::min(r->first, v), std::max(r->second, v)} : std::pair{v, v};
    }
    ranges.push_back(r);
  }
  return ranges;
}

// A gamma_k while no b_j of the box has a sign: bounded directly (not as beta_jk / b_j), which only narrows it
// for the envelopes of the next sweep; a few LPs do that, the rest of the budget would buy nothing.
constexpr int kUnsignedGammaBudget = 2;
bool GammaWithoutDenominator(const LiftedData& data, const ParamBox& box, int k) {
  const auto& lay = data.layout;
  if (k < lay.gamma_begin || k >= lay.gamma_begin + lay.num_gamma) return false;
  for (int j = lay.b_begin; j < lay.count(); ++j)
    if (box[j].lo > 0 || box[j].hi < 0) return false;
  return true;
}

// How far each end may lie outside the inner hull [lo, hi] for outer/inner <= target_ratio.
double EndAllowance(double lo, double hi, double target_ratio) { return 0.5 * (target_ratio - 1.0) * (hi - lo); }

// Stage 3, one sweep: every wanted endpoint (and, for the box of the next sweep, every parameter and form)
// refined. The forms' new ranges go to `form_ranges`. With `closing_budget`: only the endpoints still short of
// their target, each with that budget.
void BoundSweep(const LiftedData& data, const ParamBox& start, const std::vector<ParamBox>& boxes,
                const InnerRanges* inner, double target_ratio, EndpointSplit split, std::optional<int> closing_budget,
                JobRunner& runner, ExactBoundsSummary& s,
                std::vector<ExactInterval>& intervals, std::vector<Interval>& form_ranges, bool forms_only,
                const std::function<void(int, int)>& on_done) {
  const auto& lay = data.layout;
  std::vector<nlohmann::json> specs;
  std::vector<Objective> objectives;
  // D's known extent per entry (the inner hull's range, else the start's): what the family and dynamics-gamma
  // splits measure against.
  std::optional<ParamBox> scale;
  if (inner && (split == EndpointSplit::kFamily || split == EndpointSplit::kDynamicsGamma)) {
    scale = start;
    for (std::size_t k = 0; k < start.size() && k < inner->size(); ++k)
      if ((*inner)[k]) (*scale)[k] = Interval((*inner)[k]->first, (*inner)[k]->second);
  }
  for (int k = forms_only ? lay.count() : 0; k < static_cast<int>(start.size()); ++k)
    for (bool maximise : {false, true}) {
      const bool closing = closing_budget && k < lay.count() && !GammaWithoutDenominator(data, start, k);
      if (closing_budget && !(closing && ShortOfTarget(intervals[k], maximise, target_ratio))) continue;
      std::optional<double> target;
      double gap = 0.0;
      if (inner && (*inner)[k]) {
        const auto [lo, hi] = *(*inner)[k];
        target = maximise ? hi : lo;
        gap = EndAllowance(lo, hi, target_ratio);
      }
      objectives.push_back({k, maximise});
      std::optional<int> budget;
      if (closing) budget = closing_budget;
      else if (GammaWithoutDenominator(data, start, k)) budget = kUnsignedGammaBudget;
      specs.push_back(ObjectiveJobSpec(start, boxes, objectives.back(), target, gap, data.forms, budget, scale));
    }
  const auto answers = runner.Run(specs, on_done);
  for (std::size_t o = 0; o < objectives.size(); ++o) {
    const Objective& obj = objectives[o];
    if (answers[o].is_null()) continue;  // the job failed: the endpoint keeps what it had
    const ObjectiveSearchResult r = ObjectiveSearchResult::from_json(answers[o]);
    s.lps += r.lps;
    s.lp_failures += r.lp_failures;
    s.boxes_pruned += r.boxes_pruned;
    if (obj.parameter >= lay.count()) {  // a form: its range only narrows the next sweep's box
      Interval& range = form_ranges[obj.parameter - lay.count()];
      if (r.empty) continue;
      if (obj.maximise) range.hi = std::min(range.hi, r.bound);
      else range.lo = std::max(range.lo, r.bound);
      continue;
    }
    ExactEndpoint& end = obj.maximise ? intervals[obj.parameter].upper : intervals[obj.parameter].lower;
    if (r.empty) {
      end.status = EndpointStatus::kEmpty;
      continue;
    }
    // Keep the tighter of two valid bounds (an earlier sweep's, this one's); an LP bound equal to a box edge
    // makes that edge guaranteed.
    const bool tighter = obj.maximise ? r.bound < end.value : r.bound > end.value;
    if (tighter || (r.bound == end.value && r.from_lp)) {
      end.value = r.bound;
      end.status = r.from_lp ? EndpointStatus::kGuaranteed : EndpointStatus::kConservative;
      end.correction = std::abs(r.bound - r.lp_value);
    }
  }
}

AssumptionCheck CheckAssumption(const LiftedData& data, const std::vector<ExactInterval>& intervals) {
  AssumptionCheck c;
  c.grid_points = static_cast<int>(data.grid.size());
  const auto& lay = data.layout;
  c.smallest_increase = INFINITY;
  for (std::size_t m = 0; m + 1 < data.grid.size(); ++m) {
    Interval inc = data.phi_grid[m + 1][0] - data.phi_grid[m][0];
    for (int j = 0; j < lay.num_alpha; ++j) {
      const auto& iv = intervals[lay.alpha_begin + j];
      inc += Interval(iv.lower.value, iv.upper.value) * (data.phi_grid[m + 1][j + 1] - data.phi_grid[m][j + 1]);
    }
    if (inc.lo < c.smallest_increase) {
      c.smallest_increase = inc.lo;
      c.where_lo = data.grid[m];
      c.where_hi = data.grid[m + 1];
    }
  }
  c.holds = c.smallest_increase > 0.0;
  return c;
}

}  // namespace

std::string ToString(EndpointStatus status) {
  switch (status) {
    case EndpointStatus::kGuaranteed: return "guaranteed";
    case EndpointStatus::kConservative: return "conservative";
    case EndpointStatus::kEmpty: return "empty";
  }
  return "conservative";
}

std::string MonotoneAssumptionText() {
  return "the inverse output map p(alpha, w) = sum_j alpha_j phi_j(w) increases on the data range "
         "[min(y - dy), max(y + dy)] (paper 001 takes it invertible; alpha_1 = 1 fixes the sign)";
}

bool WithinTarget(const ExactInterval& interval, double target_ratio) {
  if (!interval.inner) return false;
  const auto [lo, hi] = *interval.inner;
  return interval.upper.value - interval.lower.value <= target_ratio * (hi - lo);
}

bool ShortOfTarget(const ExactInterval& interval, bool maximise, double target_ratio) {
  if (WithinTarget(interval, target_ratio)) return false;
  if (!interval.inner) return true;
  const auto [lo, hi] = *interval.inner;
  const double gap = EndAllowance(lo, hi, target_ratio);
  return maximise ? interval.upper.value > hi + gap : interval.lower.value < lo - gap;
}

bool AllWithinTarget(const std::vector<ExactInterval>& intervals, double target_ratio) {
  for (const auto& iv : intervals)
    if (!WithinTarget(iv, target_ratio)) return false;
  return true;
}

int ShortEndpointBudget(const std::vector<ExactInterval>& intervals, double target_ratio, int lp_budget, int cap) {
  int endpoints = 0, short_ones = 0;
  for (const auto& iv : intervals)
    for (bool maximise : {false, true}) {
      ++endpoints;
      if (ShortOfTarget(iv, maximise, target_ratio)) ++short_ones;
    }
  if (short_ones == 0) return lp_budget;
  return lp_budget * std::clamp(endpoints / short_ones, 1, cap);
}

bool ExactBoundsOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!ValidLpSolverName(lp_solver, error)) return false;
  if (!evaluation.IsValid(error) || !prune.IsValid(error) || !search.IsValid(error)) return false;
  if (dynamics_forms && !forms.IsValid(error)) return false;
  if (sweeps < 1 || sweeps > 5) return fail(fmt::format("sweeps must be 1..5, not {}", sweeps));
  if (!(target_ratio >= 1.0)) return fail("target_ratio must be >= 1");
  if (short_endpoint_budget_cap < 1)
    return fail(fmt::format("short_endpoint_budget_cap must be >= 1 (1 = off), not {}", short_endpoint_budget_cap));
  if (threads < 0) return fail("threads must be >= 0 (0 = one per core)");
  if (inner_hull && !inner.IsValid(error)) return false;
  return true;
}

nlohmann::json AssumptionCheck::to_json() const {
  return {{"assumption", MonotoneAssumptionText()}, {"holds", holds}, {"smallest_increase", smallest_increase},
          {"where", {where_lo, where_hi}}, {"grid_points", grid_points}};
}

nlohmann::json ExactBoundsSummary::to_json() const {
  nlohmann::json ivs = nlohmann::json::array();
  for (const auto& iv : intervals) {
    auto end = [](const ExactEndpoint& e) {
      return nlohmann::json{{"value", e.value}, {"status", ToString(e.status)},
                            {"verification", e.verified ? "verified" : "unverified"}, {"correction", e.correction}};
    };
    nlohmann::json j = {{"name", iv.name}, {"lower", end(iv.lower)}, {"upper", end(iv.upper)}};
    if (iv.inner) j["inner"] = {iv.inner->first, iv.inner->second};
    ivs.push_back(j);
  }
  return {{"intervals", ivs},
          {"start_box", BoxToJson(start_box)},
          {"invalidated", invalidated},
          {"certificates", certificates},
          {"assumption", assumption.to_json()},
          {"stage2",
           {{"prune_levels", prune_levels}, {"sweeps", sweeps}, {"closing_pass", closing_pass}, {"boxes_evaluated", boxes_evaluated}, {"boxes_pruned", boxes_pruned},
            {"boxes_live", boxes_live}, {"lps", lps}, {"lp_failures", lp_failures}, {"jobs", jobs},
            {"jobs_from_cache", jobs_from_cache}, {"lp_rows", lp_rows}, {"lp_cols", lp_cols},
            {"lp_nonzeros", lp_nonzeros}, {"prune_seconds", prune_seconds}, {"inner_seconds", inner_seconds},
            {"bound_seconds", bound_seconds}, {"wall_seconds", wall_seconds}, {"inner_points", inner_points},
            {"executor", executor}, {"lp_solver", lp_solver}, {"forms", FormsToJson(forms)}}}};
}

ExactBoundsSummary ComputeExactBounds(const ExactBoundsOptions& options, const dss::HwStructure& structure,
                                      const dss::HwData& data, const ParamBox& start_box,
                                      const std::function<void(const ExactBoundsProgress&)>& progress) {
  const auto t0 = Clock::now();
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const LiftedData lifted = MakeLiftedData(structure, data);
  const auto& lay = lifted.layout;
  if (static_cast<int>(start_box.size()) != lay.count())
    throw InputError(fmt::format("the start box has {} entries for {} parameters", start_box.size(), lay.count()));
  const ExactJobSettings settings{options.lp_solver, options.evaluation, options.search};
  const sdp::JobFunction fn = MakeExactJobFunction(lifted, settings);
  const auto executor = options.executor ? options.executor : std::make_shared<sdp::ForkExecutor>(options.threads);
  ExactBoundsSummary s;
  if (!executor->is_coordinator()) {
    executor->Serve(fn);
    s.worker_rank = true;
    return s;
  }
  struct SessionEnd {
    sdp::JobExecutor& e;
    ~SessionEnd() { e.EndSession(); }
  } session_end{*executor};
  s.executor = fmt::format("{} ({} workers)", executor->name(), executor->workers());
  s.lp_solver = options.lp_solver;
  s.parameter_names = lay.names;
  s.start_box = start_box;
  {
    const LiftedLp shape = BuildLiftedLp(lifted, start_box, WholeRecord(lifted), LiftedForm::kFeasibility);
    s.lp_rows = shape.lp.num_rows();
    s.lp_cols = shape.lp.num_cols();
    s.lp_nonzeros = static_cast<long>(shape.lp.entries.size());
  }
  // Everything a job's answer depends on besides its spec: a run directory never answers for other settings.
  const auto& ev = options.evaluation;
  nlohmann::json meta = {{"engine", "exact"},
                         {"start_box", BoxToJson(start_box)},
                         {"lp_solver", options.lp_solver},
                         {"lp_budget", options.search.lp_budget},
                         {"split", ToString(options.search.split)},
                         {"gamma_ratio", ToString(options.search.gamma_ratio)},
                         {"dynamics_forms", options.dynamics_forms ? options.forms.thin_share : 0.0},
                         {"cheap_windows", {ev.cheap_window, ev.cheap_windows}},
                         {"lp_tolerances", {ev.lp.primal_tolerance, ev.lp.dual_tolerance, ev.lp.time_limit_seconds}}};
  if (options.forms.gain) meta["gain_forms"] = true;
  if (options.forms.shape) meta["shape_forms"] = true;
  const std::string key = JobKey(meta.dump() + std::to_string(lifted.num_samples));
  const dss::RunCache cache(options.run_dir, "exact-" + key, meta);
  JobRunner runner(*executor, cache, fn, s);

  // 1. prune
  auto t = Clock::now();
  const std::vector<LiveBox> live = Prune(lifted, start_box, options.prune, runner, s, progress, t0);
  s.prune_seconds = SecondsSince(t);
  s.boxes_live = static_cast<int>(live.size());
  for (int k = 0; k < lay.count(); ++k) {
    ExactInterval iv{lay.names[k], {start_box[k].lo, EndpointStatus::kConservative}, {start_box[k].hi, EndpointStatus::kConservative}, {}};
    s.intervals.push_back(iv);
  }
  if (live.empty()) {
    s.invalidated = true;
    for (auto& iv : s.intervals) iv.lower.status = iv.upper.status = EndpointStatus::kEmpty;
    s.wall_seconds = SecondsSince(t0);
    return s;
  }
  s.certificates.clear();  // kept only as the proof of an empty set
  std::vector<ParamBox> boxes;
  for (const auto& l : live) boxes.push_back(l.box);
  ParamBox proven = HullOf(boxes);
  // The a_i of the live hull are already bounds.
  for (int i = 0; i < structure.na; ++i) {
    const int k = lay.a_begin + i;
    s.intervals[k].lower = {proven[k].lo, EndpointStatus::kGuaranteed};
    s.intervals[k].upper = {proven[k].hi, EndpointStatus::kGuaranteed};
  }

  // 2. inner hull
  std::optional<InnerHull> inner;
  if (options.inner_hull) {
    t = Clock::now();
    if (progress) progress({"inner hull (local searches)", 0, 1, "", SecondsSince(t0)});
    auto solver = MakeLpSolver(options.lp_solver);
    std::vector<double> start_point = live.front().point;
    if (start_point.empty())
      for (const auto& iv : proven) start_point.push_back(iv.mid());
    inner = ComputeInnerHull(lifted, proven, start_point, options.inner, *solver);
    s.inner_seconds = SecondsSince(t);
    s.inner_points = static_cast<int>(inner->points.size());
    for (int k = 0; k < lay.count(); ++k) s.intervals[k].inner = inner->ranges[k];
  }

  // Forms across D's thin directions, from the inner hull's points (exact/parameter_forms.hpp).
  LiftedData with_forms = lifted;
  if (inner && options.dynamics_forms) {
    std::vector<std::vector<double>> points;
    for (const auto& p : inner->points) points.push_back(p.theta);
    with_forms.forms = ThinDirections(lifted, points, options.forms);
  }
  s.forms = with_forms.forms;
  if (!with_forms.forms.empty()) {  // the bounding LPs' shape, forms included
    const LiftedLp shape =
        BuildLiftedLp(with_forms, WithFormRanges(with_forms, proven), WholeRecord(lifted), LiftedForm::kFeasibility);
    s.lp_rows = shape.lp.num_rows();
    s.lp_cols = shape.lp.num_cols();
    s.lp_nonzeros = static_cast<long>(shape.lp.entries.size());
  }
  std::optional<InnerRanges> inner_ranges;
  if (inner) inner_ranges = InnerRangesWithForms(with_forms, *inner);

  // 3. bound, in sweeps: each later sweep starts in the box the earlier ones proved.
  t = Clock::now();
  std::vector<Interval> form_ranges(with_forms.forms.size(), Interval(-INFINITY, INFINITY));
  // The forms' own ranges first (sweep 0): every endpoint's search then starts with D's strip already narrow,
  // instead of each one cutting it down on its own.
  // After the sweeps, a closing pass for the endpoints still short of their target (sweep options.sweeps + 1).
  const bool closing_pass = inner_ranges && options.short_endpoint_budget_cap > 1;
  for (int sweep = form_ranges.empty() ? 1 : 0; sweep <= options.sweeps + (closing_pass ? 1 : 0); ++sweep) {
    // Every interval within its target: a further sweep would narrow what needs no narrowing.
    if (sweep >= 2 && inner_ranges && AllWithinTarget(s.intervals, options.target_ratio)) break;
    const bool closing = sweep > options.sweeps;
    const std::string phase = sweep == 0   ? std::string("bound (the forms' ranges)")
                              : closing    ? std::string("bound (closing pass, the endpoints short of their target)")
                                           : fmt::format("bound (sweep {} of {}, endpoints)", sweep, options.sweeps);
    ParamBox sweep_start = start_box;
    for (int k = 0; k < lay.count(); ++k) sweep_start[k] = Interval(s.intervals[k].lower.value, s.intervals[k].upper.value);
    sweep_start = WithFormRanges(with_forms, sweep_start);
    for (std::size_t f = 0; f < form_ranges.size(); ++f) {
      Interval& range = sweep_start[lay.count() + f];
      range = {std::max(range.lo, form_ranges[f].lo), std::min(range.hi, form_ranges[f].hi)};
    }
    PropagateForms(with_forms, sweep_start);
    // Each endpoint's search starts from the live hull (one box): it halves only where its bound is worst, which
    // costs fewer LPs than bounding every live box of the pruning search first.
    const std::vector<ParamBox> sweep_boxes = {sweep_start};
    std::optional<int> closing_budget;
    if (closing) {
      closing_budget = ShortEndpointBudget(s.intervals, options.target_ratio, options.search.lp_budget,
                                           options.short_endpoint_budget_cap);
      s.closing_pass = true;
    } else if (sweep >= 1) {
      s.sweeps = sweep;
    }
    BoundSweep(with_forms, sweep_start, sweep_boxes, inner_ranges ? &*inner_ranges : nullptr, options.target_ratio,
               options.search.split, closing_budget, runner, s, s.intervals, form_ranges, sweep == 0,
               [&](int done, int total) {
                 if (progress) progress({phase, done, total, "", SecondsSince(t0)});
               });
  }
  s.bound_seconds = SecondsSince(t);
  s.assumption = CheckAssumption(lifted, s.intervals);
  s.wall_seconds = SecondsSince(t0);
  return s;
}

}  // namespace hw::exact
