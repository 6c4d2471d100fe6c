#include "exact/inner_hull.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "exact/band_nlp.hpp"
#include "exact/membership.hpp"
#include "exact/model_response.hpp"

namespace hw::exact {
namespace {

// A fixed-seed generator for the perturbed starts (results must not depend on the platform's distributions).
class Lcg {
 public:
  explicit Lcg(uint64_t seed) : state_(0x9E3779B97F4A7C15ull ^ (seed * 0xBF58476D1CE4E5B9ull)) {}
  double uniform(double lo, double hi) {
    state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<double>(state_ >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_;
};

struct Certified {
  std::vector<double> theta;
  std::vector<double> initial_state;
  double slack = 0.0;
  std::string objective;
};

// The margin each band end keeps in the local search, so that a point the NLP reports as feasible within
// its tolerance is still inside every band: a millionth of the narrowest band at the start.
double SearchMargin(const LiftedData& data, const std::vector<double>& theta) {
  const BandEnds bands = ComputeBandEnds(data, DecodeTheta(data, theta));
  double width = std::numeric_limits<double>::infinity();
  for (int t = 0; t < data.num_samples; ++t) width = std::min(width, bands.hi[t] - bands.lo[t]);
  return width > 0 && std::isfinite(width) ? 1e-6 * width : 0.0;
}

class HullSearch {
 public:
  HullSearch(const LiftedData& data, const ParamBox& box, const InnerHullOptions& options, LpSolver& solver)
      : data_(data), box_(box), options_(options), solver_(solver), n_(data.layout.count()),
        best_(2 * n_, -1), clock_start_(std::chrono::steady_clock::now()) {}

  // The certified point from `theta` (nullopt when it is not in D).
  std::optional<Certified> Certify(const std::vector<double>& theta, const std::string& objective) {
    const MembershipResult r = CheckMembership(data_, theta, solver_);
    if (!r.member) return std::nullopt;
    return Certified{theta, r.initial_state, r.slack, objective};
  }

  void Add(Certified point) {
    points_.push_back(std::move(point));
    const int id = static_cast<int>(points_.size()) - 1;
    for (int k = 0; k < n_; ++k)
      for (int dir : {1, -1}) {
        int& b = best_[Slot(k, dir)];
        if (b < 0 || dir * (points_[id].theta[k] - points_[b].theta[k]) > 0) b = id;
      }
  }

  // One local solve for (k, dir) from theta with the initial state z0. The result is added when it is in D;
  // otherwise the first point of D on the segment from `anchor` (a certified point; none: nullptr) towards it.
  void LocalSolve(int k, int dir, const std::vector<double>& theta, const std::vector<double>& z0,
                  const std::vector<double>* anchor) {
    if (TimeLeft() <= 0) return;
    BandNlpRequest request{k, dir, theta, z0, SearchMargin(data_, theta), TimeLeft()};
    const BandNlpResult r = SolveBandNlp(data_, box_, request);
    ++local_solves_;
    if (!r.returned) return;
    const std::string objective = fmt::format("{} {}", dir > 0 ? "max" : "min", data_.layout.names[k]);
    if (auto c = Certify(r.theta, objective)) return Add(std::move(*c));
    if (!anchor) return;
    for (double step : {1 - 1e-9, 1 - 1e-7, 1 - 1e-5, 1 - 1e-3, 0.9, 0.5}) {
      std::vector<double> p(n_);
      for (int i = 0; i < n_; ++i) p[i] = (*anchor)[i] + step * (r.theta[i] - (*anchor)[i]);
      if (auto c = Certify(p, objective + " (backtracked)")) return Add(std::move(*c));
    }
  }

  // A start for restart `round` of (k, dir): the objective's best point or another certified point, moved by
  // up to a quarter of the current range of each parameter (a point near D; the NLP restores feasibility).
  std::pair<std::vector<double>, std::vector<double>> PerturbedStart(int k, int dir, int round) {
    Lcg rng(static_cast<uint64_t>(Slot(k, dir)) * 1000 + round);
    const int pick = round % 2 ? best_[Slot(k, dir)]
                               : static_cast<int>(rng.uniform(0, static_cast<double>(points_.size()) - 1e-9));
    std::vector<double> theta = points_[pick].theta;
    for (int i = 0; i < n_; ++i) {
      const double spread = points_[best_[Slot(i, 1)]].theta[i] - points_[best_[Slot(i, -1)]].theta[i];
      theta[i] = std::clamp(theta[i] + 0.25 * spread * rng.uniform(-1, 1), box_[i].lo, box_[i].hi);
    }
    const MembershipResult r = CheckMembership(data_, theta, solver_);
    return {theta, r.initial_state.empty() ? points_[pick].initial_state : r.initial_state};
  }

  InnerHull Result() const {
    InnerHull hull;
    hull.ranges.assign(n_, std::nullopt);
    std::vector<bool> extreme(points_.size(), false);
    for (int k = 0; k < n_ && !points_.empty(); ++k) {
      hull.ranges[k] = std::pair{points_[best_[Slot(k, -1)]].theta[k], points_[best_[Slot(k, 1)]].theta[k]};
      extreme[best_[Slot(k, -1)]] = extreme[best_[Slot(k, 1)]] = true;
    }
    for (std::size_t i = 0; i < points_.size(); ++i)
      if (extreme[i]) hull.points.push_back({points_[i].theta, points_[i].slack, points_[i].objective});
    hull.local_solves = local_solves_;
    hull.seconds = Elapsed();
    return hull;
  }

  bool empty() const { return points_.empty(); }
  int num_params() const { return n_; }
  const Certified& best(int k, int dir) const { return points_[best_[Slot(k, dir)]]; }
  double TimeLeft() const { return options_.time_limit_seconds - Elapsed(); }

 private:
  int Slot(int k, int dir) const { return 2 * k + (dir > 0 ? 0 : 1); }
  double Elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start_).count();
  }
  const LiftedData& data_;
  const ParamBox& box_;
  const InnerHullOptions& options_;
  LpSolver& solver_;
  int n_;
  std::vector<Certified> points_;
  std::vector<int> best_;  // per (parameter, direction): index into points_
  int local_solves_ = 0;
  std::chrono::steady_clock::time_point clock_start_;
};

}  // namespace

bool InnerHullOptions::IsValid(std::string* error) const {
  if (restarts < 0) {
    if (error) *error = fmt::format("inner hull: restarts must be >= 0, not {}", restarts);
    return false;
  }
  if (!(time_limit_seconds > 0)) {
    if (error) *error = fmt::format("inner hull: the time limit must be positive, not {}", time_limit_seconds);
    return false;
  }
  return true;
}

InnerHull ComputeInnerHull(const LiftedData& data, const ParamBox& box, const std::vector<double>& start,
                           const InnerHullOptions& options, LpSolver& solver) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  const int n = data.layout.count();
  if (static_cast<int>(box.size()) != n || static_cast<int>(start.size()) != n)
    throw std::invalid_argument(fmt::format("inner hull: the box has {} and the start {} entries; the layout has {}",
                                            box.size(), start.size(), n));
  HullSearch search(data, box, options, solver);
  const MembershipResult at_start = CheckMembership(data, start, solver);
  bool start_in_box = true;
  for (int k = 0; k < n; ++k) start_in_box = start_in_box && box[k].contains(start[k]);
  const bool start_in_d = at_start.member && start_in_box;  // the hull's points stay in the box
  if (start_in_d) search.Add({start, at_start.initial_state, at_start.slack, "start"});
  const std::vector<double> z0 = at_start.initial_state.empty()
                                     ? std::vector<double>(InitialStateSize(data), 0.0)
                                     : at_start.initial_state;
  for (int k = 0; k < n; ++k)
    for (int dir : {1, -1}) search.LocalSolve(k, dir, start, z0, start_in_d ? &start : nullptr);
  for (int round = 1; round <= options.restarts && !search.empty(); ++round)
    for (int k = 0; k < n; ++k)
      for (int dir : {1, -1}) {
        const auto [theta, initial] = search.PerturbedStart(k, dir, round);
        const std::vector<double> best = search.best(k, dir).theta;  // a copy: adding points moves them
        search.LocalSolve(k, dir, theta, initial, &best);
      }
  return search.Result();
}

}  // namespace hw::exact
