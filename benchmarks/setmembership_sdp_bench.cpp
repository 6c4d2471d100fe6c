// One set-membership relaxation (paper-001 example, true orthant, min a1) with K data inequalities in
// the LMI: build and solve time for CSDP and SDPA as K and the order grow. A timing harness, not a test.
//   setmembership_sdp_bench [--samples N] [--horizon n] [--order d] [--k 10,40,160] [--repeats R]
#include <algorithm>
#include <chrono>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "relax/hw_outer_set.hpp"
#include "relax/moment_relaxation.hpp"

namespace {
using Clock = std::chrono::steady_clock;
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Set-membership SDP size/time harness"};
  int samples = 300, horizon = 2, order = 2, repeats = 1;
  std::string ks = "10,40,160";
  app.add_option("--samples", samples);
  app.add_option("--horizon", horizon);
  app.add_option("--order", order);
  app.add_option("--k", ks);
  app.add_option("--repeats", repeats);
  CLI11_PARSE(app, argc, argv);
  const auto ex = hw::SimulateCeroneExample(1, samples);
  const hw::relax::HwStructure s = hw::relax::CeroneExampleStructure();
  hw::relax::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
  hw::relax::HwOuterSet set(s, data, horizon, std::vector<std::pair<double, double>>(8, {-10, 10}));
  const int l = set.orthant_of(hw::CeroneExample::TrueParameters());
  const auto cons = set.data_constraints(l);
  fmt::print("N={} n={} order={} true orthant {} ({} data inequalities)\n", samples, horizon, order, l, cons.size());
  fmt::print("{:>5} {:>8} {:>7} {:>10} {:>9} {:>6} {:>9} {:>6} {:>10} {:>12} {:>12}\n", "K", "moments", "blocks", "nnz",
             "CSDP s", "it", "SDPA s", "it", "CSDP/SDPA", "CSDP bound", "SDPA bound");
  std::stringstream kss(ks);
  std::string item;
  while (std::getline(kss, item, ',')) {
    const int K = std::min<int>(std::stoi(item), cons.size());
    hw::relax::PolyProblem p;
    p.num_vars = 8;
    p.objective = hw::Polynomial::Variable(8, set.layout().a_begin);
    p.inequalities = set.box_constraints();
    for (auto& g : set.sign_constraints(l)) p.inequalities.push_back(g);
    // Spread the K constraints over the record.
    for (int k = 0; k < K; ++k) p.inequalities.push_back(cons[static_cast<std::size_t>(k) * cons.size() / K].g);
    hw::relax::MomentRelaxation r(p, order);
    std::vector<double> tc, ts;
    int itc = 0, its = 0;
    double bc = 0, bs = 0;
    for (int rep = 0; rep < repeats; ++rep) {
      auto csdp = hw::sdp::MakeSolver("csdp");
      auto sdpa = hw::sdp::MakeSolver("sdpa");
      const auto a = csdp->Solve({}, r.lmi());
      const auto b = sdpa->Solve({}, r.lmi());
      tc.push_back(a.solve_seconds);
      ts.push_back(b.solve_seconds);
      itc = a.iterations;
      its = b.iterations;
      bc = set.scaling().to_original(set.layout().a_begin, a.lower_bound);
      bs = set.scaling().to_original(set.layout().a_begin, b.lower_bound);
    }
    fmt::print("{:>5} {:>8} {:>7} {:>10} {:>9.2f} {:>6} {:>9.2f} {:>6} {:>10.2f} {:>12.6f} {:>12.6f}\n", K, r.lmi().c.size(),
               r.lmi().blocks.size(), r.lmi().nonzeros(), median(tc), itc, median(ts), its, median(tc) / median(ts), bc, bs);
  }
  return 0;
}
