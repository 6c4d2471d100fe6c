// Build and solve time of dense moment relaxations as the number of variables and the order grow,
// CSDP vs SDPA. A timing harness (not a test): prints medians over repeats and the CSDP/SDPA ratio.
//   relaxation_bench [--repeats R] [--max-vars N] [--max-order D]
#include <algorithm>
#include <chrono>
#include <random>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "pop/moment_relaxation.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Random dense quartic over the unit ball: min f s.t. 1 - |x|^2 >= 0.
hw::pop::PolyProblem RandomProblem(int n, std::mt19937& rng) {
  std::normal_distribution<double> g;
  hw::pop::PolyProblem p;
  p.num_vars = n;
  p.objective = hw::Polynomial(n);
  hw::MonomialBasis basis(n, 4);
  for (const auto& e : basis.monomials()) p.objective.add_term(e, g(rng));
  auto ball = hw::Polynomial::Constant(n, 1.0);
  for (int i = 0; i < n; ++i) ball -= hw::Polynomial::Variable(n, i) * hw::Polynomial::Variable(n, i);
  p.inequalities.push_back(ball);
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Dense moment relaxations: build and solve time, CSDP vs SDPA"};
  int repeats = 3, max_vars = 5, max_order = 3;
  app.add_option("--repeats", repeats);
  app.add_option("--max-vars", max_vars);
  app.add_option("--max-order", max_order);
  CLI11_PARSE(app, argc, argv);
  std::mt19937 rng(1);
  fmt::print("{:>4} {:>5} {:>8} {:>7} {:>10} {:>10} {:>10} {:>12} {:>10}\n", "vars", "order", "moments", "nnz",
             "build ms", "CSDP s", "SDPA s", "CSDP/SDPA", "agree");
  for (int n = 2; n <= max_vars; ++n) {
    for (int order = 2; order <= max_order; ++order) {
      const auto problem = RandomProblem(n, rng);
      std::vector<double> build, t_csdp, t_sdpa;
      double diff = 0.0;
      std::size_t moments = 0, nnz = 0;
      for (int r = 0; r < repeats; ++r) {
        const auto t0 = Clock::now();
        hw::pop::MomentRelaxation relaxation(problem, order);
        build.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        moments = relaxation.lmi().c.size();
        nnz = relaxation.lmi().nonzeros();
        double values[2];
        int k = 0;
        for (const std::string name : {"csdp", "sdpa"}) {
          auto solver = hw::sdp::MakeSolver(name);
          const auto t1 = Clock::now();
          const auto s = solver->Solve({}, relaxation.lmi());
          (k == 0 ? t_csdp : t_sdpa).push_back(std::chrono::duration<double>(Clock::now() - t1).count());
          values[k++] = s.lower_bound;
        }
        diff = std::max(diff, std::abs(values[0] - values[1]) / std::max(1.0, std::abs(values[1])));
      }
      fmt::print("{:>4} {:>5} {:>8} {:>7} {:>10.2f} {:>10.3f} {:>10.3f} {:>12.2f} {:>10.1e}\n", n, order, moments, nnz,
                 median(build), median(t_csdp), median(t_sdpa), median(t_csdp) / median(t_sdpa), diff);
    }
  }
  return 0;
}
