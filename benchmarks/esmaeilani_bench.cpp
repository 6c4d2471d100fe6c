// Esmaeilani SQP benchmarks (medians of 3 repetitions, one run):
// 1. BM_EsmaeilaniValveSqp: scaling with the number of samples, a fixed 10 SQP iterations on the simulated
//    valve case with 1..8 closing operations of 100 samples; per-run time and the share inside the QPs.
// 2. BM_QpBackend: the per-iteration convex QP by Ipopt (default) and by CGAL's exact QP solver (Gmpzf) on
//    the same problems: one closing operation of 30 samples, 6 + 6 ordered pairs (139 unknowns), 2 SQP
//    iterations. CGAL is run only at this size: at 179 unknowns 3 iterations already took 79 s (Ipopt
//    0.14 s). Counters: qp_seconds, final_cost (the two must agree), and for CGAL ratio_to_ipopt
//    (median QP time / Ipopt's median QP time in this run).
// 3. BM_OutputErrorRefinement: the optional output-error refinement (10 Levenberg-Marquardt iterations,
//    forward-difference Jacobian, one Ipopt QP per trial step) from a 10-iteration SQP estimate, valve
//    case with 1..8 closing operations of 100 samples; second argument 1 = initial states estimated
//    (3 more parameters per operation). Counters: parameters, iterations, qp_solves, qp_share.
#include <algorithm>
#include <map>
#include <vector>

#include <benchmark/benchmark.h>

#include "estimators/esmaeilani/estimator.hpp"
#include "estimators/esmaeilani/valve_case.hpp"

namespace {

using namespace hw::esmaeilani;

void BM_EsmaeilaniValveSqp(benchmark::State& state) {
  ValveCase valve;
  std::vector<Segment> segs;
  for (int k = 0; k < state.range(0); ++k) segs.push_back(valve.ClosingOperation(2000 + k, 100));
  Options opt;
  opt.max_iterations = 10;
  opt.relative_decrease = 1e-300;  // always run the 10 iterations
  double qp = 0.0, total = 0.0;
  int unknowns = 0;
  for (auto _ : state) {
    Summary sum;
    Estimate(opt, segs, valve.KnownInformation(), &sum);
    qp += sum.qp_seconds;
    total += sum.seconds;
    unknowns = sum.unknowns;
  }
  state.counters["unknowns"] = unknowns;
  state.counters["qp_share"] = qp / total;
}
BENCHMARK(BM_EsmaeilaniValveSqp)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond)->Repetitions(3)
    ->ReportAggregatesOnly(true);

std::vector<double> ipopt_qp_seconds;  // per repetition of the Ipopt case (it runs first)

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

void BM_QpBackend(benchmark::State& state) {
  const bool cgal = state.range(0) == 1;
  ValveCase valve;
  const std::vector<Segment> segs = {valve.ClosingOperation(2000, 30)};
  Options opt;
  opt.grid_f = opt.grid_g = 6;
  opt.max_iterations = 2;
  opt.relative_decrease = 1e-300;
  opt.qp.backend = cgal ? QpOptions::Backend::kCgal : QpOptions::Backend::kIpopt;
  Summary sum;
  for (auto _ : state) Estimate(opt, segs, valve.KnownInformation(), &sum);
  state.counters["unknowns"] = sum.unknowns;
  state.counters["qp_seconds"] = sum.qp_seconds;
  state.counters["final_cost"] = sum.final_cost;
  state.counters["solved"] = sum.ok() && sum.qp_solves == 2 ? 1 : 0;
  if (!cgal) {
    ipopt_qp_seconds.push_back(sum.qp_seconds);
  } else if (!ipopt_qp_seconds.empty()) {
    state.counters["ratio_to_ipopt"] = sum.qp_seconds / Median(ipopt_qp_seconds);
  }
}
BENCHMARK(BM_QpBackend)->ArgName("cgal")->Arg(0)->Arg(1)->Iterations(1)->Repetitions(3)
    ->Unit(benchmark::kMillisecond)->ReportAggregatesOnly(true);

void BM_OutputErrorRefinement(benchmark::State& state) {
  ValveCase valve;
  std::vector<Segment> segs;
  for (int k = 0; k < state.range(0); ++k) segs.push_back(valve.ClosingOperation(2000 + k, 100));
  Options opt;
  opt.max_iterations = 10;
  const EsmaeilaniModel start = Estimate(opt, segs, valve.KnownInformation(), nullptr);
  opt.oe_max_iterations = 10;
  opt.oe_estimate_initial_states = state.range(1) == 1;
  opt.relative_decrease = 1e-300;  // run the 10 iterations unless no descent is found
  double qp = 0.0, total = 0.0;
  OutputErrorSummary sum;
  for (auto _ : state) {
    RefineOutputError(opt, segs, valve.KnownInformation(), start, &sum);
    qp += sum.qp_seconds;
    total += sum.seconds;
  }
  state.counters["parameters"] = sum.parameters;
  state.counters["iterations"] = sum.iterations;
  state.counters["qp_solves"] = sum.qp_solves;  // trial steps (rejected ones included) of the last run
  state.counters["qp_share"] = qp / total;
}
BENCHMARK(BM_OutputErrorRefinement)->ArgNames({"ops", "x0"})->ArgsProduct({{1, 2, 4, 8}, {0, 1}})
    ->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
