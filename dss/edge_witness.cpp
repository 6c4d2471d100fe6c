#include "dss/edge_witness.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>

#include <fmt/format.h>

namespace hw::dss {

bool EdgeWitnessOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (random_starts < 0) return fail("edge witness: random_starts must be >= 0");
  if (min_order < 1) return fail("edge witness: min_order must be >= 1");
  if (!(edge_tolerance >= 0 && edge_tolerance < 1e-3)) return fail("edge witness: edge_tolerance must be in [0, 1e-3)");
  return local.IsValid(error);
}

namespace {

// g(p) evaluated term by term, and an upper bound of the evaluation's rounding error: each term costs at most
// deg + 1 roundings, the sum at most T - 1, so |fl(g) - g| <= 2 (T + deg + 2) u sum |terms| (u = 2^-53, the
// factor 2 covers the second-order terms). At least 1e-12 sum |terms| is allowed, which also covers the rounding
// between these unscaled rows and the scaled, normalised ones the relaxations use.
double SlackWithAllowance(const Polynomial& g, const std::vector<double>& p) {
  double value = 0.0, magnitude = 0.0;
  int degree = 0;
  for (const auto& [e, c] : g.terms()) {
    double t = c;
    int d = 0;
    for (std::size_t i = 0; i < e.size(); ++i)
      for (int k = 0; k < e[i]; ++k) t *= p[i], ++d;
    value += t;
    magnitude += std::abs(t);
    degree = std::max(degree, d);
  }
  const double u = std::numeric_limits<double>::epsilon() / 2;
  const double terms = static_cast<double>(g.terms().size());
  const double relative = std::max(2.0 * (terms + degree + 2) * u, 1e-12);
  return value - relative * magnitude;
}

// The box centre, then `count` deterministic points in the box (seeded by the orthant).
std::vector<std::vector<double>> StartsInBox(const ParameterBox& box, int count, int orthant) {
  std::vector<std::vector<double>> starts;
  std::vector<double> center;
  for (const auto& [lo, hi] : box) center.push_back(0.5 * (lo + hi));
  starts.push_back(center);
  for (auto& p : PseudoRandomPointsInBox(box, count, static_cast<std::uint64_t>(orthant + 1))) starts.push_back(std::move(p));
  return starts;
}

// An outcome at the box edge: exact and verified by a feasible point (in this orthant, or in another one for a
// skipped objective that cannot move the endpoint).
JobOutcome AtEdge(JobStatus status, double edge, JobOrigin origin, std::string message) {
  JobOutcome r;
  r.status = status;
  r.bound = r.float_bound = edge;
  r.tight = true;
  r.verification = sdp::VerifyStatus::kVerified;
  r.origin = origin;
  r.message = std::move(message);
  return r;
}

// The side of `box` an objective runs toward.
double EdgeOf(const ParameterBox& box, const Objective& o) { return o.dir < 0 ? box[o.param].first : box[o.param].second; }

}  // namespace

double CertifiedMinSlack(const HwOuterSet& set, int l, const std::vector<double>& p) {
  double m = INFINITY;
  for (const auto& g : set.orthant_inequalities(l)) m = std::min(m, SlackWithAllowance(g, p));
  return m;
}

std::vector<FeasiblePoint> CertifiedFeasiblePoints(const HwOuterSet& set, const std::vector<OrthantWork>& orthants,
                                                   const std::map<ObjectiveKey, std::vector<double>>& points) {
  std::vector<FeasiblePoint> certified;
  for (const auto& [key, p] : points) {
    const OrthantWork* w = nullptr;
    for (const auto& o : orthants)
      if (o.index == key.first) w = &o;
    if (!w || w->empty() || p.size() != w->box.size()) continue;
    bool inside = true;
    for (std::size_t i = 0; i < p.size(); ++i) inside = inside && w->box[i].first <= p[i] && p[i] <= w->box[i].second;
    if (!inside) continue;
    const double slack = CertifiedMinSlack(set, key.first, p);
    if (slack >= 0) certified.push_back({key.first, p, slack});
  }
  return certified;
}

namespace {

// Index of the first point most extreme in objective o's parameter; -1 without points.
int MostExtreme(const Objective& o, const std::vector<FeasiblePoint>& points) {
  int best = -1;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const double v = points[i].point[o.param];
    if (best < 0 || (o.dir < 0 ? v < points[best].point[o.param] : v > points[best].point[o.param])) best = i;
  }
  return best;
}

}  // namespace

std::map<int, double> WitnessedExtremes(const std::vector<Objective>& objectives,
                                        const std::vector<FeasiblePoint>& points) {
  std::map<int, double> extremes;
  for (std::size_t j = 0; j < objectives.size(); ++j)
    if (const int i = MostExtreme(objectives[j], points); i >= 0)
      extremes[static_cast<int>(j)] = points[i].point[objectives[j].param];
  return extremes;
}

std::vector<FeasiblePoint> ExtremeFeasiblePoints(const std::vector<Objective>& objectives,
                                                 const std::vector<FeasiblePoint>& points) {
  std::vector<FeasiblePoint> extreme;
  std::set<int> taken;
  for (const auto& o : objectives)
    if (const int i = MostExtreme(o, points); i >= 0 && taken.insert(i).second) extreme.push_back(points[i]);
  return extreme;
}

