#include "dss/bounds_options.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dss/hw_outer_set.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::dss {
namespace {

// Sets *error (when given) and returns false: the tail of every IsValid-style check below.
bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

}  // namespace

bool ValidOrder(int order, int horizon, std::string* error) {
  const int minimal = MinimalOrder(horizon);
  if (order < minimal)
    return Fail(error, fmt::format("order {} is below the minimal order ceil((n+1)/2) = {} of horizon {}; leave the "
                                   "order unset for the minimal order",
                                   order, minimal, horizon));
  if (order > kMaxOrder)
    return Fail(error, fmt::format("order {} is above the largest relaxation order {}", order, kMaxOrder));
  return true;
}

bool ValidThreads(int threads, std::string* error) {
  if (threads >= 0) return true;
  return Fail(error, fmt::format("threads {} is negative; give 0 (one job per core) or the number of jobs", threads));
}

bool ValidContractionPasses(int passes, std::string* error) {
  if (passes >= 0 && passes <= 10) return true;
  return Fail(error, fmt::format("contraction_passes {} is out of range 0..10 (0 = no box contraction)", passes));
}

bool ValidStoppedShortRefinements(int refinements, std::string* error) {
  if (refinements >= 0) return true;
  return Fail(error, fmt::format("stopped_short_refinements {} is negative; give 0 (never) or more", refinements));
}

bool ValidEndpointRefinements(int refinements, std::string* error) {
  if (refinements >= 0 && refinements <= kMaxEndpointRefinements) return true;
  return Fail(error, fmt::format("endpoint_refinements {} is out of range 0..{} (0 = never)", refinements,
                                 kMaxEndpointRefinements));
}

bool ValidBoundsSolver(const std::string& name, std::string* error) {
  if (name == "auto") return true;
  if (sdp::ValidSolverName(name, nullptr)) return true;
  return Fail(error, fmt::format("solver '{}' unknown; expected auto (a backend per relaxation), {}", name,
                                 fmt::join(sdp::AvailableSolvers(), ", ")));
}

std::string SolverForOrder(const std::string& name, int /*order*/, int /*block_order_cap*/) {
  return name == "auto" ? "csdp" : name;
}

bool ValidAutoSplitRounds(int rounds, const std::string& executor, std::string* error) {
  if (rounds < 0 || rounds > 5) return Fail(error, fmt::format("auto split: {} rounds; expected 0 (off) to 5", rounds));
  if (rounds > 0 && executor == "mpi")
    return Fail(error, "auto split: not under the mpi executor (its worker ranks cannot follow the cuts the "
                       "coordinator chooses); use the fork executor, or give the cuts as a split");
  return true;
}

std::vector<SettingCheck> SettingChecks(const BoundsSettings& s) {
  std::vector<SettingCheck> checks;
  if (s.horizon) checks.push_back({"--horizon", [h = *s.horizon](std::string* e) { return ValidHorizon(h, e); }});
  if (s.horizon && s.order)
    checks.push_back({"--order", [d = *s.order, h = *s.horizon](std::string* e) { return ValidOrder(d, h, e); }});
  checks.push_back({"--solver", [s](std::string* e) { return ValidBoundsSolver(s.solver, e); }});
  checks.push_back({"--threads", [s](std::string* e) { return ValidThreads(s.threads, e); }});
  if (s.executor)
    checks.push_back({"--executor", [s](std::string* e) { return sdp::ValidExecutorName(*s.executor, e); }});
  checks.push_back({"--contract-passes", [s](std::string* e) { return ValidContractionPasses(s.contraction_passes, e); }});
  checks.push_back({"--row-block-order", [s](std::string* e) { return pop::ValidBlockOrderCap(s.row_block_order, e); }});
  checks.push_back({"--stopped-short-refinements",
                    [s](std::string* e) { return ValidStoppedShortRefinements(s.stopped_short_refinements, e); }});
  checks.push_back({"--endpoint-refinements",
                    [s](std::string* e) { return ValidEndpointRefinements(s.endpoint_refinements, e); }});
  if (s.auto_split_rounds)
    checks.push_back({"--auto-split", [s](std::string* e) {
                        return ValidAutoSplitRounds(*s.auto_split_rounds, s.executor.value_or(""), e);
                      }});
  return checks;
}

bool BoundsOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) { return Fail(error, std::move(m)); };
  if (order < 1 || order > kMaxOrder) return fail(fmt::format("order {} is out of range 1..{}", order, kMaxOrder));
  BoundsSettings settings;
  settings.solver = solver;
  settings.threads = threads;
  settings.contraction_passes = contraction_passes;
  settings.row_block_order = generation.block_order_cap;
  settings.stopped_short_refinements = stopped_short_refinements;
  settings.endpoint_refinements = endpoint_refinements;
  for (const auto& check : SettingChecks(settings))
    if (!check.valid(error)) return false;
  if (contraction_max_rounds < 1) return fail("contraction_max_rounds must be >= 1");
  if (!(contraction_min_shrink >= 0 && contraction_min_shrink < 1)) return fail("contraction_min_shrink must lie in [0, 1)");
  if (!reduction.IsValid(error)) return false;
  if (!edge_witness.IsValid(error)) return false;
  return generation.IsValid(error);
}

}  // namespace hw::dss
