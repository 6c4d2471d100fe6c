#include "paper_examples/cerone/inner_hull.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "core/progress_throttle.hpp"
#include "dss/edge_witness.hpp"

namespace hw::cerone {

bool InnerHullOptions::IsValid(std::string* error) const {
  if (random_starts < 0) return *error = "inner hull: random_starts must be >= 0", false;
  if (restart_rounds < 0) return *error = "inner hull: restart_rounds must be >= 0", false;
  if (!(spread >= 0 && spread <= 10)) return *error = "inner hull: spread must be in [0, 10]", false;
  return local.IsValid(error);
}

Witness CertifyWitness(const dss::HwOuterSet& set, std::vector<double> point) {
  Witness w;
  if (point.size() != static_cast<std::size_t>(set.num_vars())) return w;
  for (std::size_t i = 0; i < point.size(); ++i) {
    if (!std::isfinite(point[i])) return w;
    point[i] = std::clamp(point[i], set.box()[i].first, set.box()[i].second);  // Ipopt may relax bounds by 1e-8
  }
  const int l = set.orthant_of(point);
  const double slack = dss::CertifiedMinSlack(set, l, point);
  if (!(slack >= 0)) return w;
  w.point = std::move(point);
  w.orthant = l;
  w.certified_slack = slack;
  return w;
}

namespace {

// The certified witnesses found so far and the local searches that produced them.
class WitnessPool {
 public:
  WitnessPool(const dss::HwOuterSet& set, const InnerHullOptions& options) : set_(set), options_(options) {}

  // Adds the point when it certifies, found by objective `origin` (-1: none).
  void Add(const std::vector<double>& point, int origin) {
    Witness w = CertifyWitness(set_, point);
    if (w.point.empty()) return;
    witnesses_.push_back(std::move(w));
    origins_.push_back(origin);
  }
  // Objective `origin` extremises parameter k in direction dir from `start`, in the start's orthant (or
  // `orthant` when >= 0).
  void Search(int origin, int k, int dir, const std::vector<double>& start, int orthant = -1) {
    const int l = orthant >= 0 ? orthant : set_.orthant_of(start);
    const auto found = dss::LocalExtreme(set_, l, k, dir, start, options_.local);
    ++solves_;
    if (found.found) Add(found.point, origin);
  }
  // Index of the witness most extreme in parameter k (dir < 0: smallest); -1 without witnesses.
  int Extreme(int k, int dir) const {
    int best = -1;
    for (int i = 0; i < static_cast<int>(witnesses_.size()); ++i)
      if (best < 0 || dir * (witnesses_[i].point[k] - witnesses_[best].point[k]) > 0) best = i;
    return best;
  }
  // The box spanned by the witnesses, widened by `spread` of each side's width, within the prior box.
  std::vector<std::pair<double, double>> WidenedHullBox() const {
    std::vector<std::pair<double, double>> box = set_.box();
    if (witnesses_.empty()) return box;
    for (int k = 0; k < set_.num_vars(); ++k) {
      const double lo = witnesses_[Extreme(k, -1)].point[k], hi = witnesses_[Extreme(k, +1)].point[k];
      const double pad = options_.spread * (hi - lo);
      box[k] = {std::max(box[k].first, lo - pad), std::min(box[k].second, hi + pad)};
    }
    return box;
  }
  const std::vector<Witness>& witnesses() const { return witnesses_; }
  int origin(int i) const { return origins_[i]; }
  int solves() const { return solves_; }

 private:
  const dss::HwOuterSet& set_;
  const InnerHullOptions& options_;
  std::vector<Witness> witnesses_;
  std::vector<int> origins_;
  int solves_ = 0;
};

std::vector<std::pair<int, int>> Objectives(const std::vector<int>& params) {
  std::vector<std::pair<int, int>> objectives;
  for (int k : params)
    for (int dir : {-1, +1}) objectives.push_back({k, dir});
  return objectives;
}

InnerInterval HullOf(const dss::HwOuterSet& set, const WitnessPool& pool, int k) {
  InnerInterval iv;
  iv.name = set.layout().names[k];
  iv.param = k;
  const int lo = pool.Extreme(k, -1), hi = pool.Extreme(k, +1);
  if (lo < 0) return iv;
  iv.found = true;
  iv.lower_witness = pool.witnesses()[lo];
  iv.upper_witness = pool.witnesses()[hi];
  iv.lower = iv.lower_witness.point[k];
  iv.upper = iv.upper_witness.point[k];
  return iv;
}

}  // namespace

InnerHull ComputeInnerHull(const dss::HwOuterSet& set, const std::vector<double>& truth,
                           const std::vector<int>& params, const InnerHullOptions& options,
                           const std::vector<std::vector<double>>& given,
                           const std::function<void(const std::string&)>& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<int> wanted = params;
  if (wanted.empty())
    for (int k = 0; k < set.num_vars(); ++k) wanted.push_back(k);
  const auto objectives = Objectives(wanted);
  WitnessPool pool(set, options);
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  ProgressThrottle throttle(10.0);
  auto report = [&](const char* stage, std::size_t done, bool stage_end) {
    const double now = seconds();
    if (!progress || !throttle.Due(now, stage_end)) return;
    progress(fmt::format("  [inner hull: {}] {} of {} objectives, {} local solves, {:.0f} s", stage, done,
                         objectives.size(), pool.solves(), now));
  };
  pool.Add(truth, -1);
  const std::size_t before_given = pool.witnesses().size();
  for (const auto& p : given) pool.Add(p, -1);
  const int given_witnesses = static_cast<int>(pool.witnesses().size() - before_given);
  // 1. From the truth, in its orthant.
  const int truth_orthant = set.orthant_of(truth);
  for (std::size_t j = 0; j < objectives.size(); ++j) {
    pool.Search(static_cast<int>(j), objectives[j].first, objectives[j].second, truth, truth_orthant);
    report("from the truth", j + 1, j + 1 == objectives.size());
  }
  // 2. From pseudo-random points around the hull (fixed before the searches, so the order does not matter).
  const auto box = pool.WidenedHullBox();
  for (std::size_t j = 0; j < objectives.size(); ++j) {
    for (const auto& start : dss::PseudoRandomPointsInBox(box, options.random_starts, options.seed * 1000003u + j))
      pool.Search(static_cast<int>(j), objectives[j].first, objectives[j].second, start);
    report("pseudo-random starts", j + 1, j + 1 == objectives.size());
  }
  // 3. From a more extreme witness that another objective's search found.
  std::vector<int> restarted_from(objectives.size(), -1);
  for (int round = 0; round < options.restart_rounds; ++round)
    for (std::size_t j = 0; j < objectives.size(); ++j) {
      const auto [k, dir] = objectives[j];
      const int best = pool.Extreme(k, dir);
      if (best < 0 || pool.origin(best) == static_cast<int>(j) || best == restarted_from[j]) continue;
      restarted_from[j] = best;
      const std::vector<double> start = pool.witnesses()[best].point;  // a copy: Search appends to the pool
      pool.Search(static_cast<int>(j), k, dir, start);
      report("restarts", j + 1, false);
    }
  InnerHull hull;
  for (int k : wanted) hull.intervals.push_back(HullOf(set, pool, k));
  hull.witnesses = static_cast<int>(pool.witnesses().size());
  hull.given_witnesses = given_witnesses;
  hull.local_solves = pool.solves();
  hull.seconds = seconds();
  return hull;
}

}  // namespace hw::cerone