nlohmann::json AnswerWitnessJob(const JobContext& job, const nlohmann::json& spec) {
  // Local extreme of one objective from the given starts in turn, until a start gives a feasible point.
  const int l = spec.at("l");
  const std::vector<int> rows = spec.at("rows").get<std::vector<int>>();
  const int param = spec.at("param"), dir = spec.at("dir");
  nlohmann::json answer{{"found", false}, {"solves", 0}};
  for (const auto& start : spec.at("starts")) {
    const auto w = LocalExtreme(job.prior_set(), l, param, dir, start.get<std::vector<double>>(),
                                job.settings().local_search, &rows);
    answer["solves"] = answer["solves"].get<int>() + 1;
    if (w.found) {
      answer["found"] = true;
      answer["point"] = w.point;
      break;
    }
  }
  return answer;
}

std::string WitnessSpec(const OrthantWork& w, const Objective& o, const std::vector<std::vector<double>>& starts) {
  return nlohmann::json{{"kind", kWitnessJob}, {"l", w.index}, {"param", o.param}, {"dir", o.dir}, {"starts", starts},
                        {"rows", w.rows}}
      .dump();
}

std::vector<nlohmann::json> RunWitnessJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                                           int* solves) {
  std::vector<nlohmann::json> answers(jobs.size(), nlohmann::json::object());
  DispatchJobs(ctx, jobs, [&](std::size_t i, const nlohmann::json& answer, bool) {
    if (!answer.contains("job_error")) {
      answers[i] = answer;
      *solves += answer.value("solves", 0);
    }
    ctx.progress.Done();
  });
  return answers;
}

namespace {

// The bound of objective `o` that orthant l's box and sign constraints give alone.
double SignBoxBound(const HwOuterSet& set, const ParameterBox& box, int l, const Objective& o) {
  double bound = EdgeOf(box, o);
  const auto signs = set.orthant_signs(l);
  for (std::size_t k = 0; k < set.sign_polynomials().size(); ++k) {
    const auto& terms = set.sign_polynomials()[k].terms();
    if (terms.size() != 1) continue;
    const auto& [e, c] = *terms.begin();
    if (degree_of(e) != 1 || e[o.param] != 1 || c == 0.0) continue;
    const int sign_of_x = (c > 0 ? 1 : -1) * signs[k];  // sigma_k * c * x_k >= 0 in orthant l
    if (o.dir < 0 && sign_of_x > 0) bound = std::max(bound, 0.0);
    if (o.dir > 0 && sign_of_x < 0) bound = std::min(bound, 0.0);
  }
  return bound;
}

}  // namespace

std::optional<JobOutcome> SettleBySignBeyondWitness(const HwOuterSet& set, const OrthantWork& w, const Objective& o,
                                                    double witnessed) {
  if (std::isnan(witnessed)) return std::nullopt;
  const double sign_bound = SignBoxBound(set, w.box, w.index, o);
  if (o.dir < 0 ? sign_bound < witnessed : sign_bound > witnessed) return std::nullopt;
  return AtEdge(JobStatus::kSkipped, sign_bound, JobOrigin::kSignConstraint,
                fmt::format("the orthant's sign constraints bound {} at {:.9g}, at or beyond a certified feasible "
                            "value {:.9g}: it cannot move the endpoint", set.layout().names[o.param], sign_bound,
                            witnessed));
}

