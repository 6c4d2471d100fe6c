// How the Esmaeilani SQP scales with the number of samples: a fixed 10 SQP iterations on the
// simulated valve case with 1..8 closing operations of 100 samples (about 510 unknowns each).
// Reports per-iteration time and the share spent inside Ipopt's QP solves.
#include <benchmark/benchmark.h>

#include "estimators/esmaeilani/estimator.hpp"
#include "estimators/esmaeilani/valve_case.hpp"

namespace {

void BM_EsmaeilaniValveSqp(benchmark::State& state) {
  using namespace hw::esmaeilani;
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

}  // namespace

BENCHMARK_MAIN();