EdgeWitnessResult SettleEdgesByWitnesses(const EdgeWitnessOptions& options, EngineContext& ctx, PipelineState& state) {
  EdgeWitnessResult result;
  const std::vector<Objective>& objectives = state.objectives;
  const std::vector<OrthantWork>& orthants = state.orthants;
  if (!options.enabled || objectives.empty()) return result;
  const auto t0 = std::chrono::steady_clock::now();
  const HwOuterSet& set = ctx.set;
  std::vector<const OrthantWork*> live;
  std::map<int, const OrthantWork*> by_index;
  for (const auto& w : orthants)
    if (!w.empty()) live.push_back(&w), by_index[w.index] = &w;
  const int num_objectives = static_cast<int>(objectives.size());
  ctx.progress.Phase("feasible points at the box edges", static_cast<int>(live.size()) * num_objectives);
  // Wave 1, one job per orthant: the first objective from deterministic starts in the box finds a feasible
  // point (or none). Wave 2: every other objective from that point. Each job's starts are fixed before the wave
  // runs, so the points do not depend on which worker ran what.
  std::vector<std::pair<std::string, std::string>> first_jobs;
  for (const auto* w : live) {
    const auto starts = StartsInBox(w->box, options.random_starts, w->index);
    const std::string spec = WitnessSpec(*w, objectives[0], starts);
    first_jobs.push_back({spec, fmt::format("witness_l{}_o0", w->index)});
  }
  const auto first = RunWitnessJobs(ctx, first_jobs, &result.local_solves);
  std::vector<std::pair<std::string, std::string>> rest_jobs;
  std::vector<ObjectiveKey> rest_keys;
  std::map<ObjectiveKey, std::vector<double>> found;
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (!first[i].value("found", false)) {
      ctx.progress.Done(num_objectives - 1);  // no point of this orthant found: nothing to start from
      continue;
    }
    const auto p0 = first[i].at("point").get<std::vector<double>>();
    found[{live[i]->index, 0}] = p0;
    for (int j = 1; j < num_objectives; ++j) {
      const std::string spec = WitnessSpec(*live[i], objectives[j], {p0});
      rest_jobs.push_back({spec, fmt::format("witness_l{}_o{}", live[i]->index, j)});
      rest_keys.push_back({live[i]->index, j});
    }
  }
  const auto rest = RunWitnessJobs(ctx, rest_jobs, &result.local_solves);
  for (std::size_t i = 0; i < rest.size(); ++i)
    if (rest[i].value("found", false)) found[rest_keys[i]] = rest[i].at("point").get<std::vector<double>>();
  // Wave 3: an objective whose point stopped short of the edge starts again from the feasible point of its
  // orthant that is most extreme in its parameter (local searches from one start miss far parts of a thin set).
  std::vector<std::pair<std::string, std::string>> retry_jobs;
  std::vector<ObjectiveKey> retry_keys;
  for (const auto& [key, point] : std::map<ObjectiveKey, std::vector<double>>(found)) {
    const auto [l, j] = key;
    const OrthantWork* w = by_index.at(l);
    const int k = objectives[j].param, dir = objectives[j].dir;
    const double edge = EdgeOf(w->box, objectives[j]);
    if (std::abs(point[k] - edge) <= options.edge_tolerance * (w->box[k].second - w->box[k].first)) continue;
    const std::vector<double>* best = nullptr;
    for (const auto& [other_key, other] : found)
      if (other_key.first == l && (dir < 0 ? other[k] < point[k] : other[k] > point[k]) &&
          (!best || (dir < 0 ? other[k] < (*best)[k] : other[k] > (*best)[k])))
        best = &other;
    if (!best) continue;
    retry_jobs.push_back({WitnessSpec(*w, objectives[j], {*best}), fmt::format("witness_l{}_o{}_retry", l, j)});
    retry_keys.push_back(key);
  }
  if (!retry_jobs.empty())
    ctx.progress.Phase("feasible points at the box edges (second starts)", static_cast<int>(retry_jobs.size()));
  const auto retry = RunWitnessJobs(ctx, retry_jobs, &result.local_solves);
  for (std::size_t i = 0; i < retry.size(); ++i) {
    if (!retry[i].value("found", false)) continue;
    const auto p = retry[i].at("point").get<std::vector<double>>();
    const auto& o = objectives[retry_keys[i].second];
    auto& current = found[retry_keys[i]];
    if (o.dir < 0 ? p[o.param] < current[o.param] : p[o.param] > current[o.param]) current = p;
  }

  const std::vector<FeasiblePoint> certified = CertifiedFeasiblePoints(set, orthants, found);
  result.feasible_points = ExtremeFeasiblePoints(objectives, certified);
  if (options.stop_beyond_witnesses) state.witnessed = WitnessedExtremes(objectives, certified);
  // Certification here, whatever the workers said: the point must attain the edge and satisfy every row.
  std::map<int, int> edge_reached_in;  // objective -> orthant whose point attains the prior box edge
  for (const auto& [key, point] : found) {
    const auto [l, j] = key;
    if (edge_reached_in.count(j)) continue;
    const OrthantWork* w = by_index.at(l);
    const int k = objectives[j].param;
    const double edge = EdgeOf(w->box, objectives[j]);
    const double prior = EdgeOf(set.box(), objectives[j]);
    const double width = w->box[k].second - w->box[k].first;
    if (edge != prior || point.size() != static_cast<std::size_t>(set.num_vars()) ||
        std::abs(point[k] - edge) > options.edge_tolerance * width)
      continue;
    std::vector<double> p = point;
    p[k] = edge;  // onto the edge exactly; the check below is of this point
    const double slack = CertifiedMinSlack(set, l, p);
    if (!(slack >= 0)) continue;
    std::string text;
    for (std::size_t i = 0; i < p.size(); ++i) text += fmt::format("{}{} = {:.9g}", i ? ", " : "", set.layout().names[i], p[i]);
    state.settled[key] = AtEdge(JobStatus::kSolved, edge, JobOrigin::kFeasiblePointAtEdge,
                                 fmt::format("a feasible point attains the prior box edge (certified min slack "
                                             "{:.3g}): {}", slack, text));
    result.points[key] = p;
    edge_reached_in[j] = l;
  }
  // The other live orthants cannot move an endpoint that is already at the prior box edge.
  for (const auto& [j, l] : edge_reached_in)
    for (const auto* w : live)
      if (w->index != l)
        state.settled[{w->index, j}] =
            AtEdge(JobStatus::kSkipped, EdgeOf(set.box(), objectives[j]), JobOrigin::kEdgeInOtherOrthant,
                   fmt::format("the interval already reaches the prior box edge (feasible point in orthant {})", l));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace hw::dss
